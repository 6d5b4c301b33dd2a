"""The right-hand side the steppers integrate: the mode's vector field, optionally augmented
with the variational equations dPhi/dt = J(x) Phi (sensitivities, monodromy matrices).

State layout when augmented: y = [x (nb), Phi row-major (nb * nb)]; ``nb == y.size`` means no
augmentation. ``yw, fw, fp, fm`` (nb,) and ``Jw`` (nb, nb) are work arrays (passed one by one:
a tuple of arrays costs reference-count updates at every use).
J comes from the system's analytic Jacobian when it has one, else from central differences.
"""
import numba
import numpy as np

EPS = np.finfo(np.float64).eps


@numba.njit(cache=True, error_model="numpy", _nrt=False, inline="always")
def rhs(vf, jac, has_jac, nb, yw, fw, fp, fm, Jw, mode, t, y, p, out):
    """out = f(y) (plain) or [f(x), J(x) Phi] (augmented). Returns extra f evaluations."""
    if nb == y.size:
        vf(mode, t, y, p, out)
        return 0
    for i in range(nb):
        yw[i] = y[i]
    vf(mode, t, yw, p, fw)
    for i in range(nb):
        out[i] = fw[i]
    extra = jacobian_central_or_exact(vf, jac, has_jac, mode, t, yw, p, Jw, fp, fm, nb)
    for i in range(nb):
        for j in range(nb):
            acc = 0.0
            for k in range(nb):
                acc += Jw[i, k] * y[nb + k * nb + j]
            out[nb + i * nb + j] = acc
    return extra


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def jacobian_central_or_exact(vf, jac, has_jac, mode, t, x, p, J, fp, fm, nb):
    """J (nb, nb) at x (x is perturbed in place and restored): analytic or central differences."""
    if has_jac:
        jac(mode, t, x, p, J)
        return 0
    for j in range(nb):
        xj = x[j]
        dj = np.cbrt(EPS) * max(abs(xj), 1e-3)
        x[j] = xj + dj
        vf(mode, t, x, p, fp)
        x[j] = xj - dj
        vf(mode, t, x, p, fm)
        x[j] = xj
        for i in range(nb):
            J[i, j] = (fp[i] - fm[i]) / (2.0 * dj)
    return 2 * nb
