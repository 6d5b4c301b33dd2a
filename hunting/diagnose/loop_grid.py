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
        errs = cached_errors(meas, cache, points, lambda p: (round(float(p[0]), 9), round(float(p[1]), 9)),
                             lambda p: model_at(*p))
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


def cached_errors(meas, cache: dict, points: list, key, model_at, errors=None) -> list:
    """Errors [m] on ``meas`` of ``model_at(point)`` for each of ``points`` (inf where the model is
    None or a re-simulation fails), each ``key(point)`` evaluated once, at its first point
    (``cache``: {key: error}, updated), the new ones side by side: ``errors(meas, models)`` (default
    the re-simulated position RMS errors, :func:`~hunting.diagnose.resimulate.position_rms_errors`)."""
    from .resimulate import position_rms_errors
    new = {}
    for p in points:
        k = key(p)
        if k not in cache and k not in new:
            new[k] = p
    models = {k: model_at(p) for k, p in new.items()}
    run = [k for k, m in models.items() if m is not None]
    errs = dict(zip(run, (errors or position_rms_errors)(meas, [models[k] for k in run])))
    cache.update((k, float(e) if np.isfinite(e := errs.get(k, np.inf)) else np.inf) for k in new)
    return [cache[key(p)] for p in points]
