"""Synthetic "measured" data with hidden effects, for tests that call the diagnosis blind.

The true plant: m q'' = cm u(t - delay) + f_ext - F(q') - offset - F_cog(q), with Coulomb +
viscous friction per direction (Fc+-, b+-; Coulomb regularized over 1e-4 m/s, far below the
speeds used), F_cog = A sin(2 pi q / pitch); a 1 kHz PD position-velocity loop like the EMPS
benchmark (u = kv (kp (q_ref - q) - v_f), v_f a backward difference of a 2-tap averaged
position, saturation at 10 V) tracks bang-bang strokes; the encoder quantizes q."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np

from .data import Measurement


@dataclass(frozen=True)
class TruePlant:
    """Parameters of the true plant and of the experiment (SI units)."""

    mass: float = 95.0
    cm: float = 35.15
    Fc_pos: float = 20.0
    Fc_neg: float = 20.0
    b_pos: float = 200.0
    b_neg: float = 200.0
    offset: float = 0.0
    cog_amplitude: float = 0.0
    cog_pitch: float = 0.01
    delay: float = 0.0
    kp: float = 160.0
    kv: float = 243.0
    fs: float = 1000.0
    resolution: float = 1e-6
    force_noise: float = 0.5
    extra: dict = field(default_factory=dict)


@numba.njit(cache=True)
def _accel(q, v, ua, f_noise, par):
    m, cm, fcp, fcn, bp, bn, off, ca, cp = par[0], par[1], par[2], par[3], par[4], par[5], par[6], par[7], par[8]
    fc = fcp if v >= 0 else fcn
    b = bp if v >= 0 else bn
    F = fc * math.tanh(v / 1e-4) + b * v + off + ca * math.sin(2 * math.pi * q / cp) - f_noise
    return (cm * ua - F) / m


@numba.njit(cache=True)
def _simulate(par, r, noise, n_delay, sub, out_q, out_u):
    kp, kv, dt, res = par[9], par[10], par[11], par[12]
    q, v = r[0], 0.0
    u_hist = np.zeros(n_delay + 1)
    qf_prev = q
    y_prev = q
    h = dt / sub
    for k in range(r.size):
        y = res * math.floor(q / res + 0.5) if res > 0 else q
        qf = 0.5 * y + 0.5 * y_prev
        vf = (qf - qf_prev) / dt
        qf_prev = qf
        y_prev = y
        u = kv * (kp * (r[k] - y) - vf)
        u = min(max(u, -10.0), 10.0)
        out_q[k] = y
        out_u[k] = u
        for j in range(n_delay, 0, -1):
            u_hist[j] = u_hist[j - 1]
        u_hist[0] = u
        ua = u_hist[n_delay]
        for _ in range(sub):                      # midpoint rule
            a1 = _accel(q, v, ua, noise[k], par)
            qm = q + 0.5 * h * v
            vm = v + 0.5 * h * a1
            a2 = _accel(qm, vm, ua, noise[k], par)
            q += h * vm
            v += h * a2


def bang_bang(fs: float, duration: float, stroke: float = 0.2, seed: int = 0) -> np.ndarray:
    """Reference: strokes of random length (30-100 % of ``stroke``) with bang-bang acceleration
    profiles and random peak speeds, dwelling 0.2 s between them."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration, 1.0 / fs)
    r = np.zeros_like(t)
    pos, k = 0.0, 0
    while k < t.size:
        L = stroke * rng.uniform(0.3, 1.0)
        target = L if pos < stroke / 2 else 0.0
        if abs(target - pos) < 1e-3:
            target = stroke - pos
        D = target - pos
        T = max(abs(D) / rng.uniform(0.05, 0.15) * 2.0, 0.2)
        n = int(T * fs)
        s = np.linspace(0, 1, n)
        prof = np.where(s < 0.5, 2 * s ** 2, 1 - 2 * (1 - s) ** 2)
        seg = pos + D * prof
        r[k:k + n] = seg[: max(0, min(n, t.size - k))]
        k += n
        pos = target
        nd = int(0.2 * fs)
        r[k:k + nd] = pos
        k += nd
    return r


def generate(true: TruePlant, duration: float = 20.0, seed: int = 0, substeps: int = 10) -> Measurement:
    """A run of the true plant tracking bang-bang strokes; q quantized, u recorded."""
    r = bang_bang(true.fs, duration, seed=seed)
    rng = np.random.default_rng(seed + 1)
    noise = rng.normal(0.0, true.force_noise, r.size)
    par = np.array([true.mass, true.cm, true.Fc_pos, true.Fc_neg, true.b_pos, true.b_neg, true.offset,
                    true.cog_amplitude, true.cog_pitch, true.kp, true.kv, 1.0 / true.fs, true.resolution])
    q, u = np.empty(r.size), np.empty(r.size)
    _simulate(par, r, noise, int(round(true.delay * true.fs)), substeps, q, u)
    t = np.arange(r.size) / true.fs
    return Measurement(t, q, u, q_ref=r, name=f"synthetic(seed={seed})")
