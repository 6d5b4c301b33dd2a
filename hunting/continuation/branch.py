"""Pseudo-arclength continuation of periodic orbits in one parameter.

Unknowns u = (x0 without the section component, T, mu), scaled by their magnitudes at the
start. Predictor: the unit tangent (null vector of [F_z | F_mu], oriented along the previous
one) with a quadratic term through the point before. Corrector: quasi-Newton on
[F(u); t . (u - u_pred)] = 0 from the Jacobian extrapolated along the branch, Broyden updates
and one flow without sensitivities per iteration; the Jacobian (monodromy-based F_z, F_mu from
the flow's parameter-sensitivity column) is taken once the residual is small, where it stops
contracting, and at the converged point unless the corrector's last one was close enough; full
Newton takes over where the quasi-Newton fails. Step size grows after
easy corrections and shrinks after hard or failed ones and sharp turns of the tangent. At
every point: Floquet multipliers and stability. Special points: folds (mu
turns back; a multiplier passes +1) located by bisection in arclength, period doublings
(a multiplier passes -1), tori (a complex pair leaves the unit circle) and "grazing": the
event sequence of the orbit changes (a stick phase or a velocity reversal appears or vanishes),
bracketed between two branch points with the event counts before and after.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import SystemDefinitionError
from ..results import SpecialPoint
from ..system import PiecewiseSystem
from .flow import Flow, flow
from .shooting import PeriodicOrbit, ShootingOptions, floquet, orbit_amplitude
from .status import OrbitStatus


@dataclass(frozen=True)
class ContinuationOptions:
    """ds : first step (in scaled arclength); ds_min, ds_max : bounds; max_points : bound on
    branch points; newton_tol, newton_max : corrector; dmu : relative step of the central
    difference d params / d mu; fold_tol : relative parameter width at which a fold stops
    being refined; chord_rate : slowest contraction of the residual accepted with a kept
    Jacobian (slower ones recompute it); max_correction : largest corrector move as a fraction
    of ds and max_angle [rad] the largest turn of the tangent in one step (larger ones halve
    ds: no branch jumping); jacobian_reuse : the corrector takes a Jacobian flow at its first
    iterate with scaled residual at most this, and a converged point within this distance
    (max-norm, scaled units) of the iterate of the corrector's last Jacobian flow keeps that
    Jacobian for its multipliers and tangent (else it gets a flow of its own; with 1e-6 the
    multipliers on the chapter-8 LuGre branch stay within 4e-4 of flows at rtol 1e-11, as
    without reuse: near the fold they are that sensitive); jacobian_method : integration
    method of the flows with sensitivities (None: the shooting method; "radau" for stiff
    loops such as LuGre: its variational stages are solved exactly with the stage Jacobians,
    5-10 ms a chapter-8 cycle against DOP853's 9-13 ms); trivial_tol : a point whose trivial
    multiplier is further than this (or 1e3 newton_tol) from 1, relative to
    max(1, |lambda_2|), gets its Jacobian again, at the point, with the shooting method and
    Phi under its error control (near a fold two multipliers meet at 1 and their errors grow
    like the square root of Phi's). Flows without sensitivities run at rtol =
    min(shooting rtol, newton_tol / 100), flows with sensitivities at 100 times that."""

    ds: float = 0.05
    ds_min: float = 1e-6
    ds_max: float = 0.3
    max_points: int = 400
    newton_tol: float = 1e-9
    newton_max: int = 12
    chord_rate: float = 0.6
    dmu: float = 1e-8
    fold_tol: float = 1e-7
    max_correction: float = 0.3
    step_tol: float = 1e-10
    max_angle: float = 0.15
    jacobian_reuse: float = 1e-6
    jacobian_method: str | None = None
    trivial_tol: float = 1e-4
    quadratic_predictor: bool = True

    def __post_init__(self):
        for name in ("ds", "ds_min", "ds_max", "newton_tol", "dmu", "fold_tol", "jacobian_reuse", "trivial_tol"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise SystemDefinitionError(f"{name} = {v!r} is not allowed: it must be a finite number > 0")
        if self.jacobian_method not in (None, "dop853", "dp5", "radau"):
            raise SystemDefinitionError(f"jacobian_method = {self.jacobian_method!r} is not allowed: "
                                        f"use None, 'dop853', 'dp5' or 'radau'")
        if self.ds_min > self.ds or self.ds > self.ds_max:
            raise SystemDefinitionError(f"need ds_min <= ds <= ds_max, got {self.ds_min}, {self.ds}, {self.ds_max}")


@dataclass(frozen=True)
class Branch:
    """A branch of periodic orbits.

    param : name; mu : (m,) parameter values; period : (m,); amplitude : (m,) max |x1|;
    multipliers : (m, n) complex (trivial first); stable : (m,) bool; x0 : (m, n);
    modes : list of mode sequences; special : list of SpecialPoint; status : OrbitStatus
    (SUCCESS: the run ended where asked; POINT_LIMIT, STEP_LIMIT, NO_START, INTEGRATION_FAILED);
    message : what happened and what to change; label; state_names : names of the x0 columns."""

    param: str
    mu: np.ndarray
    period: np.ndarray
    amplitude: np.ndarray
    multipliers: np.ndarray
    stable: np.ndarray
    x0: np.ndarray
    modes: list
    special: list
    status: OrbitStatus
    message: str
    label: str = ""
    state_names: tuple = ()

    def as_dict(self) -> dict:
        names = self.state_names or tuple(f"x{i + 1}" for i in range(self.x0.shape[1] if self.x0.ndim == 2 else 0))
        pts = [dict(param=float(m), period=float(T), amplitude=float(a),
                    multipliers=[[float(z.real), float(z.imag)] for z in lam], stable=bool(s),
                    x0={k: float(v) for k, v in zip(names, x)})
               for m, T, a, lam, s, x in zip(self.mu, self.period, self.amplitude, self.multipliers, self.stable,
                                             self.x0)]
        return dict(param=self.param, label=self.label, status=self.status.name, message=self.message,
                    points=pts, special_points=[s.as_dict() for s in self.special])


def _scaled(r, x):
    """max |r_i| / scale_i with scale_i = max(|x_i|, 0.1 max|x|): components that are zero on the
    section (x1 = 0) are measured against the orbit's size, not against zero."""
    return float(np.max(np.abs(r) / np.maximum(np.abs(x), 0.1 * np.max(np.abs(x)) + 1e-300)))


def _trivial_error(fl) -> float:
    """|lambda_trivial - 1| / max(1, |lambda_2|) of a flow's monodromy matrix."""
    lam, err = floquet(fl.Phi, fl.f)
    return err / max(1.0, float(np.abs(lam[1])) if len(lam) > 1 else 1.0)


def _nontrivial_near(lam, target):
    rest = lam[1:]
    k = int(np.argmin(np.abs(rest - target)))
    return rest[k]


def continue_orbit(system_at: Callable[[float], PiecewiseSystem], orbit: PeriodicOrbit, mu0: float,
                   mu_end: float, *, param: str = "mu", section: int | None = None,
                   options: ContinuationOptions | None = None, shooting: ShootingOptions | None = None,
                   stop_at_mu: float | None = None, max_turns: int = 1,
                   amplitude: Callable[[PiecewiseSystem, np.ndarray, float, Flow], float] | None = None,
                   param_direction: Callable[[float], np.ndarray] | None = None) -> Branch:
    """Follow the branch through ``orbit`` (at parameter mu0) towards mu_end.

    Parameters
    ----------
    system_at : callable mu -> PiecewiseSystem
        The system at parameter mu (its compiled functions shared, only the parameters change):
        ``ParameterLens.system_at``; :func:`follow` builds it from a parameter name.
    orbit : PeriodicOrbit at mu0 (converged)
    mu0, mu_end : float
        Start and end of the parameter range (mu0 != mu_end).
    param : name for the result; section : the state held fixed by the phase condition
        (default: the orbit's own, where its shooting held it)
    options, shooting : ContinuationOptions, ShootingOptions
    stop_at_mu, max_turns : after ``max_turns`` folds the run stops once mu passes stop_at_mu
    amplitude : callable (system, x0, T, flow) -> float, optional
        Each point's amplitude from its converged flow (default: max |x1| of a simulation
        sampled at 4001 points and at the events, :func:`orbit_amplitude`).
    param_direction : callable mu -> (n_params,) d params / d mu, optional
        Default: central differences of ``system_at``.

    Returns
    -------
    Branch
        Ends when mu leaves [min(mu0, mu_end), max(mu0, mu_end)] (SUCCESS), after the folds
        (SUCCESS), at max_points (POINT_LIMIT) or when the corrector fails at ds_min
        (STEP_LIMIT).
    """
    if not (np.isfinite(mu0) and np.isfinite(mu_end)) or mu0 == mu_end:
        raise SystemDefinitionError(f"mu0 = {mu0!r} and mu_end = {mu_end!r} are not allowed: the parameter range "
                                    f"must have two different finite ends")
    opt = options or ContinuationOptions()
    sopt = shooting or ShootingOptions()
    n = len(orbit.x0)
    section = orbit.section if section is None else int(section)
    free = [i for i in range(n) if i != section]
    c_sec = float(orbit.x0[section])
    scale = np.concatenate([np.maximum(np.abs(orbit.x0[free]), 1e-3 * np.max(np.abs(orbit.x0))),
                            [orbit.period, max(abs(mu0), 1e-6)]])
    lo, hi = sorted((mu0, mu_end))
    # a residual flow's error must stay below the corrector's tolerance: rtol <= newton_tol / 100
    rtol_res = min(sopt.rtol, 1e-2 * opt.newton_tol)
    kw_res = dict(method=sopt.method, rtol=rtol_res, atol=rtol_res * sopt.atol / sopt.rtol,
                  max_events=sopt.max_events, max_steps=sopt.max_steps)
    # two accuracies: residual flows (no sensitivities) at rtol_res; flows with sensitivities
    # (the corrector's Jacobians, the points' multipliers and tangents) at 100 rtol_res: they
    # only steer the corrector and give the multipliers, every residual is a flow of its own
    kw_jac = dict(kw_res, rtol=100 * kw_res["rtol"], atol=100 * kw_res["atol"],
                  method=opt.jacobian_method or sopt.method)

    # the trivial multiplier of an orbit closed to newton_tol is not closer to 1 than ~1e3 times that
    triv_tol = max(opt.trivial_tol, 1e3 * opt.newton_tol)

    def unpack(v):
        u = v * scale
        x = np.empty(n)
        x[section] = c_sec
        x[free] = u[:-2]
        return x, u[-2], u[-1]

    def fd_direction(mu):
        """d params / d mu at mu (central differences of system_at: exact for the usual
        parameters, which enter the array linearly)."""
        h = opt.dmu * max(abs(mu), 1e-3)
        return (system_at(mu + h).params - system_at(mu - h).params) / (2 * h)
    direction = param_direction or fd_direction

    def residual_and_jac(v, need_jac=True, method=None):
        """(r, J, flow) at v; J = [Phi - I without the section column | f | d phi / d mu],
        the last column from the flow's parameter-sensitivity column (``method``: instead of
        jacobian_method)."""
        x, T, mu = unpack(v)
        if not (np.isfinite(T) and T > 0 and np.all(np.isfinite(x)) and np.isfinite(mu)):
            return None                  # a diverging corrector: the caller halves the step
        sys_ = system_at(mu)
        if need_jac:
            fl = flow(sys_, x, T, param_direction=direction(mu), **(kw_jac if method is None
                                                                          else dict(kw_jac, method=method)))
        else:
            fl = flow(sys_, x, T, sensitivity=False, **kw_res)
        if not fl.ok:
            return None
        r = fl.x - x
        if not need_jac:
            return r, None, fl
        Jz = np.column_stack([(fl.Phi - np.eye(n))[:, free], fl.f, fl.dx_dmu]) * scale[None, :]
        return r, Jz, fl

    def tangent(J, prev=None):
        _, _, vt = np.linalg.svd(J)
        t = vt[-1]
        if prev is not None and np.dot(t, prev) < 0:
            t = -t
        return t / np.linalg.norm(t)

    def iterate(v_pred, t, J0, newton):
        """The corrector's iterations from v_pred, each from a flow without sensitivities.
        Quasi-Newton (``newton`` False) from J0 with Broyden updates; a precise Jacobian flow
        at the first iterate whose scaled residual is at most ``jacobian_reuse`` (it becomes
        the Newton matrix and, at convergence, the point's Jacobian), and wherever the
        residual contracts slower than chord_rate. Newton (``newton`` True): a Jacobian flow
        at every iterate. Returns (v, Jacobian recomputations, (iterate, J, flow) of the last
        Jacobian flow or None) or None."""
        v = v_pred.copy()
        Jq = J0
        res_prev = np.inf
        r_prev = dv = None
        refreshes = 0
        last_jac = None
        for k in range(opt.newton_max):
            out = residual_and_jac(v, need_jac=False)
            if out is None:
                return None
            r = out[0]
            res = _scaled(r, unpack(v)[0])
            g = np.dot(t, v - v_pred)
            if res < opt.newton_tol and abs(g) < 1e-12:
                return v, refreshes, last_jac
            slow = res > opt.chord_rate * res_prev
            if slow and res > res_prev and (newton or refreshes):
                return None                      # diverging even with a fresh Jacobian
            planned = last_jac is None and res <= opt.jacobian_reuse
            if newton or Jq is None or slow or planned:
                out = residual_and_jac(v)
                if out is None:
                    return None
                Jq = out[1]
                last_jac = (v.copy(), out[1], out[2])
                refreshes += not planned
            elif dv is not None:
                # Broyden's rank-one update with the secant (dv, r - r_prev)
                Jq = Jq + np.outer(r - r_prev - Jq @ dv, dv) / np.dot(dv, dv)
            res_prev, r_prev = res, r
            try:
                dv = np.linalg.solve(np.vstack([Jq, t]), -np.append(r, g))
            except np.linalg.LinAlgError:
                return None
            v = v + dv
            # the residual of a strongly unstable orbit has a noise floor (integration error
            # amplified by its multiplier): a negligible Newton step also means convergence
            if np.linalg.norm(dv) < opt.step_tol and res < 1e3 * opt.newton_tol:
                return v, refreshes, last_jac
        out = residual_and_jac(v, need_jac=False)
        if out is None or _scaled(out[0], unpack(v)[0]) >= 10 * opt.newton_tol:
            return None
        return v, refreshes, last_jac

    def correct(v_pred, t, J0, reuse=True):
        """Converge from the predictor onto the branch: quasi-Newton from J0 (the last point's
        Jacobian extrapolated). Where that fails (sharp folds), Newton with a Jacobian flow
        at every iterate. The converged point keeps the corrector's last Jacobian when that
        was taken within ``jacobian_reuse`` of it (max-norm, scaled units) and ``reuse``;
        else it gets its own (its monodromy matrix gives the multipliers, its null vector
        the tangent whose parameter component locates folds).
        Returns (v, J, flow, Jacobian recomputations) or None."""
        it = iterate(v_pred, t, J0, newton=False)
        if it is None:
            it = iterate(v_pred, t, None, newton=True)
            if it is None:
                return None
        v, refreshes, last_jac = it
        reused = reuse and last_jac is not None and np.max(np.abs(v - last_jac[0])) <= opt.jacobian_reuse
        if reused:
            J, fl = last_jac[1], last_jac[2]
        else:
            out = residual_and_jac(v)
            if out is None:
                return None
            J, fl = out[1], out[2]
        if _trivial_error(fl) > triv_tol and (reused or kw_jac["method"] != sopt.method):
            # near a fold two multipliers meet at 1 and their errors grow like the square root
            # of the monodromy matrix's: the point's own Jacobian, with Phi under error control
            out = residual_and_jac(v, method=sopt.method)
            if out is None:
                return None
            J, fl = out[1], out[2]
        return v, J, fl, refreshes

    v = np.concatenate([orbit.x0[free], [orbit.period, mu0]]) / scale
    out = residual_and_jac(v)
    if out is None:
        n_par = len(system_at(mu0).params)
        return Branch(param, np.empty(0), np.empty(0), np.empty(0), np.empty((0, n), dtype=complex),
                      np.empty(0, dtype=bool), np.empty((0, n)), [], [], OrbitStatus.INTEGRATION_FAILED,
                      f"the starting orbit at {param} = {mu0:.6g} could not be integrated with its sensitivities "
                      f"({n_par} parameters): check the orbit and the shooting options")
    r, J, fl = out
    t = tangent(J)
    if np.sign(t[-1]) != np.sign(mu_end - mu0):
        t = -t
    pts_v, pts_fl = [v], [fl]
    J_prev = None
    special: list[SpecialPoint] = []
    ds = opt.ds
    status, message = OrbitStatus.SUCCESS, "reached the end of the parameter range"
    turns = 0
    while True:
        if len(pts_v) >= opt.max_points:
            status, message = OrbitStatus.POINT_LIMIT, (f"max_points = {opt.max_points} reached at {param} = "
                                                        f"{unpack(v)[2]:.6g}: raise max_points or ds_max")
            break
        v_pred = v + ds * t
        if len(pts_v) >= 2 and opt.quadratic_predictor:
            # second-order predictor: the parabola through the last point with its tangent and
            # the point before it (halves the corrector's work on curved branches)
            chord = pts_v[-2] - v
            h = float(np.linalg.norm(chord))
            if h > 0:
                c = (chord + h * t) / h ** 2
                if np.linalg.norm(c) * ds ** 2 < 0.5 * ds:
                    v_pred = v_pred + c * ds ** 2
        J_pred = J
        if J_prev is not None and opt.quadratic_predictor:
            # the Jacobian extrapolated along the branch like the point: its error at the
            # predictor is O(ds^2) instead of O(ds), so the quasi-Newton corrector rarely
            # needs to recompute it
            J_pred = J + (J - J_prev) * (ds / float(np.linalg.norm(v - pts_v[-2])))
        res = correct(v_pred, t, J_pred)
        if res is None:
            ds *= 0.5
            if ds < opt.ds_min:
                status, message = OrbitStatus.STEP_LIMIT, (f"the corrector failed at step ds < ds_min = {opt.ds_min:g} "
                                                           f"near {param} = {unpack(v)[2]:.6g}: "
                                                           + OrbitStatus.STEP_LIMIT.advice)
                break
            continue
        v_new, J_new, fl_new, refreshes = res
        t_new = tangent(J_new, t)
        # guard against jumping to a nearby branch: the corrector must stay close to the
        # predictor and the tangent must not turn too much in one step
        if (np.linalg.norm(v_new - v_pred) > opt.max_correction * ds
                or np.dot(t_new, t) < np.cos(opt.max_angle)) and ds > opt.ds_min * 4:
            ds *= 0.5
            continue
        mu_new = unpack(v_new)[2]
        # the next step from the corrector's work (a Jacobian recomputed more than once: the
        # predictor was too far) and the tangent's turn (no more than half of max_angle)
        turn = float(np.arccos(np.clip(np.dot(t_new, t), -1.0, 1.0)))
        grow = min((1.4, 1.0, 0.7)[min(refreshes, 2)], 0.5 * opt.max_angle / max(turn, 1e-12))
        # fold: the parameter component of the tangent changes sign
        if np.sign(t_new[-1]) != np.sign(t[-1]):
            sp = _refine_fold(lambda vp, tp: correct(vp, tp, J, reuse=False), tangent, unpack, v, t, ds, opt, len(pts_v) - 1)
            special.append(sp)
            turns += 1
        if tuple(fl_new.modes) != tuple(fl.modes) and len(fl_new.modes) != len(fl.modes):
            special.append(SpecialPoint("grazing", len(pts_v) - 1, 0.5 * (unpack(v)[2] + mu_new),
                                        tuple(sorted((unpack(v)[2], mu_new))), abs(mu_new - unpack(v)[2]),
                                        {"events_before": len(fl.modes) - 1, "events_after": len(fl_new.modes) - 1}))
        v, t, fl, J, J_prev = v_new, t_new, fl_new, J_new, J
        pts_v.append(v)
        pts_fl.append(fl)
        if mu_new < lo or mu_new > hi:
            break
        if turns >= max_turns and stop_at_mu is not None:
            if (t[-1] < 0 and mu_new <= stop_at_mu) or (t[-1] > 0 and mu_new >= stop_at_mu):
                message = f"stopped at {param} = {mu_new:.6g} after {turns} fold(s)"
                break
        ds = float(np.clip(ds * grow, max(opt.ds_min, 0.5 * ds), opt.ds_max))
    # assemble
    mus, Ts, amps, lams, stab, xs, modes = [], [], [], [], [], [], []
    for vv, ff in zip(pts_v, pts_fl):
        x, T, mu = unpack(vv)
        lam, _ = floquet(ff.Phi, ff.f)
        mus.append(mu)
        Ts.append(T)
        xs.append(x)
        lams.append(lam)
        stab.append(bool(np.all(np.abs(lam[1:]) < 1.0)))
        modes.append(tuple(int(m) for m in ff.modes))
        amps.append(amplitude(system_at(mu), x, T, ff) if amplitude is not None
                    else orbit_amplitude(system_at(mu), x, T, method=sopt.method))
    lams = np.array(lams)
    # multiplier crossings: changes in the number of non-trivial multipliers outside the unit
    # circle through +1 (fold), through -1 (period doubling) or as a complex pair (torus)
    def counts(lam):
        rest = lam[1:]
        real = np.abs(rest.imag) < 1e-9 * np.maximum(1.0, np.abs(rest))
        return (int(np.sum(real & (rest.real > 1))), int(np.sum(real & (rest.real < -1))),
                int(np.sum(~real & (np.abs(rest) > 1))))
    for i in range(len(mus) - 1):
        ca, cb = counts(lams[i]), counts(lams[i + 1])
        for j, kind, target in ((0, "multiplier_+1", 1.0), (1, "period_doubling", -1.0), (2, "torus", None)):
            if ca[j] != cb[j]:
                lo_mu, hi_mu = sorted((mus[i], mus[i + 1]))
                data = {"unstable_before": ca[j], "unstable_after": cb[j]}
                est = 0.5 * (mus[i] + mus[i + 1])
                if target is not None:
                    a = _nontrivial_near(lams[i], target).real
                    b = _nontrivial_near(lams[i + 1], target).real
                    if a != b and (a - target) * (b - target) <= 0:
                        est = mus[i] + (target - a) / (b - a) * (mus[i + 1] - mus[i])
                    data.update(multiplier_before=a, multiplier_after=b)
                special.append(SpecialPoint(kind, i, float(est), (lo_mu, hi_mu), hi_mu - lo_mu, data))
    special.sort(key=lambda s: s.index)
    return Branch(param, np.array(mus), np.array(Ts), np.array(amps), lams, np.array(stab), np.array(xs), modes,
                  special, status, message, state_names=tuple(system_at(mu0).state_names))


def _refine_fold(correct, tangent, unpack, v0, t0, ds, opt, index):
    """Bisect the arclength step from (v0, t0) until the tangent's parameter component is ~0."""
    a, b = 0.0, ds
    best = None
    for _ in range(60):
        mid = 0.5 * (a + b)
        res = correct(v0 + mid * t0, t0)
        if res is None:
            b = mid
            continue
        v, J, fl, _ = res
        tm = tangent(J, t0)
        best = (v, tm)
        if np.sign(tm[-1]) == np.sign(t0[-1]):
            a = mid
        else:
            b = mid
        mu_a = unpack(v0 + a * t0)[2]
        mu_b = unpack(v0 + b * t0)[2]
        if abs(b - a) < 1e-10 or abs(mu_b - mu_a) < opt.fold_tol * max(abs(mu_a), 1e-12):
            break
    v = best[0] if best is not None else v0
    mu = unpack(v)[2]
    ra = correct(v0 + a * t0, t0)
    rb = correct(v0 + b * t0, t0)
    mus = [unpack(r[0])[2] for r in (ra, rb) if r is not None] or [mu]
    lo_mu, hi_mu = min(mus + [mu]), max(mus + [mu])
    x, T, _ = unpack(v)
    return SpecialPoint("fold", index, float(mu), (lo_mu, hi_mu), hi_mu - lo_mu, {"period": float(T)})
