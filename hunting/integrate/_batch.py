"""Many independent runs of the event-driven kernel, in parallel threads.

Each run starts from its own state and mode and stops at the ``stop_count``-th entry into
``stop_mode`` (or at ``t_max``, or at a bound). Nothing but the end state and a few counters is
kept per run, so a grid of thousands of initial states costs a few compiled calls. The kernel is
generic: any PiecewiseSystem, any stop mode.

``batch_kernel`` runs rows ``lo:hi`` serially without the GIL and calls the integration kernel
through a first-class function value: numba then neither links nor re-optimizes the kernel into
the batch (that cost 52 s of compilation with the parallel ``prange`` loop this replaces, whose
threads also spun ~8 ms of CPU per call, 10 s over chapter 9's 1200 small calls). ``run_batch``
spreads chunks of rows over a thread pool when there are enough of them.
"""
from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np
from numba import types

from ..system import GUARD_TYPE, JAC_TYPE, MODE_TYPE, RESET_TYPE, VF_TYPE, kernel_jacobian
from . import _kernel as K

# per-run float outputs
B_T_END, B_T_FIRST_EVENT, B_T_IN_STOP = range(3)
N_BFLOAT = 3

KERNEL_TYPE = types.FunctionType(K.KERNEL_SIG)

BATCH_SIG = types.void(
    KERNEL_TYPE, VF_TYPE, GUARD_TYPE, RESET_TYPE, JAC_TYPE, MODE_TYPE, types.boolean, types.int64,
    types.float64[:, ::1], types.int64[::1], types.float64, types.float64[::1], types.int64[:, ::1],
    types.float64, types.float64[::1], types.int64, types.int64, types.float64[::1],
    types.int64, types.int64,
    types.float64[:, ::1], types.int64[::1], types.int64[::1], types.int64[::1], types.float64[:, ::1],
    types.int64, types.int64,
)

MIN_ROWS_PER_THREAD = 4     # fewer rows run in the calling thread (a hand-off costs ~0.1 ms)
CHUNKS_PER_THREAD = 4       # run times differ between rows: small chunks balance the threads


@numba.njit(cache=True, nogil=True, error_model="numpy")     # compiled for BATCH_SIG on first use
def batch_kernel(kernel, vf, guards, reset, jac, mode_of, has_jac, method,
                 X0, mode0, t_max, p, directions,
                 rtol, atol, max_steps, max_events, guard_tol,
                 stop_mode, stop_count,
                 X_end, mode_end, status, n_events, fout, lo, hi):
    """Integrate rows lo:hi of X0 (m, n) from t = 0 until the stop condition with ``kernel``
    (a compiled integration kernel, see ``_kernel.kernel_for``).

    atol and guard_tol are per run (m,) so that maps on small amplitudes keep relative accuracy.
    Outputs (rows lo:hi): X_end (m, n), mode_end (m,), status (m,), n_events (m,), and fout
    (m, 3): time at the end, time of the first event, total time spent in ``stop_mode`` before
    the end."""
    n = X0.shape[1]
    n_modes = directions.shape[0]
    ng = directions.shape[1]
    nf, ni = K.workspace_sizes(n, n, ng, n_modes, np.int64(50))   # int64, not Literal[int](50): one compile
    wf = np.empty(nf)
    wi = np.empty(ni, dtype=np.int64)
    # copies of the shared arrays per call (per thread): reference counting on one array from
    # several threads makes its cache line bounce between cores
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
    # np.empty, not np.zeros: info is cleared per run below and the kernel writes finfo; np.zeros
    # compiled two more numba overloads (~0.3 s of the batch's ~1.5 s cold compile)
    info = np.empty(K.N_INFO, dtype=np.int64)
    finfo = np.empty(K.N_FINFO)
    xf = np.empty(n)
    x0 = np.empty(n)
    te = np.empty(0)
    no_dir = np.empty((0, 0))
    for k in range(lo, hi):
        for i in range(n):
            x0[i] = X0[k, i]
        for i in range(K.N_INFO):
            info[i] = 0
        kernel(vf, guards, reset, jac, mode_of, has_jac, method, n, 0.0, t_max,
               x0, mode0[k], p_k, no_dir, dir_k, rtol, atol[k], 0.0,
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


_POOL: tuple[int, ThreadPoolExecutor] | None = None


def n_threads() -> int:
    """Threads for batches: NUMBA_NUM_THREADS (default: the CPU count), at most the CPUs this
    process may run on."""
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:             # not on Linux
        cpus = os.cpu_count() or 1
    return max(1, min(int(numba.config.NUMBA_NUM_THREADS), cpus))


def _pool(workers: int) -> ThreadPoolExecutor:
    """The batch thread pool (made once; remade when the number of workers changes)."""
    global _POOL
    if _POOL is None or _POOL[0] != workers:
        if _POOL is not None:
            _POOL[1].shutdown(wait=False)
        _POOL = (workers, ThreadPoolExecutor(max_workers=workers, thread_name_prefix="hunting-batch"))
    return _POOL[1]


def run_batch(system, X0, mode0, *, t_max: float, atol, rtol: float = 1e-12, method: int = 1,
              max_steps: int = 200_000, max_events: int = 200, guard_tol=1e-14,
              stop_mode: int = -1, stop_count: int = 1, threads: int | None = None):
    """Python wrapper: returns (X_end, mode_end, status, n_events, fout).

    threads : worker threads (default :func:`n_threads`); rows are split into chunks run in
    parallel when there are at least MIN_ROWS_PER_THREAD per thread."""
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
    jac, has_jac = kernel_jacobian(system, used=K.calls_jacobian(int(method)))
    # the batch before the kernel: on a fresh install a helper process may be compiling the
    # kernel meanwhile (hunting.integrate.ahead)
    batch = K.compile_for(batch_kernel, BATCH_SIG)
    kernel = K.kernel_for(int(method))

    def rows(lo: int, hi: int) -> None:
        batch(kernel, system.vector_field, system.guards, system.transition, jac, system.mode_of,
              has_jac, int(method), X0, mode0, float(t_max), system.params,
              system.directions, float(rtol), atol, int(max_steps), int(max_events),
              guard_tol, int(stop_mode), int(stop_count), X_end, mode_end, status, n_events,
              fout, lo, hi)

    workers = min(n_threads() if threads is None else max(1, int(threads)), m // MIN_ROWS_PER_THREAD)
    if workers <= 1:
        rows(0, m)
    else:
        edges = np.linspace(0, m, min(m, workers * CHUNKS_PER_THREAD) + 1).astype(int)
        for f in [_pool(workers).submit(rows, int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])]:
            f.result()
    return X_end, mode_end, status, n_events, fout
