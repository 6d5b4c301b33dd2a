"""Ready-made sliding behaviour for user systems (numba helpers, call them inside your own
vector field, guard and transition functions).

Two kinds of sliding on a switching surface h(x) = 0 with fields f- (h < 0) and f+ (h > 0):

* Filippov sliding: the convex combination f_s = (1 - lam) f- + lam f+ with lam chosen so that
  grad h . f_s = 0; it exists while a- = grad h . f- > 0 > a+ = grad h . f+ (attractive). Its
  exit guards are a- (falling: leave to the h < 0 side) and -a+ (falling: leave to h > 0).
* Friction stick: the relative velocity is held at zero while the non-friction force F stays in
  the stick set [-Fs_neg, Fs_pos], which may be larger than the hull of the slip limits (static
  friction above the kinetic level). Its exit guards are Fs_pos - F and Fs_neg + F (falling).

See docs/architecture.md ("Adding a system") for a complete example.
"""
import numba


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def filippov_weight(a_minus, a_plus):
    """lam in [0, 1] of the Filippov sliding field for a- = grad h . f-, a+ = grad h . f+.

    Only meaningful while the surface attracts (a- >= 0 >= a+, not both zero)."""
    den = a_minus - a_plus
    if den == 0.0:
        return 0.5
    return a_minus / den


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def filippov_combine(f_minus, f_plus, lam, out):
    """out = (1 - lam) f- + lam f+ (arrays of shape (n,))."""
    for i in range(out.size):
        out[i] = (1.0 - lam) * f_minus[i] + lam * f_plus[i]


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def filippov_attractive(a_minus, a_plus):
    """True when both fields point into the surface (sliding possible)."""
    return a_minus >= 0.0 and a_plus <= 0.0


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def direction_from_rest(F, Fs_pos, Fs_neg):
    """Direction of motion of a body at rest under non-friction force F with stick set
    [-Fs_neg, Fs_pos]: +1, -1, or 0 (it sticks)."""
    if F > Fs_pos:
        return 1
    if F < -Fs_neg:
        return -1
    return 0
