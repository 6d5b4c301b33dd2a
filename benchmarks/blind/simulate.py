"""The blind benchmark's plant integrator: a sampled controller with a zero-order hold driving a
mass with friction, integrated interval by interval with exact stick events.

Independent of hunting's integrators by construction (nothing is imported from ``hunting``): an
adaptive Dormand-Prince 5(4) method with local error control (rtol, atol per state) runs over the
slip phases; each stop (v = 0 in a slip of direction s) is located by Illinois regula falsi on the
length of a single Dormand-Prince step taken from the accepted step's start, so a stop is as
accurate as the steps themselves, not as an interpolant. Stick is exact: a rigid mass stuck at
v = 0 stays at its position while the force it needs,

    need = cm (u + i_noise) - offset - F_cog(q) - F_spring,

lies inside [-(Fs- + growth), Fs+ + growth] (growth: the dwell effect's rise of the break-away
force with the rest time); with a rigid plant ``need`` is constant between input changes and
the threshold does not fall, so break-away can only happen at an input change and is decided
there in closed form. A flexible load keeps moving while the motor side sticks, so its
break-away margin is an event function located the same way as the stops.

State x = [q, v, w, q2, v2]: motor position [m] and velocity [m/s]; w is the LuGre bristle
deflection z [m] (law ``lugre``, smooth, no events) or the lagging Stribeck level L [N]
(frictional memory, L' = (g(|v|) - L) / lag; relaxes to the mean Fs at rest); q2, v2 the
flexible load's position and velocity (unused for a rigid plant).

Plant equation (forces act like friction, the convention of the diagnosis' model schema):

    m1 v' = cm u(t - delay) + cm i_noise - F - offset - F_cog(q) - F_spring,
    F_spring = k (q - q2) + c (v - v2),   m2 v2' = F_spring,

F = s L + b_s v (static laws in slip of direction s, L = g_s(|v|) without memory) or
F = sigma0 z + sigma1 z' + b_s v with z' = v - sigma0 |v| z / g_s(|v|) (LuGre), g_s(r) =
Fc_s + (Fs_s - Fc_s) exp(-(r / vs_s)^beta_s) the Stribeck level of direction s.

Controllers (the schema of the diagnosis' model JSON, implemented here from its description):
u_k from the quantized measurement y_k at t_k, held on [t_k, t_k+1); PID: e = y - r,
I += T e, D = (tau_f D + (sig - sig_prev)) / (tau_f + T) (sig = e, or y when the derivative acts
on the measurement), u = -(kp e + kd D + ki I); PD + velocity loop: u = kv (kp (r - y) - v_f),
v_f the backward difference of the 2-tap mean of y; then the saturation |u| <= U and the DAC's
step (round to nearest).
"""
from __future__ import annotations

import math

import numba
import numpy as np

# plant parameter vector
M1, CM, OFFSET, LUGRE = 0, 1, 2, 3
POS, NEG = 4, 9                      # each: Fc, Fs, vs, beta, b
SIGMA0, SIGMA1, LAG = 14, 15, 16
DW_GAIN, DW_TIME, DW_LEVEL = 17, 18, 19
M2, K2, C2 = 20, 21, 22
NPAR = 23
# controller vector
C_TYPE, C_KP, C_KD, C_KI, C_KV, C_TAUF, C_DMEAS, C_SAT, C_DAC = range(9)
NCTRL = 9
PID, PDV = 1.0, 2.0
# phase modes
SLIP, STUCK, SMOOTH = 0, 1, 2
# statuses
OK, NOT_FINITE, TOO_MANY_STEPS, TOO_MANY_EVENTS = 0, 1, 2, 3
STATUS_TEXT = {OK: "ok", NOT_FINITE: "state not finite", TOO_MANY_STEPS: "step limit reached (raise rtol?)",
               TOO_MANY_EVENTS: "more than 50 stick/slip events in one sample interval"}

MAX_STEPS = 200_000                  # Dormand-Prince steps per phase
MAX_EVENTS = 50                      # stick/slip transitions per sub-interval

# Dormand-Prince 5(4) tableau
_C = np.array([0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0])
_A = np.zeros((7, 7))
_A[1, :1] = [1 / 5]
_A[2, :2] = [3 / 40, 9 / 40]
_A[3, :3] = [44 / 45, -56 / 15, 32 / 9]
_A[4, :4] = [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729]
_A[5, :5] = [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656]
_A[6, :6] = [35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84]
_B5 = _A[6].copy()
_B4 = np.array([5179 / 57600, 0.0, 7571 / 16695, 393 / 640, -92097 / 339200, 187 / 2100, 1 / 40])
_E = _B5 - _B4


@numba.njit(cache=True)
def stribeck(P, base, speed):
    """Stribeck level g(speed) [N] of the curve at P[base:base+5] (speed >= 0)."""
    Fc, Fs = P[base], P[base + 1]
    if Fs == Fc:
        return Fc
    return Fc + (Fs - Fc) * math.exp(-((speed / P[base + 2]) ** P[base + 3]))


@numba.njit(cache=True)
def cogging(q, cog):
    """F_cog(q) [N]; cog = [pitch, cos_1, sin_1, cos_2, sin_2, ...] (size < 3: none)."""
    if cog.size < 3:
        return 0.0
    w = 2.0 * math.pi / cog[0]
    acc = 0.0
    for k in range((cog.size - 1) // 2):
        acc += cog[1 + 2 * k] * math.cos(w * (k + 1) * q) + cog[2 + 2 * k] * math.sin(w * (k + 1) * q)
    return acc


@numba.njit(cache=True)
def spring(x, P):
    """The flexible load's force on the motor side [N] (0 for a rigid plant)."""
    if P[M2] == 0.0:
        return 0.0
    return P[K2] * (x[0] - x[3]) + P[C2] * (x[1] - x[4])


@numba.njit(cache=True)
def rhs(x, P, cog, fa, mode, s, dx):
    """dx/dt into dx (5,) at applied force fa = cm (u + i_noise) [N]."""
    fsp = spring(x, P)
    v = x[1]
    if mode == STUCK:
        dx[0] = 0.0
        dx[1] = 0.0
        dx[2] = (0.5 * (P[POS + 1] + P[NEG + 1]) - x[2]) / P[LAG] if P[LAG] > 0.0 else 0.0
    elif mode == SLIP:
        base = POS if s > 0 else NEG
        g = stribeck(P, base, s * v)
        lev = x[2] if P[LAG] > 0.0 else g
        F = s * lev + P[base + 4] * v
        dx[0] = v
        dx[1] = (fa - P[OFFSET] - cogging(x[0], cog) - F - fsp) / P[M1]
        dx[2] = (g - x[2]) / P[LAG] if P[LAG] > 0.0 else 0.0
    else:
        base = POS if v >= 0.0 else NEG
        g = stribeck(P, base, abs(v))
        zd = v - P[SIGMA0] * abs(v) * x[2] / g
        F = P[SIGMA0] * x[2] + P[SIGMA1] * zd + P[base + 4] * v
        dx[0] = v
        dx[1] = (fa - P[OFFSET] - cogging(x[0], cog) - F - fsp) / P[M1]
        dx[2] = zd
    if P[M2] == 0.0:
        dx[3] = 0.0
        dx[4] = 0.0
    else:
        dx[3] = x[4]
        dx[4] = fsp / P[M2]


@numba.njit(cache=True)
def dp_step(x, h, P, cog, fa, mode, s, K, xs, xn, err):
    """One Dormand-Prince 5(4) step of length h from x: the 5th-order state into xn and the
    embedded error estimate into err. K (7, 5) and xs (5,) are work arrays."""
    rhs(x, P, cog, fa, mode, s, K[0])
    for i in range(1, 7):
        for j in range(5):
            acc = 0.0
            for l in range(i):
                acc += _A[i, l] * K[l, j]
            xs[j] = x[j] + h * acc
        rhs(xs, P, cog, fa, mode, s, K[i])
    for j in range(5):
        acc = 0.0
        e = 0.0
        for l in range(7):
            acc += _B5[l] * K[l, j]
            e += _E[l] * K[l, j]
        xn[j] = x[j] + h * acc
        err[j] = h * e


@numba.njit(cache=True)
def err_norm(x, xn, err, atol, rtol):
    worst = 0.0
    for j in range(5):
        sc = atol[j] + rtol * max(abs(x[j]), abs(xn[j]))
        worst = max(worst, abs(err[j]) / sc)
    return worst


@numba.njit(cache=True)
def breakaway_margin(x, P, cog, fa, t_rest):
    """How far the force the stuck motor side needs is inside its break-away thresholds [N]
    (negative: it breaks away)."""
    need = fa - P[OFFSET] - cogging(x[0], cog) - spring(x, P)
    grow = P[DW_LEVEL]
    if P[DW_TIME] > 0.0:
        grow += P[DW_GAIN] * (1.0 - math.exp(-t_rest / P[DW_TIME]))
    return min(P[POS + 1] + grow - need, need + P[NEG + 1] + grow)


@numba.njit(cache=True)
def event_value(x, P, cog, fa, mode, s, t_rest):
    if mode == SLIP:
        return s * x[1]
    return breakaway_margin(x, P, cog, fa, t_rest)


@numba.njit(cache=True)
def integrate_phase(x, length, P, cog, fa, mode, s, t_rest, h, atol, rtol, with_event, work):
    """Integrate x in place over at most ``length`` [s] in one mode. With ``with_event`` the
    phase ends where the event value (slip: s v; stuck: the break-away margin) falls from > 0 to
    <= 0. Returns (status, time done [s], event hit, next step size)."""
    K = work[0:7]
    xs, xn, err, x0 = work[7], work[8], work[9], work[10]
    t = 0.0
    g_old = event_value(x, P, cog, fa, mode, s, t_rest) if with_event else 1.0
    for _ in range(MAX_STEPS):
        rem = length - t
        if rem <= 1e-15 * length:
            return OK, length, False, h
        hh = min(h, rem)
        dp_step(x, hh, P, cog, fa, mode, s, K, xs, xn, err)
        en = err_norm(x, xn, err, atol, rtol)
        if not math.isfinite(en):
            if hh < 1e-14 * length:
                return NOT_FINITE, t, False, h
            h = 0.2 * hh
            continue
        if en > 1.0:
            h = hh * max(0.2, 0.9 * en ** -0.2)
            continue
        h_next = hh * min(5.0, max(0.2, 0.9 * (en + 1e-30) ** -0.2))
        if with_event:
            g_new = event_value(xn, P, cog, fa, mode, s, t_rest + t + hh)
            if g_new <= 0.0 and g_old > 0.0:
                # Illinois regula falsi on the length of a single step from x
                x0[:] = x
                a, ga, b, gb = 0.0, g_old, hh, g_new
                side = 0
                for _it in range(100):
                    th = b - gb * (b - a) / (gb - ga)
                    if not (a < th < b):
                        th = 0.5 * (a + b)
                    dp_step(x0, th, P, cog, fa, mode, s, K, xs, xn, err)
                    gt = event_value(xn, P, cog, fa, mode, s, t_rest + t + th)
                    if gt <= 0.0:
                        b, gb = th, gt
                        if side == -1:
                            ga *= 0.5
                        side = -1
                    else:
                        a, ga = th, gt
                        if side == 1:
                            gb *= 0.5
                        side = 1
                    if b - a <= 1e-15 * (1.0 + t + b) or gt == 0.0:
                        break
                dp_step(x0, b, P, cog, fa, mode, s, K, xs, xn, err)
                x[:] = xn
                return OK, t + b, True, h_next
            g_old = g_new
        x[:] = xn
        t += hh
        h = h_next
    return TOO_MANY_STEPS, t, False, h


@numba.njit(cache=True)
def advance(x, length, P, cog, fa, st, h, atol, rtol, work):
    """Advance the plant over ``length`` [s] at the constant applied force fa [N]. st = [stuck
    (0/1), direction s, rest time [s]] is updated in place. Returns (status, next step size)."""
    rem = length
    lugre = P[LUGRE] > 0.5
    rigid = P[M2] == 0.0
    for _ in range(MAX_EVENTS):
        if rem <= 1e-15 * length:
            return OK, h
        if lugre:
            status, done, hit, h = integrate_phase(x, rem, P, cog, fa, SMOOTH, 1.0, 0.0, h, atol, rtol, False, work)
            return status, h
        if st[0] > 0.5:
            margin = breakaway_margin(x, P, cog, fa, st[2])
            if margin < 0.0:
                need = fa - P[OFFSET] - cogging(x[0], cog) - spring(x, P)
                st[0] = 0.0
                st[1] = 1.0 if need > 0.0 else -1.0
                continue
            if rigid:
                if P[LAG] > 0.0:
                    fs = 0.5 * (P[POS + 1] + P[NEG + 1])
                    x[2] = fs + (x[2] - fs) * math.exp(-rem / P[LAG])
                st[2] += rem
                return OK, h
            status, done, hit, h = integrate_phase(x, rem, P, cog, fa, STUCK, 0.0, st[2], h, atol, rtol, True, work)
            st[2] += done
            rem -= done
            if status != OK:
                return status, h
            if hit:
                need = fa - P[OFFSET] - cogging(x[0], cog) - spring(x, P)
                st[0] = 0.0
                st[1] = 1.0 if need > 0.0 else -1.0
            continue
        status, done, hit, h = integrate_phase(x, rem, P, cog, fa, SLIP, st[1], 0.0, h, atol, rtol, True, work)
        rem -= done
        if status != OK:
            return status, h
        if hit:
            x[1] = 0.0
            need = fa - P[OFFSET] - cogging(x[0], cog) - spring(x, P)
            if -(P[NEG + 1] + P[DW_LEVEL]) <= need <= P[POS + 1] + P[DW_LEVEL]:
                st[0] = 1.0
                st[2] = 0.0
            else:
                st[1] = 1.0 if need > 0.0 else -1.0
    return TOO_MANY_EVENTS, h


@numba.njit(cache=True)
def controller_output(C, dt, y, r, cs):
    """The controller's output for measurement y and reference r; cs = [I, D, sig_prev, y_prev,
    qf_prev, started] is its state (updated)."""
    if cs[5] < 0.5:                       # first sample: no difference quotient yet
        cs[2] = y if C[C_DMEAS] > 0.5 else y - r
        cs[3] = y
        cs[4] = y
        cs[5] = 1.0
    if C[C_TYPE] == PID:
        e = y - r
        cs[0] += dt * e
        sig = y if C[C_DMEAS] > 0.5 else e
        cs[1] = (C[C_TAUF] * cs[1] + (sig - cs[2])) / (C[C_TAUF] + dt)
        cs[2] = sig
        u = -(C[C_KP] * e + C[C_KD] * cs[1] + C[C_KI] * cs[0])
    else:
        qf = 0.5 * (y + cs[3])
        u = C[C_KV] * (C[C_KP] * (r - y) - (qf - cs[4]) / dt)
        cs[4] = qf
        cs[3] = y
    if u > C[C_SAT]:
        u = C[C_SAT]
    elif u < -C[C_SAT]:
        u = -C[C_SAT]
    if C[C_DAC] > 0.0:
        u = C[C_DAC] * math.floor(u / C[C_DAC] + 0.5)
    return u


@numba.njit(cache=True)
def run_loop(P, cog, C, delay, dt, r, i_noise, s_noise, resolution, x, st, rtol, atol, q_out, u_out, X_out, stuck_out):
    """The closed loop over r.size samples from state x, stick state st (module docstring).
    Writes the measured position q_out, the controller output u_out, the true state X_out (n, 5)
    and the stick flag at each sample instant. Returns (status, samples done)."""
    n = r.size
    d = int(math.floor(delay / dt + 1e-9))
    phi = delay - d * dt
    if phi < 1e-9 * dt:
        phi = 0.0
    cs = np.zeros(6)
    work = np.zeros((11, 5))
    h = 0.25 * dt
    for k in range(n):
        ym = x[0] + s_noise[k]
        y = resolution * math.floor(ym / resolution + 0.5) if resolution > 0.0 else ym
        u = controller_output(C, dt, y, r[k], cs)
        q_out[k] = y
        u_out[k] = u
        X_out[k, :] = x
        stuck_out[k] = st[0]
        if phi > 0.0:
            j = k - d - 1
            ua = u_out[j] if j >= 0 else 0.0
            status, h = advance(x, phi, P, cog, P[CM] * (ua + i_noise[k]), st, h, atol, rtol, work)
            if status != OK:
                return status, k
        j = k - d
        ua = u_out[j] if j >= 0 else 0.0
        status, h = advance(x, dt - phi, P, cog, P[CM] * (ua + i_noise[k]), st, h, atol, rtol, work)
        if status != OK:
            return status, k
        for i in range(5):
            if not math.isfinite(x[i]):
                return NOT_FINITE, k
    return OK, n
