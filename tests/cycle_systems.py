"""Hand-written systems for the cycle-search tests (written the way a user adds one).

The block on a moving belt of issue 19's example: m q'' = -k q - F, relative velocity
w = v - vb, slip F = sgn(w) (Fc + (Fs - Fc) exp(-|w| / vs)), stick (w = 0, v = vb) while the
force that holds it, F = -k q, stays in [-Fs, Fs]. States (q, v); p = [m, k, Fc, Fs, vs, vb].
"""
import math

import numba
import numpy as np

from hunting import GUARD_SIG, MODE_SIG, RESET_SIG, VF_SIG, Mode, PiecewiseSystem

SLIP_POS, SLIP_NEG, STICK = 0, 1, 2
BELT = dict(m=1.0, k=2.0, Fc=0.3, Fs=0.5, vs=0.05, vb=0.1)


@numba.njit(VF_SIG, cache=True, error_model="numpy", _nrt=False)
def belt_vf(mode, t, x, p, out):
    if mode == STICK:
        out[0] = p[5]
        out[1] = 0.0
        return
    s = 1.0 if mode == SLIP_POS else -1.0
    w = x[1] - p[5]
    F = s * (p[2] + (p[3] - p[2]) * math.exp(-s * w / p[4]))
    out[0] = x[1]
    out[1] = (-p[1] * x[0] - F) / p[0]


@numba.njit(GUARD_SIG, cache=True, error_model="numpy", _nrt=False)
def belt_guards(mode, t, x, p, out):
    if mode == STICK:
        F = -p[1] * x[0]                 # the force that keeps w' = 0
        out[0] = p[3] - F                # leaves forward (w > 0)
        out[1] = p[3] + F                # leaves backward (w < 0)
    else:
        w = x[1] - p[5]
        out[0] = w if mode == SLIP_POS else -w
        out[1] = 1.0


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def _at_rest(x, p):
    F = -p[1] * x[0]
    if F > p[3]:
        return SLIP_POS
    if F < -p[3]:
        return SLIP_NEG
    return STICK


@numba.njit(RESET_SIG, cache=True, error_model="numpy", _nrt=False)
def belt_reset(mode, guard, t, x, p, x_out):
    x_out[0] = x[0]
    x_out[1] = x[1]
    if mode == STICK:
        return SLIP_POS if guard == 0 else SLIP_NEG
    x_out[1] = p[5]
    return _at_rest(x_out, p)


@numba.njit(MODE_SIG, cache=True, error_model="numpy", _nrt=False)
def belt_mode(t, x, p):
    w = x[1] - p[5]
    if w > 0:
        return SLIP_POS
    if w < 0:
        return SLIP_NEG
    return _at_rest(x, p)


def belt_system(**kw):
    v = {**BELT, **kw}
    return PiecewiseSystem(
        name="belt", state_names=("q", "v"),
        modes=(Mode("slip+"), Mode("slip-"), Mode("stick", "stick", 1)),
        guard_names=("w = 0 / break-away forward", "break-away backward"),
        param_names=tuple(BELT), params=np.array([v[k] for k in BELT]),
        vector_field=belt_vf, guards=belt_guards, transition=belt_reset, mode_of=belt_mode)


def belt_reference_cycle(m=1.0, k=2.0, Fc=0.3, Fs=0.5, vs=0.05, vb=0.1):
    """The belt's stick-slip cycle with scipy's solve_ivp (independent of hunting): from the
    break-away state (q = Fs/k, v = vb) slip backwards (w < 0) until w = 0 again (an event
    located by solve_ivp), then stick at the belt's speed until -k q reaches -Fs again.

    Returns dict(period, slip, stick, q_min, q_max, v_min, v_max)."""
    from scipy.integrate import solve_ivp

    def rhs(t, y):
        w = y[1] - vb
        F = -(Fc + (Fs - Fc) * math.exp(w / vs))          # slip with w < 0
        return [y[1], (-k * y[0] - F) / m]

    def w_zero(t, y):
        return y[1] - vb
    w_zero.terminal, w_zero.direction = True, 1.0
    q_b = Fs / k
    # leave the break-away state (w = 0) before the event is armed
    sol = solve_ivp(rhs, (0.0, 100.0), [q_b, vb], method="DOP853", rtol=1e-12, atol=1e-14,
                    events=w_zero, first_step=1e-8)
    t_slip = float(sol.t_events[0][0])
    q_entry = float(sol.y_events[0][0][0])
    t_stick = (q_b - q_entry) / vb
    # extremes: where q' = v or v' vanishes inside the slip phase (events located by solve_ivp)
    def v_zero(t, y):
        return y[1]

    def a_zero(t, y):
        return rhs(t, y)[1]
    ext = solve_ivp(rhs, (0.0, t_slip), [q_b, vb], method="DOP853", rtol=1e-12, atol=1e-14,
                    events=(v_zero, a_zero), first_step=1e-8)
    qs = np.concatenate([[q_b, q_entry], ext.y_events[0][:, 0]])
    vs_ = np.concatenate([[vb], ext.y_events[1][:, 1]])
    return dict(period=t_slip + t_stick, slip=t_slip, stick=t_stick, q_min=float(qs.min()), q_max=float(qs.max()),
                v_min=float(vs_.min()), v_max=float(vs_.max()))


# ---------------------------------------------------------------- a family of cycles
# the Hopf normal form (x, y) with a third state that never moves: every z carries a cycle, so
# no cycle is isolated and the shooting Jacobian is singular (a zero row for z)
@numba.njit(VF_SIG, cache=True, error_model="numpy", _nrt=False)
def family_vf(mode, t, x, p, out):
    r2 = x[0] * x[0] + x[1] * x[1]
    out[0] = x[0] - 2.0 * x[1] - x[0] * r2
    out[1] = 2.0 * x[0] + x[1] - x[1] * r2
    out[2] = 0.0


@numba.njit(GUARD_SIG, cache=True, error_model="numpy", _nrt=False)
def family_guards(mode, t, x, p, out):
    out[0] = 1.0


@numba.njit(RESET_SIG, cache=True, error_model="numpy", _nrt=False)
def family_reset(mode, guard, t, x, p, x_out):
    for i in range(x.size):
        x_out[i] = x[i]
    return mode


@numba.njit(MODE_SIG, cache=True, error_model="numpy", _nrt=False)
def family_mode(t, x, p):
    return 0


def family_system():
    return PiecewiseSystem(name="family", state_names=("x", "y", "z"), modes=("smooth",), guard_names=("none",),
                           param_names=(), params=np.zeros(1), vector_field=family_vf, guards=family_guards,
                           transition=family_reset, mode_of=family_mode)


# ---------------------------------------------------------------- the same as descriptions
BELT_DESCRIPTION = {
    "name": "belt", "parameters": dict(BELT), "states": ["q", "v"], "signals": {"u": "-k*q"},
    "equations": {"q": "v", "v": "(u - F)/m"},
    "friction": {"force": "F", "velocity": "v - vb", "model": "switch",
                 "slip": "sign(w)*(Fc + (Fs - Fc)*exp(-abs(w)/vs))", "stick": "Fs"}}

# the PID + LuGre loop of Canudas de Wit et al. (1995), in the position q with set point qd
PID_LUGRE_DESCRIPTION = {
    "name": "pid-lugre",
    "parameters": {"m": 1.0, "kp": 3.0, "kd": 6.0, "ki": 4.0, "qd": 1.0, "Fc": 1.0, "Fs": 1.5, "vs": 0.001,
                   "sigma0": 1e5, "sigma1": 316.22776601683796, "sigma2": 0.4},
    "states": ["q", "v", "ie"], "signals": {"e": "q - qd", "u": "-(kp*e + kd*v + ki*ie)"},
    "equations": {"q": "v", "v": "(u - F)/m", "ie": "e"},
    "friction": {"force": "F", "velocity": "v", "model": "lugre", "level": "Fc + (Fs - Fc)*exp(-(w/vs)**2)",
                 "sigma0": "sigma0", "sigma1": "sigma1", "viscous": "sigma2*w"}}
