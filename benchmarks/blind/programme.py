"""Random setpoint programmes for the blind benchmark: a chain of segments, each starting where
the previous one ended.

Segment kinds: ``move`` (minimum-jerk point-to-point, 10 t^3 - 15 t^4 + 6 t^5), ``dwell`` (hold
still), ``sine`` (c + A (1 - cos(2 pi f t)) over whole periods: it leaves and returns with zero
velocity), ``ramp`` (constant velocity with sharp corners), ``scurve`` (constant-acceleration
trapezoid in velocity). Amplitudes are drawn relative to a stroke scale, speeds relative to a
speed scale, so that every programme visits both directions, low and high speeds, and rests."""
from __future__ import annotations

import numpy as np

KINDS = ("move", "dwell", "sine", "ramp", "scurve")
WEIGHTS = (0.3, 0.2, 0.2, 0.15, 0.15)


def _loguniform(rng, lo, hi):
    return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))


def segments(rng: np.random.Generator, duration: float, stroke: float, speed: float) -> list:
    """Segments [(kind, length [s], params)] filling ``duration`` [s]; stroke [m] and speed
    [m/s] set the scale of amplitudes and velocities. The first and last segments are dwells
    (the record starts and ends at rest)."""
    out = [("dwell", rng.uniform(0.05, 0.2), {})]
    used = out[0][1]
    pos = 0.0
    for _ in range(1000):
        if used >= duration:
            break
        kind = KINDS[rng.choice(len(KINDS), p=WEIGHTS)]
        # stay within +-stroke: aim back towards the middle when far out
        sign = -np.sign(pos) if abs(pos) > 0.6 * stroke else rng.choice([-1.0, 1.0])
        if kind == "dwell":
            seg = ("dwell", rng.uniform(0.05, 0.8), {})
        elif kind == "move":
            amp = _loguniform(rng, 0.03, 1.0) * stroke
            vpk = _loguniform(rng, 0.05, 1.0) * speed
            seg = ("move", max(1.875 * amp / vpk, 0.04), {"dist": sign * amp})
        elif kind == "sine":
            amp = _loguniform(rng, 0.02, 0.4) * stroke
            f = min(_loguniform(rng, 0.05, 1.0) * speed / (np.pi * amp), 20.0)
            periods = int(rng.integers(1, 4))
            seg = ("sine", periods / f, {"amp": sign * amp, "f": f})
        elif kind == "ramp":
            vel = _loguniform(rng, 0.01, 0.7) * speed
            seg = ("ramp", min(_loguniform(rng, 0.05, 0.8) * stroke / vel, 2.0), {"vel": sign * vel})
        else:
            vel = _loguniform(rng, 0.05, 1.0) * speed
            ta = rng.uniform(0.02, 0.3)
            tc = min(_loguniform(rng, 0.05, 0.8) * stroke / vel, 1.5)
            seg = ("scurve", 2 * ta + tc, {"vel": sign * vel, "ta": ta})
        out.append(seg)
        used += seg[1]
        pos += _displacement(seg)
    out.append(("dwell", rng.uniform(0.1, 0.3), {}))
    return out


def _displacement(seg) -> float:
    kind, length, p = seg
    if kind == "move":
        return p["dist"]
    if kind == "ramp":
        return p["vel"] * length
    if kind == "scurve":
        return p["vel"] * (length - p["ta"])
    return 0.0


def _shape(kind, p, tau, length):
    """Displacement from the segment's start at times tau in [0, length]."""
    if kind == "move":
        s = np.clip(tau / length, 0.0, 1.0)
        return p["dist"] * (10 * s ** 3 - 15 * s ** 4 + 6 * s ** 5)
    if kind == "sine":
        return p["amp"] * (1 - np.cos(2 * np.pi * p["f"] * tau))
    if kind == "ramp":
        return p["vel"] * tau
    if kind == "scurve":
        ta, v = p["ta"], p["vel"]
        tc = length - 2 * ta
        acc = v / ta
        x = np.where(tau < ta, 0.5 * acc * tau ** 2, 0.5 * v * ta + v * (tau - ta))
        late = tau > ta + tc
        tl = tau - ta - tc
        return np.where(late, 0.5 * v * ta + v * tc + v * tl - 0.5 * acc * tl ** 2, x)
    return np.zeros_like(tau)


def evaluate(segs: list, t: np.ndarray) -> np.ndarray:
    """The programme's reference at times t [s] (n,); held at its last value after the end."""
    r = np.zeros_like(t, dtype=float)
    start, pos = 0.0, 0.0
    for seg in segs:
        kind, length, p = seg
        sel = (t >= start) & (t < start + length)
        r[sel] = pos + _shape(kind, p, t[sel] - start, length)
        start += length
        pos += _displacement(seg)
    r[t >= start] = pos
    return r


def draw(rng: np.random.Generator, duration: float, dt: float, stroke: float, speed: float) -> tuple[np.ndarray, list]:
    """(reference (n,) on t = k dt, k < duration / dt, its segments)."""
    segs = segments(rng, duration, stroke, speed)
    t = np.arange(int(round(duration / dt))) * dt
    return evaluate(segs, t), segs
