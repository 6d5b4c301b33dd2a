"""The minimum of a loop's re-simulated error over two coefficients, by grids.

A stick-slip loop's position error is rugged in its coefficients (each stick and slip moves with
them), so a descent stops in its first dip; a grid over the whole range, then finer grids about
its best point, finds the valley. Used by the refinements that fit two coefficients on the
fitting record's loop (presliding's stiffness and damping, a resonance's load mass and damping)."""
from __future__ import annotations

import numpy as np

FINE = 5    # points per coefficient of each finer grid


def grid_minimum(cost, xs: np.ndarray, ys: np.ndarray, rounds: int,
                 y_range: tuple[float, float] | None = None) -> tuple[float, float, float]:
    """(cost, x, y) at the smallest ``cost(x, y)`` over the grid ``xs`` x ``ys`` (evenly spaced),
    then ``rounds`` FINE x FINE grids about the best point so far, one grid step of the previous
    grid to each side, each half as wide as the one before; x never beyond xs[-1], y within
    ``y_range`` where given. Points are evaluated once each (cached): at most
    len(xs) len(ys) + rounds (FINE^2 - 1) calls."""
    cache = {}

    def at(x, y):
        key = (round(float(x), 9), round(float(y), 9))
        if key not in cache:
            cache[key] = float(cost(float(x), float(y)))
        return cache[key], float(x), float(y)
    best = min(at(a, b) for a in xs for b in ys)
    dx, dy = xs[1] - xs[0], ys[1] - ys[0]
    for _ in range(rounds):
        bs = np.linspace(best[2] - dy, best[2] + dy, FINE)
        if y_range is not None:
            bs = np.clip(bs, *y_range)
        best = min([best] + [at(a, b) for a in np.linspace(best[1] - dx, min(best[1] + dx, xs[-1]), FINE) for b in bs])
        dx, dy = dx / 2, dy / 2
    return best
