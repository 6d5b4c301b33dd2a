"""Attractors of the event map found by iteration: the stable hunting cycles of a loop without
symmetry (cogging, chapter 10), where the number of stick phases per period is not known in
advance. The thesis reads it from the first iterate P^k with contracting fixed points (Fig. 10.11);
iterating P from many starting errors finds the same cycles (and the equilibrium set when it
attracts) and gives each cycle's stick errors in the order they occur."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import Status, SystemDefinitionError
from ..models.loop import ServoLoop
from .engine import MapOptions, evaluate_map


@dataclass(frozen=True)
class Attractor:
    """kind : "equilibrium" (the stick errors shrink to zero: the equilibrium set attracts),
    "cycle" (period k stick phases) or "irregular" (no period <= max_period: a long or chaotic
    orbit); d : (k,) stick errors of one period in order of occurrence (irregular: the last
    max_period iterates); multiplier : dP^k/dd at the cycle (product of the slopes of P along
    it; |.| < 1 contracting); basin : number of starting errors that ended here."""

    kind: str
    period: int
    d: np.ndarray
    multiplier: float
    basin: int

    @property
    def amplitude(self) -> float:
        return float(np.max(np.abs(self.d))) if self.d.size else 0.0

    def as_dict(self) -> dict:
        return dict(kind=self.kind, period=self.period, d=[float(v) for v in self.d],
                    multiplier=self.multiplier, basin=self.basin)


def attractors(loop: ServoLoop, starts, *, transient: int = 100, max_period: int = 64, tol: float = 1e-7,
               options: MapOptions | None = None) -> list[Attractor]:
    """Iterate P from each starting stick error (m,) ``transient`` times, then look for the
    smallest period k <= max_period with |P^k(d) - d| <= tol * scale (scale = max |starts|). Equal
    cycles reached from several starts are merged. Returns attractors ordered by amplitude."""
    starts = np.asarray(starts, dtype=float).ravel()
    if starts.size < 1 or not np.all(np.isfinite(starts)):
        raise SystemDefinitionError(f"starts = {starts!r} must be finite stick errors")
    if not (1 <= max_period <= 10_000 and transient >= 0):
        raise SystemDefinitionError("need 1 <= max_period <= 10000 and transient >= 0")
    opt = options or MapOptions(rtol=1e-10, max_events=20 * (transient + 1), max_steps=10_000_000)
    scale = float(np.max(np.abs(starts)))
    def step(d, k):
        # runs that end at rest (t_max reached in a stick phase with |error| below the floor)
        # and errors already that small have reached the equilibrium set: 0; other failed
        # evaluations are dropped (NaN)
        out = np.full(d.shape, np.nan)
        live = np.isfinite(d) & (np.abs(d) > floor)
        out[np.isfinite(d) & ~live] = 0.0
        if live.any():
            mv = evaluate_map(loop, d[live], k, opt)
            at_rest = (mv.status == Status.SUCCESS) & (np.abs(mv.image) <= floor)
            out[live] = np.where(mv.ok, mv.image, np.where(at_rest, 0.0, np.nan))
        return out

    floor = 1e-7 * scale
    d = step(starts, transient) if transient else starts.copy()
    seq = [d]
    for _ in range(max_period):
        seq.append(step(seq[-1], 1))
    seq = np.array(seq)                                  # (max_period + 1, m)
    found: list[Attractor] = []
    for j in range(starts.size):
        col = seq[:, j]
        if not np.all(np.isfinite(col)):
            continue
        if np.max(np.abs(col)) <= floor or (np.max(np.abs(col[len(col) // 2:])) < 0.5 * np.max(np.abs(col[:len(col) // 2]))
                                             and np.max(np.abs(col[-8:])) < 1e-3 * scale):
            kind, per, pts = "equilibrium", 0, np.zeros(0)
        else:
            per, pts = _period(loop, col, max_period, tol * scale, opt)
            kind = "cycle" if per else "irregular"
            pts = pts if per else col[1:]
        same = next((a for a in found if a.kind == kind and a.period == per
                     and (kind == "equilibrium" or kind == "irregular" or
                          np.min(np.abs(a.d - pts[0])) <= 10 * tol * scale)), None)
        if same is not None:
            found[found.index(same)] = Attractor(same.kind, same.period, same.d, same.multiplier, same.basin + 1)
            continue
        found.append(Attractor(kind, per, pts, float("nan"), 1))
    # multipliers of the cycles: product of central-difference slopes of P along the orbit
    out = []
    for a in found:
        mult = a.multiplier
        if a.kind == "cycle":
            h = opt.fd_step * np.maximum(np.abs(a.d), opt.d_floor) * 10
            plus = evaluate_map(loop, a.d + h, 1, opt).image
            minus = evaluate_map(loop, a.d - h, 1, opt).image
            mult = float(np.prod((plus - minus) / (2 * h)))
        out.append(Attractor(a.kind, a.period, a.d, mult, a.basin))
    return sorted(out, key=lambda a: a.amplitude)


def _period(loop, col, max_period, tol, opt):
    """Smallest period k of the iterates col (k, orbit) once the fixed point of P^k near col[0]
    is polished by Newton's method (slowly contracting cycles are far from converged after the
    transient); (0, None) when no k <= max_period works."""
    scale = max(float(np.max(np.abs(col))), 1e-300)
    for k in range(1, max_period + 1):
        if abs(col[k] - col[0]) > 1e-3 * scale:
            continue
        d = float(col[0])
        for _ in range(30):                      # Newton on g(d) = P^k(d) - d
            h = 1e-7 * max(abs(d), opt.d_floor)
            mv = evaluate_map(loop, [d, d + h, d - h], k, opt)
            if not np.all(mv.ok):
                break
            g = mv.image[0] - d
            if abs(g) <= tol:
                orbit = [d]
                for _ in range(k - 1):
                    nxt = evaluate_map(loop, [orbit[-1]], 1, opt)
                    orbit.append(float(nxt.image[0]))
                return k, np.array(orbit)
            dg = (mv.image[1] - mv.image[2]) / (2 * h) - 1.0
            if dg == 0 or not np.isfinite(dg):
                break
            d = d - g / dg
    return 0, None
