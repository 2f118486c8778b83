"""How it is filtered: the Kalman filter, resamplers and particle-set diagnostics."""

__all__: list[str] = []
