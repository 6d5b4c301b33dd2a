"""Fixed points of P^k: bracketed on a grid, refined on the true map, classified.

A fixed point d* != 0 of P^k is a hunting limit cycle with k stick phases per period (after
reduction to the minimal k); d* = 0 is the equilibrium set, whose stability follows from the
one-sided slopes of P^k at the origin: exact from the loop's linearization where the friction
curve has one at zero velocity (beta >= 1, Coulomb; :mod:`hunting.eventmap.origin`), from
probes of the map otherwise (beta < 1 and the discontinuous curve: the map jumps at the
origin, thesis section 9.5). A fixed point between the origin and the first grid point is
bracketed with the slope at the origin, so a coarse grid does not hide it.
"""
from __future__ import annotations

import logging

from dataclasses import dataclass

import numpy as np

from ..errors import Status, SystemDefinitionError
from ..models.loop import ServoLoop
from .engine import EventMap, MapOptions, evaluate_map, event_map
from .family import as_stick_map
from .origin import force_length, linear_origin

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class OriginSlope:
    """Behaviour of P^k near d = 0 from the right and the left.

    slope_right, slope_left : dP^k/dd at 0+ and 0- (method "linearization"), or P^k(delta)/delta
    at the smallest probe (method "probes"; NaN where a probe failed);
    behaviour : "linear" (a finite slope: from the linearization, or probe ratios that settle),
    "steep" (unbounded: the linearized slip grows away without sticking, or the probe ratios
    still grow at the smallest probe), "discontinuous" (|P^k(delta)| does not go to 0: the map
    jumps at the origin, beta < 1 and the discontinuous curve) or "undefined" (a probe failed;
    see its status);
    probes : (deltas, ratios right, ratios left), or () when not computed;
    method : "linearization" or "probes"."""

    slope_right: float
    slope_left: float
    behaviour: str
    probes: tuple
    method: str = "probes"

    @property
    def stable(self) -> bool:
        if self.behaviour not in ("linear", "steep"):
            return False
        return max(abs(self.slope_right), abs(self.slope_left)) < 1.0


@dataclass(frozen=True)
class FixedPoint:
    """A fixed point of P^k.

    d : stick error [m]; iterate : minimal k; slope : d P^k / dd at d (for the equilibrium: the
    larger one-sided slope in magnitude); stable : |slope| < 1 (equilibrium: not discontinuous
    and contracting on both sides); kind : "equilibrium" or "cycle"; orbit : the k stick errors
    of the cycle, starting at d; residual : |P^k(d) - d|; origin : OriginSlope of the
    equilibrium; fit_d, fit_slope : the thesis' local fit (cubic through four grid neighbours,
    or a line through the origin), when requested."""

    d: float
    iterate: int
    slope: float
    stable: bool
    kind: str
    orbit: tuple
    residual: float
    origin: OriginSlope | None = None
    fit_d: float | None = None
    fit_slope: float | None = None

    def as_dict(self) -> dict:
        out = dict(d=self.d, iterate=self.iterate, slope=self.slope, stable=bool(self.stable), kind=self.kind,
                   orbit=[float(v) for v in self.orbit], residual=self.residual)
        if self.origin is not None:
            out["origin"] = dict(slope_right=self.origin.slope_right, slope_left=self.origin.slope_left,
                                 behaviour=self.origin.behaviour)
        if self.fit_d is not None:
            out.update(fit_d=self.fit_d, fit_slope=self.fit_slope)
        return out


def _classify(deltas, images, ratios) -> str:
    if not np.all(np.isfinite(ratios)):
        return "undefined"
    shrink = np.abs(images[-1]) / max(np.abs(images[-3]), 1e-300)     # over two decades
    if shrink > 0.5:
        return "discontinuous"
    a, b = abs(ratios[-2]), abs(ratios[-1])
    if abs(b - a) <= 0.02 * max(a, b):
        return "linear"
    return "steep" if b > a else "linear"


def probe_origin(loop: ServoLoop, iterate: int, scale: float, options: MapOptions | None = None) -> tuple:
    """(deltas, P^k(delta)/delta right, left, behaviour) from probes delta = scale * 10^-j,
    j = 2..7. Smaller probes are not used: below about 1e-7 of the map's scale the break-away
    motion is driven by a force difference that rounding errors of O(eps Fs) swamp."""
    deltas = scale * 10.0 ** -np.arange(2, 8)
    right = evaluate_map(loop, deltas, iterate, options)
    left = evaluate_map(loop, -deltas, iterate, options)
    rr = np.where(right.ok, right.image / deltas, np.nan)
    rl = np.where(left.ok, left.image / -deltas, np.nan)
    kinds = {_classify(deltas, right.image, rr), _classify(deltas, left.image, rl)}
    behaviour = next(k for k in ("undefined", "discontinuous", "steep", "linear") if k in kinds)
    return deltas, rr, rl, behaviour


def probe_scale(loop: ServoLoop, scale: float | None) -> float:
    """The probes' scale: the force length Fs / |cm kp + alpha| of the loop, or ``scale`` (the
    grid's extent) when that is smaller or the loop has no proportional action."""
    L = force_length(loop)
    cands = [v for v in (L, scale) if v is not None and np.isfinite(v) and v > 0]
    return min(cands) if cands else 1.0


def origin_slope(loop: ServoLoop, iterate: int, scale: float | None = None, options: MapOptions | None = None,
                 *, probes: bool = False) -> OriginSlope:
    """One-sided slopes of P^k at 0: from the linearization (:func:`linear_origin`) where the
    friction curve has one, else from probes of the map (:func:`probe_origin`) at
    :func:`probe_scale` (``scale``: the extent of the grid, an upper bound). ``probes`` also
    computes the probes where the linearization answers (a cross-check)."""
    lin = linear_origin(loop, iterate)
    if lin is not None:
        behaviour = "linear" if np.isfinite(lin.slope_right) and np.isfinite(lin.slope_left) else "steep"
        pr = ()
        if probes:
            deltas, rr, rl, _ = probe_origin(loop, iterate, probe_scale(loop, scale), options)
            pr = (deltas, rr, rl)
        return OriginSlope(lin.slope_right, lin.slope_left, behaviour, pr, "linearization")
    deltas, rr, rl, behaviour = probe_origin(loop, iterate, probe_scale(loop, scale), options)
    return OriginSlope(float(rr[-1]), float(rl[-1]), behaviour, (deltas, rr, rl), "probes")


def _origin_brackets(loop, em: EventMap, g: np.ndarray, os_: OriginSlope, iterate: int, opt) -> list:
    """Brackets (a, b, g(a), g(b)) of fixed points between the origin and the grid point nearest
    to it on each side, where the slope at the origin gives g = P^k(d) - d one sign near 0 and
    that grid point the other (the 0.00336 cycle of table 9.1 on a grid 0:0.5:11)."""
    out = []
    if os_.behaviour != "linear":
        return out
    for side, slope in ((1.0, os_.slope_right), (-1.0, os_.slope_left)):
        expect = np.sign(slope - 1.0) * side          # sign of g(d) = (slope - 1) d for small |d| on this side
        idx = np.flatnonzero(em.ok & (np.sign(em.grid) == side))
        if expect == 0 or idx.size == 0:
            continue
        i = idx[np.argmin(np.abs(em.grid[idx]))]
        d1, g1 = em.grid[i], g[i]
        if np.sign(g1) != -expect:
            continue
        ds = d1 * 10.0 ** -np.arange(1, 8)            # towards 0 until g has the sign of the slope
        mv = evaluate_map(loop, ds, iterate, opt)
        gs = np.where(mv.ok, mv.image - ds, np.nan)
        near = np.flatnonzero(np.sign(gs) == expect)
        if near.size == 0:
            continue
        j = int(near[0])                               # the largest probe with the slope's sign
        b, gb = (ds[j - 1], gs[j - 1]) if j > 0 and np.sign(gs[j - 1]) == -expect else (d1, g1)
        out.append((ds[j], b, gs[j], gb))
    return out


def _refine(loop, a, b, ga, gb, iterate, opt, tol, max_iter=200):
    """Vectorized Illinois on g(d) = P^k(d) - d over brackets [a, b] with g(a) g(b) < 0."""
    a, b, ga, gb = (np.array(v, dtype=float) for v in (a, b, ga, gb))
    side = np.zeros(a.size, dtype=int)
    active = np.ones(a.size, dtype=bool)
    for _ in range(max_iter):
        active &= np.abs(b - a) > tol
        if not active.any():
            break
        idx = np.flatnonzero(active)
        c = (a[idx] * gb[idx] - b[idx] * ga[idx]) / (gb[idx] - ga[idx])
        bad = ~((c > np.minimum(a[idx], b[idx])) & (c < np.maximum(a[idx], b[idx])))
        c[bad] = 0.5 * (a[idx] + b[idx])[bad]
        mv = evaluate_map(loop, c, iterate, opt)
        gc = np.where(mv.ok, mv.image - c, np.nan)
        for j, k in enumerate(idx):
            if not np.isfinite(gc[j]):
                active[k] = False
                continue
            if gc[j] == 0.0:
                a[k] = b[k] = c[j]
                ga[k] = gb[k] = 0.0
                active[k] = False
            elif np.sign(gc[j]) == np.sign(gb[k]):
                b[k], gb[k] = c[j], gc[j]
                if side[k] == 1:
                    ga[k] *= 0.5
                side[k] = 1
            else:
                a[k], ga[k] = c[j], gc[j]
                if side[k] == -1:
                    gb[k] *= 0.5
                side[k] = -1
    use_b = np.abs(gb) < np.abs(ga)
    return np.where(use_b, b, a), np.abs(gb - ga)


def _slope(loop, d, k, opt) -> float:
    """dP^k/dd at d: central differences with Richardson extrapolation (steps h and h/2), since
    maps are strongly curved near folds and unstable cycles (slopes up to 1e8 in chapter 8)."""
    h = opt.fd_step * max(abs(d), opt.d_floor)
    pm = evaluate_map(loop, [d + h, d - h, d + h / 2, d - h / 2], k, opt)
    d1 = (pm.image[0] - pm.image[1]) / (2 * h)
    d2 = (pm.image[2] - pm.image[3]) / h
    return float((4 * d2 - d1) / 3)


def _thesis_fit(grid, image, i):
    """Cubic through four neighbouring points around bracket [i, i+1]: root of P^k(d) - d."""
    lo = max(0, min(i - 1, grid.size - 4))
    xs, ys = grid[lo:lo + 4], image[lo:lo + 4]
    c = np.polyfit(xs, ys - xs, 3)
    roots = np.roots(c)
    roots = roots[np.isreal(roots)].real
    roots = roots[(roots >= grid[i]) & (roots <= grid[i + 1])]
    if roots.size == 0:
        return None, None
    r = float(roots[0])
    return r, float(np.polyval(np.polyder(np.polyfit(xs, ys, 3)), r))


def _grid(grid) -> np.ndarray:
    """The stick errors of a grid: at least 2 finite numbers (fixed points are bracketed
    between neighbours), else a SystemDefinitionError naming the grid."""
    allowed = "at least 2 finite stick errors, e.g. np.linspace(0, 0.5, 501)"
    try:
        g = np.asarray(grid, dtype=float).ravel()
    except (TypeError, ValueError):
        raise SystemDefinitionError(f"grid = {grid!r} is not allowed: {allowed}") from None
    if g.size < 2 or not np.all(np.isfinite(g)):
        raise SystemDefinitionError(f"grid = {grid!r} is not allowed: {allowed}")
    return g


def fixed_points(loop: ServoLoop, grid, iterate: int = 2, *, tol: float = 1e-12,
                 options: MapOptions | None = None, thesis_fits: bool = False,
                 emap: EventMap | None = None, origin: OriginSlope | None = None) -> list[FixedPoint]:
    """All fixed points of P^k found on ``grid``, refined to |Δd| <= tol on the true map.

    Cycles are reported once per orbit (the largest stick error of the orbit as ``d``) with
    their minimal number of stick phases; the equilibrium set d = 0 is always reported when the
    grid spans or touches 0. ``thesis_fits`` adds the thesis' local fits for comparison;
    ``origin``: the slope at d = 0 when already computed (:func:`origin_slope` of the same loop
    and ``iterate`` at the grid's extent), so it is not computed again."""
    loop = as_stick_map(loop)            # a preset name, compiled model or PiecewiseSystem as well
    opt = options or MapOptions()
    grid = _grid(grid) if emap is None else emap.grid
    em = emap if emap is not None else event_map(loop, grid, iterate, derivative=False, options=opt)
    g = em.image - em.grid
    ok = em.ok
    i = np.flatnonzero(ok[:-1] & ok[1:] & (np.sign(g[:-1]) * np.sign(g[1:]) < 0)
                       & (em.grid[:-1] * em.grid[1:] > 0))
    scale = max(np.max(np.abs(grid)), opt.d_floor)
    os_ = None
    if grid.min() <= 0 <= grid.max():
        os_ = origin if origin is not None else origin_slope(loop, iterate, scale, opt)
    extra = _origin_brackets(loop, em, g, os_, iterate, opt) if os_ is not None else []
    lo = np.concatenate([em.grid[i], [e[0] for e in extra]])
    hi = np.concatenate([em.grid[i + 1], [e[1] for e in extra]])
    glo = np.concatenate([g[i], [e[2] for e in extra]])
    ghi = np.concatenate([g[i + 1], [e[3] for e in extra]])
    if lo.size:
        roots, jumps = _refine(loop, lo, hi, glo, ghi, iterate, opt, tol)
    else:
        roots, jumps = np.empty(0), np.empty(0)
    exact = np.flatnonzero(ok & (g == 0) & (em.grid != 0))
    roots = np.concatenate([roots, em.grid[exact]])
    jumps = np.concatenate([jumps, np.zeros(exact.size)])
    brackets = list(i) + [None] * (len(extra) + exact.size)
    out: list[FixedPoint] = []
    seen: list[np.ndarray] = []
    for r, bi, jump in zip(roots, brackets, jumps):
        res = evaluate_map(loop, [r], iterate, opt)
        resid = abs(res.image[0] - r)
        # a sign change of P^k(d) - d across a bracket of width ~tol whose ends still differ by
        # a finite amount is a jump of the map, not a fixed point (a steep root differs by
        # slope * tol only: 3e-7 for the slope 3e5 of the unstable cycles of chapter 8)
        if not res.ok[0] or jump > 1e-2 * max(abs(r), opt.d_floor):
            continue
        orbit = [r]
        x = r
        for _ in range(iterate - 1):
            x = float(evaluate_map(loop, [x], 1, opt).image[0])
            orbit.append(x)
        k = iterate
        for j in range(1, iterate):
            if iterate % j == 0 and abs(orbit[j] - r) < 1e-7 * max(abs(r), opt.d_floor):
                k = j
                break
        orbit = np.array(orbit[:k])
        if any(o.size == orbit.size and np.min(np.abs(o - r)) < 1e-7 * max(abs(r), opt.d_floor) for o in seen):
            continue
        seen.append(orbit)
        rep = float(orbit[np.argmax(orbit)])
        slope = _slope(loop, rep, k, opt)
        fit_d = fit_s = None
        if thesis_fits and bi is not None and rep == r:
            fit_d, fit_s = _thesis_fit(em.grid, em.image, bi)
        out.append(FixedPoint(rep, k, slope, abs(slope) < 1.0, "cycle", tuple(np.roll(orbit, -int(np.argmax(orbit)))),
                              float(resid), None, fit_d, fit_s))
    if os_ is not None:
        slope = max(os_.slope_right, os_.slope_left, key=lambda v: abs(v) if np.isfinite(v) else np.inf)
        fit_d = fit_s = None
        if thesis_fits:
            pos = np.flatnonzero((em.grid > 0) & ok)[:2]
            if pos.size == 2:
                x, y = em.grid[pos], em.image[pos]
                fit_d, fit_s = 0.0, float(np.dot(x, y) / np.dot(x, x))
        out.append(FixedPoint(0.0, 1, float(slope), os_.stable, "equilibrium", (0.0,), 0.0, os_, fit_d, fit_s))
    out.sort(key=lambda f: (f.kind != "equilibrium", f.d))
    return out


def status_summary(em: EventMap) -> dict:
    """Counts of each status on a map grid (by name)."""
    names, counts = np.unique([Status(int(s)).name for s in em.status], return_counts=True)
    return dict(zip(names.tolist(), counts.tolist()))
