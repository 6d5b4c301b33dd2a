"""Dense LU factorization with partial pivoting for the small matrices of the implicit method.

numba's np.linalg.solve refactors on every call; the Newton iteration of Radau IIA reuses one
factorization for several solves, so the factorization is kept here (n <= a few tens).
"""
import numba


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def lu_factor(a, piv):
    """Factor ``a`` (m, m) in place into L\\U; ``piv`` (m,) int64 receives row swaps.

    Returns False when a pivot is exactly zero (singular matrix)."""
    m = a.shape[0]
    for k in range(m):
        imax = k
        vmax = abs(a[k, k])
        for i in range(k + 1, m):
            v = abs(a[i, k])
            if v > vmax:
                vmax = v
                imax = i
        piv[k] = imax
        if vmax == 0.0:
            return False
        if imax != k:
            for j in range(m):
                tmp = a[k, j]
                a[k, j] = a[imax, j]
                a[imax, j] = tmp
        inv = 1.0 / a[k, k]
        for i in range(k + 1, m):
            a[i, k] *= inv
            lik = a[i, k]
            if lik != 0.0:
                for j in range(k + 1, m):
                    a[i, j] -= lik * a[k, j]
    return True


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def lu_solve(lu, piv, b):
    """Solve in place ``A x = b`` with the factorization from :func:`lu_factor`."""
    m = lu.shape[0]
    for k in range(m):
        j = piv[k]
        if j != k:
            tmp = b[k]
            b[k] = b[j]
            b[j] = tmp
    for i in range(1, m):
        s = b[i]
        for j in range(i):
            s -= lu[i, j] * b[j]
        b[i] = s
    for i in range(m - 1, -1, -1):
        s = b[i]
        for j in range(i + 1, m):
            s -= lu[i, j] * b[j]
        b[i] = s / lu[i, i]
