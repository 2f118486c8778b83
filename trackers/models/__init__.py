"""What is filtered: observation models (colour histograms), dynamics, layered templates."""

__all__: list[str] = []
