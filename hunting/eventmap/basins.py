"""Basins of attraction of the event map on a grid: where each starting stick error ends."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..models.loop import ServoLoop
from .engine import MapOptions, evaluate_map


@dataclass(frozen=True)
class Basins:
    """grid : (m,) starting stick errors; attractor : (m,) index into ``attractors`` (-1: not
    settled within max_iter, -2: the map failed); attractors : the stable FixedPoints;
    intervals : list of (d_lo, d_hi, attractor index) of consecutive grid points with one fate."""

    grid: np.ndarray
    attractor: np.ndarray
    attractors: list
    intervals: list


def basins(loop: ServoLoop, grid, fixed: list, iterate: int = 2, *, max_iter: int = 400,
           tol: float = 1e-3, options: MapOptions | None = None) -> Basins:
    """Iterate P^k from every grid point (all points together, in parallel) until it comes within
    ``tol`` (relative to the grid's scale) of a stable fixed point's orbit or of the equilibrium
    set (when that is stable)."""
    grid = np.asarray(grid, dtype=float).ravel()
    stable = [f for f in fixed if f.stable]
    scale = max(float(np.max(np.abs(grid))), 1e-12)
    targets = [np.concatenate([np.asarray(f.orbit), -np.asarray(f.orbit)]) if loop.odd else np.asarray(f.orbit)
               for f in stable]
    fate = np.full(grid.size, -1)
    d = grid.copy()
    active = np.ones(grid.size, dtype=bool)
    for _ in range(max_iter):
        for j, tg in enumerate(targets):
            near = active & (np.min(np.abs(d[:, None] - tg[None, :]), axis=1) <= tol * scale)
            fate[near] = j
            active &= ~near
        if not active.any():
            break
        mv = evaluate_map(loop, d[active], iterate, options)
        idx = np.flatnonzero(active)
        bad = ~mv.ok
        fate[idx[bad]] = -2
        active[idx[bad]] = False
        d[idx[~bad]] = mv.image[~bad]
    intervals = []
    start = 0
    for i in range(1, grid.size + 1):
        if i == grid.size or fate[i] != fate[start]:
            intervals.append((float(grid[start]), float(grid[i - 1]), int(fate[start])))
            start = i
    return Basins(grid, fate, stable, intervals)
