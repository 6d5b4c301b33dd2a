#!/usr/bin/env python3
"""Independent test-data generator for a friction-diagnosis library.

python generate.py OUTDIR --seed S

Writes OUTDIR/d0000 .. d0089 (40 clean + 50 single-effect records).
Physics: single mass on a guide (or variants for the hidden effects), Stribeck
friction with exact stick (event-driven, adaptive Dormand-Prince 5(4) with
root-located stick/slip events), LuGre variant with a linearly implicit
Rosenbrock (ode23s-type) integrator, digital PID with ZOH output.
"""
import argparse
import copy
import json
import math
import os
import time

import numpy as np
from scipy import linalg, signal

MM = 1e-3
UM = 1e-6
CAUSES = ['offset', 'asymmetry', 'cogging', 'stribeck', 'viscous', 'mass',
          'delay', 'flexibility', 'reversal', 'dwell']
N_CLEAN = 40
N_PER_CAUSE = 5
MIN_CUT = 0.15
MAX_ATTEMPTS = 8


class Unstable(Exception):
    pass


def clip_step(h, rem):
    """(step, truncated): the proposed step h cut to the remaining interval rem, or to half of it
    when it would leave a sliver (> rem / 2)."""
    if h >= rem:
        return rem, True
    if h > 0.5 * rem:
        return 0.5 * rem, True
    return h, False


def logu(rng, a, b):
    return float(math.exp(rng.uniform(math.log(a), math.log(b))))


# ---------------------------------------------------------------------------
# Dormand-Prince 5(4) tableau
A21 = 1 / 5
A31, A32 = 3 / 40, 9 / 40
A41, A42, A43 = 44 / 45, -56 / 15, 32 / 9
A51, A52, A53, A54 = 19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729
A61, A62, A63, A64, A65 = 9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656
B1, B3, B4, B5, B6 = 35 / 384, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84
E1, E3, E4, E5, E6, E7 = (71 / 57600, -71 / 16695, 71 / 1920, -17253 / 339200,
                          22 / 525, -1 / 40)
EPS_T = 1e-13          # time slack [s] when reaching a segment end
EVENT_TOL = 1e-10      # event location tolerance [s]
# integration tolerances (absolute ones relative to encoder step / velocity scale)
RTOL, ATOL_Q, ATOL_V = 1e-11, 1e-6, 1e-6
RTOL_LG, ATOL_Q_LG, ATOL_V_LG = 1e-12, 1e-8, 1e-8


class EventModel:
    """Piecewise-smooth mechanical model with stick (mode 0) and slip (mode +-1).

    Subclasses provide rhs(y), g(t, y) (event function, event when <= 0),
    on_event(t, y), breakaway(t, y), g_stick(t, y).
    """
    static_stick = True

    def pos(self):
        """The encoder's side: the motor's position [m]."""
        return self.y[0]

    def vel(self):
        return self.y[1]

    def _init_int(self, atol, rtol, dt):
        self.atol = atol
        self.nc = len(atol)
        self.rtol = rtol
        self.h = dt
        self.nsteps = 0
        self.nevents = 0

    def step(self, y, h, k1):
        f = self.rhs
        n = len(y)
        r = range(n)
        k2 = f([y[i] + h * (A21 * k1[i]) for i in r])
        k3 = f([y[i] + h * (A31 * k1[i] + A32 * k2[i]) for i in r])
        k4 = f([y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]) for i in r])
        k5 = f([y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i])
                for i in r])
        k6 = f([y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i]
                            + A65 * k5[i]) for i in r])
        yn = [y[i] + h * (B1 * k1[i] + B3 * k3[i] + B4 * k4[i] + B5 * k5[i]
                          + B6 * k6[i]) for i in r]
        k7 = f(yn)
        s = 0.0
        rt = self.rtol
        at = self.atol
        for i in range(self.nc):
            e = h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i]
                     + E7 * k7[i])
            sc = at[i] + rt * max(abs(y[i]), abs(yn[i]))
            s += (e / sc) ** 2
        return yn, k7, math.sqrt(s / self.nc)

    def locate(self, t, y, k1, h, g0, g1, y1):
        """Find the first time in (t, t+h] where g <= 0 (Illinois / bisection)."""
        lo, glo = 0.0, g0
        hi, ghi, yhi = h, g1, y1
        side = 0
        for _ in range(200):
            if hi - lo <= EVENT_TOL:
                break
            if glo > 0.0 and ghi < 0.0:
                tau = (lo * ghi - hi * glo) / (ghi - glo)
                if not (lo < tau < hi):
                    tau = 0.5 * (lo + hi)
            else:
                tau = 0.5 * (lo + hi)
            ys = self.step(y, tau, k1)[0]
            gs = self.g(t + tau, ys)
            if gs > 0.0:
                lo, glo = tau, gs
                if side == 1:
                    ghi *= 0.5
                side = 1
            else:
                hi, ghi, yhi = tau, gs, ys
                if side == -1:
                    glo *= 0.5
                side = -1
        return hi, yhi

    def advance(self, t0, t1, F):
        """Integrate from t0 to t1 with constant external force F."""
        self.F = F
        t = t0
        y = self.y
        k1 = None
        nev = 0
        while t1 - t > EPS_T:
            if self.mode == 0:
                g0 = self.g_stick(t, y)
                if g0 < 0.0:
                    y = self.breakaway(t, y)
                    k1 = None
                    continue
                if self.static_stick:
                    break
            else:
                g0 = self.g(t, y)
            rem = t1 - t
            h, trunc = clip_step(self.h, rem)
            if k1 is None:
                k1 = self.rhs(y)
            while True:
                yn, k7, en = self.step(y, h, k1)
                self.nsteps += 1
                if en <= 1.0:
                    break
                h *= max(0.1, 0.9 * en ** -0.2)
                trunc = False
                if h < 1e-14:
                    raise Unstable('step size underflow')
            fac = 5.0 if en < 1e-10 else min(5.0, 0.9 * en ** -0.2)
            hn = h * fac
            self.h = max(self.h, hn) if trunc else hn
            g1 = self.g(t + h, yn)
            if g1 <= 0.0:
                tau, ye = self.locate(t, y, k1, h, g0, g1, yn)
                t = t + tau
                y = self.on_event(t, ye)
                k1 = None
                nev += 1
                self.nevents += 1
                if nev > 2000:
                    raise Unstable('event chattering')
            else:
                t += h
                y = yn
                k1 = k7
        self.y = y


def stribeck_shape(v, vs, beta):
    x = abs(v) / vs
    return math.exp(-x * x) if beta == 2 else math.exp(-(x ** beta))


class RigidModel(EventModel):
    """m q'' = F - F_cog(q) - F_fric; exact stick; optional dwell-time static friction."""

    def __init__(self, P, res, dt, energy=False):
        self.m = P['m']
        self.Fcp, self.Fsp, self.bp = P['Fc_p'], P['Fs_p'], P['b_p']
        self.Fcn, self.Fsn, self.bn = P['Fc_n'], P['Fs_n'], P['b_n']
        self.vs, self.beta = P['vs'], P['beta']
        cog = P.get('cog')
        self.cogA = cog['A'] if cog else 0.0
        self.cogk = 2 * math.pi / cog['pitch'] if cog else 0.0
        self.cogphi = cog['phi'] if cog else 0.0
        dw = P.get('dwell')
        self.dwell = dw is not None
        if dw:
            self.dFp, self.dFn, self.dtau = dw['dFs_p'], dw['dFs_n'], dw['tau']
        self.energy = energy
        self.y = [0.0, 0.0, 0.0, 0.0] if energy else [0.0, 0.0]
        self.mode = 0
        self.t_stick = -math.inf
        self.Fs_ep = self.Fsp
        self.F = 0.0
        atol = [ATOL_Q * res, ATOL_V * min(self.vs, res / dt)]
        self._init_int(atol, RTOL, dt)

    def fapp(self, q):
        if self.cogA:
            return self.F - self.cogA * math.sin(self.cogk * q + self.cogphi)
        return self.F

    def thr(self, t):
        if self.dwell:
            rest = t - self.t_stick
            bonus = 1.0 - math.exp(-rest / self.dtau) if rest < math.inf else 1.0
            return self.Fsp + self.dFp * bonus, self.Fsn + self.dFn * bonus
        return self.Fsp, self.Fsn

    def g_stick(self, t, y):
        fa = self.fapp(y[0])
        tp, tn = self.thr(t)
        return min(tp - fa, tn + fa)

    def g(self, t, y):
        return self.mode * y[1]

    def fric(self, v):
        e = stribeck_shape(v, self.vs, self.beta)
        if self.mode > 0:
            return self.Fcp + (self.Fs_ep - self.Fcp) * e + self.bp * v
        return -(self.Fcn + (self.Fs_ep - self.Fcn) * e) + self.bn * v

    def rhs(self, y):
        q, v = y[0], y[1]
        fa = self.fapp(q)
        fr = self.fric(v)
        if self.energy:
            return [v, (fa - fr) / self.m, fa * v, fr * v]
        return [v, (fa - fr) / self.m]

    def breakaway(self, t, y):
        fa = self.fapp(y[0])
        tp, tn = self.thr(t)
        if fa > tp:
            self.mode, self.Fs_ep = 1, tp
        else:
            self.mode, self.Fs_ep = -1, tn
        return y

    def on_event(self, t, y):
        y = list(y)
        y[1] = 0.0
        fa = self.fapp(y[0])
        if -self.Fsn <= fa <= self.Fsp:          # rest time 0 -> static level Fs
            self.mode = 0
            self.t_stick = t
        elif fa > self.Fsp:
            self.mode, self.Fs_ep = 1, self.Fsp
        else:
            self.mode, self.Fs_ep = -1, self.Fsn
        return y


class FlexModel(EventModel):
    """Motor mass m1 (friction, encoder) + load m2 coupled by spring k / damper c."""
    static_stick = False

    def __init__(self, P, res, dt):
        fl = P['flex']
        self.m1, self.m2, self.k, self.c = fl['m1'], fl['m2'], fl['k'], fl['c']
        self.Fc, self.Fs, self.b = P['Fc_p'], P['Fs_p'], P['b_p']
        self.vs, self.beta = P['vs'], P['beta']
        self.y = [0.0, 0.0, 0.0, 0.0]
        self.mode = 0
        self.F = 0.0
        atol = [ATOL_Q * res, ATOL_V * min(self.vs, res / dt), ATOL_Q * res,
                ATOL_V * min(self.vs, res / dt)]
        self._init_int(atol, RTOL, dt)

    def fapp_y(self, y):
        return self.F - self.k * (y[0] - y[2]) - self.c * (y[1] - y[3])

    def g_stick(self, t, y):
        fa = self.fapp_y(y)
        return min(self.Fs - fa, self.Fs + fa)

    def g(self, t, y):
        if self.mode == 0:
            return self.g_stick(t, y)
        return self.mode * y[1]

    def rhs(self, y):
        q1, v1, q2, v2 = y
        if self.mode == 0:
            return [0.0, 0.0, v2, (self.k * (q1 - q2) - self.c * v2) / self.m2]
        fs = self.k * (q1 - q2) + self.c * (v1 - v2)
        e = stribeck_shape(v1, self.vs, self.beta)
        fr = self.mode * (self.Fc + (self.Fs - self.Fc) * e) + self.b * v1
        return [v1, (self.F - fs - fr) / self.m1, v2, fs / self.m2]

    def breakaway(self, t, y):
        self.mode = 1 if self.fapp_y(y) > 0 else -1
        return y

    def on_event(self, t, y):
        y = list(y)
        if self.mode == 0:
            return self.breakaway(t, y)
        y[1] = 0.0
        fa = self.fapp_y(y)
        if -self.Fs <= fa <= self.Fs:
            self.mode = 0
        else:
            self.mode = 1 if fa > 0 else -1
        return y


RD = 1.0 / (2.0 + math.sqrt(2.0))
RE32 = 6.0 + math.sqrt(2.0)


class LuGreModel:
    """LuGre friction, states (q, v, z); Rosenbrock ode23s-type (L-stable) steps."""

    def __init__(self, P, res, dt):
        self.m = P['m']
        self.Fc, self.Fs, self.b = P['Fc_p'], P['Fs_p'], P['b_p']
        self.vs, self.beta = P['vs'], P['beta']
        self.s0, self.s1 = P['lugre']['sigma0'], P['lugre']['sigma1']
        L = self.Fs / self.s0
        self.y = [0.0, 0.0, 0.0]
        self.atol = [ATOL_Q_LG * res, ATOL_V_LG * min(self.vs, res / dt), ATOL_Q_LG * L]
        self.rtol = RTOL_LG
        self.h = dt
        self.F = 0.0
        self.nsteps = 0
        self.nevents = 0
        self.mode = None

    def pos(self):
        return self.y[0]

    def vel(self):
        return self.y[1]

    def gfun(self, v):
        x = abs(v) / self.vs
        if self.beta == 2:
            e = math.exp(-x * x)
            dg = -(self.Fs - self.Fc) * e * 2 * x / self.vs
        else:
            e = math.exp(-x)
            dg = -(self.Fs - self.Fc) * e / self.vs
        return self.Fc + (self.Fs - self.Fc) * e, dg   # dg = dg/d|v|

    def rhs_jac(self, y):
        q, v, z = y
        g, dg = self.gfun(v)
        av = abs(v)
        s0, s1 = self.s0, self.s1
        zd = v - s0 * av * z / g
        Ff = s0 * z + s1 * zd + self.b * v
        a = (self.F - Ff) / self.m
        sg = 1.0 if v > 0 else (-1.0 if v < 0 else 0.0)
        # d(|v|/g)/dv
        dr = sg / g - av * dg * sg / (g * g)
        zd_v = 1.0 - s0 * z * dr
        zd_z = -s0 * av / g
        a_v = -(s1 * zd_v + self.b) / self.m
        a_z = -(s0 + s1 * zd_z) / self.m
        return [v, a, zd], (a_v, a_z, zd_v, zd_z)

    def rhs(self, y):
        q, v, z = y
        g, _ = self.gfun(v)
        zd = v - self.s0 * abs(v) * z / g
        Ff = self.s0 * z + self.s1 * zd + self.b * v
        return [v, (self.F - Ff) / self.m, zd]

    def ros_step(self, y, h):
        f0, (a_v, a_z, zd_v, zd_z) = self.rhs_jac(y)
        hd = h * RD
        A11 = 1.0 - hd * a_v
        A12 = -hd * a_z
        A21_ = -hd * zd_v
        A22 = 1.0 - hd * zd_z
        det = A11 * A22 - A12 * A21_

        def solve(r):
            xv = (r[1] * A22 - A12 * r[2]) / det
            xz = (A11 * r[2] - A21_ * r[1]) / det
            return [r[0] + hd * xv, xv, xz]

        k1 = solve(f0)
        f1 = self.rhs([y[i] + 0.5 * h * k1[i] for i in range(3)])
        k2 = solve([f1[i] - k1[i] for i in range(3)])
        k2 = [k2[i] + k1[i] for i in range(3)]
        yn = [y[i] + h * k2[i] for i in range(3)]
        f2 = self.rhs(yn)
        k3 = solve([f2[i] - RE32 * (k2[i] - f1[i]) - 2.0 * (k1[i] - f0[i])
                    for i in range(3)])
        s = 0.0
        for i in range(3):
            e = h / 6.0 * (k1[i] - 2.0 * k2[i] + k3[i])
            sc = self.atol[i] + self.rtol * max(abs(y[i]), abs(yn[i]))
            s += (e / sc) ** 2
        return yn, math.sqrt(s / 3.0)

    def advance(self, t0, t1, F):
        self.F = F
        t = t0
        y = self.y
        while t1 - t > EPS_T:
            rem = t1 - t
            h, trunc = clip_step(self.h, rem)
            while True:
                yn, en = self.ros_step(y, h)
                self.nsteps += 1
                if en <= 1.0:
                    break
                h *= max(0.1, 0.9 * en ** (-1 / 3))
                trunc = False
                if h < 1e-15:
                    raise Unstable('lugre step underflow')
            fac = 5.0 if en < 1e-10 else min(5.0, 0.9 * en ** (-1 / 3))
            hn = h * fac
            self.h = max(self.h, hn) if trunc else hn
            t += h
            y = yn
        self.y = y


def build_model(P, res, dt, energy=False):
    if P['kind'] == 'lugre':
        return LuGreModel(P, res, dt)
    if P['kind'] == 'flex':
        return FlexModel(P, res, dt)
    return RigidModel(P, res, dt, energy)


# ---------------------------------------------------------------------------
def pid_replay(qm, qref, dt, C):
    """Vectorised (independent) implementation of the PID law, for checks."""
    e = qm - qref
    I = dt * np.cumsum(e)
    de = np.diff(e, prepend=e[0])
    tf = C['tau_f']
    D = signal.lfilter([1.0 / (tf + dt)], [1.0, -tf / (tf + dt)], de)
    u = -(C['kp'] * e + C['kd'] * D + C['ki'] * I)
    if C.get('saturation'):
        u = np.clip(u, -C['saturation'], C['saturation'])
    return u


def simulate(P, C, res, qref, dt, sensor_noise=None, act_noise=None, log=False,
             energy=False, qlimit=None):
    """Closed-loop simulation. Returns dict(q=measured, u=applied controller output)."""
    model = build_model(P, res, dt, energy)
    N = len(qref)
    kp, kd, ki, tf = C['kp'], C['kd'], C['ki'], C['tau_f']
    umax = C.get('saturation')
    cm, off = P['cm'], P['offset']
    delay = P['delay']
    nd = int(math.floor(delay / dt + 1e-12))
    r = delay - nd * dt
    if r < 1e-12:
        r = 0.0
    qref_l = qref.tolist()
    sn = sensor_noise.tolist() if sensor_noise is not None else None
    an = act_noise.tolist() if act_noise is not None else None
    qm = [0.0] * N
    ul = [0.0] * N
    if log:
        qt = np.zeros(N)
        vt = np.zeros(N)
        md = np.zeros(N, dtype=int)
        fa = np.zeros(N)
        thr = np.zeros((N, 2))
        en = np.zeros((N, 2))
    I = 0.0
    D = 0.0
    e_prev = 0.0
    if qlimit is None:
        qlimit = 1.0
    for k in range(N):
        t = k * dt
        x = model.pos()
        if log:
            qt[k] = x
            vt[k] = model.vel()
            md[k] = model.mode if model.mode is not None else 9
            if isinstance(model, RigidModel):
                # force acting just before t_k (last segment of previous interval)
                fa[k] = model.fapp(x)
                thr[k] = model.thr(t)
                if energy:
                    en[k] = model.y[2:4]
        if abs(x) > qlimit or x != x:
            raise Unstable('position diverged')
        if sn is not None:
            x += sn[k]
        q_k = res * math.floor(x / res + 0.5)
        qm[k] = q_k
        e = q_k - qref_l[k]
        if k == 0:
            e_prev = e
        I += dt * e
        D = (tf * D + (e - e_prev)) / (tf + dt)
        e_prev = e
        u = -(kp * e + kd * D + ki * I)
        if umax is not None:
            if u > umax:
                u = umax
            elif u < -umax:
                u = -umax
        ul[k] = u
        w = (an[k] if an is not None else 0.0) - off
        t1 = (k + 1) * dt
        if nd == 0 and r == 0.0:
            model.advance(t, t1, cm * u + w)
        else:
            ua = ul[k - nd - 1] if k - nd - 1 >= 0 else 0.0
            ub = ul[k - nd] if k - nd >= 0 else 0.0
            if r > 0.0:
                model.advance(t, t + r, cm * ua + w)
                model.advance(t + r, t1, cm * ub + w)
            else:
                model.advance(t, t1, cm * ub + w)
    out = dict(q=np.array(qm), u=np.array(ul), nsteps=model.nsteps,
               nevents=model.nevents)
    if log:
        out.update(q_true=qt, v_true=vt, mode=md, fapp=fa, thr=thr, energy=en, model=model)
    return out


# ---------------------------------------------------------------------------
# Linear closed-loop check (friction replaced by its viscous part)
def closed_loop_poles(P, C, dt):
    cm = P['cm']
    b = min(P['b_p'], P['b_n'])
    if P['kind'] == 'flex':
        fl = P['flex']
        m1, m2, k, c = fl['m1'], fl['m2'], fl['k'], fl['c']
        A = np.array([[0, 1, 0, 0], [-k / m1, -(b + c) / m1, k / m1, c / m1],
                      [0, 0, 0, 1], [k / m2, c / m2, -k / m2, -c / m2]], float)
        B = np.array([0, cm / m1, 0, 0], float)
    else:
        m = P['m']
        A = np.array([[0, 1], [0, -b / m]], float)
        B = np.array([0, cm / m], float)
    n = A.shape[0]
    Cq = np.zeros(n)
    Cq[0] = 1.0

    def phigam(tau):
        M = np.zeros((n + 1, n + 1))
        M[:n, :n] = A * tau
        M[:n, n] = B * tau
        E = linalg.expm(M)
        return E[:n, :n], E[:n, n]

    delay = P['delay']
    nd = int(math.floor(delay / dt + 1e-12))
    r = delay - nd * dt
    if r < 1e-12:
        r = 0.0
    Phi, _ = phigam(dt)
    if r > 0:
        Pr, Gr = phigam(r)
        Pd, Gd = phigam(dt - r)
        Ga = Pd @ Gr
        Gb = Gd
    else:
        Ga = np.zeros(n)
        Gb = phigam(dt)[1]
    nb = nd + 1
    # X = [x(n), I_{k-1}, D_{k-1}, e_{k-1}, u_{k-1} .. u_{k-nb}]
    NX = n + 3 + nb
    iI, iD, iE, iU = n, n + 1, n + 2, n + 3
    erow = np.zeros(NX)
    erow[:n] = Cq
    Irow = dt * erow.copy()
    Irow[iI] += 1
    tf = C['tau_f']
    al, be = tf / (tf + dt), 1.0 / (tf + dt)
    Drow = be * erow.copy()
    Drow[iD] += al
    Drow[iE] -= be
    L = -(C['kp'] * erow + C['kd'] * Drow + C['ki'] * Irow)

    def ulag(j):
        if j == 0:
            return L
        v = np.zeros(NX)
        v[iU + j - 1] = 1.0
        return v

    M = np.zeros((NX, NX))
    M[:n, :n] = Phi
    M[:n, :] += np.outer(Ga, ulag(nd + 1)) + np.outer(Gb, ulag(nd))
    M[iI] = Irow
    M[iD] = Drow
    M[iE] = erow
    M[iU] = L
    for j in range(1, nb):
        M[iU + j, iU + j - 1] = 1.0
    lam = np.linalg.eigvals(M)
    rho = float(np.max(np.abs(lam)))
    zs = []
    for l in lam:
        if abs(l) < 1e-8 or abs(l - 1) < 1e-12:
            continue
        s = np.log(l) / dt
        zs.append(-s.real / abs(s))
    return rho, (min(zs) if zs else 1.0)


# ---------------------------------------------------------------------------
# Reference programmes
def make_programme(rng, T, dt, wn, amax, kinds=None, min_range=0.0, need_rests=False,
                   unidirectional=False, amp=None):
    N = int(round(T / dt))
    for _try in range(50):
        A = amp if amp is not None else logu(rng, 0.5 * MM, 50 * MM)
        A = max(A, 0.6 * min_range)
        vlo = max(1 * MM, A / (T / 6))
        vhi = min(200 * MM, A / 0.05)
        V = logu(rng, vlo, max(vhi, vlo * 1.01))
        # acceleration phase length from the acceleration limit (cascaded moving averages
        # of lengths Ta, Tj turn the piecewise-linear path into a jerk-limited profile)
        Ta = min(max(V / amax, 0.01), 0.4)
        V = max(min(V, amax * Ta), 1.0 * MM)
        Tj = Ta * rng.uniform(0.2, 0.6)
        smooth = Ta + Tj
        if kinds is None:
            allk = ['p2p', 'tri', 'sine']
            nk = rng.integers(1, 4)
            ks = [str(x) for x in rng.choice(allk, size=nk, replace=False)]
        else:
            ks = list(kinds)
        if need_rests and 'p2p' not in ks:
            ks.append('p2p')
        if unidirectional:
            ks = ['p2p']
        parts = [np.zeros(int(rng.uniform(0.1, 0.3) / dt))]
        total = len(parts[0])
        pos = 0.0
        kinds_used = []
        first = True
        while total < N + int(smooth / dt) + 2:
            kind = 'p2p' if (need_rests and first) else ks[rng.integers(len(ks))]
            first = False
            kinds_used.append(kind)
            if kind == 'p2p':
                for _ in range(int(rng.integers(2, 6))):
                    if unidirectional:
                        tgt = pos + A * rng.uniform(0.2, 0.6)
                    elif abs(pos) > 0.3 * A:
                        tgt = -math.copysign(1.0, pos) * A * rng.uniform(0.2, 1.0)
                    else:
                        tgt = (1 if rng.random() < 0.5 else -1) * A * rng.uniform(0.3, 1.0)
                    v = V * rng.uniform(0.4, 1.0)
                    n = max(1, int(abs(tgt - pos) / v / dt))
                    parts.append(pos + (tgt - pos) * np.arange(1, n + 1) / n)
                    pos = tgt
                    dwell = logu(rng, 0.1, 2.0) + smooth
                    parts.append(np.full(int(dwell / dt), pos))
                    total += n + int(dwell / dt)
            elif kind == 'tri':
                a = A * rng.uniform(0.3, 1.0)
                v = max(1 * MM, V * logu(rng, 0.02, 0.5))
                c = pos
                seq = []
                nrev = int(rng.integers(2, 7))
                d0 = 1 if rng.random() < 0.5 else -1
                pts = [c + d0 * a]
                for i in range(nrev):
                    pts.append(c - (-1) ** i * d0 * a)
                pts.append(c)
                dw = rng.random() < 0.3
                for p_ in pts:
                    n = max(1, int(abs(p_ - pos) / v / dt))
                    seq.append(pos + (p_ - pos) * np.arange(1, n + 1) / n)
                    pos = p_
                    if dw:
                        seq.append(np.full(int(logu(rng, 0.05, 0.5) / dt), pos))
                seq.append(np.full(int((logu(rng, 0.1, 1.0) + smooth) / dt), pos))
                seg = np.concatenate(seq)
                parts.append(seg)
                total += len(seg)
            else:  # sine
                a = A * rng.uniform(0.3, 1.0)
                v = V * rng.uniform(0.3, 1.0)
                f = v / (2 * math.pi * a)
                f = min(max(f, 0.2), 5.0, wn / (2 * math.pi) / 4,
                        math.sqrt(amax / a) / (2 * math.pi))
                a = min(a, amax / (2 * math.pi * f) ** 2)
                ncyc = int(rng.integers(2, 7))
                n = int(ncyc / f / dt)
                tt = np.arange(1, n + 1) * dt
                Tc = 1.0 / f
                w = np.ones(n)
                up = tt < Tc
                w[up] = 0.5 - 0.5 * np.cos(math.pi * tt[up] / Tc)
                dn = tt > (n * dt - Tc)
                w[dn] = 0.5 - 0.5 * np.cos(math.pi * (n * dt - tt[dn]) / Tc)
                seg = pos + a * np.sin(2 * math.pi * f * tt) * w
                seg[-1] = pos
                parts.append(seg)
                parts.append(np.full(int((logu(rng, 0.1, 1.0) + smooth) / dt), pos))
                total += n + len(parts[-1])
        raw = np.concatenate(parts)[:N]
        na = max(1, int(round(Ta / dt)))
        nj = max(1, int(round(Tj / dt)))
        y = signal.lfilter(np.ones(na) / na, [1.0], raw)
        y = signal.lfilter(np.ones(nj) / nj, [1.0], y)
        y[0] = 0.0
        rng_ok = (y.max() - y.min()) >= min_range
        vel = np.diff(y) / dt
        both = (vel.max() > 0.5 * MM) and (vel.min() < -0.5 * MM)
        rests_ok = (not need_rests) or len([r_ for r_ in rest_stats(y, dt) if r_ >= 0.1]) >= 3
        if rng_ok and rests_ok and (both or unidirectional):
            info = dict(amplitude=A, speed=V, amax=amax, kinds=sorted(set(kinds_used)),
                        smoothing=[Ta, Tj], unidirectional=bool(unidirectional))
            return y, info
    raise RuntimeError('could not build programme')


def rest_stats(qref, dt):
    """lengths of rest phases (reference constant) in s."""
    still = np.abs(np.diff(qref)) < 1e-15
    out = []
    n = 0
    for s in still:
        if s:
            n += 1
        elif n:
            out.append(n * dt)
            n = 0
    if n:
        out.append(n * dt)
    return [x for x in out if x >= 0.05]


# ---------------------------------------------------------------------------
def nominal_spec(nom):
    return dict(kind='rigid', m=nom['m'], cm=nom['cm'], offset=0.0,
                Fc_p=nom['Fc'], Fs_p=nom['Fs'], b_p=nom['b'],
                Fc_n=nom['Fc'], Fs_n=nom['Fs'], b_n=nom['b'],
                vs=nom['vs'], beta=nom['beta'], cog=None, dwell=None, delay=0.0)


def draw_controller(rng, m, cm, dt, wn=None):
    if wn is None:
        hi = min(30.0, 0.15 / dt / (2 * math.pi))
        wn = 2 * math.pi * logu(rng, 5.0, hi)
    zeta = rng.uniform(0.5, 1.0)
    kp = m * wn ** 2 / cm
    kd = 2 * zeta * m * wn / cm
    ki = kp * wn / rng.uniform(3, 10)
    tau_f = 0.0 if rng.random() < 0.5 else 1.0 / (wn * rng.uniform(5, 20))
    return dict(type='pid', kp=kp, kd=kd, ki=ki, tau_f=tau_f), dict(wn=wn, zeta=zeta)


def draw_effect(rng, cause, nom, P, dt, res, pre):
    """Return truth spec and params dict."""
    T = copy.deepcopy(P)
    Fc, Fs, b = nom['Fc'], nom['Fs'], nom['b']
    prm = {}
    if cause == 'offset':
        off = (1 if rng.random() < 0.5 else -1) * rng.uniform(0.05, 0.3) * Fc
        T['offset'] = off
        prm = dict(offset=off)
    elif cause == 'asymmetry':
        var = rng.choice(['coulomb', 'viscous', 'both']) if b > 0.5 * Fc / 0.1 else 'coulomb'
        fc_f = b_f = 1.0
        if var in ('coulomb', 'both'):
            fc_f = 1 + (1 if rng.random() < 0.5 else -1) * rng.uniform(0.15, 0.5)
        if var in ('viscous', 'both'):
            b_f = 1 + (1 if rng.random() < 0.5 else -1) * rng.uniform(0.3, 1.0)
        T['Fc_n'] = Fc * fc_f
        T['Fs_n'] = Fs * fc_f
        T['b_n'] = b * b_f
        prm = dict(variant=str(var), Fc_neg=T['Fc_n'], Fs_neg=T['Fs_n'], b_neg=T['b_n'],
                   Fc_pos=Fc, Fs_pos=Fs, b_pos=b, Fc_neg_factor=fc_f, b_neg_factor=b_f)
    elif cause == 'cogging':
        A = rng.uniform(0.05, 0.3) * Fc
        T['cog'] = dict(A=A, pitch=pre['pitch'], phi=rng.uniform(0, 2 * math.pi))
        prm = dict(T['cog'])
        prm['law'] = 'F_cog = A*sin(2*pi*q/pitch + phi), enters as -F_cog in m q\'\''
    elif cause == 'stribeck':
        var = rng.choice(['bump', 'vs', 'both'])
        bf = vf = 1.0
        if var in ('bump', 'both'):
            bf = rng.uniform(1.5, 3.0) if rng.random() < 0.5 else rng.uniform(0.3, 0.6)
        if var in ('vs', 'both'):
            vf = logu(rng, 1.4, 2.5) if rng.random() < 0.5 else logu(rng, 0.4, 0.7)
        Fs_t = Fc + (Fs - Fc) * bf
        T['Fs_p'] = T['Fs_n'] = Fs_t
        T['vs'] = nom['vs'] * vf
        prm = dict(variant=str(var), Fs=Fs_t, vs=T['vs'], bump_factor=bf, vs_factor=vf)
    elif cause == 'viscous':
        if b < 0.3 * Fc / 0.1:
            bt = b + rng.uniform(0.2, 1.0) * Fc / 0.1
            var = 'additive'
        else:
            bt = b * rng.uniform(1.5, 3.0)
            var = 'factor'
        T['b_p'] = T['b_n'] = bt
        prm = dict(b=bt, variant=var, factor=bt / b if b > 0 else None)
    elif cause == 'mass':
        f = rng.uniform(1.2, 1.6) if rng.random() < 0.5 else rng.uniform(0.65, 0.85)
        T['m'] = nom['m'] * f
        prm = dict(mass=T['m'], factor=f)
    elif cause == 'delay':
        T['delay'] = pre['delay']
        prm = dict(delay=pre['delay'], delay_samples=pre['delay'] / dt)
    elif cause == 'flexibility':
        m = nom['m']
        frac = rng.uniform(0.2, 0.6)
        f_res = pre['f_res']
        zeta = rng.uniform(0.02, 0.1)
        m2 = frac * m
        m1 = m - m2
        k = m2 * (2 * math.pi * f_res) ** 2
        c = 2 * zeta * math.sqrt(k * m2)
        T['kind'] = 'flex'
        T['flex'] = dict(m1=m1, m2=m2, k=k, c=c)
        prm = dict(m1=m1, m2=m2, k=k, c=c, f_res=f_res, zeta=zeta, load_fraction=frac,
                   note='friction on motor side; encoder on motor side')
    elif cause == 'reversal':
        Lmin = max(2 * UM, 3 * res)
        L = logu(rng, Lmin, max(50 * UM, 1.01 * Lmin))
        s0 = Fs / L
        zeta = rng.uniform(0.3, 1.0)
        s1 = 2 * zeta * math.sqrt(s0 * nom['m'])
        T['kind'] = 'lugre'
        T['lugre'] = dict(sigma0=s0, sigma1=s1)
        prm = dict(law='LuGre', sigma0=s0, sigma1=s1, slip_length=L, zeta=zeta,
                   Fc=Fc, Fs=Fs, vs=nom['vs'], beta=nom['beta'], b=b, z0=0.0)
    elif cause == 'dwell':
        fr = rng.uniform(0.2, 0.8)
        tau = logu(rng, 0.05, 1.0)
        T['dwell'] = dict(dFs_p=fr * Fs, dFs_n=fr * Fs, tau=tau)
        prm = dict(dFs=fr * Fs, dFs_fraction=fr, tau=tau, initial_rest='infinite',
                   law='break-away threshold Fs+dFs*(1-exp(-t_rest/tau)); the Stribeck '
                       'peak of the following slip episode equals that threshold')
    return T, prm


def noise_arrays(rng, N, dt, sens_std, act):
    sn = rng.normal(0.0, sens_std, N) if sens_std else None
    an = None
    if act:
        wn_ = rng.normal(0.0, 1.0, N)
        if act['tau'] > 0:
            a = math.exp(-dt / act['tau'])
            an = signal.lfilter([math.sqrt(1 - a * a)], [1.0, -a], wn_)
            an[0] = wn_[0]
            an = an * act['std']
        else:
            an = act['std'] * wn_
    return sn, an


def rms(x):
    return float(np.sqrt(np.mean(np.square(x))))


def build_record(seed, idx, cause, attempt, do_rms):
    rng = np.random.default_rng([seed, idx, attempt, 12345])
    fs = logu(rng, 500, 5000)
    dt = 1.0 / fs
    pre = {}
    wn = None
    min_range = 0.0
    wn_hi = min(2 * math.pi * 30, 0.15 / dt)
    # plant mass, Coulomb level and loop bandwidth drawn jointly (rejection sampling) so
    # that the servo stiffness m*wn^2 suits the friction: x = Fc/(m*wn^2), the
    # friction-induced position error before integral action, is 2..100 um
    for _ in range(100000):
        m = logu(rng, 0.5, 20)
        Fc = logu(rng, 1.0, 50.0)
        x = logu(rng, 2e-6, 100e-6)
        wn = math.sqrt(Fc / (m * x))
        if not (2 * math.pi * 5 <= wn <= wn_hi):
            continue
        if cause == 'delay':
            d = rng.uniform(0.12, 0.35) / wn
            if not (max(0.5e-3, dt) <= d <= 5e-3):
                continue
            pre['delay'] = d
        break
    else:
        raise Unstable('no parameter draw')
    nom = dict(m=m, cm=logu(rng, 1, 10), Fc=Fc)
    nom['Fs'] = nom['Fc'] * rng.uniform(1.1, 1.6)
    nom['vs'] = logu(rng, 0.5e-3, 20e-3)
    nom['beta'] = 2 if rng.random() < 0.75 else 1
    nom['b'] = nom['Fc'] / 0.1 * (rng.uniform(0, 5) if rng.random() < 0.7 else
                                  rng.uniform(0, 0.3))
    res = logu(rng, 0.05 * UM, 5 * UM)
    sens_std = rng.uniform(0.2, 1.0) * res if rng.random() < 0.35 else None
    Tlen = logu(rng, 5, 20)
    P = nominal_spec(nom)
    if cause == 'flexibility':
        pre['f_res'] = logu(rng, 15, 60)
    if cause == 'cogging':
        pre['pitch'] = logu(rng, 1 * MM, 20 * MM)
        min_range = 2.2 * pre['pitch']
    # controller (nominal design), check linear closed loop
    for _ in range(50):
        C, cinfo = draw_controller(rng, nom['m'], nom['cm'], dt, wn)
        rho, zmin = closed_loop_poles(P, C, dt)
        if rho < 1 and zmin >= 0.25:
            break
    else:
        raise Unstable('nominal loop')
    # truth
    for _ in range(30):
        if cause is None:
            Ptrue, prm = copy.deepcopy(P), {}
        else:
            Ptrue, prm = draw_effect(rng, cause, nom, P, dt, res, pre)
        if Ptrue['kind'] == 'lugre':
            break
        rho_t, zmin_t = closed_loop_poles(Ptrue, C, dt)
        if rho_t < 1 and zmin_t >= 0.01:
            break
    else:
        raise Unstable('truth loop')
    # programmes
    uni = [False, False]
    if cause not in ('asymmetry', 'offset', 'dwell') and rng.random() < 0.1:
        uni[int(rng.integers(2))] = True
    progs = []
    for j in range(2):
        amax = min(max(nom['Fc'] / nom['m'] * logu(rng, 0.5, 5.0), 0.05), 10.0)
        qref, pinfo = make_programme(rng, Tlen, dt, cinfo['wn'], amax, min_range=min_range,
                                     need_rests=(cause == 'dwell'), unidirectional=uni[j])
        progs.append((qref, pinfo))
    want_sat = rng.random() < 0.2
    # unmodelled actuator noise
    act = None
    if rng.random() < 0.5:
        act = dict(std=rng.uniform(0.01, 0.05) * nom['Fc'],
                   tau=0.0 if rng.random() < 0.5 else logu(rng, 0.002, 0.05))
    out = dict(nom=nom, P=P, Ptrue=Ptrue, prm=prm, C=C, cinfo=cinfo, dt=dt, res=res,
               sens_std=sens_std, act=act, exps={}, rms_nom={}, rms_true={})
    noises = []
    for j in range(2):
        nrng = np.random.default_rng([seed, idx, attempt, j, 777])
        noises.append(noise_arrays(nrng, len(progs[j][0]), dt, sens_std, act))
    if want_sat:
        # saturation level set just above the 99.8 % quantile of |u| of an unsaturated run,
        # so that it is reached rarely
        uabs = []
        for j in range(2):
            qref = progs[j][0]
            sim = simulate(Ptrue, C, res, qref, dt, noises[j][0], noises[j][1],
                           qlimit=10 * (np.max(np.abs(qref)) + 0.01))
            uabs.append(np.abs(sim['u']))
        C['saturation'] = float(np.quantile(np.concatenate(uabs), 0.998)) * rng.uniform(1.0, 1.25)
    for j, name in enumerate(['fit', 'val']):
        qref, pinfo = progs[j]
        N = len(qref)
        sn, an = noises[j]
        qlim = 10 * (np.max(np.abs(qref)) + 0.01)
        sim = simulate(Ptrue, C, res, qref, dt, sn, an, qlimit=qlim)
        sat = float(np.mean(np.abs(sim['u']) >= C['saturation'])) if C.get('saturation') else 0.0
        out['exps'][name] = dict(t=np.arange(N) * dt, q=sim['q'], u=sim['u'], q_ref=qref,
                                 info=pinfo, sat=sat, nsteps=sim['nsteps'],
                                 nevents=sim['nevents'])
        if do_rms:
            s_nom = simulate(P, C, res, qref, dt, qlimit=qlim)
            out['rms_nom'][name] = rms(s_nom['q'] - sim['q'])
            if cause is None:
                out['rms_true'][name] = out['rms_nom'][name]
            else:
                s_tr = simulate(Ptrue, C, res, qref, dt, qlimit=qlim)
                out['rms_true'][name] = rms(s_tr['q'] - sim['q'])
    return out


def to_model_json(nom, C, res, sens_std):
    ctrl = dict(type='pid', kp=C['kp'], kd=C['kd'], ki=C['ki'], tau_f=C['tau_f'])
    if C.get('saturation'):
        ctrl['saturation'] = C['saturation']
    sensor = dict(resolution=res)
    if sens_std:
        sensor['noise'] = sens_std
    return {"plant": {"mass": nom['m'], "motor_constant": nom['cm'], "offset": 0.0},
            "friction": {"law": "stribeck", "Fc": nom['Fc'], "Fs": nom['Fs'], "vs": nom['vs'],
                         "beta": float(nom['beta']), "b": nom['b']},
            "controller": ctrl, "sensor": sensor}


def write_record(d, rec, cause, attempts, cut):
    os.makedirs(d, exist_ok=True)
    for name, ex in rec['exps'].items():
        np.savez(os.path.join(d, name + '.npz'), t=ex['t'].astype(np.float64),
                 q=ex['q'].astype(np.float64), u=ex['u'].astype(np.float64),
                 q_ref=ex['q_ref'].astype(np.float64))
    with open(os.path.join(d, 'model.json'), 'w') as f:
        json.dump(to_model_json(rec['nom'], rec['C'], rec['res'], rec['sens_std']), f, indent=1)
    notes = []
    if cause is None:
        notes.append('clean: the machine equals model.json apart from noise')
    else:
        notes.append(f'single hidden effect: {cause}')
    if rec['act']:
        a = rec['act']
        notes.append('unmodelled actuator force noise std %.3g N (%s)' % (
            a['std'], 'white, ZOH per sample' if a['tau'] == 0 else
            'first-order low-pass tau=%.3g s, ZOH per sample' % a['tau']))
    for name in ('fit', 'val'):
        ex = rec['exps'][name]
        notes.append('%s programme: %s, amplitude %.3g mm, speed %.3g mm/s%s' % (
            name, '+'.join(ex['info']['kinds']), ex['info']['amplitude'] * 1e3,
            ex['info']['speed'] * 1e3, ', unidirectional' if ex['info']['unidirectional'] else ''))
        if ex['sat'] > 0:
            notes.append('%s: saturated in %.2g %% of samples' % (name, 100 * ex['sat']))
    if cut is not None and cut < MIN_CUT:
        notes.append('WARNING: validation error cut %.3f below %.2f after %d attempts' % (
            cut, MIN_CUT, attempts))
    truth = {"clean": cause is None, "causes": [] if cause is None else [cause],
             "params": rec['prm'], "notes": '; '.join(notes),
             "actuator_noise": rec['act'],
             "position_rms_nominal": rec['rms_nom'], "position_rms_truth": rec['rms_true'],
             "val_error_cut": cut, "attempts": attempts,
             "controller_design": rec['cinfo'],
             "saturation_fraction": {k: rec['exps'][k]['sat'] for k in ('fit', 'val')}}
    with open(os.path.join(d, 'truth.json'), 'w') as f:
        json.dump(truth, f, indent=1, default=float)


def generate_one(seed, idx, cause, do_rms_clean=True):
    best = None
    for attempt in range(MAX_ATTEMPTS):
        try:
            rec = build_record(seed, idx, cause, attempt, do_rms=(cause is not None or do_rms_clean))
        except Unstable as exc:
            print(f'  d{idx:04d} attempt {attempt}: unstable ({exc}), redraw', flush=True)
            continue
        if cause is None:
            return rec, attempt + 1, None
        rn, rt = rec['rms_nom']['val'], rec['rms_true']['val']
        cut = 1.0 - rt / rn if rn > 0 else 0.0
        if best is None or cut > best[2]:
            best = (rec, attempt + 1, cut)
        if cut >= MIN_CUT:
            return rec, attempt + 1, cut
        print(f'  d{idx:04d} {cause} attempt {attempt}: cut {cut:.3f} too small, redraw',
              flush=True)
    if best is None:
        raise RuntimeError(f'record {idx} failed')
    return best


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('outdir')
    ap.add_argument('--seed', type=int, required=True)
    ap.add_argument('--only', type=str, default=None, help='comma list of record indices')
    args = ap.parse_args()
    rng = np.random.default_rng([args.seed, 999999])
    causes = [c for c in CAUSES for _ in range(N_PER_CAUSE)]
    perm = rng.permutation(len(causes))
    assign = [None] * N_CLEAN + [causes[i] for i in perm]
    only = set(int(x) for x in args.only.split(',')) if args.only else None
    os.makedirs(args.outdir, exist_ok=True)
    t0 = time.time()
    summary = []
    for idx, cause in enumerate(assign):
        if only is not None and idx not in only:
            continue
        t1 = time.time()
        rec, att, cut = generate_one(args.seed, idx, cause)
        write_record(os.path.join(args.outdir, f'd{idx:04d}'), rec, cause, att, cut)
        ns = sum(e['nsteps'] for e in rec['exps'].values())
        n = sum(len(e['t']) for e in rec['exps'].values())
        print(f'd{idx:04d} {str(cause):12s} N={n:6d} steps={ns:7d} att={att} '
              f'cut={"-" if cut is None else "%.3f" % cut} rms_nom_val={rec["rms_nom"].get("val", float("nan")):.3g} '
              f'{time.time() - t1:.1f}s', flush=True)
        summary.append(dict(idx=idx, cause=cause, cut=cut, attempts=att))
    with open(os.path.join(args.outdir, 'summary.json'), 'w') as f:
        json.dump(dict(seed=args.seed, records=summary, seconds=time.time() - t0), f, indent=1)
    print(f'total {time.time() - t0:.1f}s')


if __name__ == '__main__':
    main()
