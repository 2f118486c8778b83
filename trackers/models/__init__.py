"""What is filtered: observation models (protocol, colour histograms), dynamics, layers."""

__all__ = ["dynamics", "layered", "observation"]
