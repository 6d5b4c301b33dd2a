"""The PID-controlled 1-DOF servo with friction: the closed loops of chapters 4, 8, 9 and 10.

States: x1 = q - q_d (position error) [m or rad], x2 = q' [m/s], x3 = int x1 dt [m s],
and for LuGre x4 = z (bristle deflection) [m]. Forces on the mass::

    m x2' = F_nf(t, x) - F_friction,   F_nf = cm u + f_ext(t) - F_cog(x1 + q_d),
    u = -(kp x1 + kd x2 + ki x3).

One set of numba functions serves every friction model (selected by a code in the flat
parameter array), so the kernels compile once for all of them.

Modes
-----
switch (exact Filippov stick): 0 "slip+", 1 "slip-", 2 "stick". Guards: slip+ fires when x2
falls through 0, slip- when -x2 does; stick fires when Fs+ - F_nf or Fs- + F_nf falls through
0 (break-away). Entry into stick sets x2 = 0 exactly; stick holds x1, x2 and integrates x3.
switch-banded (thesis section 9.2): 0 "slip" (|x2| > eta), 1 "stick" (|x2| <= eta, |F_nf| <=
Fs: x2' = -alpha x2, x1' = 0), 2 "transition" (|x2| <= eta, |F_nf| > Fs).
lugre: 0 "v+" (x2 >= 0), 1 "v-" (x2 < 0); the guard x2 = 0 locates the kink of |x2|.
"""
from __future__ import annotations

import math

import numba
import numpy as np

from ..sliding import direction_from_rest
from ..system import (GUARD_SIG, JAC_SIG, MODE_SIG, RESET_SIG, VF_SIG, Mode, PiecewiseSystem, compile_for,
                      compile_later)
from .friction import lugre_partials, lugre_rates, slip_force, stribeck_level_slope
from .plant import cogging_force, cogging_slope, external_force

# ---- flat parameter layout: the names are the one source, the slots below are read from them
PARAM_NAMES = ("m", "cm", "kp", "kd", "ki", "q_d", "fext_kind", "fext_amp", "fext_period", "model",
               "Fc_pos", "Fs_pos", "vs_pos", "beta_pos", "b_pos",
               "Fc_neg", "Fs_neg", "vs_neg", "beta_neg", "b_neg",
               "eta", "alpha", "sigma0", "sigma1", "vd", "cog_kind", "cog_n", "cog_period")
_SLOT = {name: i for i, name in enumerate(PARAM_NAMES)}
M, CM, KP, KD, KI, QD = (_SLOT[k] for k in ("m", "cm", "kp", "kd", "ki", "q_d"))
FEXT_KIND, FEXT_AMP, FEXT_PERIOD, MODEL = (_SLOT[k] for k in ("fext_kind", "fext_amp", "fext_period", "model"))
POS = _SLOT["Fc_pos"]      # Fc, Fs, vs, beta, b for v > 0
NEG = _SLOT["Fc_neg"]      # the same for v < 0
ETA, ALPHA, SIGMA0, SIGMA1, VD = (_SLOT[k] for k in ("eta", "alpha", "sigma0", "sigma1", "vd"))
COG = _SLOT["cog_kind"]    # kind, n, period, data... (the cogging block runs to the end of the array)

MODEL_SWITCH, MODEL_BANDED, MODEL_LUGRE = 0, 1, 2
SLIP_POS, SLIP_NEG, STICK = 0, 1, 2               # switch
BAND_SLIP, BAND_STICK, BAND_TRANSITION = 0, 1, 2  # switch-banded
V_POS, V_NEG = 0, 1                               # lugre


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def nonfriction_force(t, x, p):
    """F_nf = cm u + f_ext(t) - F_cog(q) [N]: every force on the mass except friction."""
    u = -(p[KP] * x[0] + p[KD] * x[1] + p[KI] * x[2])
    return p[CM] * u + external_force(t, p[FEXT_KIND], p[FEXT_AMP], p[FEXT_PERIOD]) \
        - cogging_force(x[0] + p[QD], p, COG)


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _slip(v, s, p):
    base = POS if s > 0 else NEG
    return slip_force(v, s, p[base], p[base + 1], p[base + 2], p[base + 3], p[base + 4])


@numba.njit(cache=True, error_model="numpy", _nrt=False)    # compiled for VF_SIG on first use
def servo_vf(mode, t, x, p, out):
    model = p[MODEL]
    F = nonfriction_force(t, x, p)
    m = p[M]
    out[2] = x[0]
    if model == MODEL_SWITCH:
        if mode == STICK:
            out[0] = 0.0
            out[1] = 0.0
        else:
            s = 1.0 if mode == SLIP_POS else -1.0
            out[0] = x[1]
            out[1] = (F - _slip(x[1], s, p)) / m
    elif model == MODEL_BANDED:
        if mode == BAND_SLIP:
            s = 1.0 if x[1] > 0 else -1.0
            out[0] = x[1]
            out[1] = (F - _slip(x[1], s, p)) / m
        elif mode == BAND_STICK:
            out[0] = 0.0
            out[1] = -p[ALPHA] * x[1]
        else:
            Fs = p[POS + 1] if F > 0 else p[NEG + 1]
            out[0] = x[1]
            out[1] = (F - math.copysign(Fs, F)) / m
    else:
        s = 1.0 if mode == V_POS else -1.0
        base = POS if s > 0 else NEG
        zdot, Ff = lugre_rates(x[1], x[3], s, p[base], p[base + 1], p[base + 2], p[base + 3],
                               p[base + 4], p[SIGMA0], p[SIGMA1], p[VD])
        out[0] = x[1]
        out[1] = (F - Ff) / m
        out[3] = zdot


@numba.njit(cache=True, error_model="numpy", _nrt=False)    # compiled for JAC_SIG on first use
def servo_jac(mode, t, x, p, J):
    """Analytic Jacobian of :func:`servo_vf` in ``mode`` (the mode's smooth field)."""
    n = x.size
    for i in range(n):
        for j in range(n):
            J[i, j] = 0.0
    J[2, 0] = 1.0
    model = p[MODEL]
    m = p[M]
    cm = p[CM]
    # gradient of the non-friction force
    F1 = -cm * p[KP] - cogging_slope(x[0] + p[QD], p, COG)
    F2 = -cm * p[KD]
    F3 = -cm * p[KI]
    if model == MODEL_SWITCH and mode == STICK:
        return
    if model == MODEL_BANDED and mode == BAND_STICK:
        J[1, 1] = -p[ALPHA]
        return
    J[0, 1] = 1.0
    if model == MODEL_BANDED and mode == BAND_TRANSITION:
        J[1, 0] = F1 / m
        J[1, 1] = F2 / m
        J[1, 2] = F3 / m
        return
    if model == MODEL_LUGRE:
        s = 1.0 if mode == V_POS else -1.0
        base = POS if s > 0 else NEG
        dzv, dzz, dFv, dFz = lugre_partials(x[1], x[3], s, p[base], p[base + 1], p[base + 2], p[base + 3],
                                            p[base + 4], p[SIGMA0], p[SIGMA1], p[VD])
        J[1, 0] = F1 / m
        J[1, 1] = (F2 - dFv) / m
        J[1, 2] = F3 / m
        J[1, 3] = -dFz / m
        J[3, 1] = dzv
        J[3, 3] = dzz
        return
    # slip of the Switch models: friction s g(s v) + b v, d/dv = g'(s v) + b
    if model == MODEL_BANDED:
        s = 1.0 if x[1] > 0 else -1.0
    else:
        s = 1.0 if mode == SLIP_POS else -1.0
    base = POS if s > 0 else NEG
    dslip = stribeck_level_slope(s * x[1], p[base], p[base + 1], p[base + 2], p[base + 3]) + p[base + 4]
    J[1, 0] = F1 / m
    J[1, 1] = (F2 - dslip) / m
    J[1, 2] = F3 / m


@numba.njit(cache=True, error_model="numpy", _nrt=False)    # compiled for GUARD_SIG on first use
def servo_guards(mode, t, x, p, out):
    model = p[MODEL]
    if model == MODEL_SWITCH:
        if mode == SLIP_POS:
            out[0] = x[1]
            out[1] = 1.0
        elif mode == SLIP_NEG:
            out[0] = -x[1]
            out[1] = 1.0
        else:
            F = nonfriction_force(t, x, p)
            out[0] = p[POS + 1] - F
            out[1] = p[NEG + 1] + F
    elif model == MODEL_BANDED:
        eta = p[ETA]
        if mode == BAND_SLIP:
            out[0] = abs(x[1]) - eta
            out[1] = 1.0
        else:
            F = nonfriction_force(t, x, p)
            Fs = p[POS + 1] if F > 0 else p[NEG + 1]
            out[0] = eta - abs(x[1])
            out[1] = Fs - abs(F) if mode == BAND_STICK else abs(F) - Fs
    else:
        out[0] = x[1] if mode == V_POS else -x[1]
        out[1] = 1.0


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _switch_mode_at_rest(t, x, p):
    d = direction_from_rest(nonfriction_force(t, x, p), p[POS + 1], p[NEG + 1])
    if d > 0:
        return SLIP_POS
    if d < 0:
        return SLIP_NEG
    return STICK


@numba.njit(cache=True, error_model="numpy", _nrt=False)    # compiled for RESET_SIG on first use
def servo_reset(mode, guard, t, x, p, x_out):
    for i in range(x.size):
        x_out[i] = x[i]
    model = p[MODEL]
    if model == MODEL_SWITCH:
        if mode == STICK:
            return SLIP_POS if guard == 0 else SLIP_NEG
        x_out[1] = 0.0
        return _switch_mode_at_rest(t, x_out, p)
    if model == MODEL_BANDED:
        F = nonfriction_force(t, x, p)
        Fs = p[POS + 1] if F > 0 else p[NEG + 1]
        if mode == BAND_SLIP:
            return BAND_STICK if abs(F) <= Fs else BAND_TRANSITION
        if guard == 0:
            return BAND_SLIP
        return BAND_TRANSITION if mode == BAND_STICK else BAND_STICK
    return V_NEG if mode == V_POS else V_POS


@numba.njit(cache=True, error_model="numpy", _nrt=False)    # compiled for MODE_SIG on first use
def servo_mode_of(t, x, p):
    model = p[MODEL]
    if model == MODEL_SWITCH:
        if x[1] > 0:
            return SLIP_POS
        if x[1] < 0:
            return SLIP_NEG
        return _switch_mode_at_rest(t, x, p)
    if model == MODEL_BANDED:
        if abs(x[1]) > p[ETA]:
            return BAND_SLIP
        F = nonfriction_force(t, x, p)
        Fs = p[POS + 1] if F > 0 else p[NEG + 1]
        return BAND_STICK if abs(F) <= Fs else BAND_TRANSITION
    if x[1] > 0:
        return V_POS
    if x[1] < 0:
        return V_NEG
    # at rest: the direction the velocity will take (sign of the acceleration)
    zdot, Ff = lugre_rates(0.0, x[3], 1.0, p[POS], p[POS + 1], p[POS + 2], p[POS + 3], p[POS + 4],
                           p[SIGMA0], p[SIGMA1], p[VD])
    return V_NEG if nonfriction_force(t, x, p) - Ff < 0 else V_POS


MODE_TABLES = {
    MODEL_SWITCH: ((Mode("slip+"), Mode("slip-"), Mode("stick", "stick", 1)),
                   ("velocity zero", "break-away"), [[-1, -1], [-1, -1], [-1, -1]], [1, 0, 2]),
    MODEL_BANDED: ((Mode("slip"), Mode("stick"), Mode("transition")),
                   ("band", "static level"), [[-1, -1], [-1, -1], [-1, -1]], [0, 1, 2]),
    MODEL_LUGRE: ((Mode("v+"), Mode("v-")), ("velocity zero", "unused"), [[-1, -1], [-1, -1]], [1, 0]),
}


def build_servo_system(name: str, params: np.ndarray, *, odd: bool, units: dict) -> PiecewiseSystem:
    """Wrap a flat servo parameter array (layout above) into a PiecewiseSystem."""
    # compiled here, not at import: a command that never builds a preset loop (a user model,
    # `hunting models`, --help) does not pay the ~3 s of compiling these on a fresh install
    for fn, sig in ((servo_vf, VF_SIG), (servo_guards, GUARD_SIG), (servo_reset, RESET_SIG),
                    (servo_mode_of, MODE_SIG)):
        compile_for(fn, sig, vectorize=False, unroll=False)
    # the Jacobian only when a kernel calls it (Radau, sensitivities): not for simulations and
    # event maps, which run the lean kernel
    compile_later(servo_jac, JAC_SIG)
    model = int(params[MODEL])
    modes, guard_names, directions, mirror = MODE_TABLES[model]
    states = ("x1", "x2", "x3") + (("x4",) if model == MODEL_LUGRE else ())
    return PiecewiseSystem(
        name=name, state_names=states, modes=modes, guard_names=guard_names,
        param_names=PARAM_NAMES, params=params, vector_field=servo_vf, guards=servo_guards,
        transition=servo_reset, mode_of=servo_mode_of, directions=np.array(directions), jacobian=servo_jac,
        odd=odd, mirror_mode=np.array(mirror) if odd else None, units=units)
