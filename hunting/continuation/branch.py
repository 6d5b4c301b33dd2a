"""Pseudo-arclength continuation of periodic orbits in one parameter.

Unknowns u = (x0 without the section component, T, mu), scaled by their magnitudes at the
start; the phase plane x[section] = c moves to the orbit's fastest point in x[section] when
the base point slows below ``reanchor`` of its speed (an orbit drifting off its first plane
would make a false fold). Predictor: the unit tangent (null vector of [F_z | F_mu], oriented along the previous
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

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import SystemDefinitionError
from ..integrate.simulate import simulate
from ..results import SpecialPoint
from ..system import PiecewiseSystem
from .flow import Flow, flow
from .shooting import STEPS_PER_PERIOD, PeriodicOrbit, ShootingOptions, floquet, orbit_amplitude, steps_over_event
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
    min(shooting rtol, newton_tol / 100), flows with sensitivities at 100 times that.
    max_step : bound on the flows' steps (the orbit's own, when smaller, is kept);
    check_events : for systems with stick modes, each point's period is sampled (2001 points)
    and checked for a stick guard on its firing side (:func:`missed_event`: a flow stepped over
    a short break-away, and the point is not an orbit of the system); from such a point on the
    flows take at most T / STEPS_PER_PERIOD per step and the point is corrected again.
    reanchor : the phase condition x[section] = c is a fixed plane; an orbit that drifts with
    the parameter can leave it (its extreme of x[section] passes c) and the branch would turn
    there in a false fold. When the speed |x[section]'| at the base point falls below this
    fraction of its largest value along the orbit, the base point moves to where that speed
    is largest (same orbit, new c); 0 turns this off."""

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
    max_step: float = np.inf
    check_events: bool = True
    reanchor: float = 0.3

    def __post_init__(self):
        if not (np.isfinite(self.reanchor) and 0 <= self.reanchor < 1):
            raise SystemDefinitionError(f"reanchor = {self.reanchor!r} is not allowed: it must be in [0, 1)")
        for name in ("ds", "ds_min", "ds_max", "newton_tol", "dmu", "fold_tol", "jacobian_reuse", "trivial_tol"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise SystemDefinitionError(f"{name} = {v!r} is not allowed: it must be a finite number > 0")
        if not self.max_step > 0:
            raise SystemDefinitionError(f"max_step = {self.max_step!r} is not allowed: it must be > 0 (inf: no bound)")
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
    message : what happened and what to change; label; state_names : names of the x0 columns;
    units : the system's units by name (figure labels; empty when unknown)."""

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
    units: dict = field(default_factory=dict)

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


def mode_cycle(fl: Flow, T: float, min_fraction: float = 1e-9) -> tuple:
    """The orbit's event structure as a cyclic sequence of modes, independent of where on the
    orbit the flow started: mode stretches shorter than ``min_fraction`` T dropped (a start
    on a switching surface passes through a mode for no time), repeats merged, the two ends
    joined, and the sequence rotated to its smallest form. Two orbits have the same structure
    exactly when these agree (the number of events per period is its length).

    Examples
    --------
    >>> import numpy as np
    >>> from hunting.continuation.branch import mode_cycle
    >>> class F: pass
    >>> a, b = F(), F()
    >>> a.modes, a.event_times = np.array([2, 1, 2]), np.array([1.0, 3.0])
    >>> b.modes, b.event_times = np.array([0, 2, 1, 2]), np.array([0.0, 1.0, 3.0])
    >>> mode_cycle(a, 5.0), mode_cycle(b, 5.0)
    ((1, 2), (1, 2))
    """
    modes = [int(m) for m in fl.modes]
    bounds = np.concatenate([[0.0], np.asarray(fl.event_times, dtype=float), [float(T)]])
    seq = []
    for m, dur in zip(modes, np.diff(bounds)[:len(modes)]):
        if dur <= min_fraction * T:
            continue
        if not seq or seq[-1] != m:
            seq.append(m)
    if len(seq) > 1 and seq[0] == seq[-1]:
        seq.pop()
    if not seq:
        return ()
    return min(tuple(seq[k:] + seq[:k]) for k in range(len(seq)))


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
                  max_events=sopt.max_events, max_steps=sopt.max_steps,
                  max_step=min(opt.max_step, sopt.max_step, getattr(orbit, "max_step", np.inf)))
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

    sticks = opt.check_events and any(m.kind in ("stick", "filippov") for m in system_at(mu0).modes)
    capped_at = []                  # the parameter value from which the flows' steps were bounded

    def missed(v):
        """Whether the flow of point v stepped over a short event; if so, bound the steps of
        every later flow (kw_res, kw_jac) to T / STEPS_PER_PERIOD."""
        if not sticks:
            return False
        x, T, mu = unpack(v)
        h = T / STEPS_PER_PERIOD
        if kw_res["max_step"] <= h or not steps_over_event(system_at(mu), x, T, method=sopt.method,
                                                           max_step=kw_res["max_step"]):
            return False
        kw_res["max_step"] = kw_jac["max_step"] = h
        capped_at.append(mu)
        return True

    v = np.concatenate([orbit.x0[free], [orbit.period, mu0]]) / scale
    missed(v)
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

    def section_speeds(x, T, mu):
        """(samples (m, n), |x[section]'| (m,)) along one period from x, or None."""
        sys_ = system_at(mu)
        tr = simulate(sys_, x, (0.0, T), t_eval=np.linspace(0.0, T, 2001), rtol=kw_res["rtol"],
                      atol=kw_res["atol"], max_step=kw_res["max_step"], max_events=sopt.max_events)
        if not tr.success or len(tr.t) < 2:
            return None
        speed = np.array([abs(sys_.evaluate(xi, int(mi))[section]) for xi, mi in zip(tr.x, tr.mode)])
        return tr.x, speed

    def reanchor(v, t, fl, force=False):
        """Move the base point of the orbit at v to where |x[section]'| is largest (the phase
        plane x[section] = c_sec follows the orbit) unless its speed there is still at least
        ``reanchor`` of that largest one (then it only becomes the new ``ref_speed``) and not
        ``force``. Returns (v, t, fl, J) in the new coordinates, or None where the point stays
        (its plane is still transversal, or the moved point does not converge)."""
        nonlocal c_sec, ref_speed
        x, T, mu = unpack(v)
        out = section_speeds(x, T, mu)
        if out is None:
            return None
        xs, speed = out
        i = int(np.argmax(speed))
        if not force and abs(fl.f[section]) >= opt.reanchor * speed[i]:
            ref_speed = abs(float(fl.f[section]))
            return None
        old = c_sec, scale.copy()
        x_new = xs[i].copy()
        c_sec = float(x_new[section])
        scale[:-2] = np.maximum(np.abs(x_new[free]), 1e-3 * np.max(np.abs(x_new)))
        e_mu = np.zeros_like(v)
        e_mu[-1] = 1.0
        res = correct(np.concatenate([x_new[free], [T, mu]]) / scale, e_mu, None, reuse=False)
        if res is None or abs(unpack(res[0])[2] - mu) > 1e-9 * max(abs(mu), 1e-12):
            c_sec, scale[:] = old[0], old[1]
            return None
        v_new, J_new, fl_new, _ = res
        t_new = tangent(J_new)
        # T and mu keep their scales: their tangent components orient the new tangent
        if np.dot(t_new[-2:], t[-2:]) < 0:
            t_new = -t_new
        ref_speed = abs(float(fl_new.f[section]))
        return v_new, t_new, fl_new, J_new

    # |x[section]'| at the base point when it was last judged transversal: the start's own
    # plane is kept (the cycle search chose it) until the speed falls below reanchor of this
    ref_speed = abs(float(fl.f[section]))
    pts_v, pts_fl = [v], [fl]
    pts_xtm = [unpack(v)]
    v_before = None                     # the point before v in the current coordinates
    forced_at = -1                      # the point from which the base point was last moved at a turn
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
        if v_before is not None and opt.quadratic_predictor:
            # second-order predictor: the parabola through the last point with its tangent and
            # the point before it (halves the corrector's work on curved branches)
            chord = v_before - v
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
            J_pred = J + (J - J_prev) * (ds / float(np.linalg.norm(v - v_before)))
        res = correct(v_pred, t, J_pred)
        if res is not None and missed(res[0]):
            # the point is not an orbit of the system: correct it again with bounded steps
            res = correct(res[0], t, res[1], reuse=False)
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
        if mu_new < lo or mu_new > hi:
            # the step passed the end of the range: the last point lands on it exactly
            # (a corrector with the parameter held at the end, from the chord's point there)
            mu_end_hit = hi if mu_new > hi else lo
            mu_old = unpack(v)[2]
            if mu_new != mu_old:
                e_mu = np.zeros_like(v)
                e_mu[-1] = 1.0
                frac = (mu_end_hit - mu_old) / (mu_new - mu_old)
                land = correct(v + frac * (v_new - v), e_mu, J_new)
                if land is not None and abs(unpack(land[0])[2] - mu_end_hit) <= 1e-9 * max(abs(mu_end_hit), 1e-12):
                    v_new, J_new, fl_new, _ = land
                    t_new = tangent(J_new, t)
                    mu_new = unpack(v_new)[2]
        # the next step from the corrector's work (a Jacobian recomputed more than once: the
        # predictor was too far) and the tangent's turn (no more than half of max_angle)
        turn = float(np.arccos(np.clip(np.dot(t_new, t), -1.0, 1.0)))
        grow = min((1.4, 1.0, 0.7)[min(refreshes, 2)], 0.5 * opt.max_angle / max(turn, 1e-12))
        # fold: the parameter component of the tangent changes sign; not where the orbit only
        # slid off the phase plane (the section tangent to it: the branch retraces the same
        # orbits), there the base point moves and the step is taken again
        if np.sign(t_new[-1]) != np.sign(t[-1]):
            if (opt.reanchor > 0 and forced_at != len(pts_v)
                    and min(abs(fl.f[section]), abs(fl_new.f[section])) < opt.reanchor * ref_speed):
                forced_at = len(pts_v)              # once per point: a real fold is reported next time
                moved = reanchor(v, t, fl, force=True)
                if moved is not None:
                    v, t, fl, J = moved
                    J_prev = v_before = None
                    continue
            sp = _refine_fold(lambda vp, tp: correct(vp, tp, J, reuse=False), tangent, unpack, v, t, ds, opt, len(pts_v) - 1)
            special.append(sp)
            turns += 1
        sig_old, sig_new = mode_cycle(fl, unpack(v)[1]), mode_cycle(fl_new, unpack(v_new)[1])
        if sig_old != sig_new:
            names = [m.name for m in system_at(mu_new).modes]
            special.append(SpecialPoint("grazing", len(pts_v) - 1, 0.5 * (unpack(v)[2] + mu_new),
                                        tuple(sorted((unpack(v)[2], mu_new))), abs(mu_new - unpack(v)[2]),
                                        {"events_before": len(sig_old), "events_after": len(sig_new),
                                         "modes_before": [names[m] for m in sig_old],
                                         "modes_after": [names[m] for m in sig_new]}))
        v_before = v
        v, t, fl, J, J_prev = v_new, t_new, fl_new, J_new, J
        pts_v.append(v)
        pts_fl.append(fl)
        pts_xtm.append(unpack(v))
        if opt.reanchor > 0 and ref_speed > 0 and abs(fl.f[section]) < opt.reanchor * ref_speed:
            moved = reanchor(v, t, fl)
            if moved is not None:
                v, t, fl, J = moved
                J_prev = v_before = None
        if mu_new <= lo or mu_new >= hi:
            break
        if turns >= max_turns and stop_at_mu is not None:
            if (t[-1] < 0 and mu_new <= stop_at_mu) or (t[-1] > 0 and mu_new >= stop_at_mu):
                message = f"stopped at {param} = {mu_new:.6g} after {turns} fold(s)"
                break
        ds = float(np.clip(ds * grow, max(opt.ds_min, 0.5 * ds), opt.ds_max))
    # assemble
    mus, Ts, amps, lams, stab, xs, modes = [], [], [], [], [], [], []
    for (x, T, mu), ff in zip(pts_xtm, pts_fl):
        lam, _ = floquet(ff.Phi, ff.f)
        mus.append(mu)
        Ts.append(T)
        xs.append(x)
        lams.append(lam)
        stab.append(bool(np.all(np.abs(lam[1:]) < 1.0)))
        modes.append(tuple(int(m) for m in ff.modes))
        amps.append(amplitude(system_at(mu), x, T, ff) if amplitude is not None
                    else orbit_amplitude(system_at(mu), x, T, method=sopt.method, max_step=kw_res["max_step"]))
    lams = np.array(lams)
    # multiplier crossings: changes in the number of non-trivial multipliers outside the unit
    # circle through +1 (fold), through -1 (period doubling) or as a complex pair (torus)
    def counts(lam):
        rest = lam[1:]
        real = np.abs(rest.imag) < 1e-9 * np.maximum(1.0, np.abs(rest))
        return (int(np.sum(real & (rest.real > 1))), int(np.sum(real & (rest.real < -1))),
                int(np.sum(~real & (np.abs(rest) > 1))))
    cycles = [mode_cycle(ff, T) for ff, T in zip(pts_fl, Ts)]
    for i in range(len(mus) - 1):
        ca, cb = counts(lams[i]), counts(lams[i + 1])
        if cycles[i] != cycles[i + 1]:
            # the multipliers jump where the event sequence changes (a nonsmooth point): not a
            # smooth crossing; the grazing point carries the counts
            for sp in special:
                if sp.kind == "grazing" and sp.index == i and (ca != cb):
                    sp.data.update(unstable_before=int(sum(ca)), unstable_after=int(sum(cb)))
            continue
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
    special = _merge_grazing(special)
    g = special[-1] if special else None
    if (status == OrbitStatus.STEP_LIMIT and g is not None and g.kind == "grazing"
            and abs(mus[-1] - g.param) <= max(100 * g.precision, 1e-3 * abs(mu_end - mu0))):
        message = (f"the corrector failed at step ds < ds_min = {opt.ds_min:g} at a grazing point near {param} = "
                   f"{g.param:.6g}, where the event sequence changes ({' -> '.join(g.data['modes_before'])} to "
                   f"{' -> '.join(g.data['modes_after'])}): the branch is not smooth there. Restart the "
                   f"continuation past it (a cycle found at a parameter value beyond) to follow the other side")
    if capped_at:
        message += (f" (from {param} = {capped_at[0]:.6g} on, flows with steps of at most T / {STEPS_PER_PERIOD}: "
                    f"one had stepped over a short event)")
    sys0 = system_at(mu0)
    return Branch(param, np.array(mus), np.array(Ts), np.array(amps), lams, np.array(stab), np.array(xs), modes,
                  special, status, message, state_names=tuple(sys0.state_names), units=dict(sys0.units or {}))


def _merge_grazing(special: list) -> list:
    """Join grazing points at consecutive branch points that switch back and forth between the
    same two event sequences (the corrector straddling one nonsmooth point) into one, whose
    interval covers them all (``data["crossings"]``: how many switches)."""
    out = []
    for sp in special:
        prev = out[-1] if out else None
        if (sp.kind == "grazing" and prev is not None and prev.kind == "grazing"
                and sp.index - prev.data.get("last_index", prev.index) <= 6
                and {tuple(sp.data["modes_before"]), tuple(sp.data["modes_after"])}
                == {tuple(prev.data["modes_before"]), tuple(prev.data["modes_after"])}):
            lo = min(prev.interval[0], sp.interval[0])
            hi = max(prev.interval[1], sp.interval[1])
            data = dict(prev.data, crossings=prev.data.get("crossings", 1) + 1, last_index=sp.index)
            out[-1] = SpecialPoint("grazing", prev.index, 0.5 * (lo + hi), (lo, hi), hi - lo, data)
            continue
        out.append(sp)
    for k, sp in enumerate(out):
        if sp.kind == "grazing" and "last_index" in sp.data:
            sp.data.pop("last_index")
    return out


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
