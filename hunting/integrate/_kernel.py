"""The event-driven integration kernel for piecewise-smooth systems (numba, compiled once).

One call integrates a :class:`~hunting.system.PiecewiseSystem` from ``t0`` towards ``t1``:
adaptive steps of one method inside a mode, guards checked on every accepted step, the first
crossing located on the step's dense output to near machine precision, the transition function
applied, and integration restarted in the next mode. Outputs go to caller-owned buffers; the
kernel returns at a step boundary with ``BUFFER_FULL`` when they are full so the caller can grow
them and resume.

Guards that are (nearly) zero when a segment starts -- the tangential departure from stick, a
velocity that was just set to zero by a transition -- are *unarmed*: they are sampled on the
dense output and armed once they have moved away from zero on the non-firing side. An unarmed
guard that instead moves beyond ``guard_tol`` on the firing side fires at that threshold.
"""
import math
import time

import numba
import numpy as np
from numba import types

from ..errors import Status
from ..system import GUARD_TYPE, JAC_TYPE, MODE_TYPE, RESET_TYPE, VF_TYPE, compile_for
from . import ahead
from ._rhs import jacobian_central_or_exact, param_step, rhs
from ._steppers import (EPS, dense_eval, dop853_step, dp5_step, explicit_dense, numerical_jacobian,
                        radau_dense, radau_step, select_initial_step)
from ._tableau import METHOD_DOP853, METHOD_DP5, METHOD_RADAU

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0
N_SAMPLES = 4          # interior samples of an unarmed guard per step
ROOT_MAXITER = 200

# info[] slots (int64)
I_STATUS, I_NOUT, I_NEV, I_NSTEPS, I_NREJ, I_NFEV, I_MODE, I_STOPHITS, I_IEVAL, I_NJAC, I_NEVTOT = range(11)
N_INFO = 11
# dpw argument of a run without a parameter-sensitivity column
NO_PARAM_DIRECTION = np.empty((0, 0))
# finfo[] slots (float64)
F_T, F_H = range(2)
N_FINFO = 2

_S_SUCCESS = int(Status.SUCCESS)
_S_STOPPED = int(Status.STOPPED)
_S_MAXSTEPS = int(Status.MAX_STEPS)
_S_MAXEVENTS = int(Status.MAX_EVENTS)
_S_ZENO = int(Status.ZENO)
_S_SMALL = int(Status.STEP_TOO_SMALL)
_S_NEWTON = int(Status.NEWTON_FAILED)
_S_NONFINITE = int(Status.NON_FINITE)
_S_FULL = int(Status.BUFFER_FULL)
_S_INVALID = int(Status.INVALID_MODE)


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True,
             forceinline=True)
def _put_row(dst, row, src):
    """dst[row, :] = src without the temporaries of slice assignment (the kernel runs without NRT).

    This and the kernel's other small helpers (``_put``, ``_guards_base``, ``_rhs_at``,
    ``_dense_state``, ``_guard_at``; also ``rhs`` and the steppers) are compiled once and called
    with LLVM's ``alwaysinline`` (``forceinline=True``) instead of numba's IR inlining, which
    copies, re-types and re-lowers a helper at every call site (~25 sites). LLVM then inlines the calls, so the run time is the
    same; without ``forceinline`` the calls stayed and simulations and event maps were 3-4 %
    slower."""
    for i in range(src.size):
        dst[row, i] = src[i]


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True,
             forceinline=True)
def _put(dst, src):
    for i in range(src.size):
        dst[i] = src[i]


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True,
             forceinline=True)
def _guards_base(guards, mode, t, y, p, out, xb):
    """Guards of the base state y[:nb] (y may carry sensitivities after it)."""
    for i in range(xb.size):
        xb[i] = y[i]
    guards(mode, t, xb, p, out)


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True,
             forceinline=True)
def _rhs_at(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, y, p, out, full):
    """rhs as a compiled call, for the kernel's evaluations at the start and after events (the
    steppers inline rhs itself)."""
    return rhs(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, y, p, out, full)


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True,
             forceinline=True)
def _dense_state(method, t_old, h, y_old, Q, t, out, full):
    """dense_eval as a compiled call, for the kernel's outputs at events and t_eval (not per step:
    the root finders inline dense_eval itself)."""
    dense_eval(method, t_old, h, y_old, Q, t, out, full)


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True,
             forceinline=True)
def _guard_at(guards, mode, t, t_old, h, y_old, Q, method, p, i, xs, xb, gs, full):
    dense_eval(method, t_old, h, y_old, Q, t, xs, full)
    _guards_base(guards, mode, t, xs, p, gs, xb)
    return gs[i]


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def locate_root(guards, mode, i, shift, ta, ga, tb, gb, t_old, h, y_old, Q, method, p, xs, xb, gs, full):
    """Root of g_i(t) + shift on [ta, tb] given opposite signs at the ends (Illinois method
    with bisection safeguard). Returns the right end of the final bracket: the first time at
    which the guard is on its firing side, to within a few ulps of t."""
    fa = ga + shift
    fb = gb + shift
    if fb == 0.0:
        return tb
    side = 0
    for _ in range(ROOT_MAXITER):
        width = tb - ta
        if width <= 4.0 * EPS * max(abs(ta), abs(tb), 1e-300):
            break
        if fa != fb:
            tc = (ta * fb - tb * fa) / (fb - fa)
        else:
            tc = 0.5 * (ta + tb)
        if not (ta < tc < tb):
            tc = 0.5 * (ta + tb)
        fc = _guard_at(guards, mode, tc, t_old, h, y_old, Q, method, p, i, xs, xb, gs, full) + shift
        if fc == 0.0:
            return tc
        if (fc > 0.0) == (fb > 0.0):
            tb = tc
            fb = fc
            if side == 1:
                fa *= 0.5
            side = 1
        else:
            ta = tc
            fa = fc
            if side == -1:
                fb *= 0.5
            side = -1
    return tb


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _armed_state(d, g, tol):
    """Is a guard with direction d and value g away from zero on its non-firing side?"""
    if d < 0:
        return g > tol
    if d > 0:
        return g < -tol
    return abs(g) > tol


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _fires(d, ga, gb, shift_a_to_b):
    """Does the guard cross zero (after shift) from a to b in its firing direction?"""
    a = ga + shift_a_to_b
    b = gb + shift_a_to_b
    if d <= 0 and a > 0.0 and b <= 0.0:
        return True
    if d >= 0 and a < 0.0 and b >= 0.0:
        return True
    return False


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _scan_unarmed(guards, mode, i, d, tol, t, g0, t_new, g1, h, y_old, Q, method, p, xs, xb, gs, full):
    """Scan an unarmed guard over one step. Returns (event time or inf, armed at the end);
    an event found while still unarmed is a threshold event (armed False)."""
    ta = t
    ga = g0
    armed = False
    for k in range(1, N_SAMPLES + 2):
        if k == N_SAMPLES + 1:
            tb = t_new
            gb = g1
        else:
            tb = t + h * k / (N_SAMPLES + 1)
            gb = _guard_at(guards, mode, tb, t, h, y_old, Q, method, p, i, xs, xb, gs, full)
        if armed:
            if _fires(d, ga, gb, 0.0):
                return locate_root(guards, mode, i, 0.0, ta, ga, tb, gb, t, h, y_old, Q, method, p,
                                   xs, xb, gs, full), True
        else:
            # beyond the tolerance band on the firing side: fire at the band's edge
            if d <= 0 and gb < -tol and ga + tol >= 0.0:
                return locate_root(guards, mode, i, tol, ta, ga, tb, gb, t, h, y_old, Q, method, p,
                                   xs, xb, gs, full), False
            if d >= 0 and gb > tol and ga - tol <= 0.0:
                return locate_root(guards, mode, i, -tol, ta, ga, tb, gb, t, h, y_old, Q, method, p,
                                   xs, xb, gs, full), False
            if _armed_state(d, gb, tol):
                armed = True
        ta = tb
        ga = gb
    return np.inf, armed


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _polish_slope(guards, mode, i_ev, t, h, t_ev, x, Q, method, p, xs, xb, gs, full):
    """Slope of guard ``i_ev`` at the located event ``t_ev`` on the dense output of the step
    (t, h), for the kernel's Newton iteration on the step length that ends on the guard.
    Returns (polish, slope); polish is False when the slope cannot be taken."""
    delta = 1e-7 * h
    ta = max(t, t_ev - delta)
    tb = min(t + h, t_ev + delta)
    ga = _guard_at(guards, mode, ta, t, h, x, Q, method, p, i_ev, xs, xb, gs, full)
    gb = _guard_at(guards, mode, tb, t, h, x, Q, method, p, i_ev, xs, xb, gs, full)
    if tb <= ta or ga == gb:
        return False, 0.0
    return True, (gb - ga) / (tb - ta)


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _polish_newton(guards, mode, i_ev, t, he, h, t_ev, slope, it, y_new, p, gs, xb):
    """Newton iteration ``it`` (0..3) on the step length: the step of ``he`` from t ended at
    y_new; the guard there over its slope at the event gives the correction. Returns (done,
    next step length); done keeps he (converged, the last iteration, or a correction that
    leaves the step or the dense output's neighbourhood of the event)."""
    _guards_base(guards, mode, t + he, y_new, p, gs, xb)
    dh = -gs[i_ev] / slope
    if abs(dh) <= 4.0 * EPS * max(abs(t + he), 1e-300) or it == 3:
        return True, he
    he_new = he + dh
    if not (0.0 < he_new <= h) or abs(dh) > 1e-3 * h + abs(t_ev - t - he) * 10.0 + 1e-12 * h:
        return True, he
    return False, he_new


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def saltation(vf, guards, reset, mode_old, mode_new, i_ev, t, xm, xp, p, S, fm, fp, grad, xw, xw2, gs, Rx):
    """Saltation matrix S (nb, nb) of an event: x+ = R(x-) when guard i_ev of mode_old vanishes,

        S = R_x + (f+ - R_x f-) n^T / (n . f- + h_t),

    with f- the old mode's field at x-, f+ the new mode's at x+, n = grad h and R_x by central
    differences (guards and resets are cheap; for the usual linear guards and resets the
    differences are exact). Returns n . f- + h_t (near 0: grazing); leaves the jump
    (f+ - R_x f-) / (n . f- + h_t) in fp."""
    nb = xm.size
    vf(mode_old, t, xm, p, fm)
    vf(mode_new, t, xp, p, fp)
    for i in range(nb):
        xw[i] = xm[i]
    for j in range(nb):
        dj = np.cbrt(EPS) * max(abs(xm[j]), 1e-3)
        xw[j] = xm[j] + dj
        guards(mode_old, t, xw, p, gs)
        gp = gs[i_ev]
        reset(mode_old, i_ev, t, xw, p, xw2)
        for i in range(nb):
            Rx[i, j] = xw2[i]
        xw[j] = xm[j] - dj
        guards(mode_old, t, xw, p, gs)
        gm = gs[i_ev]
        reset(mode_old, i_ev, t, xw, p, xw2)
        for i in range(nb):
            Rx[i, j] = (Rx[i, j] - xw2[i]) / (2.0 * dj)
        grad[j] = (gp - gm) / (2.0 * dj)
        xw[j] = xm[j]
    dt = np.cbrt(EPS) * max(abs(t), 1.0)
    guards(mode_old, t + dt, xm, p, gs)
    gp = gs[i_ev]
    guards(mode_old, t - dt, xm, p, gs)
    h_t = (gp - gs[i_ev]) / (2.0 * dt)
    den = h_t
    for j in range(nb):
        den += grad[j] * fm[j]
    for i in range(nb):
        acc = 0.0
        for k in range(nb):
            acc += Rx[i, k] * fm[k]
        jump = (fp[i] - acc) / den
        fp[i] = jump
        for j in range(nb):
            S[i, j] = Rx[i, j] + jump * grad[j]
    return den


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def saltation_param(guards, reset, mode_old, i_ev, t, xm, p, dpw, gs, xw2, out):
    """Parameter terms of an event for the sensitivity column psi (direction dpw[0]):
    psi+ = S psi + jump * g_mu + R_mu. Writes g_mu to gs[0] and R_mu (nb,) to out; p is
    perturbed in place and restored from dpw[1]."""
    h = param_step(p, dpw)
    for k in range(p.size):
        dpw[1, k] = p[k]
        p[k] = dpw[1, k] + h * dpw[0, k]
    guards(mode_old, t, xm, p, gs)
    gp = gs[i_ev]
    reset(mode_old, i_ev, t, xm, p, out)
    for k in range(p.size):
        p[k] = dpw[1, k] - h * dpw[0, k]
    guards(mode_old, t, xm, p, gs)
    gm = gs[i_ev]
    reset(mode_old, i_ev, t, xm, p, xw2)
    for k in range(p.size):
        p[k] = dpw[1, k]
    for i in range(xm.size):
        out[i] = (out[i] - xw2[i]) / (2.0 * h)
    gs[0] = (gp - gm) / (2.0 * h)


KERNEL_SIG = types.void(
    VF_TYPE, GUARD_TYPE, RESET_TYPE, JAC_TYPE, MODE_TYPE, types.boolean, types.int64, types.int64,
    types.float64, types.float64, types.float64[::1], types.int64, types.float64[::1],
    types.float64[:, ::1], types.int64[:, ::1],
    types.float64, types.float64, types.float64, types.float64, types.int64, types.int64,
    types.float64, types.boolean,
    types.float64[::1], types.boolean, types.int64, types.int64, types.int64, types.float64,
    types.float64[::1], types.float64[:, ::1], types.int64[::1],
    types.float64[::1], types.float64[:, ::1], types.float64[:, ::1], types.int64[::1],
    types.int64[::1], types.int64[::1],
    types.int64[::1], types.float64[::1], types.float64[::1],
    types.float64[::1], types.int64[::1],
)


def event_buffers(cap: int, n: int) -> tuple:
    """(ev_t, ev_xb, ev_xa, ev_g, ev_f, ev_to, info, finfo): the event log for ``cap`` events of
    an n-state system and the kernel's status arrays, as integrate_kernel takes them (Python
    callers; the batch kernel allocates its own inside numba)."""
    return (np.empty(cap), np.empty((cap, n)), np.empty((cap, n)), np.empty(cap, dtype=np.int64),
            np.empty(cap, dtype=np.int64), np.empty(cap, dtype=np.int64), np.zeros(N_INFO, dtype=np.int64),
            np.zeros(N_FINFO))


@numba.njit(cache=True)
def workspace_sizes(n, nb, ng, n_modes, zeno_count):
    """Sizes (float, int) of the workspaces integrate_kernel needs (callable from Python and numba)."""
    nf = 40 * n + 11 * n * n + 11 * nb + 3 * nb * nb + 3 * ng + max(zeno_count, 1) + n_modes
    return nf, 4 * n + ng


def _make_kernel(full_flag, implicit_flag):
    """The kernel body as a closure over ``FULL`` (None: lean, True: with sensitivities) and
    ``IMPLICIT`` (whether it carries the DP5 and Radau IIA steps besides DOP853). numba prunes
    branches on closure constants before typing and keys its disk cache on their values, so
    the kernels come from this one source and are cached side by side. (An inlined body shared
    by several entries does not work: calls with more than 30 arguments compile to f(*args),
    which numba cannot inline.)"""
    FULL = full_flag
    IMPLICIT = implicit_flag

    def integrate_kernel(vf, guards, reset, jac, mode_of, has_jac, method, nb,
                         t0, t1, x0, mode0, p, dpw, directions,
                         rtol, atol, h0, hmax, max_steps, max_events, guard_tol, fixed,
                         t_eval, record_steps, stop_mode, stop_count, zeno_count, zeno_window,
                         out_t, out_x, out_mode,
                         ev_t, ev_xb, ev_xa, ev_guard, ev_from, ev_to,
                         info, finfo, x_final, wf, wi):
        """Integrate from (t0, x0, mode0) towards t1; see the module docstring.

        Inputs: ``mode0 < 0`` asks ``mode_of``; ``h0 <= 0`` selects the first step; ``fixed``
        takes steps of h0 without error control (convergence studies; rtol/atol then only set the
        Newton tolerance of the implicit method); ``t_eval``
        (sorted, within [t0, t1]) or, when empty, every accepted step and both sides of each event
        are recorded if ``record_steps``. ``stop_mode >= 0`` stops on the ``stop_count``-th entry
        into that mode (counted from ``info[I_STOPHITS]``). ``info[I_IEVAL]`` is the next t_eval
        index, ``info[I_NEVTOT]`` the events so far (both carried across resumes).

        ``nb < x0.size`` integrates sensitivities: x0 = [x (nb), Phi0 row-major (nb * m)], the
        variational equations ride along (part of the explicit methods' error control; Radau
        differentiates its collocation solution exactly and controls x only) and every event multiplies Phi
        by its saltation matrix. Guards, transitions and mode_of always see the base state only.
        With m = nb + 1 the last column is the sensitivity to a parameter mu along the direction
        dpw[0] = dp/dmu (dpw (2, len(p)), row 1 scratch): psi' = J psi + f_mu, and at events
        psi+ = S psi + jump g_mu + R_mu; otherwise m = nb and dpw may be NO_PARAM_DIRECTION.

        Outputs: info (status, counts, final mode), finfo (final t, last step), x_final, and the
        buffers out_* (points, all n columns) and ev_* (event time, base state before/after, guard,
        modes). wf, wi: float and int workspaces of at least workspace_sizes(...) entries."""
        # None: the lean kernel (every `full is not None` branch is pruned before typing, down to
        # the steppers and helpers, which are typed with a NoneType argument); True: the full one
        full = FULL
        n = x0.size
        n_modes = directions.shape[0]
        ng = directions.shape[1]
        cap_out = out_t.size
        cap_ev = ev_t.size
        n_eval = t_eval.size
        use_eval = n_eval > 0

        # every work array is carved out of the caller's workspace (see workspace_sizes): the kernel
        # allocates nothing, runs without reference counting (_nrt=False) and its helpers inline
        o = 0
        x = wf[o:o + n]
        o += n
        xb = wf[o:o + nb]
        o += nb
        xb2 = wf[o:o + nb]
        o += nb
        f = wf[o:o + n]
        o += n
        y_new = wf[o:o + n]
        o += n
        f_new = wf[o:o + n]
        o += n
        ytmp = wf[o:o + n]
        o += n
        ftmp = wf[o:o + n]
        o += n
        err = wf[o:o + n]
        o += n
        xs = wf[o:o + n]
        o += n
        K = wf[o:o + 16 * n].reshape((16, n))
        o += 16 * n
        Q = wf[o:o + 7 * n].reshape((7, n))
        o += 7 * n
        g_old = wf[o:o + ng]
        o += ng
        g_new = wf[o:o + ng]
        o += ng
        gs = wf[o:o + ng]
        o += ng
        nz = max(zeno_count, 1)
        zeno_times = wf[o:o + nz]
        o += nz
        # last error-controlled step size per mode: re-entering a mode starts from it instead of
        # from a step grown without bound in a mode whose flow the method integrates exactly (stick)
        h_mode = wf[o:o + n_modes]
        o += n_modes
        armed = wi[4 * n:4 * n + ng]
        if full is not None:
            # Radau IIA, the variational equations and saltation matrices
            J = wf[o:o + n * n].reshape((n, n))
            o += n * n
            M = wf[o:o + 9 * n * n].reshape((3 * n, 3 * n))
            o += 9 * n * n
            Mr = wf[o:o + n * n].reshape((n, n))
            o += n * n
            Z = wf[o:o + 3 * n].reshape((3, n))
            o += 3 * n
            F3 = wf[o:o + 3 * n].reshape((3, n))
            o += 3 * n
            R = wf[o:o + 3 * n]
            o += 3 * n
            yw = wf[o:o + nb]
            o += nb
            fw = wf[o:o + nb]
            o += nb
            fp = wf[o:o + nb]
            o += nb
            fm = wf[o:o + nb]
            o += nb
            fbm = wf[o:o + nb]
            o += nb
            fbp = wf[o:o + nb]
            o += nb
            gradh = wf[o:o + nb]
            o += nb
            xw = wf[o:o + nb]
            o += nb
            xw2 = wf[o:o + nb]
            o += nb
            Jw = wf[o:o + nb * nb].reshape((nb, nb))
            o += nb * nb
            Ssal = wf[o:o + nb * nb].reshape((nb, nb))
            o += nb * nb
            Rx = wf[o:o + nb * nb].reshape((nb, nb))
            piv = wi[0:3 * n]
            pivr = wi[3 * n:4 * n]
        else:
            # the lean kernel passes the right-hand side's work arrays to the steppers, which do
            # not touch them without sensitivities: stand-ins of the same types, not 25 more
            # slices to compile
            yw = fw = fp = fm = ftmp
            Jw = K
        for i in range(nz):
            zeno_times[i] = -np.inf
        for i in range(n_modes):
            h_mode[i] = np.inf
        for i in range(7):
            for j in range(n):
                Q[i, j] = 0.0
        sens = nb < n
        m_sens = (n - nb) // nb          # columns of Phi: nb, or nb + 1 with the parameter column

        for i in range(n):
            x[i] = x0[i]
        t = t0
        mode = mode0
        for i in range(nb):
            xb[i] = x[i]
        if mode < 0:
            mode = mode_of(t, xb, p)
        if mode < 0 or mode >= n_modes:
            info[I_STATUS] = _S_INVALID
            info[I_MODE] = mode
            finfo[F_T] = t
            _put(x_final, x)
            return

        n_threshold = 0   # consecutive events of guards that never left their tolerance band

        n_out = info[I_NOUT]
        n_ev = info[I_NEV]
        n_ev_total = info[I_NEVTOT]
        stop_hits = info[I_STOPHITS]
        i_eval = info[I_IEVAL]
        n_steps = 0
        n_rej = 0
        nfev = 0
        njac = 0
        order = 8 if method == METHOD_DOP853 else 5
        expo = -1.0 / 8.0 if method == METHOD_DOP853 else (-1.0 / 5.0 if method == METHOD_DP5 else -0.25)
        status = _S_SUCCESS

        nfev += 1 + _rhs_at(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, x, p, f, full)
        _guards_base(guards, mode, t, x, p, g_old, xb)
        for i in range(ng):
            armed[i] = _armed_state(directions[mode, i], g_old[i], guard_tol)

        if record_steps and not use_eval and n_out == 0:
            out_t[0] = t
            _put_row(out_x, n_out, x)   # n_out == 0 here; a literal 0 compiled _put_row a second time
            out_mode[0] = mode
            n_out = 1
        while use_eval and i_eval < n_eval and t_eval[i_eval] <= t:
            if t_eval[i_eval] == t:
                out_t[n_out] = t
                _put_row(out_x, n_out, x)
                out_mode[n_out] = mode
                n_out += 1
            i_eval += 1

        if h0 > 0.0:
            h = h0
        else:
            h = select_initial_step(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, x, f, p, max(t1 - t, 1e-300), order,
                                    rtol, atol, ytmp, ftmp, full)
            nfev += 1
        n_small = 0
        rejected = False
        # Event polishing re-enters this loop's one step: while `polishing`, each pass takes a step
        # of he from (t, x) (a Newton iterate for the step that ends on the guard) instead of the
        # next step, so the step is inlined once (a second copy for polishing doubled the compile).
        polishing = False
        he = 0.0
        slope = 0.0
        it_pol = ng - ng
        tiny = 0.0
        last = False
        t_new = t
        t_ev = np.inf
        i_ev = ng - ng - 1   # -1, typed int64 (a literal compiled the helpers taking it twice)
        ev_exact = True      # False for threshold events of unarmed guards (no polishing)
        while True:
            if polishing:
                hs = he
            else:
                remaining = t1 - t
                if remaining <= 0.0:
                    status = _S_SUCCESS
                    break
                if n_steps + n_rej >= max_steps:
                    status = _S_MAXSTEPS
                    break
                if (not use_eval) and record_steps and cap_out - n_out < 3:
                    status = _S_FULL
                    break
                if n_ev >= cap_ev:
                    status = _S_FULL
                    break
                tiny = 8.0 * EPS * max(abs(t), 1e-300)
                if h > hmax:
                    h = hmax
                last = False
                if h >= remaining - tiny:
                    h = remaining
                    last = True
                if h <= tiny and not last:
                    status = _S_SMALL
                    break
                hs = h
            conv = True
            if full is not None and IMPLICIT and method == METHOD_RADAU:
                if not polishing:
                    if not sens:
                        if has_jac:
                            jac(mode, t, x, p, J)
                        else:
                            numerical_jacobian(vf, mode, t, x, f, p, rtol, atol, J, ytmp, ftmp)
                            nfev += n
                    else:
                        # J_x into J's leading block: radau_step solves the variational stages with
                        # the stage Jacobians itself
                        for i in range(nb):
                            xw[i] = x[i]
                        nfev += jacobian_central_or_exact(vf, jac, has_jac, mode, t, xw, p, J, fbm, fbp, nb)
                    njac += 1
                en, conv, fe = radau_step(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, x, f, hs, p, rtol, atol, J,
                                          M, piv, Mr, pivr, Z, F3, R, ytmp, y_new, f_new, err, full)
                nfev += fe
            else:
                # inlined here (the hot path: a call passing ~25 array arguments cost 5-8 % per
                # step). The lean kernel prunes the DP5 branch before inlining, so it never copies
                # the DP5 step.
                if full is not None and IMPLICIT and method == METHOD_DP5:
                    en = dp5_step(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, x, f, hs, p, rtol, atol, K,
                                  ytmp, y_new, f_new, err, full)
                else:
                    en = dop853_step(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, x, f, hs, p, rtol, atol, K,
                                     ytmp, y_new, f_new, err, full)
                nfev += 12 if method == METHOD_DOP853 else 6
            if polishing:
                # a Radau step that does not converge leaves xs at the dense output's state
                if conv:
                    done, he_next = _polish_newton(guards, mode, i_ev, t, he, h, t_ev, slope, it_pol, y_new, p, gs, xb)
                    if not done:
                        he = he_next
                        it_pol += 1
                        continue
                    _put(xs, y_new)
                    t_ev = t + he
                polishing = False
            else:
                if not conv:
                    n_rej += 1
                    h *= 0.5
                    if h <= tiny:
                        status = _S_NEWTON
                        break
                    continue
                finite = np.isfinite(en)
                for i in range(n):
                    if not np.isfinite(y_new[i]) or not np.isfinite(f_new[i]):
                        finite = False
                if not finite:
                    n_rej += 1
                    n_small += 1
                    h *= 0.25
                    if h <= tiny or n_small > 60:
                        status = _S_NONFINITE
                        break
                    continue
                if fixed:
                    en = 0.0
                if en > 1.0:
                    n_rej += 1
                    rejected = True
                    h *= max(MIN_FACTOR, SAFETY * en ** expo)
                    if h <= tiny:
                        status = _S_SMALL
                        break
                    continue
                n_small = 0
                n_steps += 1
                t_new = t1 if last else t + h
                # ---- events on this step; dense output only when a guard or t_eval needs it
                _guards_base(guards, mode, t_new, y_new, p, g_new, xb)
                need_dense = use_eval and i_eval < n_eval and t_eval[i_eval] <= t_new
                for i in range(ng):
                    if (not armed[i]) or _fires(directions[mode, i], g_old[i], g_new[i], 0.0):
                        need_dense = True
                if full is not None and IMPLICIT and method == METHOD_RADAU:
                    radau_dense(Z, Q)
                elif need_dense:
                    nfev += explicit_dense(method, vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, x, y_new, f_new, h, p,
                                           K, ytmp, Q, full)
                t_ev = np.inf
                i_ev = ng - ng - 1
                ev_exact = True
                for i in range(ng):
                    d = directions[mode, i]
                    if armed[i]:
                        if _fires(d, g_old[i], g_new[i], 0.0):
                            tr = locate_root(guards, mode, i, 0.0, t, g_old[i], t_new, g_new[i], t, h, x, Q,
                                             method, p, xs, xb, gs, full)
                            if tr < t_ev:
                                t_ev = tr
                                i_ev = i
                                ev_exact = True
                    else:
                        tr, arm_end = _scan_unarmed(guards, mode, i, d, guard_tol, t, g_old[i], t_new,
                                                    g_new[i], h, x, Q, method, p, xs, xb, gs, full)
                        if tr < t_ev:
                            t_ev = tr
                            i_ev = i
                            ev_exact = arm_end
                        armed[i] = arm_end
                if i_ev < 0:
                    # ---- no event: accept the whole step
                    while use_eval and i_eval < n_eval and t_eval[i_eval] <= t_new:
                        _dense_state(method, t, h, x, Q, t_eval[i_eval], xs, full)
                        out_t[n_out] = t_eval[i_eval]
                        _put_row(out_x, n_out, xs)
                        out_mode[n_out] = mode
                        n_out += 1
                        i_eval += 1
                    t = t_new
                    for i in range(n):
                        x[i] = y_new[i]
                        f[i] = f_new[i]
                    for i in range(ng):
                        g_old[i] = g_new[i]
                    if record_steps and not use_eval:
                        out_t[n_out] = t
                        _put_row(out_x, n_out, x)
                        out_mode[n_out] = mode
                        n_out += 1
                    if last:
                        status = _S_SUCCESS
                        break
                    if fixed:
                        h = h0
                    elif en == 0.0:
                        h *= 1.0 if rejected else MAX_FACTOR
                    else:
                        h *= min(1.0 if rejected else MAX_FACTOR, SAFETY * en ** expo)
                        h_mode[mode] = h
                    rejected = False
                    continue
                # output up to the event
                while use_eval and i_eval < n_eval and t_eval[i_eval] <= t_ev:
                    _dense_state(method, t, h, x, Q, t_eval[i_eval], xs, full)
                    out_t[n_out] = t_eval[i_eval]
                    _put_row(out_x, n_out, xs)
                    out_mode[n_out] = mode
                    n_out += 1
                    i_eval += 1
                _dense_state(method, t, h, x, Q, t_ev, xs, full)
                if ev_exact and t_ev > t:
                    # polish: integrate to the event with steps of the method itself (next passes
                    # of the loop), so the event state has the method's order rather than its
                    # dense output's
                    polishing, slope = _polish_slope(guards, mode, i_ev, t, h, t_ev, x, Q, method, p, ytmp, xb, gs,
                                                     full)
                    if polishing:
                        he = t_ev - t
                        it_pol = ng - ng   # 0, typed int64 as i_ev
                        continue
            # ---- the event at t_ev (state xs): transition, logs, the next mode
            for i in range(nb):
                xb[i] = xs[i]
            new_mode = reset(mode, i_ev, t_ev, xb, p, xb2)
            for i in range(nb):
                ytmp[i] = xb2[i]
            if full is not None and sens and 0 <= new_mode < n_modes:
                saltation(vf, guards, reset, mode, new_mode, i_ev, t_ev, xb, xb2, p, Ssal, fbm, fbp,
                          gradh, xw, xw2, gs, Rx)
                nfev += 2
                for i in range(nb):
                    for j in range(m_sens):
                        acc = 0.0
                        for k in range(nb):
                            acc += Ssal[i, k] * xs[nb + k * m_sens + j]
                        ytmp[nb + i * m_sens + j] = acc
                if m_sens > nb:
                    # the event time moves with mu through g_mu; the reset moves with R_mu
                    saltation_param(guards, reset, mode, i_ev, t_ev, xb, p, dpw, gs, xw2, fbm)
                    for i in range(nb):
                        ytmp[nb + i * m_sens + nb] += fbp[i] * gs[0] + fbm[i]
            elif full is not None and sens:
                for i in range(nb, n):
                    ytmp[i] = xs[i]
            ev_t[n_ev] = t_ev
            _put_row(ev_xb, n_ev, xb)
            _put_row(ev_xa, n_ev, xb2)
            ev_guard[n_ev] = i_ev
            ev_from[n_ev] = mode
            ev_to[n_ev] = new_mode
            n_ev += 1
            n_ev_total += 1
            if record_steps and not use_eval:
                out_t[n_out] = t_ev
                _put_row(out_x, n_out, xs)
                out_mode[n_out] = mode
                n_out += 1
            t = t_ev
            for i in range(n):
                x[i] = ytmp[i]
            if new_mode < 0:
                status = _S_STOPPED
                break
            if new_mode >= n_modes:
                status = _S_INVALID
                mode = new_mode
                break
            mode = new_mode
            if record_steps and not use_eval:
                out_t[n_out] = t
                _put_row(out_x, n_out, x)
                out_mode[n_out] = mode
                n_out += 1
            # Zeno: zeno_count events within zeno_window, or zeno_count consecutive events of
            # guards that never armed (the motion chatters inside the guard tolerance)
            n_threshold = 0 if ev_exact else n_threshold + 1
            if zeno_count > 0 and n_threshold >= zeno_count:
                status = _S_ZENO
                break
            if zeno_count > 0:
                k = n_ev_total % zeno_count
                if t - zeno_times[k] < zeno_window:
                    status = _S_ZENO
                    break
                zeno_times[k] = t
            if stop_mode >= 0 and mode == stop_mode:
                stop_hits += 1
                if stop_hits >= stop_count:
                    status = _S_STOPPED
                    break
            if n_ev_total >= max_events:
                status = _S_MAXEVENTS
                break
            nfev += 1 + _rhs_at(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, x, p, f, full)
            _guards_base(guards, mode, t, x, p, g_old, xb)
            for i in range(ng):
                armed[i] = _armed_state(directions[mode, i], g_old[i], guard_tol)
            if fixed:
                h = h0
            else:
                h = min(h, h_mode[mode])

        info[I_STATUS] = status
        info[I_NOUT] = n_out
        info[I_NEV] = n_ev
        info[I_NSTEPS] += n_steps
        info[I_NREJ] += n_rej
        info[I_NFEV] += nfev
        info[I_MODE] = mode
        info[I_STOPHITS] = stop_hits
        info[I_IEVAL] = i_eval
        info[I_NJAC] += njac
        info[I_NEVTOT] = n_ev_total
        finfo[F_T] = t
        finfo[F_H] = h
        _put(x_final, x)

    return integrate_kernel


# ---- the compiled kernels: three entries of one body, each compiled on first use
#
# All take KERNEL_SIG, so one compiled kernel of each kind serves every system and parameter
# value. The lean kernel (DOP853, no sensitivities: simulations and event maps) is a third of
# the full one's compile time; the variational kernel (DOP853 with sensitivities and saltation
# matrices: flows, shooting, continuation) leaves out the DP5 and Radau IIA steps, the full
# kernel (every method, sensitivities) compiles only when a command asks for DP5 or Radau.
# None compiles at import.

_OPTIONS = dict(cache=True, error_model="numpy", _nrt=False, nogil=True)
KINDS = {"lean": (None, False), "variational": (True, False), "full": (True, True)}
_DISPATCHERS = {kind: numba.njit(**_OPTIONS)(_make_kernel(*flags)) for kind, flags in KINDS.items()}


def compiled(kind: str):
    """The kernel ``kind`` (one of KINDS: "lean", "variational" or "full"), compiled for
    KERNEL_SIG on first use. The variational kernel runs DOP853 only: give it no other method.

    All compile without LLVM's loop unroller, the lean and the variational kernel without its
    loop vectorizer too: the lean kernel's loops run over the states of one system (3-4 for the
    presets), too few for vector code or unrolled copies, which took ~1.3 s and ~1-2 s of its
    ~12 s compile at the same run time.
    The kernels with sensitivities loop over n (n + 1) entries; without
    unrolled copies the full kernel compiles in ~27 instead of ~40 s CPU (with the functions it
    compiles in turn, 2 runs each) and runs as fast (flows of table 9.1 and a 4-state LuGre
    loop, DOP853 with and without sensitivities and Radau, both kernels in one process called
    in alternation: 0.98-1.01 times the run time, bit-identical states). The full kernel keeps
    vector code; the variational one compiles without it too: 9.4 instead of 11.3 s wall
    (fresh cache, one process), and the table 8.1 LuGre branch K = 0.05 -> fold -> 0.615 took
    5.0-5.2 s against 5.2-5.5 s, a shooting of its K = 0.3 cycle 0.112-0.118 against
    0.110-0.112 s (best of 3 and of 5, two processes each, in alternation), fold and period
    bit-identical (2026-11-28; systems of 3-4 states, the presets' and the examples').

    A kernel whose cache entry is whole loads without a lock (:func:`hunting.integrate.ahead.load`);
    a compile holds the kernels' cache lock (:func:`hunting.integrate.ahead.kernel_lock`): where
    a helper process compiles this kernel meanwhile, it waits for it and loads it from the cache."""
    disp = _DISPATCHERS[kind]
    if not disp.overloads and not ahead.load(disp, KERNEL_SIG):
        with ahead.kernel_lock(disp):
            compile_for(disp, KERNEL_SIG, vectorize=kind == "full", unroll=False)
    disp.disable_compile()
    return disp


def compiling_ahead(kinds):
    """A context in which a helper process compiles the uncached ones of kernels ``kinds``
    (KINDS, in order) while this process goes on (:func:`hunting.integrate.ahead.compiling_ahead`)."""
    bad = [k for k in kinds if k not in KINDS]
    if bad:
        raise ValueError(f"kernel kinds {bad} are not allowed: use {tuple(KINDS)}")
    return ahead.compiling_ahead({k: (_DISPATCHERS[k], KERNEL_SIG) for k in kinds})


def flow_kernel(method: int):
    """The compiled kernel that runs ``method`` (METHOD_*) with sensitivities: the variational
    kernel for DOP853, else the full one."""
    return compiled("full" if method != METHOD_DOP853 else "variational")


def kernel_for(method: int):
    """The compiled kernel that runs ``method`` (METHOD_*) without sensitivities: the full one
    for DP5 and Radau; for DOP853 the lean kernel, or the variational one standing in for it
    while the lean one is not compiled (:func:`plain_kind`)."""
    return compiled("full" if calls_jacobian(method) else plain_kind())


def plain_kind() -> str:
    """The kernel kind that runs DOP853 without sensitivities in this process: "lean", or
    "variational" where the lean kernel is neither compiled nor cached and the variational one
    is, or a helper compiles it before the lean one (a command that shoots or continues on a
    fresh install, :func:`compiling_ahead` with ("variational", "lean")). The variational
    kernel gives bit-identical states without sensitivities but runs plain simulations ~15-20 %
    slower (table 9.1 and a 4-state PID + LuGre loop, both kernels in one process called in
    alternation); standing in, it saves that command the lean kernel's compile (~9 s CPU),
    which the helper does after the variational one, for the next command."""
    global _lean_looked_up
    lean, var = _DISPATCHERS["lean"], _DISPATCHERS["variational"]
    if lean.overloads:
        return "lean"
    # standing in already: the lean kernel's cache index (a file read, ~0.4 ms) is looked up
    # again at most every LEAN_LOOKUP seconds, not on every simulation or batch
    if var.overloads and time.monotonic() - _lean_looked_up < LEAN_LOOKUP:
        return "variational"
    _lean_looked_up = time.monotonic()
    if ahead.cached(lean, KERNEL_SIG):
        return "lean"
    if var.overloads or ahead.cached(var, KERNEL_SIG):
        return "variational"
    order = ahead.queued()
    if "variational" in order and order.index("variational") < (order.index("lean") if "lean" in order else len(order)):
        return "variational"
    return "lean"


LEAN_LOOKUP = 1.0           # [s] between looks for the lean kernel in the cache while the variational one stands in
_lean_looked_up = -math.inf


def calls_jacobian(method: int) -> bool:
    """Whether :func:`kernel_for` ``(method)`` may call the system's Jacobian: the lean kernel
    (DOP853) never does, the full one does for Radau."""
    return method != METHOD_DOP853


def __getattr__(name: str):
    # integrate_kernel: the full kernel, compiled on first access (PEP 562)
    if name == "integrate_kernel":
        return compiled("full")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
