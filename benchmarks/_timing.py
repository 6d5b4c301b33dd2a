"""Timing helper shared by the benchmarks (ratios in one process, never wall-clock assertions)."""
from __future__ import annotations

import time


def best_of(fn, repeat: int = 5):
    """(shortest wall time [s] of ``repeat`` calls of fn, the last call's result)."""
    times = []
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out
