"""Event-driven integration of piecewise-smooth systems (numba kernels)."""
from .simulate import simulate

__all__ = ["simulate"]
