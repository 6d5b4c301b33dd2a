"""``hunting.simulate``: the Python front end of the event-driven integration kernel."""
from __future__ import annotations

import math

import numpy as np

from ..errors import ConvergenceError, Status, SystemDefinitionError, check_finite_positive
from ..results import EventLog, Trajectory, make_status
from ..system import PiecewiseSystem, no_jacobian
from . import _kernel as K
from ._tableau import METHODS


def _grow(a: np.ndarray, rows: int) -> np.ndarray:
    new = np.empty((rows,) + a.shape[1:], dtype=a.dtype)
    new[: a.shape[0]] = a
    return new


def simulate(system: PiecewiseSystem, x0, t_span, *, method: str = "dop853", rtol: float = 1e-10,
             atol: float = 1e-12, t_eval=None, mode0: int | str | None = None,
             first_step: float | None = None, max_step: float = math.inf,
             max_steps: int = 1_000_000, max_events: int = 100_000, guard_tol: float = 1e-12,
             fixed_step: float | None = None, stop_mode: int | str | None = None, stop_count: int = 1, zeno_count: int = 50,
             zeno_window: float | None = None, params=None, throw: bool = False) -> Trajectory:
    """Integrate a piecewise-smooth system with exact event location.

    Parameters
    ----------
    system : PiecewiseSystem
    x0 : array (n,)
        Initial state.
    t_span : (t0, t1) with t1 > t0 [s]
    method : "dop853" (default, Dormand-Prince 8(5,3)), "dp5" (Dormand-Prince 5(4)) or "radau"
        (Radau IIA order 5, implicit, for stiff LuGre loops)
    rtol, atol : local error tolerances of the step-size control
    t_eval : array (m,), optional
        Output times (sorted, inside t_span). Without it every accepted step and both sides of
        every event are returned.
    mode0 : initial mode index or name; by default the system's ``mode_of`` decides
    first_step, max_step : step-size bounds [s]
    fixed_step : take steps of this size without error control (for convergence studies; steps
        are still cut at events and at t1)
    max_steps, max_events : bounds that end a run with a status instead of hanging
    guard_tol : guards within this distance of zero at the start of a segment are armed only
        once they move away from zero (tangential departures)
    stop_mode, stop_count : stop on the ``stop_count``-th entry into this mode
    zeno_count, zeno_window : ``zeno_count`` events within ``zeno_window`` seconds (default
        1e-9 of the span) end the run with status ZENO
    params : optional flat parameter array replacing ``system.params`` for this run
    throw : raise ConvergenceError (carrying the Trajectory) unless the run succeeded

    Returns
    -------
    Trajectory
    """
    if not isinstance(system, PiecewiseSystem):
        raise SystemDefinitionError(f"system = {system!r} is not a PiecewiseSystem "
                                    "(models build one: e.g. hunting.preset('table9.1').system)")
    x0 = system.check_state(x0)
    try:
        t0, t1 = (float(v) for v in t_span)
    except (TypeError, ValueError):
        raise SystemDefinitionError(f"t_span = {t_span!r} must be a pair (t0, t1)") from None
    if not (math.isfinite(t0) and math.isfinite(t1)) or t1 <= t0:
        raise SystemDefinitionError(f"t_span = {t_span!r} is not allowed: need finite t0 < t1")
    key = str(method).lower()
    if key not in METHODS:
        raise SystemDefinitionError(f"method = {method!r} is not allowed: use one of {sorted(METHODS)}")
    meth = METHODS[key]
    rtol = check_finite_positive("rtol", rtol)
    atol = check_finite_positive("atol", atol)
    if rtol < 100 * np.finfo(float).eps:
        raise SystemDefinitionError(f"rtol = {rtol!r} is too small: use rtol >= {100 * np.finfo(float).eps:.2g}")
    h0 = 0.0 if first_step is None else check_finite_positive("first_step", first_step)
    hmax = check_finite_positive("max_step", max_step, allow_inf=True)
    fixed = fixed_step is not None
    if fixed:
        h0 = check_finite_positive("fixed_step", fixed_step)
    for name, v in (("max_steps", max_steps), ("max_events", max_events), ("stop_count", stop_count)):
        if int(v) != v or v < 1:
            raise SystemDefinitionError(f"{name} = {v!r} is not allowed: it must be a positive integer")
    if int(zeno_count) != zeno_count or zeno_count < 0:
        raise SystemDefinitionError(f"zeno_count = {zeno_count!r} must be an integer >= 0 (0 disables)")
    guard_tol = check_finite_positive("guard_tol", guard_tol, allow_zero=True)
    zw = 1e-9 * (t1 - t0) if zeno_window is None else check_finite_positive("zeno_window", zeno_window)
    p = system.params if params is None else np.ascontiguousarray(params, dtype=np.float64)
    if p.shape != system.params.shape or not np.all(np.isfinite(p)):
        raise SystemDefinitionError(f"params must be finite with shape {system.params.shape}")

    def _mode(m, what):
        if m is None:
            return -1
        if isinstance(m, str):
            return system.mode_index(m)
        if int(m) != m or not 0 <= m < system.n_modes:
            raise SystemDefinitionError(f"{what} = {m!r} is not a mode index 0..{system.n_modes - 1}")
        return int(m)

    m0 = _mode(mode0, "mode0")
    sm = _mode(stop_mode, "stop_mode")
    if t_eval is not None:
        te = np.ascontiguousarray(t_eval, dtype=np.float64).reshape(-1)
        if te.size == 0 or np.any(np.diff(te) < 0) or te[0] < t0 or te[-1] > t1 or not np.all(np.isfinite(te)):
            raise SystemDefinitionError("t_eval must be a non-empty sorted array inside t_span")
        cap = te.size
    else:
        te = np.empty(0)
        cap = 1024
    n = system.n_states
    out_t = np.empty(cap)
    out_x = np.empty((cap, n))
    out_m = np.empty(cap, dtype=np.int64)
    cap_ev = min(int(max_events), 256)
    ev_t = np.empty(cap_ev)
    ev_xb = np.empty((cap_ev, n))
    ev_xa = np.empty((cap_ev, n))
    ev_g = np.empty(cap_ev, dtype=np.int64)
    ev_f = np.empty(cap_ev, dtype=np.int64)
    ev_to = np.empty(cap_ev, dtype=np.int64)
    info = np.zeros(K.N_INFO, dtype=np.int64)
    finfo = np.zeros(K.N_FINFO)
    x_final = np.empty(n)
    jac = system.jacobian if system.jacobian is not None else no_jacobian
    nf, ni = K.workspace_sizes(n, n, system.n_guards, system.n_modes, int(zeno_count))
    wf, wi = np.empty(nf), np.empty(ni, dtype=np.int64)
    t_cur, x_cur, m_cur = t0, x0, m0
    for _ in range(10_000):
        steps_left = int(max_steps) - int(info[K.I_NSTEPS] + info[K.I_NREJ])
        K.integrate_kernel(system.vector_field, system.guards, system.transition, jac, system.mode_of,
                           system.jacobian is not None, meth, n, t_cur, t1, x_cur, m_cur, p, K.NO_PARAM_DIRECTION,
                           system.directions, rtol, atol, h0, hmax, steps_left, int(max_events),
                           guard_tol, fixed, te, True, sm, int(stop_count), int(zeno_count), zw,
                           out_t, out_x, out_m, ev_t, ev_xb, ev_xa, ev_g, ev_f, ev_to,
                           info, finfo, x_final, wf, wi)
        if info[K.I_STATUS] != Status.BUFFER_FULL:
            break
        # grow whichever buffer is full and resume from the step boundary
        if info[K.I_NOUT] + 3 > out_t.size:
            out_t, out_x, out_m = (_grow(a, 2 * a.shape[0]) for a in (out_t, out_x, out_m))
        if info[K.I_NEV] >= ev_t.size:
            rows = 2 * ev_t.shape[0]
            ev_t, ev_xb, ev_xa, ev_g, ev_f, ev_to = (_grow(a, rows) for a in (ev_t, ev_xb, ev_xa, ev_g, ev_f, ev_to))
        t_cur, x_cur, m_cur = float(finfo[K.F_T]), x_final.copy(), int(info[K.I_MODE])
        if not fixed:
            h0 = float(finfo[K.F_H])
    status, message = make_status(int(info[K.I_STATUS]), float(finfo[K.F_T]))
    if status == Status.INVALID_MODE:
        raise SystemDefinitionError(f"{system.name}: mode function or transition returned mode "
                                    f"{int(info[K.I_MODE])}, not one of 0..{system.n_modes - 1}")
    nout, nev = int(info[K.I_NOUT]), int(info[K.I_NEV])
    t_out, x_out, m_out = out_t[:nout].copy(), out_x[:nout].copy(), out_m[:nout].copy()
    if t_eval is None and (nout == 0 or t_out[-1] != finfo[K.F_T]):
        # the run stopped at an event or bound: make the final state the last point
        t_out = np.append(t_out, finfo[K.F_T])
        x_out = np.vstack([x_out, x_final[None, :]])
        m_out = np.append(m_out, info[K.I_MODE])
    events = EventLog(ev_t[:nev].copy(), ev_xb[:nev].copy(), ev_xa[:nev].copy(), ev_g[:nev].copy(),
                      ev_f[:nev].copy(), ev_to[:nev].copy())
    stats = dict(n_steps=int(info[K.I_NSTEPS]), n_rejected=int(info[K.I_NREJ]),
                 n_fev=int(info[K.I_NFEV]), n_jac=int(info[K.I_NJAC]), method=key)
    traj = Trajectory(t_out, x_out, m_out, events, status, message, system.state_names,
                      tuple(m.name for m in system.modes), stats)
    if throw and not status.ok:
        raise ConvergenceError(f"{system.name}: {message}", traj)
    return traj
