"""One step of each integration method, its error norm and its dense output (numba).

Every stepper advances the state of one mode from ``t`` to ``t + h``; none of them knows about
events. Dense output is stored in a coefficient array ``Q`` of shape (7, n) and evaluated by
:func:`dense_eval`; for DP5 and Radau IIA it holds y(t_old + s h) = y_old + sum_k Q[k] s^(k+1),
for DOP853 Hairer's alternating form.
"""
import numba
import numpy as np

from ._linalg import lu_factor, lu_solve
from ._rhs import jacobian_central_or_exact, param_derivative, rhs
from ._tableau import (D853_A, D853_B, D853_C, D853_D, D853_E3, D853_E5, D853_NS, D853_NSE,
                       DP5_A, DP5_B, DP5_C, DP5_E, DP5_P, METHOD_DOP853, METHOD_DP5,
                       RADAU_A, RADAU_C, RADAU_E, RADAU_MU_REAL, RADAU_P)

EPS = np.finfo(np.float64).eps
NEWTON_MAXITER = 6


@numba.njit(cache=True, error_model="numpy", _nrt=False, inline="always")
def _rms_scaled(err, y, y_new, rtol, atol):
    n = err.size
    s = 0.0
    for i in range(n):
        sc = atol + rtol * max(abs(y[i]), abs(y_new[i]))
        e = err[i] / sc
        s += e * e
    return np.sqrt(s / n)


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def select_initial_step(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, y, f, p, direction_span, order, rtol, atol,
                        ytmp, ftmp, full):
    """Hairer's starting step (Solving ODEs I, II.4). Returns h > 0 (one extra f evaluation)."""
    n = y.size
    d0 = 0.0
    d1 = 0.0
    for i in range(n):
        sc = atol + abs(y[i]) * rtol
        d0 += (y[i] / sc) ** 2
        d1 += (f[i] / sc) ** 2
    d0 = np.sqrt(d0 / n)
    d1 = np.sqrt(d1 / n)
    if d0 < 1e-5 or d1 < 1e-5:
        h0 = 1e-6
    else:
        h0 = 0.01 * d0 / d1
    h0 = min(h0, direction_span)
    for i in range(n):
        ytmp[i] = y[i] + h0 * f[i]
    rhs(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t + h0, ytmp, p, ftmp, full)
    d2 = 0.0
    for i in range(n):
        sc = atol + abs(y[i]) * rtol
        d2 += ((ftmp[i] - f[i]) / sc) ** 2
    d2 = np.sqrt(d2 / n) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / (order + 1))
    return min(100 * h0, h1, direction_span)


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True,
             forceinline=True)
def dp5_step(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, y, f, h, p, rtol, atol, K, ytmp, y_new,
             f_new, err, full):
    """One Dormand-Prince 5(4) step (FSAL). Returns the scaled error norm.

    K: (16, n) stage derivatives (rows 0..6); writes y_new, f_new. The explicit steppers are two
    functions, not one with a method branch: the kernels choose between them under
    ``full is not None``, which numba prunes before typing, so the lean kernel never compiles
    the DP5 step. Both are compiled once and force-inlined (LLVM) at the kernel's one step."""
    n = y.size
    ns = 6
    for i in range(n):
        K[0, i] = f[i]
    for s in range(1, ns):
        for i in range(n):
            acc = 0.0
            for j in range(s):
                acc += DP5_A[s, j] * K[j, i]
            ytmp[i] = y[i] + h * acc
        rhs(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t + DP5_C[s] * h, ytmp, p, err, full)
        for i in range(n):
            K[s, i] = err[i]
    for i in range(n):
        acc = 0.0
        for j in range(ns):
            acc += DP5_B[j] * K[j, i]
        y_new[i] = y[i] + h * acc
    rhs(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t + h, y_new, p, f_new, full)
    for i in range(n):
        K[ns, i] = f_new[i]
    for i in range(n):
        acc = 0.0
        for j in range(ns + 1):
            acc += DP5_E[j] * K[j, i]
        err[i] = h * acc
    return _rms_scaled(err, y, y_new, rtol, atol)


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True,
             forceinline=True)
def dop853_step(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, y, f, h, p, rtol, atol, K, ytmp, y_new,
                f_new, err, full):
    """One DOP853 step (FSAL). Returns Hairer's error norm (3rd/5th order mix).

    K: (16, n) stage derivatives (rows 0..12; 13..15 are the dense output's); writes y_new,
    f_new."""
    n = y.size
    ns = D853_NS
    for i in range(n):
        K[0, i] = f[i]
    for s in range(1, ns):
        for i in range(n):
            acc = 0.0
            for j in range(s):
                acc += D853_A[s, j] * K[j, i]
            ytmp[i] = y[i] + h * acc
        rhs(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t + D853_C[s] * h, ytmp, p, err, full)
        for i in range(n):
            K[s, i] = err[i]
    for i in range(n):
        acc = 0.0
        for j in range(ns):
            acc += D853_B[j] * K[j, i]
        y_new[i] = y[i] + h * acc
    rhs(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t + h, y_new, p, f_new, full)
    for i in range(n):
        K[ns, i] = f_new[i]
    e5 = 0.0
    e3 = 0.0
    for i in range(n):
        a5 = 0.0
        a3 = 0.0
        for j in range(ns + 1):
            a5 += D853_E5[j] * K[j, i]
            a3 += D853_E3[j] * K[j, i]
        sc = atol + rtol * max(abs(y[i]), abs(y_new[i]))
        e5 += (a5 / sc) ** 2
        e3 += (a3 / sc) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    denom = e5 + 0.01 * e3
    return abs(h) * e5 / np.sqrt(denom * n)


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def explicit_dense(method, vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, y, y_new, f_new, h, p, K, ytmp, Q, full):
    """Fill the dense-output coefficients Q for the step just accepted (DOP853: 3 more f evals)."""
    n = y.size
    if full is not None and method == METHOD_DP5:
        for k in range(4):
            for i in range(n):
                acc = 0.0
                for j in range(7):
                    acc += K[j, i] * DP5_P[j, k]
                Q[k, i] = h * acc
        return 0
    for s in range(D853_NS + 1, D853_NSE):
        for i in range(n):
            acc = 0.0
            for j in range(s):
                acc += D853_A[s, j] * K[j, i]
            ytmp[i] = y[i] + h * acc
        rhs(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t + D853_C[s] * h, ytmp, p, K[s], full)
    for i in range(n):
        dy = y_new[i] - y[i]
        Q[0, i] = dy
        Q[1, i] = h * K[0, i] - dy
        Q[2, i] = 2.0 * dy - h * (f_new[i] + K[0, i])
        for r in range(4):
            acc = 0.0
            for j in range(D853_NSE):
                acc += D853_D[r, j] * K[j, i]
            Q[3 + r, i] = h * acc
    return D853_NSE - D853_NS - 1


@numba.njit(cache=True, error_model="numpy", _nrt=False, inline="always")
def dense_eval(method, t_old, h, y_old, Q, t, out, full):
    """State at time t in [t_old, t_old + h] from the step's dense output (``full`` None:
    DOP853 only)."""
    n = y_old.size
    s = (t - t_old) / h
    if full is None or method == METHOD_DOP853:
        for i in range(n):
            acc = 0.0
            for r in range(6, -1, -1):
                acc += Q[r, i]
                # reversed index (6 - r) even -> * s, odd -> * (1 - s)
                if (6 - r) % 2 == 0:
                    acc *= s
                else:
                    acc *= 1.0 - s
            out[i] = y_old[i] + acc
        return
    nq = 4 if method == METHOD_DP5 else 3
    for i in range(n):
        acc = 0.0
        for r in range(nq - 1, -1, -1):
            acc = (acc + Q[r, i]) * s
        out[i] = y_old[i] + acc


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def numerical_jacobian(vf, mode, t, y, f, p, rtol, atol, J, ytmp, ftmp):
    """Forward-difference Jacobian J (n, n) of the mode's vector field at (t, y)."""
    n = y.size
    floor = atol / rtol if rtol > 0 else 1e-8
    for j in range(n):
        for i in range(n):
            ytmp[i] = y[i]
        dj = np.sqrt(EPS) * max(abs(y[j]), floor)
        ytmp[j] = y[j] + dj
        dj = ytmp[j] - y[j]
        vf(mode, t, ytmp, p, ftmp)
        for i in range(n):
            J[i, j] = (ftmp[i] - f[i]) / dj


@numba.njit(cache=True, error_model="numpy", _nrt=False, inline="always")
def _stage_block_column(Ms, h, b, J, nb):
    """Block column b of the stage matrix without its identity: Ms[a nb + i, b nb + j] =
    -h A[a, b] J[i, j] for the three stages a (J the Jacobian at stage b, or one for all)."""
    for a in range(3):
        hab = h * RADAU_A[a, b]
        for i in range(nb):
            for j in range(nb):
                Ms[a * nb + i, b * nb + j] = -hab * J[i, j]


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def radau_step(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, y, f, h, p, rtol, atol, J, M, piv, Mr, pivr, Z, F3,
               R, ytmp, y_new, f_new, err, full):
    """One Radau IIA (order 5) step of y = [x (nb), Phi row-major (nb, mc)] (mc = 0: no
    sensitivities, nb = n).

    Simplified Newton on the 3 nb state stages (``J`` (n, n): its leading (nb, nb) block holds
    J_x at (t, x)). With sensitivities, the variational stages are linear in Phi and are solved
    exactly with the Jacobians at the converged stage states Y_b:
    (I - h {A_ab J_x(Y_b)}) W = h (A kron I) [J_x(Y_b) Phi0 + f_mu(Y_b)], one LU of 3 nb x 3 nb
    for all mc columns (a dense Newton matrix of the 3 n augmented system would cost (3 n)^3 per
    step: 72^3 for the LuGre loop). Phi_new is then the exact derivative of the step's
    collocation solution (internal numerical differentiation), so the error control covers the
    state only, as CVODES does by default: with Phi in it the steps were 3.7 times as many on
    the chapter-8 LuGre cycles, while Phi's error follows the state's (at rtol 1e-8, Phi within
    3.1e-6 and x within 3e-7 of rtol 1e-12 at K = 0.05, 0.3, 0.6).
    Returns (error norm, converged, f evals); when Newton does not converge the caller shrinks
    h. Writes Z (3, n) stage increments, y_new, f_new."""
    n = y.size
    mc = (n - nb) // nb
    k3 = 3 * nb
    Ms = M[:k3, :k3]
    Rs = R[:k3]
    for b in range(3):
        _stage_block_column(Ms, h, b, J, nb)
    for k in range(k3):
        Ms[k, k] += 1.0
    if not lu_factor(Ms, piv):
        return np.inf, False, 0
    tol = max(10.0 * EPS / rtol, min(0.03, rtol ** 0.5))
    for a in range(3):
        for i in range(n):
            Z[a, i] = 0.0
    nfev = 0
    converged = False
    dz_old = -1.0
    rate = -1.0
    for it in range(NEWTON_MAXITER):
        for a in range(3):
            for i in range(nb):
                yw[i] = y[i] + Z[a, i]
            vf(mode, t + RADAU_C[a] * h, yw, p, fw)
            for i in range(nb):
                F3[a, i] = fw[i]
        nfev += 3
        for a in range(3):
            for i in range(nb):
                if not np.isfinite(F3[a, i]):
                    return np.inf, False, nfev
        for a in range(3):
            for i in range(nb):
                acc = 0.0
                for b in range(3):
                    acc += RADAU_A[a, b] * F3[b, i]
                Rs[a * nb + i] = -Z[a, i] + h * acc
        lu_solve(Ms, piv, Rs)
        s = 0.0
        for a in range(3):
            for i in range(nb):
                Z[a, i] += Rs[a * nb + i]
                sc = atol + abs(y[i]) * rtol
                s += (Rs[a * nb + i] / sc) ** 2
        dz = np.sqrt(s / k3)
        if dz_old >= 0.0:
            rate = dz / dz_old if dz_old > 0 else 0.0
        if rate >= 0.0 and (rate >= 1.0 or rate ** (NEWTON_MAXITER - it) / (1.0 - rate) * dz > tol):
            break
        if dz == 0.0 or (rate >= 0.0 and rate / (1.0 - rate) * dz < tol):
            converged = True
            break
        dz_old = dz
    if not converged:
        return np.inf, False, nfev
    if mc > 0:
        # variational stages: F3[b, nb:] = J_x(Y_b) Phi0 (+ f_mu(Y_b) in the parameter column)
        for b in range(3):
            tb = t + RADAU_C[b] * h
            for i in range(nb):
                yw[i] = y[i] + Z[b, i]
            nfev += jacobian_central_or_exact(vf, jac, has_jac, mode, tb, yw, p, Jw, fp, fm, nb)
            _stage_block_column(Ms, h, b, Jw, nb)
            for i in range(nb):
                for j in range(mc):
                    acc = 0.0
                    for k in range(nb):
                        acc += Jw[i, k] * y[nb + k * mc + j]
                    F3[b, nb + i * mc + j] = acc
            if mc > nb:
                nfev += param_derivative(vf, mode, tb, yw, p, dpw, fp, fm)
                for i in range(nb):
                    F3[b, nb + i * mc + nb] += fp[i]
        for k in range(k3):
            Ms[k, k] += 1.0
        if not lu_factor(Ms, piv):
            return np.inf, False, nfev
        for j in range(mc):
            for a in range(3):
                for i in range(nb):
                    acc = 0.0
                    for b in range(3):
                        acc += RADAU_A[a, b] * F3[b, nb + i * mc + j]
                    Rs[a * nb + i] = h * acc
            lu_solve(Ms, piv, Rs)
            for a in range(3):
                for i in range(nb):
                    Z[a, nb + i * mc + j] = Rs[a * nb + i]
    for i in range(n):
        y_new[i] = y[i] + Z[2, i]
    # error estimate of the state: (mu/h I - J_x)^-1 (f + Z^T E / h)
    Mrs = Mr[:nb, :nb]
    for i in range(nb):
        for j in range(nb):
            Mrs[i, j] = -J[i, j]
        Mrs[i, i] += RADAU_MU_REAL / h
    if not lu_factor(Mrs, pivr):
        return np.inf, False, nfev
    e = err[:nb]
    for i in range(nb):
        acc = 0.0
        for a in range(3):
            acc += Z[a, i] * RADAU_E[a]
        e[i] = f[i] + acc / h
    lu_solve(Mrs, pivr, e)
    en = _rms_scaled(e, y[:nb], y_new[:nb], rtol, atol)
    if en > 1.0:
        # Hairer's refinement of the estimate for stiff components (one more f evaluation)
        for i in range(nb):
            yw[i] = y[i] + e[i]
        vf(mode, t, yw, p, fw)
        nfev += 1
        for i in range(nb):
            acc = 0.0
            for a in range(3):
                acc += Z[a, i] * RADAU_E[a]
            e[i] = fw[i] + acc / h
        lu_solve(Mrs, pivr, e)
        en = _rms_scaled(e, y[:nb], y_new[:nb], rtol, atol)
    nfev += 1 + rhs(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t + h, y_new, p, f_new, full)
    return en, True, nfev


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def radau_dense(Z, Q):
    """Dense output of the collocation polynomial: Q[k] = (Z^T P)[:, k], k < 3."""
    n = Z.shape[1]
    for k in range(3):
        for i in range(n):
            acc = 0.0
            for a in range(3):
                acc += Z[a, i] * RADAU_P[a, k]
            Q[k, i] = acc
