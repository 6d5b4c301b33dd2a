"""The right-hand side the steppers integrate: the mode's vector field, optionally augmented
with the variational equations dPhi/dt = J(x) Phi (sensitivities, monodromy matrices).

State layout when augmented: y = [x (nb), Phi row-major (nb * m)], m = nb, or m = nb + 1 with
a parameter-sensitivity column (direction dp/dmu in dpw[0]); ``nb == y.size`` means no
augmentation. ``yw, fw, fp, fm`` (nb,) and ``Jw`` (nb, nb) are work arrays (passed one by one:
a tuple of arrays costs reference-count updates at every use).
J comes from the system's analytic Jacobian when it has one, else from central differences.
"""
import numba
import numpy as np

EPS = np.finfo(np.float64).eps
CBRT_EPS = float(np.cbrt(EPS))    # central-difference step factor, not recomputed per call (~5 % of a step)


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True,
             forceinline=True)
def rhs(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, y, p, out, full):
    """out = f(y) (plain) or [f(x), J(x) Phi (+ f_mu in the parameter column)] (augmented).
    Returns extra f evaluations.

    ``full`` is None in the lean kernel (no sensitivities: the augmented branch is pruned before
    typing) and any int in the full kernel. The augmented branch is a call, not inlined: rhs is
    inlined at every stage of every stepper, and the variational code at each of them doubled
    the kernels' compile time."""
    if full is None or nb == y.size:
        vf(mode, t, y, p, out)
        return 0
    return rhs_augmented(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, y, p, out)


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def rhs_augmented(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, dpw, mode, t, y, p, out):
    """The augmented right-hand side [f(x), J(x) Phi (+ f_mu)]; returns extra f evaluations."""
    m = (y.size - nb) // nb
    for i in range(nb):
        yw[i] = y[i]
    vf(mode, t, yw, p, fw)
    for i in range(nb):
        out[i] = fw[i]
    extra = jacobian_central_or_exact(vf, jac, has_jac, mode, t, yw, p, Jw, fp, fm, nb)
    for i in range(nb):
        for j in range(m):
            acc = 0.0
            for k in range(nb):
                acc += Jw[i, k] * y[nb + k * m + j]
            out[nb + i * m + j] = acc
    if m > nb:
        extra += param_derivative(vf, mode, t, yw, p, dpw, fp, fm)
        for i in range(nb):
            out[nb + i * m + nb] += fp[i]
    return extra


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def param_step(p, dpw):
    """Central-difference step in mu for the direction dpw[0] = dp/dmu (relative to the
    parameters it moves)."""
    h = np.inf
    for k in range(p.size):
        if dpw[0, k] != 0.0:
            h = min(h, max(abs(p[k]), 1e-3) / abs(dpw[0, k]))
    return CBRT_EPS * (h if h < np.inf else 1.0)


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def param_derivative(vf, mode, t, x, p, dpw, out, fm):
    """out = d f / d mu at x by central differences along dpw[0] (p is perturbed in place and
    restored from dpw[1]; fm is scratch). Returns the f evaluations."""
    h = param_step(p, dpw)
    for k in range(p.size):
        dpw[1, k] = p[k]
        p[k] = dpw[1, k] + h * dpw[0, k]
    vf(mode, t, x, p, out)
    for k in range(p.size):
        p[k] = dpw[1, k] - h * dpw[0, k]
    vf(mode, t, x, p, fm)
    for k in range(p.size):
        p[k] = dpw[1, k]
    for i in range(x.size):
        out[i] = (out[i] - fm[i]) / (2.0 * h)
    return 2


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def jacobian_central_or_exact(vf, jac, has_jac, mode, t, x, p, J, fp, fm, nb):
    """J (nb, nb) at x (x is perturbed in place and restored): analytic or central differences."""
    if has_jac:
        jac(mode, t, x, p, J)
        return 0
    for j in range(nb):
        xj = x[j]
        dj = CBRT_EPS * max(abs(xj), 1e-3)
        x[j] = xj + dj
        vf(mode, t, x, p, fp)
        x[j] = xj - dj
        vf(mode, t, x, p, fm)
        x[j] = xj
        for i in range(nb):
            J[i, j] = (fp[i] - fm[i]) / (2.0 * dj)
    return 2 * nb
