"""Systems written the way a user adds one (see docs/architecture.md): module-level numba
functions with the protocol's signatures, then a PiecewiseSystem. No kernel is touched."""
import math

import numba
import numpy as np

from hunting import GUARD_SIG, MODE_SIG, RESET_SIG, VF_SIG, Mode, PiecewiseSystem
from hunting.sliding import direction_from_rest, filippov_attractive, filippov_combine, filippov_weight

# ---------------------------------------------------------------- two masses, friction on mass 1
# states: x1, v1 (mass 1, with friction), x2, v2 (mass 2, driven); p = [m1, m2, k, c, Fc, Fs, A, w]
SLIP_POS, SLIP_NEG, STICK = 0, 1, 2


@numba.njit(cache=True, error_model="numpy")
def spring_force(t, x, p):
    """Every force on mass 1 except friction."""
    return p[2] * (x[2] - x[0]) + p[3] * (x[3] - x[1])


@numba.njit(VF_SIG, cache=True, error_model="numpy", _nrt=False)
def two_mass_vf(mode, t, x, p, out):
    F1 = spring_force(t, x, p)
    out[2] = x[3]
    out[3] = (-F1 + p[6] * math.sin(p[7] * t)) / p[1]
    if mode == STICK:
        out[0] = 0.0
        out[1] = 0.0
    else:
        s = 1.0 if mode == SLIP_POS else -1.0
        out[0] = x[1]
        out[1] = (F1 - s * p[4]) / p[0]


@numba.njit(GUARD_SIG, cache=True, error_model="numpy", _nrt=False)
def two_mass_guards(mode, t, x, p, out):
    if mode == STICK:
        F1 = spring_force(t, x, p)
        out[0] = p[5] - F1          # break-away forward
        out[1] = p[5] + F1          # break-away backward
    else:
        out[0] = x[1] if mode == SLIP_POS else -x[1]
        out[1] = 1.0


@numba.njit(cache=True, error_model="numpy")
def _rest_mode(t, x, p):
    d = direction_from_rest(spring_force(t, x, p), p[5], p[5])
    return SLIP_POS if d > 0 else (SLIP_NEG if d < 0 else STICK)


@numba.njit(RESET_SIG, cache=True, error_model="numpy")
def two_mass_reset(mode, guard, t, x, p, x_out):
    x_out[:] = x
    if mode == STICK:
        return SLIP_POS if guard == 0 else SLIP_NEG
    x_out[1] = 0.0
    return _rest_mode(t, x_out, p)


@numba.njit(MODE_SIG, cache=True, error_model="numpy")
def two_mass_mode(t, x, p):
    if x[1] != 0.0:
        return SLIP_POS if x[1] > 0 else SLIP_NEG
    return _rest_mode(t, x, p)


def two_mass_system(m1=1.0, m2=0.5, k=50.0, c=0.2, Fc=1.0, Fs=1.5, A=2.0, w=3.0):
    return PiecewiseSystem(
        name="two-mass", state_names=("x1", "v1", "x2", "v2"),
        modes=(Mode("slip+"), Mode("slip-"), Mode("stick", "stick", 1)),
        guard_names=("velocity zero / break-away forward", "break-away backward"),
        param_names=("m1", "m2", "k", "c", "Fc", "Fs", "A", "w"),
        params=np.array([m1, m2, k, c, Fc, Fs, A, w]),
        vector_field=two_mass_vf, guards=two_mass_guards, transition=two_mass_reset,
        mode_of=two_mass_mode)


# ---------------------------------------------------------------- Filippov sliding, closed form
# states (y, s): y' = -sgn(y) + 2 sin(s), s' = 1; surface y = 0, sliding while |2 sin s| < 1
BELOW, ABOVE, SLIDE = 0, 1, 2


@numba.njit(cache=True, error_model="numpy")
def _fields(x, fm, fp):
    a = 2.0 * math.sin(x[1])
    fm[0] = 1.0 + a
    fm[1] = 1.0
    fp[0] = -1.0 + a
    fp[1] = 1.0


@numba.njit(VF_SIG, cache=True, error_model="numpy")
def filippov_vf(mode, t, x, p, out):
    fm = np.empty(2)
    fp = np.empty(2)
    _fields(x, fm, fp)
    if mode == BELOW:
        out[:] = fm
    elif mode == ABOVE:
        out[:] = fp
    else:
        filippov_combine(fm, fp, filippov_weight(fm[0], fp[0]), out)


@numba.njit(GUARD_SIG, cache=True, error_model="numpy")
def filippov_guards(mode, t, x, p, out):
    if mode == SLIDE:
        a = 2.0 * math.sin(x[1])
        out[0] = 1.0 + a        # grad h . f-  falls through 0: leave below
        out[1] = 1.0 - a        # -grad h . f+ falls through 0: leave above
    else:
        out[0] = x[0] if mode == ABOVE else -x[0]
        out[1] = 1.0


@numba.njit(cache=True, error_model="numpy")
def _surface_mode(x):
    a = 2.0 * math.sin(x[1])
    if filippov_attractive(1.0 + a, -1.0 + a):
        return SLIDE
    return ABOVE if -1.0 + a > 0 else BELOW


@numba.njit(RESET_SIG, cache=True, error_model="numpy")
def filippov_reset(mode, guard, t, x, p, x_out):
    x_out[:] = x
    if mode == SLIDE:
        x_out[0] = 0.0
        return BELOW if guard == 0 else ABOVE
    x_out[0] = 0.0
    return _surface_mode(x_out)


@numba.njit(MODE_SIG, cache=True, error_model="numpy")
def filippov_mode(t, x, p):
    if x[0] != 0.0:
        return ABOVE if x[0] > 0 else BELOW
    return _surface_mode(x)


def filippov_system():
    return PiecewiseSystem(
        name="filippov-example", state_names=("y", "s"),
        modes=(Mode("below"), Mode("above"), Mode("slide", "filippov", 0)),
        guard_names=("surface / exit below", "exit above"), param_names=(), params=np.zeros(1),
        vector_field=filippov_vf, guards=filippov_guards, transition=filippov_reset,
        mode_of=filippov_mode)


# ---------------------------------------------------------------- bouncing ball (Zeno)
@numba.njit(VF_SIG, cache=True, error_model="numpy")
def ball_vf(mode, t, x, p, out):
    out[0] = x[1]
    out[1] = -p[0]


@numba.njit(GUARD_SIG, cache=True, error_model="numpy")
def ball_guards(mode, t, x, p, out):
    out[0] = x[0]


@numba.njit(RESET_SIG, cache=True, error_model="numpy")
def ball_reset(mode, guard, t, x, p, x_out):
    x_out[0] = 0.0
    x_out[1] = -p[1] * x[1]
    return 0


@numba.njit(MODE_SIG, cache=True, error_model="numpy")
def ball_mode(t, x, p):
    return 0


def ball_system(g=9.81, e=0.5):
    return PiecewiseSystem(name="ball", state_names=("h", "v"), modes=("flight",), guard_names=("floor",),
                           param_names=("g", "e"), params=np.array([g, e]), vector_field=ball_vf,
                           guards=ball_guards, transition=ball_reset, mode_of=ball_mode)


# ---------------------------------------------------------------- Hopf normal form (known cycle)
# x' = x - w y - x r^2, y' = w x + y - y r^2: limit cycle r = 1, period 2 pi / w, non-trivial
# Floquet multiplier exp(-2 * 2 pi / w). Two modes split at x = 0 with the same field, so the
# events and their (identity) saltation matrices are exercised.
@numba.njit(VF_SIG, cache=True, error_model="numpy", _nrt=False)
def hopf_vf(mode, t, x, p, out):
    r2 = x[0] * x[0] + x[1] * x[1]
    out[0] = x[0] - p[0] * x[1] - x[0] * r2
    out[1] = p[0] * x[0] + x[1] - x[1] * r2


@numba.njit(GUARD_SIG, cache=True, error_model="numpy", _nrt=False)
def hopf_guards(mode, t, x, p, out):
    out[0] = x[0] if mode == 0 else -x[0]


@numba.njit(RESET_SIG, cache=True, error_model="numpy", _nrt=False)
def hopf_reset(mode, guard, t, x, p, x_out):
    x_out[0] = x[0]
    x_out[1] = x[1]
    return 1 - mode


@numba.njit(MODE_SIG, cache=True, error_model="numpy", _nrt=False)
def hopf_mode(t, x, p):
    return 0 if x[0] > 0 or (x[0] == 0 and x[1] < 0) else 1


def hopf_system(w=2.0):
    return PiecewiseSystem(name="hopf", state_names=("x", "y"), modes=("x>0", "x<0"), guard_names=("x = 0",),
                           param_names=("w",), params=np.array([w]), vector_field=hopf_vf, guards=hopf_guards,
                           transition=hopf_reset, mode_of=hopf_mode)


# ---------------------------------------------------------------- relay oscillator (known cycle)
# x' = y, y' = -x + 2 delta y - F sgn(y): linear in each half plane, spirals out around (-F sgn y, 0).
# Symmetric cycle: amplitude a = F (1 + e^k) / (e^k - 1), k = delta pi / w, w = sqrt(1 - delta^2),
# period 2 pi / w, multipliers 1 and e^(2k) (unstable); the crossings of y = 0 have saltation
# matrices diag(1, (a - F)/(a + F)) (a jump of 2F in y').
@numba.njit(VF_SIG, cache=True, error_model="numpy", _nrt=False)
def relay_vf(mode, t, x, p, out):
    s = 1.0 if mode == 0 else -1.0
    out[0] = x[1]
    out[1] = -x[0] + 2.0 * p[0] * x[1] - p[1] * s


@numba.njit(GUARD_SIG, cache=True, error_model="numpy", _nrt=False)
def relay_guards(mode, t, x, p, out):
    out[0] = x[1] if mode == 0 else -x[1]


@numba.njit(RESET_SIG, cache=True, error_model="numpy", _nrt=False)
def relay_reset(mode, guard, t, x, p, x_out):
    x_out[0] = x[0]
    x_out[1] = 0.0
    return 1 - mode


@numba.njit(MODE_SIG, cache=True, error_model="numpy", _nrt=False)
def relay_mode(t, x, p):
    if x[1] != 0.0:
        return 0 if x[1] > 0 else 1
    return 0 if -x[0] > 0 else 1


def relay_system(delta=0.1, F=1.0):
    return PiecewiseSystem(name="relay", state_names=("x", "y"), modes=("y>0", "y<0"), guard_names=("y = 0",),
                           param_names=("delta", "F"), params=np.array([delta, F]), vector_field=relay_vf,
                           guards=relay_guards, transition=relay_reset, mode_of=relay_mode)
