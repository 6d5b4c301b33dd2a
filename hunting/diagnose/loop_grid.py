"""The minimum of a loop's re-simulated error over two coefficients, by grids.

A stick-slip loop's position error is rugged in its coefficients (each stick and slip moves with
them), so a descent stops in its first dip; a grid over the whole range, then finer grids about
its best point, finds the valley. Used by the refinements that fit two coefficients on the
fitting record's loop (presliding's stiffness and damping, a resonance's load mass and damping)."""
from __future__ import annotations

import numpy as np

FINE = 5    # points per coefficient of each finer grid


def grid_minimum(meas, model_at, xs: np.ndarray, ys: np.ndarray, rounds: int,
                 y_range: tuple[float, float] | None = None) -> tuple[float, float, float]:
    """(error, x, y) at the smallest re-simulated position RMS error [m] of ``model_at(x, y)`` (a
    NominalModel) on the record ``meas`` over the grid ``xs`` x ``ys`` (evenly spaced), then
    ``rounds`` FINE x FINE grids about the best point so far, one grid step of the previous grid
    to each side, each half as wide as the one before; x never beyond xs[-1], y within
    ``y_range`` where given. Points are re-simulated once each (cached), each grid's side by side
    (:func:`~hunting.diagnose.resimulate.position_rms_errors`): at most len(xs) len(ys) +
    rounds (FINE^2 - 1) re-simulations."""
    cache = {}

    def at(points):
        errs = cached_errors(meas, cache, points, lambda p: (round(float(p[0]), 9), round(float(p[1]), 9)), model_at)
        return [(e, float(x), float(y)) for e, (x, y) in zip(errs, points)]
    best = min(at([(a, b) for a in xs for b in ys]))
    dx, dy = xs[1] - xs[0], ys[1] - ys[0]
    for _ in range(rounds):
        bs = np.linspace(best[2] - dy, best[2] + dy, FINE)
        if y_range is not None:
            bs = np.clip(bs, *y_range)
        best = min([best] + at([(a, b) for a in np.linspace(best[1] - dx, min(best[1] + dx, xs[-1]), FINE)
                                for b in bs]))
        dx, dy = dx / 2, dy / 2
    return best


def cached_errors(meas, cache: dict, points: list, key, model_at) -> list:
    """Re-simulated position RMS errors [m] on ``meas`` of ``model_at(*point)`` for each of
    ``points`` (inf where a re-simulation fails), each ``key(point)`` evaluated once, at its first
    point (``cache``: {key: error}, updated), the new ones side by side
    (:func:`~hunting.diagnose.resimulate.position_rms_errors`)."""
    from .resimulate import position_rms_errors
    new = {}
    for p in points:
        k = key(p)
        if k not in cache and k not in new:
            new[k] = p
    errs = position_rms_errors(meas, [model_at(*p) for p in new.values()])
    cache.update((k, float(e) if np.isfinite(e) else np.inf) for k, e in zip(new, errs))
    return [cache[key(p)] for p in points]
