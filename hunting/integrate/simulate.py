"""``hunting.simulate``: the Python front end of the event-driven integration kernel."""
from __future__ import annotations

import math

import numpy as np

from ..errors import ConvergenceError, Status, SystemDefinitionError, check_finite_positive, status_message
from ..results import EventLog, Trajectory, make_status
from ..system import PiecewiseSystem, kernel_jacobian
from . import _kernel as K
from ._tableau import METHODS


#: the largest |x_i| a run starts from: cubes of the state stay finite in double precision
#: (x**3 overflows beyond 5.6e102); no physical state in any unit comes near it
MAX_STATE = 1e100


def _grow(a: np.ndarray, rows: int) -> np.ndarray:
    new = np.empty((rows,) + a.shape[1:], dtype=a.dtype)
    new[: a.shape[0]] = a
    return new


def _initial_state(system: PiecewiseSystem, x0) -> np.ndarray:
    allowed = f"{system.n_states} finite numbers (states {', '.join(system.state_names)})"
    if isinstance(x0, (str, bytes)):
        raise SystemDefinitionError(f"x0 = {x0!r} is not allowed: x0 must be {allowed}, not a string")
    try:
        return system.check_state(x0)
    except SystemDefinitionError:
        raise
    except (TypeError, ValueError):
        raise SystemDefinitionError(f"x0 = {x0!r} is not allowed: x0 must be {allowed}") from None


def _state_limits(system: PiecewiseSystem, x0: np.ndarray, growth, bounds) -> tuple:
    """(|x_i| limits from ``bounds`` and ``growth``: an (n,) array, a number when every state
    has the same one, None when there is nothing to check; the growth limit alone, inf without one)."""
    g_lim = math.inf
    if growth is not None:
        g = check_finite_positive("growth", growth)
        if g <= 1:
            raise SystemDefinitionError(f"growth = {growth!r} is not allowed: it must be > 1 (None: no check)")
        g_lim = g * max(1.0, *(abs(float(v)) for v in x0))
    if bounds is None:
        return (None if math.isinf(g_lim) else g_lim), g_lim
    n = system.n_states
    try:
        b = np.broadcast_to(np.asarray(bounds, dtype=np.float64), (n,))
    except (TypeError, ValueError):
        raise SystemDefinitionError(f"bounds = {bounds!r} is not allowed: a number or {n} numbers > 0 "
                                    f"(|x_i| limits for {list(system.state_names)}; inf: no limit)") from None
    if np.any(np.isnan(b)) or np.any(b <= 0):
        raise SystemDefinitionError(f"bounds = {bounds!r} is not allowed: every limit must be > 0 (inf: no limit)")
    lim = np.minimum(b, g_lim)
    return (lim if np.any(np.isfinite(lim)) else None), g_lim


def _peak(a: np.ndarray) -> float:
    """max |a| (0 for an empty array)."""
    return float(np.abs(a).max()) if a.size else 0.0


def _first_over(x: np.ndarray, lim) -> int:
    """Index of the first row of x (m, n) with some |x_i| > lim_i (lim: (n,) or a number), or -1."""
    if _peak(x) <= (lim if isinstance(lim, float) else np.min(lim)):
        return -1
    over = np.flatnonzero((np.abs(x) > lim).any(axis=1))
    return int(over[0]) if over.size else -1


def simulate(system: PiecewiseSystem, x0, t_span, *, method: str = "dop853", rtol: float = 1e-10,
             atol: float = 1e-12, t_eval=None, mode0: int | str | None = None,
             first_step: float | None = None, max_step: float = math.inf,
             max_steps: int = 1_000_000, max_events: int = 100_000, guard_tol: float = 1e-12,
             fixed_step: float | None = None, stop_mode: int | str | None = None, stop_count: int = 1, zeno_count: int = 50,
             zeno_window: float | None = None, params=None, growth: float | None = 1e6, bounds=None,
             throw: bool = False) -> Trajectory:
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
    growth : the run ends with status DIVERGED once some |x_i| exceeds growth * max(max|x0|, 1)
        (the state's own units; None: no check). A loop made unstable by its parameters
        otherwise runs on to 1e76 and reports SUCCESS.
    bounds : optional |x_i| limits, a number or (n,) (inf: no limit); leaving them ends the run
        with status OUT_OF_BOUNDS. The returned trajectory ends at the first output point beyond
        a limit (with t_eval: the output points before it).
    throw : raise ConvergenceError (carrying the Trajectory) unless the run succeeded

    Returns
    -------
    Trajectory
    """
    if not isinstance(system, PiecewiseSystem):
        raise SystemDefinitionError(f"system = {system!r} is not a PiecewiseSystem "
                                    "(models build one: e.g. hunting.preset('table9.1').system)")
    x0 = _initial_state(system, x0)
    lim, g_lim = _state_limits(system, x0, growth, bounds)
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
    bad_start = _start_problem(system, t0, x0, m0, p)
    if bad_start is not None:
        return _ended_at_start(system, t0, x0, bad_start, key, throw)
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
    ev_t, ev_xb, ev_xa, ev_g, ev_f, ev_to, info, finfo = K.event_buffers(cap_ev, n)
    x_final = np.empty(n)
    jac, has_jac = kernel_jacobian(system, used=K.calls_jacobian(meth))
    nf, ni = K.workspace_sizes(n, n, system.n_guards, system.n_modes, int(zeno_count))
    wf, wi = np.empty(nf), np.empty(ni, dtype=np.int64)
    t_cur, x_cur, m_cur = t0, x0, m0
    checked = 0                         # output rows already checked against the limits
    kernel = K.kernel_for(meth)
    for _ in range(10_000):
        steps_left = int(max_steps) - int(info[K.I_NSTEPS] + info[K.I_NREJ])
        kernel(system.vector_field, system.guards, system.transition, jac, system.mode_of,
               has_jac, meth, n, t_cur, t1, x_cur, m_cur, p, K.NO_PARAM_DIRECTION,
               system.directions, rtol, atol, h0, hmax, steps_left, int(max_events),
               guard_tol, fixed, te, True, sm, int(stop_count), int(zeno_count), zw,
               out_t, out_x, out_m, ev_t, ev_xb, ev_xa, ev_g, ev_f, ev_to,
               info, finfo, x_final, wf, wi)
        if info[K.I_STATUS] != Status.BUFFER_FULL:
            break
        if lim is not None:             # stop a diverging run at the first full buffer beyond the limits
            if _first_over(out_x[checked:int(info[K.I_NOUT])], lim) >= 0:
                break
            checked = int(info[K.I_NOUT])
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
    if status == Status.NON_FINITE and system.explain is not None:
        detail = system.explain(int(info[K.I_MODE]), float(finfo[K.F_T]), x_final, p)
        if detail:
            message = f"{message}; {detail}"
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
    if lim is not None:
        status, message, t_out, x_out, m_out, nev = _limit_status(
            status, message, lim, g_lim, t_out, x_out, m_out, ev_t[:nev], ev_xa[:nev], float(finfo[K.F_T]),
            x_final, system.state_names, t_eval is None)
    events = EventLog(ev_t[:nev].copy(), ev_xb[:nev].copy(), ev_xa[:nev].copy(), ev_g[:nev].copy(),
                      ev_f[:nev].copy(), ev_to[:nev].copy())
    stats = dict(n_steps=int(info[K.I_NSTEPS]), n_rejected=int(info[K.I_NREJ]),
                 n_fev=int(info[K.I_NFEV]), n_jac=int(info[K.I_NJAC]), method=key)
    traj = Trajectory(t_out, x_out, m_out, events, status, message, system.state_names,
                      tuple(m.name for m in system.modes), stats)
    if throw and not status.ok:
        raise ConvergenceError(f"{system.name}: {message}", traj)
    return traj


def _start_problem(system: PiecewiseSystem, t0: float, x0: np.ndarray, m0: int, p: np.ndarray):
    """(status, mode, message) when a run cannot start: a state beyond :data:`MAX_STATE`
    (OUT_OF_BOUNDS), or a vector field or guard that is not finite at the initial state
    (NON_FINITE, naming the model's expression when the system can: ``system.explain``);
    None when it can. Checked before integrating, so the cause is named instead of a step size
    that collapses at t0."""
    big = np.flatnonzero(np.abs(x0) > MAX_STATE)
    mode = m0 if m0 >= 0 else int(system.mode_of(t0, x0, p))
    if big.size:
        i = int(big[0])
        return (Status.OUT_OF_BOUNDS, mode,
                f"at t = {t0:.12g}: the initial state {system.state_names[i]} = {x0[i]:.4g} is beyond {MAX_STATE:g}, "
                "the largest magnitude a run starts from (powers of the state overflow double precision): "
                "give an initial state of physical size")
    if not 0 <= mode < system.n_modes:
        return None                     # the kernel reports INVALID_MODE
    f = np.empty(system.n_states)
    g = np.empty(system.n_guards)
    with np.errstate(all="ignore"):
        system.vector_field(mode, t0, x0, p, f)
        system.guards(mode, t0, x0, p, g)
    if np.all(np.isfinite(f)) and np.all(np.isfinite(g)):
        return None
    detail = system.explain(mode, t0, x0, p) if system.explain is not None else None
    if detail is None:
        parts = [f"d{n}/dt = {v}" for n, v in zip(system.state_names, f) if not np.isfinite(v)]
        parts += [f"guard '{n}' = {v}" for n, v in zip(system.guard_names or ("guard",), g) if not np.isfinite(v)]
        zeros = _zero_parameters_to_blame(system, mode, t0, x0, p)
        detail = ", ".join(parts) + (f" (finite with {', '.join(z + ' != 0' for z in zeros)})" if zeros else "")
    return (Status.NON_FINITE, mode,
            f"at t = {t0:.12g}: the vector field is not finite at the initial state (mode {system.modes[mode].name}): "
            f"{detail}; change the parameter values or the initial state")


def _zero_parameters_to_blame(system: PiecewiseSystem, mode: int, t0: float, x0: np.ndarray, p: np.ndarray) -> list:
    """The named parameters that are 0 and whose change to 1 alone makes the vector field and
    guards finite at the initial state (a division by a zero mass, say)."""
    out = []
    f = np.empty(system.n_states)
    g = np.empty(system.n_guards)
    for j, name in enumerate(system.param_names):
        if p[j] != 0:
            continue
        q = p.copy()
        q[j] = 1.0
        with np.errstate(all="ignore"):
            system.vector_field(mode, t0, x0, q, f)
            system.guards(mode, t0, x0, q, g)
        if np.all(np.isfinite(f)) and np.all(np.isfinite(g)):
            out.append(name)
    return out


def _ended_at_start(system, t0, x0, problem, method, throw) -> Trajectory:
    """The trajectory of a run that cannot start: the initial point and the reason."""
    status, mode, message = problem
    none = np.empty(0)
    events = EventLog(none, np.empty((0, x0.size)), np.empty((0, x0.size)), *(np.empty(0, dtype=np.int64),) * 3)
    stats = dict(n_steps=0, n_rejected=0, n_fev=1, n_jac=0, method=method)
    traj = Trajectory(np.array([t0]), x0[None, :].copy(), np.array([max(mode, 0)], dtype=np.int64), events, status,
                      message, system.state_names, tuple(m.name for m in system.modes), stats)
    if throw:
        raise ConvergenceError(f"{system.name}: {message}", traj)
    return traj


def _limit_status(status, message, lim, g_lim, t_out, x_out, m_out, ev_t, ev_x, t_end, x_end, names, dense):
    """Status DIVERGED / OUT_OF_BOUNDS and the trajectory cut after the first point beyond the
    limits, when there is one; else everything unchanged. Checks the outputs, the event states
    and the final state (with t_eval the outputs alone could step over a short excursion; without
    it, ``dense``, every event state and the final state are outputs)."""
    low = lim if isinstance(lim, float) else float(np.min(lim))
    if _peak(x_out) <= low and (dense or max(_peak(ev_x), _peak(x_end)) <= low):    # the common case, quickly
        return status, message, t_out, x_out, m_out, ev_t.size
    candidates = []
    j = _first_over(x_out, lim)
    if j >= 0:
        candidates.append((t_out[j], x_out[j]))
    k = _first_over(ev_x, lim)
    if k >= 0:
        candidates.append((ev_t[k], ev_x[k]))
    if _first_over(x_end[None, :], lim) >= 0:
        candidates.append((t_end, x_end))
    if not candidates:
        return status, message, t_out, x_out, m_out, ev_t.size
    t_bad, x_bad = min(candidates, key=lambda c: c[0])
    lim = np.broadcast_to(lim, x_bad.shape)
    i = int(np.argmax(np.abs(x_bad) / lim))
    new = Status.DIVERGED if abs(x_bad[i]) > g_lim else Status.OUT_OF_BOUNDS
    why = "growth limit: max(|x0|, 1) times growth" if new == Status.DIVERGED else "the bound given"
    name = names[i] if i < len(names) else f"x{i + 1}"
    text = f"at t = {t_bad:.6g}: {name} = {x_bad[i]:.4g} is beyond {lim[i]:.4g} ({why}): {status_message(new)}"
    if not status.ok and status != Status.BUFFER_FULL:
        text += f" (the integration itself ended with {status.name})"
    keep = t_out <= t_bad
    return new, text, t_out[keep], x_out[keep], m_out[keep], int(np.searchsorted(ev_t, t_bad, side="right"))
