"""Bifurcation diagrams from event maps: fixed points of P^k against a parameter, with folds
and changes of the equilibrium set's stability located by refinement in the parameter."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from ..errors import SystemDefinitionError
from ..models.presets import preset
from ..results import SpecialPoint
from ..system import PiecewiseSystem
from .engine import MapOptions, evaluate_map
from .family import as_stick_map
from .fixedpoints import fixed_points, origin_slope


def default_grid(d_max: float, n: int = 201, n_small: int = 40) -> np.ndarray:
    """Uniform grid on [0, d_max] plus a geometric grid towards 0, so that small cycles near the
    equilibrium set are bracketed."""
    g = np.concatenate([np.linspace(0.0, d_max, n), np.geomspace(d_max * 2e-4, d_max * 0.02, n_small)])
    return np.unique(g)


@dataclass(frozen=True)
class MapDiagram:
    """Fixed points of P^k over a parameter sweep.

    param : name; values : (p,) parameter values; fixed : list (per value) of lists of
    FixedPoint; special : list of SpecialPoint (folds, equilibrium stability changes);
    label : description of the loop."""

    param: str
    values: np.ndarray
    fixed: list
    special: list
    iterate: int
    label: str = ""

    def cycles(self):
        """Flat arrays (param, d, stable) of every cycle found."""
        rows = [(v, f.d, f.stable) for v, fps in zip(self.values, self.fixed) for f in fps if f.kind == "cycle"]
        if not rows:
            return np.empty(0), np.empty(0), np.empty(0, dtype=bool)
        a = np.array(rows, dtype=object)
        return a[:, 0].astype(float), a[:, 1].astype(float), a[:, 2].astype(bool)

    def equilibrium_stable(self) -> np.ndarray:
        return np.array([next((f.stable for f in fps if f.kind == "equilibrium"), False) for fps in self.fixed])

    def n_cycles(self) -> np.ndarray:
        return np.array([sum(f.kind == "cycle" for f in fps) for fps in self.fixed])

    def as_dict(self) -> dict:
        return dict(param=self.param, iterate=self.iterate, label=self.label,
                    points=[dict(param=float(v), fixed_points=[f.as_dict() for f in fps])
                            for v, fps in zip(self.values, self.fixed)],
                    special_points=[s.as_dict() for s in self.special])


def _loop_at(system, overrides, param, value):
    """The map's loop at param = value: a preset by name, or a compiled model / PiecewiseSystem
    with the parameter set by name (its stick family)."""
    if isinstance(system, str):
        return preset(system, **{**overrides, param: value})
    values = {**overrides, param: value}
    changed = system.with_params(values) if isinstance(system, PiecewiseSystem) else system.with_params(**values)
    return as_stick_map(changed)


def _fold_margin(preset_name, overrides, param, value, lo_d, hi_d, sign, iterate, opt):
    """max over d in [lo_d, hi_d] of sign * (P^k(d) - d): > 0 while the cycle pair exists."""
    loop = _loop_at(preset_name, overrides, param, value)
    ds = np.linspace(lo_d, hi_d, 33)
    mv = evaluate_map(loop, ds, iterate, opt)
    g = np.where(mv.ok, sign * (mv.image - ds), -np.inf)
    i = int(np.argmax(g))
    a, b = ds[max(i - 1, 0)], ds[min(i + 1, ds.size - 1)]

    def neg(d):
        m = evaluate_map(loop, [d], iterate, opt)
        return -(sign * (m.image[0] - d)) if m.ok[0] else np.inf
    r = minimize_scalar(neg, bounds=(a, b), method="bounded", options=dict(xatol=1e-9 * max(hi_d, 1e-12)))
    return max(-r.fun, g[i]), float(r.x)


def _refine_fold(preset_name, overrides, param, v_exist, v_gone, lo_d, hi_d, sign, iterate, opt, tol):
    d_f = 0.5 * (lo_d + hi_d)
    for _ in range(60):
        if abs(v_gone - v_exist) <= tol * max(1.0, abs(v_exist)):
            break
        mid = 0.5 * (v_exist + v_gone)
        m, d_f = _fold_margin(preset_name, overrides, param, mid, lo_d, hi_d, sign, iterate, opt)
        if m > 0:
            v_exist = mid
        else:
            v_gone = mid
    return v_exist, v_gone, d_f


def _refine_equilibrium(preset_name, overrides, param, v_a, v_b, stable_a, iterate, scale, opt, tol):
    for _ in range(60):
        if abs(v_b - v_a) <= tol * max(1.0, abs(v_a)):
            break
        mid = 0.5 * (v_a + v_b)
        st = origin_slope(_loop_at(preset_name, overrides, param, mid), iterate, scale, opt).stable
        if st == stable_a:
            v_a = mid
        else:
            v_b = mid
    return v_a, v_b


def map_diagram(preset_name: str, param: str, values, *, overrides: dict | None = None, iterate: int = 2,
                grid=None, d_max: float = 0.5, refine: bool = True, tol: float = 1e-6,
                options: MapOptions | None = None) -> MapDiagram:
    """Fixed points of P^k for each parameter value; folds (a stable and an unstable cycle meet
    and vanish) and changes of the equilibrium set's stability refined by bisection in the
    parameter to a relative width ``tol``.

    preset_name, overrides : the loop (``hunting.preset(preset_name, **overrides, param=v)``),
        or a compiled model or PiecewiseSystem with one Switch contact (its parameters by name)
    param : the parameter to sweep (any preset parameter, e.g. "P" or "K", or a model's or
        system's parameter); values : (p,)"""
    overrides = dict(overrides or {})
    values = np.asarray(values, dtype=float)
    if values.ndim != 1 or values.size < 1 or not np.all(np.isfinite(values)):
        raise SystemDefinitionError(f"values = {values!r} must be a non-empty 1-D array of finite numbers")
    opt = options or MapOptions()
    grid = default_grid(d_max) if grid is None else np.asarray(grid, dtype=float)
    scale = float(np.max(np.abs(grid)))
    fixed = [fixed_points(_loop_at(preset_name, overrides, param, v), grid, iterate, options=opt) for v in values]
    special: list[SpecialPoint] = []
    for i in range(values.size - 1):
        a, b = fixed[i], fixed[i + 1]
        ca = [f for f in a if f.kind == "cycle"]
        cb = [f for f in b if f.kind == "cycle"]
        # fold: a stable/unstable pair present on one side only
        for side_exist, side_gone, v_e, v_g in ((ca, cb, values[i], values[i + 1]), (cb, ca, values[i + 1], values[i])):
            if len(side_exist) - len(side_gone) >= 2:
                st = [f for f in side_exist if f.stable]
                un = [f for f in side_exist if not f.stable]
                if st and un:
                    pair = sorted([min(un, key=lambda f: f.d), min(st, key=lambda f: abs(f.d - un[0].d))], key=lambda f: f.d)
                    lo_d, hi_d = pair[0].d, pair[1].d
                    mid_d = 0.5 * (lo_d + hi_d)
                    mv = evaluate_map(_loop_at(preset_name, overrides, param, v_e), [mid_d], iterate, opt)
                    sign = float(np.sign(mv.image[0] - mid_d))
                    if refine:
                        ve, vg, d_f = _refine_fold(preset_name, overrides, param, v_e, v_g, lo_d, hi_d, sign,
                                                   iterate, opt, tol)
                    else:
                        ve, vg, d_f = v_e, v_g, mid_d
                    lo, hi = sorted((ve, vg))
                    special.append(SpecialPoint("fold", i, 0.5 * (lo + hi), (lo, hi), hi - lo, {"d": d_f}))
        ea = next(f for f in a if f.kind == "equilibrium")
        eb = next(f for f in b if f.kind == "equilibrium")
        if ea.stable != eb.stable:
            lo, hi = values[i], values[i + 1]
            if refine:
                lo, hi = _refine_equilibrium(preset_name, overrides, param, lo, hi, ea.stable, iterate, scale, opt, tol)
            lo, hi = sorted((lo, hi))
            special.append(SpecialPoint("equilibrium_stability", i, 0.5 * (lo + hi), (lo, hi), hi - lo,
                                        {"stable_above": float(eb.stable)}))
    name = preset_name if isinstance(preset_name, str) else getattr(preset_name, "name", "system")
    label = f"{name} " + " ".join(f"{k}={v}" for k, v in overrides.items())
    return MapDiagram(param, values, fixed, special, iterate, label.strip())
