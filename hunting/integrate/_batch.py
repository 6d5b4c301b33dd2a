"""Many independent runs of the event-driven kernel in parallel (numba prange).

Each run starts from its own state and mode and stops at the ``stop_count``-th entry into
``stop_mode`` (or at ``t_max``, or at a bound). Nothing but the end state and a few counters is
kept per run, so a grid of thousands of initial states costs one compiled call. The kernel is
generic: any PiecewiseSystem, any stop mode.
"""
import numba
import numpy as np
from numba import types

from ..system import GUARD_TYPE, JAC_TYPE, MODE_TYPE, RESET_TYPE, VF_TYPE
from . import _kernel as K

# per-run float outputs
B_T_END, B_T_FIRST_EVENT, B_T_IN_STOP = range(3)
N_BFLOAT = 3

BATCH_SIG = types.void(
    VF_TYPE, GUARD_TYPE, RESET_TYPE, JAC_TYPE, MODE_TYPE, types.boolean, types.int64,
    types.float64[:, ::1], types.int64[::1], types.float64, types.float64[::1], types.int64[:, ::1],
    types.float64, types.float64[::1], types.int64, types.int64, types.float64[::1],
    types.int64, types.int64,
    types.float64[:, ::1], types.int64[::1], types.int64[::1], types.int64[::1], types.float64[:, ::1],
)


@numba.njit(BATCH_SIG, cache=True, parallel=True, error_model="numpy")
def batch_kernel(vf, guards, reset, jac, mode_of, has_jac, method,
                 X0, mode0, t_max, p, directions,
                 rtol, atol, max_steps, max_events, guard_tol,
                 stop_mode, stop_count,
                 X_end, mode_end, status, n_events, fout):
    """Integrate every row of X0 (m, n) from t = 0 until the stop condition.

    atol and guard_tol are per run (m,) so that maps on small amplitudes keep relative accuracy.
    Outputs: X_end (m, n), mode_end (m,), status (m,), n_events (m,), and fout (m, 3): time at
    the end, time of the first event, total time spent in ``stop_mode`` before the end."""
    m = X0.shape[0]
    n = X0.shape[1]
    n_modes = directions.shape[0]
    ng = directions.shape[1]
    nf, ni = K.workspace_sizes(n, n, ng, n_modes, 50)
    for k in numba.prange(m):
        wf = np.empty(nf)
        wi = np.empty(ni, dtype=np.int64)
        # per-run copies of the shared arrays: reference counting on one array from several
        # threads makes its cache line bounce between cores
        p_k = p.copy()
        dir_k = directions.copy()
        out_t = np.empty(1)
        out_x = np.empty((1, n))
        out_m = np.empty(1, dtype=np.int64)
        cap = max_events + 1
        ev_t = np.empty(cap)
        ev_xb = np.empty((cap, n))
        ev_xa = np.empty((cap, n))
        ev_g = np.empty(cap, dtype=np.int64)
        ev_f = np.empty(cap, dtype=np.int64)
        ev_to = np.empty(cap, dtype=np.int64)
        info = np.zeros(K.N_INFO, dtype=np.int64)
        finfo = np.zeros(K.N_FINFO)
        xf = np.empty(n)
        te = np.empty(0)
        K.integrate_kernel(vf, guards, reset, jac, mode_of, has_jac, method, n, 0.0, t_max,
                           np.ascontiguousarray(X0[k]), mode0[k], p_k, np.empty((0, 0)), dir_k, rtol, atol[k], 0.0,
                           np.inf, max_steps, max_events, guard_tol[k], False, te, False, stop_mode,
                           stop_count, 50, 1e-10, out_t, out_x, out_m,
                           ev_t, ev_xb, ev_xa, ev_g, ev_f, ev_to, info, finfo, xf, wf, wi)
        st = info[K.I_STATUS]
        if st == K._S_FULL:
            st = K._S_MAXEVENTS
        status[k] = st
        mode_end[k] = info[K.I_MODE]
        nev = info[K.I_NEV]
        n_events[k] = nev
        for i in range(n):
            X_end[k, i] = xf[i]
        fout[k, B_T_END] = finfo[K.F_T]
        fout[k, B_T_FIRST_EVENT] = ev_t[0] if nev > 0 else np.nan
        t_in = 0.0
        t_enter = 0.0 if mode0[k] == stop_mode else np.nan
        for e in range(nev):
            if ev_to[e] == stop_mode and ev_f[e] != stop_mode:
                t_enter = ev_t[e]
            elif ev_f[e] == stop_mode and ev_to[e] != stop_mode and t_enter == t_enter:
                t_in += ev_t[e] - t_enter
                t_enter = np.nan
        fout[k, B_T_IN_STOP] = t_in


def run_batch(system, X0, mode0, *, t_max: float, atol, rtol: float = 1e-12, method: int = 1,
              max_steps: int = 200_000, max_events: int = 200, guard_tol=1e-14,
              stop_mode: int = -1, stop_count: int = 1):
    """Python wrapper: returns (X_end, mode_end, status, n_events, fout)."""
    from ..system import no_jacobian
    X0 = np.ascontiguousarray(X0, dtype=np.float64)
    m = X0.shape[0]
    mode0 = np.array(np.broadcast_to(np.asarray(mode0, dtype=np.int64), (m,)))
    atol = np.array(np.broadcast_to(np.asarray(atol, dtype=np.float64), (m,)))
    guard_tol = np.array(np.broadcast_to(np.asarray(guard_tol, dtype=np.float64), (m,)))
    X_end = np.empty_like(X0)
    mode_end = np.empty(m, dtype=np.int64)
    status = np.empty(m, dtype=np.int64)
    n_events = np.empty(m, dtype=np.int64)
    fout = np.empty((m, N_BFLOAT))
    jac = system.jacobian if system.jacobian is not None else no_jacobian
    batch_kernel(system.vector_field, system.guards, system.transition, jac, system.mode_of,
                 system.jacobian is not None, method, X0, mode0, float(t_max), system.params,
                 system.directions, float(rtol), atol, int(max_steps), int(max_events),
                 guard_tol, int(stop_mode), int(stop_count), X_end, mode_end, status, n_events,
                 fout)
    return X_end, mode_end, status, n_events, fout
