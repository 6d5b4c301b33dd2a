"""Synthetic "measured" data with hidden effects, for tests that call the diagnosis blind.

The true plant: m q'' = cm u(t - delay) + f_ext - F(q') - offset - F_cog(q), with Coulomb +
viscous friction per direction (Fc+-, b+-; exact stick, or LuGre with bristle stiffness sigma0),
optionally a Stribeck level (Fs, vs)
with frictional memory (lag) and a dwell-time growth of the break-away force,
F_cog = A sin(2 pi q / pitch), a random force disturbance; a 1 kHz PD position-velocity loop like
the EMPS benchmark (u = kv (kp (q_ref - q) - v_f), v_f a backward difference of a 2-tap averaged
position, saturation at ``saturation`` V, optionally a DAC step) tracks bang-bang strokes with
rests between them; the encoder quantizes q. The loop is simulated by
:func:`hunting.diagnose.resimulate.resimulate` (the same sampled-loop engine as the behaviour view).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..models.friction import DirectionalCurve, StribeckCurve
from ..models.plant import Cogging
from .causes.presliding import bristle_damping
from .data import Measurement
from .model import Dwell, NominalModel
from .resimulate import resimulate


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
    Fs: float | None = None          # Stribeck level at rest (both directions; None: Fc, no dip)
    vs: float = 0.01
    lag: float = 0.0
    dwell_gain: float = 0.0
    dwell_time: float = 1.0
    saturation: float = 10.0
    dac_step: float = 0.0
    rest: tuple = (0.2, 0.2)         # range of the rests between strokes [s]
    stroke_speed: tuple = (0.05, 0.15)   # range of the strokes' mean speeds [m/s]
    stroke: float = 0.2              # longest stroke [m]
    sigma0: float = 0.0              # LuGre bristle stiffness [N/m] (0: static friction with exact stick)
    sigma1: float | None = None      # LuGre bristle damping [N s/m] (None: damping ratio 0.5 on sigma0)


def bang_bang(fs: float, duration: float, stroke: float = 0.2, seed: int = 0, rest=(0.2, 0.2),
              speed=(0.05, 0.15)) -> np.ndarray:
    """Reference: strokes of random length (30-100 % of ``stroke``) with bang-bang acceleration
    profiles and random mean speeds (uniform in ``speed`` [m/s]), resting between them for a time
    log-uniform in ``rest`` [s] (many short rests and some long ones)."""
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
        T = max(abs(D) / rng.uniform(*speed) * 2.0, 0.2)
        n = int(T * fs)
        s = np.linspace(0, 1, n)
        prof = np.where(s < 0.5, 2 * s ** 2, 1 - 2 * (1 - s) ** 2)
        seg = pos + D * prof
        r[k:k + n] = seg[: max(0, min(n, t.size - k))]
        k += n
        pos = target
        nd = int((rest[0] if rest[0] == rest[1] else np.exp(rng.uniform(*np.log(rest)))) * fs)
        r[k:k + nd] = pos
        k += nd
    return r


def true_model(true: TruePlant) -> NominalModel:
    """The true plant and its controller as a NominalModel (what a perfect diagnosis recovers)."""
    dip = 0.0 if true.Fs is None else true.Fs - true.Fc_pos
    curve = DirectionalCurve(StribeckCurve(true.Fc_pos, true.Fc_pos + dip, vs=true.vs, b=true.b_pos),
                             StribeckCurve(true.Fc_neg, true.Fc_neg + dip, vs=true.vs, b=true.b_neg))
    cog = (Cogging.sine(true.cog_amplitude, true.cog_pitch),) if true.cog_amplitude else ()
    ctrl = {"type": "pd-velocity-loop", "kp": true.kp, "kv": true.kv, "sample_time": 1.0 / true.fs,
            "saturation": true.saturation}
    if true.dac_step:
        ctrl["output_resolution"] = true.dac_step
    dwell = Dwell(0.0, true.dwell_gain, true.dwell_time) if true.dwell_gain else None
    law = "lugre" if true.sigma0 else ("stribeck" if dip else "coulomb-viscous")
    s1 = (bristle_damping(true.sigma0, true.mass) if true.sigma1 is None else true.sigma1) if true.sigma0 else None
    return NominalModel(true.mass, true.cm, curve, law, offset=true.offset, controller=ctrl, cogging=cog,
                        delay=true.delay, lag=true.lag, dwell=dwell, sigma0=true.sigma0 or None, sigma1=s1)


def regulator(model: NominalModel, d0: float, n: int, dt: float, *, seed: int = 0, resolution: float = 0.0,
              force_noise: float = 0.0, substeps: int = 20) -> Measurement:
    """A regulator task measured on ``model`` (its own controller): n samples at dt [s] from
    rest at error d0 [m] with q_ref = 0, the encoder quantizing to ``resolution`` [m] (0: none),
    a white force disturbance of standard deviation ``force_noise`` [N] drawn with ``seed``."""
    t = np.arange(n) * dt
    rest = Measurement(t, np.full(n, d0), np.zeros(n), q_ref=np.zeros(n))
    noise = np.random.default_rng(seed).normal(0.0, force_noise, n) if force_noise else None
    sim = resimulate(rest, model, resolution=resolution, force_noise=noise, substeps=substeps)
    return Measurement(t, sim.q, sim.u, q_ref=np.zeros(n), name=f"regulator(d0={d0:g}, seed={seed})")


def generate(true: TruePlant, duration: float = 20.0, seed: int = 0, substeps: int = 10) -> Measurement:
    """A run of the true plant tracking bang-bang strokes; q quantized, u recorded."""
    r = bang_bang(true.fs, duration, true.stroke, seed=seed, rest=true.rest, speed=true.stroke_speed)
    noise = np.random.default_rng(seed + 1).normal(0.0, true.force_noise, r.size)
    t = np.arange(r.size) / true.fs
    template = Measurement(t, np.full(r.size, r[0]), np.zeros(r.size), q_ref=r, name=f"synthetic(seed={seed})")
    sim = resimulate(template, true_model(true), substeps=substeps, resolution=true.resolution, force_noise=noise)
    return Measurement(t, sim.q, sim.u, q_ref=r, name=f"synthetic(seed={seed})")
