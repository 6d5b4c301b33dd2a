"""What a grid can and cannot tell about an event map, and a grid that would tell more.

A map sampled on a grid hides what happens between the grid points: fixed points in pairs
(P^k(d) - d changes sign twice between neighbours), the curvature near the equilibrium set
(a first grid point beyond the range where P^k is linear), or the whole map when the spacing
is far coarser than its structure (a grid 0:1e6:11 on table 9.1, whose stick errors are below
0.64). :func:`check_resolution` evaluates the midpoints of the grid, refines the intervals
where the midpoint is off the straight line through its neighbours (or reveals new sign
changes of P^k(d) - d) by bisection for a bounded number of levels, finds the fixed points the
grid missed, and suggests a grid: the range of the map's images (a fixed point satisfies
|d*| = |P^k(d*)|) with the spacing at which the refinement stopped finding anything new.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from ..errors import Status
from .engine import EventMap, evaluate_map
from .fixedpoints import FixedPoint, fixed_points, origin_slope

log = logging.getLogger(__name__)

MAX_LEVELS = 6              # bisection levels below the grid spacing (1/64)
MAX_POINTS = 100_001        # largest suggested grid
LINEAR_TOL = 0.1            # P^k(d)/d within 10 % of the slope at 0: "linear"


@dataclass(frozen=True)
class MapResolution:
    """The verdict on a grid.

    warnings : plain sentences (empty when the grid resolves the map); suggested_grid : (start,
    stop, n) or None; fixed : fixed points on every point evaluated (grid, midpoints and
    refinements); unbracketed : the cycles of ``fixed`` that no two neighbouring grid points
    bracket (fixed_points on the grid alone may miss them, or find them only from the slope at
    the origin); jumps : d
    where the map is discontinuous (refinement narrows them to one interval per level);
    refined : the EventMap on every point evaluated."""

    warnings: list
    suggested_grid: tuple | None
    fixed: list
    unbracketed: list
    jumps: list
    refined: EventMap = field(repr=False)

    @property
    def ok(self) -> bool:
        return not self.warnings

    def suggestion_text(self) -> str:
        if self.suggested_grid is None:
            return ""
        a, b, n = self.suggested_grid
        return f"{a:.6g}:{b:.6g}:{n}"

    def as_dict(self) -> dict:
        return dict(warnings=list(self.warnings), suggested_grid=self.suggestion_text() or None,
                    unbracketed=[f.as_dict() for f in self.unbracketed], jumps=[float(d) for d in self.jumps])


def _round_up(x: float) -> float:
    """x rounded up to two significant digits (a range a user can type)."""
    if not np.isfinite(x) or x <= 0:
        return x
    unit = 10.0 ** (np.floor(np.log10(x)) - 1)
    return float(np.ceil(x / unit - 1e-9) * unit)


def _merge(em: EventMap, d: np.ndarray, mv) -> EventMap:
    """The EventMap on em.grid and the extra points d (values mv), sorted."""
    grid = np.concatenate([em.grid, d])
    order = np.argsort(grid, kind="stable")
    image = np.concatenate([em.image, np.where(mv.ok, mv.image, np.nan)])
    cat = [np.concatenate([a, b])[order] for a, b in ((em.status, mv.status), (em.slip_time, mv.slip_time),
                                                       (em.stick_time, mv.stick_time))]
    return EventMap(grid[order], image[order], cat[0], cat[1], cat[2], None, "none", em.iterate, em.loop,
                    em.options)


def _sign_changes(g: np.ndarray) -> int:
    s = np.sign(g[np.isfinite(g) & (g != 0)])
    return int(np.sum(s[1:] != s[:-1]))


def _refine_intervals(em: EventMap, g0_sign: float | None, scale: float, budget: int):
    """Bisect the grid's intervals while a midpoint is off the line through its neighbours by
    more than 5 % of ``scale`` or reveals new sign changes of g = P^k(d) - d. Returns (points
    evaluated (d, MapValues) list, level at which each interval was resolved (-1: never),
    jumps)."""
    loop, k, opt = em.loop, em.iterate, em.options
    a, b = em.grid[:-1], em.grid[1:]
    pa, pb = em.image[:-1], em.image[1:]
    owner = np.arange(a.size)
    level_ok = np.full(a.size, -1)
    active = em.ok[:-1] & em.ok[1:]
    a, b, pa, pb, owner = a[active], b[active], pa[active], pb[active], owner[active]
    evaluated = []
    counts = np.zeros(em.grid.size - 1, dtype=int)          # flagged children per interval and level
    history = []
    for level in range(MAX_LEVELS + 1):
        if a.size == 0 or budget <= 0:
            break
        if a.size > budget:
            a, b, pa, pb, owner = a[:budget], b[:budget], pa[:budget], pb[:budget], owner[:budget]
        mid = 0.5 * (a + b)
        mv = evaluate_map(loop, mid, k, opt)
        budget -= mid.size
        evaluated.append((mid, mv))
        pm = np.where(mv.ok, mv.image, np.nan)
        off = np.abs(pm - 0.5 * (pa + pb)) > 0.05 * scale
        ga, gm, gb = pa - a, pm - mid, pb - b
        if g0_sign is not None:            # just beside d = 0, g has the sign the slope at the origin gives
            ga = np.where(a == 0, g0_sign, ga)
            gb = np.where(b == 0, -g0_sign, gb)
        split = np.array([_sign_changes(np.array([x, y, z])) > _sign_changes(np.array([x, z]))
                          for x, y, z in zip(ga, gm, gb)], dtype=bool)
        bad = (off | split | ~np.isfinite(pm))
        resolved_now = np.setdiff1d(owner[~bad], owner[bad])
        level_ok[resolved_now[level_ok[resolved_now] < 0]] = level
        counts[:] = 0
        np.add.at(counts, owner[bad], 1)
        history.append(counts.copy())
        keep = bad & np.isfinite(pm)
        a, b = np.concatenate([a[keep], mid[keep]]), np.concatenate([mid[keep], b[keep]])
        pa, pb = np.concatenate([pa[keep], pm[keep]]), np.concatenate([pm[keep], pb[keep]])
        owner = np.concatenate([owner[keep], owner[keep]])
    unresolved = np.unique(owner)
    level_ok[unresolved] = -1
    # a jump: the refinement narrows it to one flagged interval per level, down to the last
    jumps = []
    if history:
        hist = np.array(history)
        for i in unresolved:
            if len(history) > MAX_LEVELS and np.all(hist[:, i] == 1):
                sel = owner == i
                jumps.append(float(0.5 * (a[sel].min() + b[sel].max())))
    return evaluated, level_ok, jumps


def check_resolution(em: EventMap, fixed: list[FixedPoint] | None = None, *, budget: int | None = None) -> MapResolution:
    """Judge whether the grid of ``em`` resolves the map P^k and its fixed points.

    Parameters
    ----------
    em : EventMap on the user's grid; fixed : its fixed points (from :func:`fixed_points`;
        computed when None)
    budget : bound on extra map evaluations (default 4 x the grid size, at least 200)

    Returns
    -------
    MapResolution; its warnings are also logged (logger ``hunting.eventmap.resolution``)."""
    loop, k, opt = em.loop, em.iterate, em.options
    grid = em.grid
    budget = max(4 * grid.size, 200) if budget is None else int(budget)
    h = float(np.max(np.diff(grid))) if grid.size > 1 else 0.0
    spans_zero = grid.min() <= 0 <= grid.max()
    # once, with the probes (they say how far the map is linear), for every fixed-point search here
    os_ = (origin_slope(loop, k, max(float(np.max(np.abs(grid))), opt.d_floor), opt, probes=True)
           if spans_zero else None)
    fixed = fixed_points(loop, grid, k, emap=em, options=opt, origin=os_) if fixed is None else fixed
    g0 = None
    if os_ is not None and os_.behaviour == "linear" and np.isfinite(os_.slope_right):
        g0 = float(np.sign(os_.slope_right - 1.0))
    scale = float(np.nanmax(np.abs(np.where(em.ok, em.image, np.nan)))) if np.any(em.ok) else 0.0
    evaluated, level_ok, jumps = _refine_intervals(em, g0, max(scale, opt.d_floor), budget)
    if os_ is not None and os_.behaviour != "linear":       # the known jump at the origin
        first = min(abs(float(d)) for d in grid[grid != 0]) if np.any(grid != 0) else 0.0
        jumps = [j for j in jumps if abs(j) >= first]
    refined = em
    for d, mv in evaluated:
        refined = _merge(refined, d, mv)
    warnings: list[str] = []
    spacing: list[float] = []
    # the range a fixed point can lie in: |d*| = |P^k(d*)| <= the largest image (with a margin)
    img = np.abs(refined.image[refined.ok])
    reach = 1.25 * float(img.max()) if img.size else np.inf
    lo, hi = float(grid.min()), float(grid.max())
    s_lo, s_hi = max(lo, -_round_up(reach)), min(hi, _round_up(reach))
    if s_hi <= s_lo:
        s_lo, s_hi = lo, hi
    unresolved = np.flatnonzero(level_ok < 0) if grid.size > 1 else np.empty(0, int)
    inside = [i for i in unresolved if grid[i + 1] > s_lo and grid[i] < s_hi
              and not any(grid[i] <= j <= grid[i + 1] for j in jumps)]
    if os_ is not None and os_.behaviour == "discontinuous":
        inside = [i for i in inside if not (grid[i] <= 0 <= grid[i + 1])]     # the known jump at 0
    coarse = [i for i in range(grid.size - 1) if level_ok[i] > 0]
    if inside:
        warnings.append(f"the grid does not resolve the map in {len(inside)} of its {grid.size - 1} intervals "
                        f"(d from {grid[inside[0]]:.6g} to {grid[inside[-1] + 1]:.6g}): the map changes faster "
                        f"than the spacing {h:.3g}, and bisecting it {MAX_LEVELS} times did not change that")
    if coarse:
        need = max(level_ok[i] for i in coarse)
        spacing.append(h / 2 ** (need + 1))
        warnings.append(f"the map bends or crosses the diagonal between grid points in {len(coarse)} interval(s) "
                        f"(d from {grid[coarse[0]]:.6g} to {grid[coarse[-1] + 1]:.6g}); a spacing of "
                        f"{h / 2 ** need:.3g} resolves them")
    # the equilibrium set: is the first grid point inside the range where P^k is linear?
    if g0 is not None:
        for side, slope in ((1.0, os_.slope_right), (-1.0, os_.slope_left)):
            idx = np.flatnonzero(em.ok & (np.sign(grid) == side))
            if idx.size == 0:
                continue
            i = idx[np.argmin(np.abs(grid[idx]))]
            secant = em.image[i] / grid[i]
            crosses = np.sign(secant - 1.0) != np.sign(slope - 1.0)     # a fixed point lies in between
            if crosses or abs(grid[i]) > reach:
                deltas, rr, rl = os_.probes
                ratios = rr if side > 0 else rl
                lin = deltas[np.abs(ratios - slope) <= LINEAR_TOL * max(1.0, abs(slope))]
                d_lin = float(lin.max()) if lin.size else float(deltas[-1])
                why = ("a fixed point lies between it and the equilibrium set" if crosses else
                       "fixed points near the equilibrium set can be missed")
                warnings.append(f"the grid point nearest to the equilibrium set, d = {grid[i]:.6g}, lies beyond "
                                f"the range where P^{k} is linear (P^{k}(d)/d = {secant:.4g} there, {slope:.4g} at "
                                f"d -> 0, linear up to about |d| = {d_lin:.2g}): {why}")
    # fixed points: those on every evaluated point that the grid alone does not bracket
    all_fixed = fixed_points(loop, refined.grid, k, emap=refined, options=opt, origin=os_)
    known = [f.d for f in fixed if f.kind == "cycle"]
    missed = [f for f in all_fixed if f.kind == "cycle"
              and not any(abs(f.d - d) <= 1e-7 * max(abs(f.d), opt.d_floor) for d in known)]
    cycles = [f for f in all_fixed if f.kind == "cycle"]
    g = em.image - grid
    unbracketed = []
    for f in cycles:
        j = np.searchsorted(grid, f.d)
        bracketed = (0 < j < grid.size and grid[j - 1] * grid[j] > 0 and em.ok[j - 1] and em.ok[j]
                     and np.sign(g[j - 1]) * np.sign(g[j]) < 0
                     and sum(grid[j - 1] < c.d < grid[j] for c in cycles) == 1)
        if not bracketed or f in missed:
            unbracketed.append(f)
            warnings.append(f"the {'stable' if f.stable else 'unstable'} cycle at d = {f.d:.8g} is not bracketed by "
                            f"neighbouring grid points{' (the grid alone misses it)' if f in missed else ''}: found "
                            "by refining between them")
    if cycles and warnings:
        ds = np.sort(np.concatenate([[0.0] if spans_zero else [], np.abs([f.d for f in cycles])]))
        gaps = np.diff(ds)
        if gaps.size:
            spacing.append(float(gaps[gaps > 0].min()) / 3 if np.any(gaps > 0) else h)
    failed = ~em.ok & (grid != 0)
    if failed.any():
        names, counts = np.unique([Status(int(s)).name for s in em.status[failed]], return_counts=True)
        warnings.append(f"{int(failed.sum())} of {grid.size} points did not reach a stick phase "
                        f"({', '.join(f'{n}: {c}' for n, c in zip(names, counts))}): the map is undefined there")
    suggested = None
    if warnings and (spacing or (s_lo, s_hi) != (lo, hi)):
        width = s_hi - s_lo
        step = min(spacing) if spacing else h
        if (s_lo, s_hi) != (lo, hi):         # a new range: at least the thesis' 500 intervals on it
            step = min(step, width / 500)
        n = int(np.ceil(width / step)) + 1
        if n > MAX_POINTS:
            n = MAX_POINTS
            warnings.append(f"a grid that fine needs more than {MAX_POINTS} points on [{s_lo:.6g}, {s_hi:.6g}]: "
                            "narrow the range to the feature of interest")
        suggested = (s_lo, s_hi, max(n, 2))
        if (s_lo, s_hi) != (lo, hi):
            warnings.append(f"every image lies within |d| <= {reach / 1.25:.4g}, so every fixed point does")
        warnings.append(f"suggested grid: {suggested[0]:.6g}:{suggested[1]:.6g}:{suggested[2]}")
    for w in warnings:
        log.warning(w)
    return MapResolution(warnings, suggested, all_fixed, unbracketed, jumps, refined)
