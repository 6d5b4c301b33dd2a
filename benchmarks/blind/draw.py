"""Random benchmark systems and hidden effects.

A clean system is a plant with friction (Coulomb + viscous, or a Stribeck curve; sometimes
direction-dependent, with a known offset, known cogging, a known one- or two-sample delay, a
known DAC step or saturation, or LuGre friction), a sampled PID or PD + velocity-loop controller
tuned for it, an encoder and actuator noise. The user's nominal model is that clean system,
exactly. An effect changes the true plant (or controller) away from the nominal one; its size is
drawn log-uniformly between a small value (near or below what the data can show) and a strong one.

Every effect records its true parameters as final values (what the extended model should hold),
under the names the diagnosis reports (``offset``, ``b_pos``/``b_neg``, ``pitch``/``amplitude_k``,
``Fc``/``Fs``/``vs``, ``Fc``/``Fs``/``scale`` (level), ``b``, ``mass``, ``delay``, ``load_mass``/``frequency``/``damping``/
``stiffness``, ``lag``, ``sigma0``/``sigma1``, ``level``/``gain``/``time``, ``saturation``,
``output_resolution``), and the names that count as finding it (``accept``: e.g. LuGre bristles are
``reversal`` or ``presliding``; a Coulomb-level asymmetry is a constant force while sliding, so
``offset`` names it as well)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .system import Controller, Curve, Noise, Plant, Sensor

CAUSES = ("offset", "asymmetry", "cogging", "stribeck", "viscous", "mass", "delay", "flexibility", "lag", "reversal",
          "dwell", "saturation", "quantization")
# effects added after the tuning and reporting sets were drawn: ``CAUSES`` keeps its order (the
# datasets of those families are a function of it), families drawn since use ``ALL_CAUSES``
LATER = ("level",)
ALL_CAUSES = CAUSES + LATER
# the validation metric of each effect's size: the force residual, or the re-simulated position
# (LuGre bristles: either, as the diagnosis names them on both: reversal and presliding)
BEHAVIOUR_CHANNEL = ("dwell", "saturation", "quantization")
EITHER_CHANNEL = ("reversal",)
# the parameters a found cause is judged on (final values)
# (those present both in the report and the truth are compared: e.g. an offset reported for a
# Coulomb-level asymmetry against its constant force while sliding)
PRIMARY = {"offset": ("offset",), "asymmetry": ("b_pos", "b_neg", "Fc_pos", "Fc_neg"),
           "cogging": ("pitch", "amplitude_1"), "presliding": ("sigma0",),
           "stribeck": ("Fs",), "level": ("Fc", "Fs"), "viscous": ("b",), "mass": ("mass",), "delay": ("delay",),
           "flexibility": ("load_mass", "frequency"), "lag": ("lag",), "reversal": ("sigma0",), "dwell": ("gain",), "dwell_peak": ("gain",),
           "level_asymmetry": ("Fc_pos", "Fc_neg"),
           "saturation": ("saturation",), "quantization": ("output_resolution",)}
# pairs that cannot coexist in one plant
# (a level change and a Stribeck-shape change both rescale the curve's levels: one plant holds one)
_EXCLUSIVE = {frozenset(p) for p in (("reversal", "lag"), ("reversal", "dwell"), ("level", "stribeck"))}
FREQS = (500.0, 800.0, 1000.0, 1000.0, 2000.0, 2500.0, 4000.0, 5000.0)
MAX_SAMPLES = 20000


def size_gain(cause: str, force: float, behaviour: float) -> float:
    """The validation gain that measures an effect's size (``measures``): the re-simulated
    position's for the behaviour-channel causes, the larger of both for LuGre bristles, else
    the force residual's."""
    if cause in BEHAVIOUR_CHANNEL:
        return behaviour
    return max(force, behaviour) if cause in EITHER_CHANNEL else force


def lu(rng, lo, hi) -> float:
    """Log-uniform draw in [lo, hi]."""
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def at(frac: float, lo: float, hi: float) -> float:
    """The log-scale point at frac in [0, 1] between lo and hi."""
    return float(math.exp(math.log(lo) + frac * (math.log(hi) - math.log(lo))))


@dataclass
class Draft:
    """A system being drawn: true and nominal plant and controller, sensor, noise, the sample
    interval dt [s], the record duration [s], the programme's stroke [m] and speed [m/s], and
    the effects applied so far ([{cause, variant, size, accept, params}])."""

    plant: Plant
    ctrl: Controller
    nominal: Plant
    nominal_ctrl: Controller
    sensor: Sensor
    noise: Noise
    dt: float
    duration: float
    stroke: float
    speed: float
    bandwidth: float
    effects: list = field(default_factory=list)
    isolated: list = field(default_factory=list)   # [(plant, controller)]: nominal + one effect
    needs_saturation: float = 0.0       # fraction of peak |u| for a saturation drawn later
    known_saturation: float = 0.0       # fraction of peak |u| for a known saturation


def clean(rng: np.random.Generator, *, need_dip: bool = False, static: bool = False, plain: bool = False,
          short: bool = False) -> Draft:
    """A clean system (module docstring). need_dip : the curve has a Stribeck dip; static : not
    LuGre; plain : no known cogging, DAC or saturation (an effect will add one); short : records
    of 2-3 s at 1 kHz (the tests' subset) instead of 3-10 s at 0.5-5 kHz."""
    fs = 1000.0 if short else float(rng.choice(FREQS))
    dt = 1.0 / fs
    duration = lu(rng, 2.0, 3.0) if short else min(lu(rng, 3.0, 10.0), MAX_SAMPLES * dt)
    m = lu(rng, 0.3, 30.0)
    cm = 1.0 if rng.random() < 0.5 else lu(rng, 2.0, 40.0)
    Fc = m * lu(rng, 0.3, 5.0)
    speed = lu(rng, 0.01, 0.3)
    stroke = lu(rng, 0.002, 0.05)
    stroke = max(stroke, 0.3 * speed)
    b = Fc / speed * lu(rng, 0.05, 1.5)
    dip = need_dip or rng.random() < 0.55
    if dip:
        Fs, vs, beta = Fc * rng.uniform(1.15, 1.8), speed * lu(rng, 0.03, 0.4), (2.0 if rng.random() < 0.7 else 1.0)
    else:
        Fs, vs, beta = Fc, speed * 0.1, 2.0
    pos = Curve(Fc, Fs, vs, beta, b)
    neg = pos
    if rng.random() < 0.15:
        k = rng.uniform(0.8, 1.2)
        neg = Curve(Fc * k, Fc * k + (Fs - Fc), vs, beta, b * rng.uniform(0.7, 1.3))
    plant = Plant(m, cm, pos, neg)
    if rng.random() < 0.15:
        plant = replace(plant, offset=float(rng.choice([-1, 1]) * Fc * rng.uniform(0.05, 0.3)))
    if not plain and rng.random() < 0.12:
        plant = replace(plant, cogging=_cogging(rng, Fc * rng.uniform(0.05, 0.3), lu(rng, 0.001, 0.01), stroke))
    if not static and rng.random() < 0.12:
        s0 = max(pos.Fs, neg.Fs) / lu(rng, 1e-6, 5e-5)
        plant = replace(plant, law="lugre", sigma0=s0, sigma1=2 * rng.uniform(0.3, 1.0) * math.sqrt(s0 * m))
    if rng.random() < 0.1:
        plant = replace(plant, delay=dt * int(rng.integers(1, 3)))
    fb = min(lu(rng, 4.0, 25.0), fs / 40)
    w = 2 * math.pi * fb
    if rng.random() < 0.7:
        zeta = rng.uniform(0.6, 1.0)
        ctrl = Controller("pid", kp=m * w * w / cm, kd=2 * zeta * m * w / cm, ki=m * w ** 3 / cm / rng.uniform(3, 8),
                          tau_f=0.0 if rng.random() < 0.5 else max(1 / (2 * math.pi * rng.uniform(4, 10) * fb), dt),
                          d_on_meas=bool(rng.random() < 0.4))
    else:
        wv = min(2 * math.pi * rng.uniform(3, 6) * fb, 2 * math.pi * fs / 15)
        ctrl = Controller("pd-velocity-loop", kp=wv / rng.uniform(3, 6), kv=m * wv / cm)
    if not plain and rng.random() < 0.15:
        ctrl = replace(ctrl, dac=Fc / cm * lu(rng, 1e-3, 2e-2))
    res = min(lu(rng, 5e-8, 5e-6), stroke / 2000)
    sensor = Sensor(res, 0.0 if rng.random() < 0.5 else res * rng.uniform(0.1, 0.5))
    f_noise = Fc * lu(rng, 0.003, 0.03) / cm
    ar = rng.uniform(0.3, 1.0)
    noise = Noise(ar_std=f_noise * ar, ar_time=lu(rng, 5e-4, 3e-2), white_std=f_noise * math.sqrt(1 - ar * ar))
    d = Draft(plant, ctrl, plant, ctrl, sensor, noise, dt, duration, stroke, speed, fb)
    if not plain and rng.random() < 0.1:
        d.known_saturation = rng.uniform(0.8, 1.3)
    return d


def _cogging(rng, amp: float, pitch: float, stroke: float) -> tuple:
    pitch = min(pitch, stroke / 6)
    amps = [amp] + [amp * rng.uniform(0.0, 0.5) if rng.random() < 0.5 else 0.0 for _ in range(2)]
    ph = rng.uniform(0, 2 * math.pi, 3)
    return (pitch, tuple(float(a * math.cos(p)) for a, p in zip(amps, ph)),
            tuple(float(a * math.sin(p)) for a, p in zip(amps, ph)))


def add_effect(d: Draft, cause: str, frac: float, rng: np.random.Generator, others: tuple = ()) -> None:
    """Apply one hidden effect of size ``frac`` in [0, 1] (0: smallest, 1: strongest) to the
    true plant or controller of ``d`` and record it in d.effects; the same effect alone on the
    nominal plant and controller goes to d.isolated."""
    seed = int(rng.integers(2 ** 62))
    p, c, effect = _apply(d, d.plant, d.ctrl, cause, frac, np.random.default_rng(seed), others)
    d.isolated.append(_apply(d, d.nominal, d.nominal_ctrl, cause, frac, np.random.default_rng(seed), others)[:2])
    d.plant, d.ctrl = p, c
    d.effects.append(effect)


def _apply(d: Draft, p: Plant, c: Controller, cause: str, frac: float, rng, others: tuple):
    """(plant, controller, effect record) with the effect applied to p and c."""
    Fc, b = d.nominal.pos.Fc, d.nominal.pos.b
    variant, accept = "", (cause,)
    if cause == "offset":
        size = at(frac, 0.01, 0.5)
        p = replace(p, offset=p.offset + float(rng.choice([-1, 1])) * size * Fc)
        params = {"offset": p.offset}
    elif cause == "asymmetry":
        size = at(frac, 0.03, 0.6)
        variant = "viscous" if "offset" in others else str(rng.choice(["viscous", "coulomb", "both"]))
        pos, neg = p.pos, p.neg
        if variant in ("viscous", "both"):
            pos, neg = replace(pos, b=pos.b * (1 + size)), replace(neg, b=neg.b * (1 - size))
        if variant in ("coulomb", "both"):
            dp, dn = pos.Fc * size, -neg.Fc * size
            pos = replace(pos, Fc=pos.Fc + dp, Fs=pos.Fs + dp)
            neg = replace(neg, Fc=neg.Fc + dn, Fs=neg.Fs + dn)
        params = {"b_pos": pos.b, "b_neg": neg.b, "Fc_pos": pos.Fc, "Fc_neg": neg.Fc}
        if variant != "viscous":
            # while sliding, Fc+ + dp and Fc- + dn are the mean level plus a constant force
            # (dp - dn) / 2: an offset names it as well, with that value
            accept = ("asymmetry", "offset")
            params["offset"] = p.offset + 0.5 * ((pos.Fc - p.pos.Fc) - (neg.Fc - p.neg.Fc))
        p = replace(p, pos=pos, neg=neg)
    elif cause == "cogging":
        size = at(frac, 0.01, 0.5)
        cog = _cogging(rng, size * Fc, lu(rng, 5e-4, 0.01), d.stroke)
        p = replace(p, cogging=cog)
        params = {"pitch": cog[0]}
        params.update({f"amplitude_{k + 1}": float(math.hypot(a, s)) for k, (a, s) in enumerate(zip(cog[1], cog[2]))})
    elif cause == "stribeck":
        nom = d.nominal.pos
        if nom.Fs == nom.Fc:
            variant, size = "dip", at(frac, 0.05, 1.0)
            f = lambda cv: replace(cv, Fs=cv.Fc + size * Fc, vs=d.speed * lu(rng, 0.03, 0.4), beta=2.0)  # noqa: E731
        elif rng.random() < 0.5:
            variant, size = "Fs", at(frac, 0.1, 1.0)
            k = 1 + size if rng.random() < 0.5 or size > 0.9 else 1 - size
            f = lambda cv: replace(cv, Fs=cv.Fc + k * (cv.Fs - cv.Fc))  # noqa: E731
            size = size * (nom.Fs - nom.Fc) / Fc
        else:
            variant, ratio = "vs", at(frac, 1.3, 4.0)
            k = ratio if rng.random() < 0.5 else 1 / ratio
            f = lambda cv: replace(cv, vs=cv.vs * k)  # noqa: E731
            size = math.log(ratio) * (nom.Fs - nom.Fc) / Fc
        p = replace(p, pos=f(p.pos), neg=f(p.neg))
        params = {"Fc": p.pos.Fc, "Fs": p.pos.Fs, "vs": p.pos.vs}
    elif cause == "level":
        # the friction level of both directions scaled by one factor k, Coulomb and static level
        # together (a normal-load, preload, wear or lubricant change scales mu(v) N as a whole;
        # the viscous part is film shear and stays), up or down; size |k - 1| from 2 % (about
        # the detection limit at the generator's 0.3-3 % force noise) to a factor 2 or 1/2.
        # accept: ``level`` says it exactly; ``stribeck`` with the right levels says the same
        # thing with a shape parameter more (its Fs is judged against the truth's: PRIMARY), so a
        # careful engineer accepts it; ``offset`` (constant, not odd in v) or ``viscous`` (grows
        # with speed) would name another force and do not count.
        size = at(frac, 0.02, 1.0)
        k = 1 + size if rng.random() < 0.5 else 1 / (1 + size)
        f = lambda cv: replace(cv, Fc=cv.Fc * k, Fs=cv.Fs * k)  # noqa: E731
        p = replace(p, pos=f(p.pos), neg=f(p.neg))
        variant = "up" if k > 1 else "down"
        accept = ("level", "stribeck")
        params = {"Fc": p.pos.Fc, "Fs": p.pos.Fs, "scale": k}
    elif cause == "viscous":
        size = at(frac, 0.05, 2.0)
        k = 1 + size if rng.random() < 0.6 else 1 / (1 + size)
        db = b * (k - 1)
        p = replace(p, pos=replace(p.pos, b=p.pos.b + db), neg=replace(p.neg, b=p.neg.b + db))
        params = {"b": p.pos.b}
    elif cause == "mass":
        size = at(frac, 0.02, 0.6)
        k = 1 + size if rng.random() < 0.5 else 1 / (1 + size)
        p = replace(p, mass=p.mass * k)
        params = {"mass": p.mass}
    elif cause == "delay":
        top = min(5e-3, 0.35 / (2 * math.pi * d.bandwidth))
        tau = max(at(frac, 0.05, 1.0) * top, 0.1 * d.dt)
        size = tau * 2 * math.pi * d.bandwidth          # phase lag at the loop bandwidth [rad]
        p = replace(p, delay=p.delay + tau)
        params = {"delay": p.delay}
    elif cause == "flexibility":
        size = at(frac, 0.05, 0.6)
        f = max(min(lu(rng, 1.0, 5.0) * d.bandwidth, 0.08 / d.dt), 3.0)
        zeta = lu(rng, 0.02, 0.3)
        p = replace(p, flex=(size * p.mass, f, zeta))
        params = {"load_mass": size * p.mass, "frequency": f, "damping": zeta,
                  "stiffness": size * p.mass * (2 * math.pi * f) ** 2}
    elif cause == "lag":
        size = at(frac, 0.002, 0.1)
        p = replace(p, lag=size)
        params = {"lag": size}
    elif cause == "reversal":
        res = d.sensor.resolution
        slip = at(frac, max(2 * res, 5e-7), 1e-4)      # the slip length Fs / sigma0 [m]
        size = slip
        s0 = max(p.pos.Fs, p.neg.Fs) / slip
        p = replace(p, law="lugre", sigma0=s0, sigma1=2 * rng.uniform(0.3, 1.0) * math.sqrt(s0 * p.mass))
        accept = ("reversal", "presliding")
        params = {"sigma0": s0, "sigma1": p.sigma1}
    elif cause == "dwell":
        size = at(frac, 0.05, 0.8)
        tr = lu(rng, 0.03, 1.0)
        p = replace(p, dwell=(0.0, size * max(p.pos.Fs, p.neg.Fs), tr))
        params = {"level": 0.0, "gain": p.dwell[1], "time": tr}
    elif cause == "saturation":
        size = at(frac, 0.03, 0.6)
        d.needs_saturation = 1 - size
        params = {}                                     # set once the unsaturated peak is known
        c = replace(c, saturation=-1.0)                 # marks the controller to receive it
    elif cause == "quantization":
        size = at(frac, 0.005, 0.3)
        c = replace(c, dac=size * Fc / p.cm)
        params = {"output_resolution": c.dac}
    else:
        raise ValueError(f"cause {cause!r} is not one of {ALL_CAUSES}")
    return p, c, dict(cause=cause, variant=variant, frac=float(frac), size=float(size), accept=list(accept),
                      params={k: float(v) for k, v in params.items()})


def needs(cause: str) -> dict:
    """Constraints an effect puts on the clean system it is drawn into."""
    return dict(need_dip=cause == "lag", static=cause in ("reversal", "lag", "dwell"),
                plain=cause in ("cogging", "saturation", "quantization"))


def compatible(a: str, b: str) -> bool:
    return a != b and frozenset((a, b)) not in _EXCLUSIVE


def draft(rng: np.random.Generator, causes: tuple = (), fracs: tuple = (), short: bool = False) -> Draft:
    """A clean system with the given effects (sizes fracs in [0, 1]); short : see :func:`clean`."""
    req = [needs(c) for c in causes]
    d = clean(rng, need_dip=any(r["need_dip"] for r in req), static=any(r["static"] for r in req),
              plain=any(r["plain"] for r in req), short=short)
    for c, f in zip(causes, fracs):
        add_effect(d, c, f, rng, others=tuple(x for x in causes if x != c))
    return d
