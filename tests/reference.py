"""Independent references for the tests: closed forms of the Coulomb-friction PID loop and a
scipy solve_ivp event-chaining simulator of the Switch loop (a second method)."""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.linalg import expm
from scipy.optimize import brentq


def slip_affine(m, kp, kd, ki, Fc, b, s):
    """x' = A x + c in slip with direction s for Coulomb friction (no Stribeck)."""
    A = np.array([[0.0, 1.0, 0.0], [-kp / m, -(kd + b) / m, -ki / m], [1.0, 0.0, 0.0]])
    c = np.array([0.0, -s * Fc / m, 0.0])
    return A, c


def affine_flow(A, c, x0, t):
    """exp of the augmented matrix: the exact solution of x' = A x + c."""
    n = A.shape[0]
    M = np.zeros((n + 1, n + 1))
    M[:n, :n] = A
    M[:n, n] = c
    E = expm(M * t)
    return E[:n, :n] @ x0 + E[:n, n]


def coulomb_first_stop(m, kp, kd, ki, Fc, b, x0, s, t_max=20.0):
    """Time and state where x2 first returns to zero in slip direction s (closed form + root)."""
    A, c = slip_affine(m, kp, kd, ki, Fc, b, s)
    ts = np.linspace(1e-9, t_max, 20001)
    v = np.array([affine_flow(A, c, x0, t)[1] for t in ts]) * s
    k = np.flatnonzero((v[:-1] > 0) & (v[1:] <= 0))[0]
    te = brentq(lambda t: affine_flow(A, c, x0, t)[1], ts[k], ts[k + 1], xtol=1e-15, rtol=1e-15)
    return te, affine_flow(A, c, x0, te)


def scipy_switch_sequence(m, kp, kd, ki, Fs, Fc, vs, beta, b, d0, n_sticks, rtol=1e-12, atol=1e-14,
                          method="DOP853"):
    """Stick errors d_k of the exact Switch loop (u = -(kp x1 + kd x2 + ki x3), cm = 1) from the
    stick state with error d0, by solve_ivp with terminal events; stick phases in closed form.
    Returns (stick errors, stick entry times, number of f evaluations)."""
    def g(v):
        if np.isinf(beta):
            return Fc
        return Fc + (Fs - Fc) * np.exp(-np.abs(v / vs) ** beta)

    def rhs(t, x, s):
        F = -(kp * x[0] + kd * x[1] + ki * x[2])
        return [x[1], (F - s * g(x[1]) - b * x[1]) / m, x[0]]

    t, x = 0.0, np.array([d0, 0.0, 0.0])
    # start of the stick phase: x3 such that the loop just sits in stick (x3 = 0 as in the thesis)
    ds, ts, nfev = [], [], 0
    while len(ds) < n_sticks:
        # stick: x1 fixed, x3 grows linearly; break-away when |kp d + ki x3| = Fs
        d = x[0]
        F0 = -(kp * d + ki * x[2])
        if abs(F0) <= Fs:
            if d == 0:
                break
            # F(t) = F0 - ki d t reaches sign(-d) Fs
            target = -np.sign(d) * Fs
            dt = (F0 - target) / (ki * d)
            x = np.array([d, 0.0, x[2] + d * dt])
            t += dt
        F = -(kp * x[0] + ki * x[2])
        s = 1.0 if F > 0 else -1.0
        while True:
            ev = lambda tt, xx, s=s: xx[1]  # noqa: E731
            ev.terminal = True
            ev.direction = -s
            sol = solve_ivp(rhs, (t, t + 100.0), x, method=method, rtol=rtol, atol=atol, events=ev,
                            args=(s,))
            nfev += sol.nfev
            te, xe = sol.t_events[0][0], sol.y_events[0][0].copy()
            xe[1] = 0.0
            t, x = te, xe
            F = -(kp * x[0] + ki * x[2])
            if abs(F) <= Fs:
                break
            s = -s
        ds.append(x[0])
        ts.append(t)
    return np.array(ds), np.array(ts), nfev
