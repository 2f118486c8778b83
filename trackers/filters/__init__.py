"""How it is filtered: the Kalman filter, resamplers, weight normaliser, set diagnostics."""

__all__ = ["diagnostics", "kalman", "resampling", "weights"]
