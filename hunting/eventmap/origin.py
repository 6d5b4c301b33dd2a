"""The slope of the event map at the equilibrium set, from the loop's linearization.

Derivation (exact Switch model, states x1 error, x2 velocity, x3 integral of x1). A stick phase
with error d ends when the integral action has moved the non-friction force F_nf to the edge of
the stick set: at F_nf = -Fs- for d > 0 (the mass then slips with x2 < 0), at +Fs+ for d < 0.
From there, while x2 keeps its sign s, the friction force is s g(|x2|) + b x2 and, for small d,

    g(|x2|) = Fs + g'(0+) |x2| + o(x2),   g'(0+) = 0 for beta > 1 and for Coulomb friction,
                                          g'(0+) = -(Fs - Fc)/vs for beta = 1,

so the slip motion is affine: with z = x - x_eq, x_eq = (0, 0, x3_eq) the state at which F_nf
equals the friction level s Fs (the slip phase's equilibrium),

    z' = A z,   A = [[0, 1, 0], [-k1/m, -(cm kd + b + g'(0+))/m, -cm ki/m], [1, 0, 0]],
    k1 = cm kp + alpha (alpha = dF_cog/dq at the setpoint),

and z(0) = d v0, v0 = (1, 0, -k1/(cm ki)), because x3 at break-away and x3_eq differ by the
force k1 d that the proportional action (and cogging) adds at error d. Everything is linear in
d: the next stick phase starts at the first t* > 0 with z2(t*) = 0 (the acceleration there has
the sign that ends the slip, and F_nf differs from s Fs by O(d), inside the stick set), the
same t* for every small d, and the next stick error is x1(t*) = d e1' exp(A t*) v0. So

    P'(0+) = e1' exp(A- t*-) v0,   P'(0-) = e1' exp(A+ t*+) v0     (A-: the x2 < 0 curve)

and P^k near 0 is the composition of these one-sided slopes (each stick phase alternates the
side when the slopes are negative). For 0 < beta < 1 and the discontinuous curve g is not
linearizable at 0 (the map jumps at the origin): there is no such slope.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm
from scipy.optimize import brentq

from ..models.loop import ServoLoop

MAX_CHUNKS = 200           # bound on the search for t*: 200 chunks of 512 samples
CHUNK = 512


@dataclass(frozen=True)
class LinearSlip:
    """The slip phase after a stick phase, linearized at zero velocity.

    direction : slip direction s (-1 after d > 0, +1 after d < 0); A : (3, 3); v0 : (3,)
    initial deviation per unit d; g1 : g'(0+) of the curve used [force unit s/m]."""

    direction: int
    A: np.ndarray
    v0: np.ndarray
    g1: float


def linear_slip(loop: ServoLoop, direction: int) -> LinearSlip | None:
    """The linearized slip phase in ``direction`` (+1 or -1), or None when the friction curve
    of that direction is not linearizable at zero velocity (0 < beta < 1, discontinuous), or
    when ``loop`` is not a ServoLoop (a StickFamily of another system: probes decide)."""
    if not isinstance(loop, ServoLoop):
        return None
    pl, c = loop.plant, loop.controller
    curve = loop.friction.curve.positive if direction > 0 else loop.friction.curve.negative
    if curve.Fs == curve.Fc or (np.isfinite(curve.beta) and curve.beta > 1):
        g1 = 0.0
    elif curve.beta == 1:
        g1 = -(curve.Fs - curve.Fc) / curve.vs
    else:
        return None
    m, cm = pl.mass, pl.motor_constant
    alpha = 0.0 if pl.cogging is None else float(pl.cogging.slope(pl.setpoint)[0])
    k1 = cm * c.kp + alpha
    A = np.array([[0.0, 1.0, 0.0],
                  [-k1 / m, -(cm * c.kd + curve.b + g1) / m, -cm * c.ki / m],
                  [1.0, 0.0, 0.0]])
    v0 = np.array([1.0, 0.0, -k1 / (cm * c.ki)])
    return LinearSlip(int(direction), A, v0, g1)


def _flow(A: np.ndarray, v0: np.ndarray):
    """z(t) = exp(A t) v0 for an array of t: by the eigendecomposition when it is well
    conditioned, else by expm per time (defective or nearly defective A)."""
    lam, V = np.linalg.eig(A)
    if np.linalg.cond(V) < 1e8:
        c = np.linalg.solve(V, v0.astype(complex))

        def z(ts):
            return (np.exp(np.outer(ts, lam)) * c) @ V.T
        return z, lam

    def z_expm(ts):
        return np.array([expm(A * t) @ v0 for t in ts])
    return z_expm, lam


@dataclass(frozen=True)
class StickEntry:
    """How the linearized slip phase ends. kind: "return" (z2 returns to zero at t [s] with
    state deviation z (3,) per unit d), "decayed" (z decays to 1e-8 of its start without z2
    returning: the mass creeps onto the equilibrium set and the next stick error is o(d)),
    "grown" (|z| grows by 1e8 first: the linearization leaves its range, P^k(d)/d is unbounded)
    or "unknown" (neither within the bounded search)."""

    kind: str
    t: float | None = None
    z: np.ndarray | None = None


def stick_entry(ls: LinearSlip) -> StickEntry:
    """Where the linearized slip velocity z2 first returns to zero after break-away. The search
    steps by 0.02 / max|lambda| for at most MAX_CHUNKS * CHUNK samples."""
    A, v0 = ls.A, ls.v0
    z, lam = _flow(A, v0)
    start_sign = np.sign((A @ A @ v0)[1])        # z2 ~ (A^2 v0)_2 t^2 / 2 just after break-away
    if not np.all(np.isfinite(lam)) or np.max(np.abs(lam)) == 0 or start_sign == 0:
        return StickEntry("unknown")
    h = 0.02 / np.max(np.abs(lam))
    size = np.linalg.norm(v0)

    def z2(t):
        return float(z(np.array([t]))[0, 1].real)

    t0 = 0.0
    with np.errstate(over="ignore", invalid="ignore"):
        for _ in range(MAX_CHUNKS):
            ts = t0 + h * np.arange(1, CHUNK + 1)
            zs = z(ts).real
            flip = np.flatnonzero(np.sign(zs[:, 1]) == -start_sign)
            norm = np.abs(zs).max(axis=1)
            grown = np.flatnonzero(~(norm < 1e8 * size))
            small = np.flatnonzero(norm < 1e-8 * size)
            first = min(a[0] if a.size else CHUNK for a in (flip, grown, small))
            if first == CHUNK:
                t0 = float(ts[-1])
                continue
            if grown.size and grown[0] == first:
                return StickEntry("grown")
            if flip.size and flip[0] == first:
                i = int(first)
                lo = ts[i - 1] if i > 0 else 0.5 * ts[0]
                t_star = float(brentq(z2, lo, ts[i], xtol=1e-15 * ts[i], rtol=4 * np.finfo(float).eps))
                return StickEntry("return", t_star, z(np.array([t_star]))[0].real)
            return StickEntry("decayed")
    return StickEntry("unknown")


@dataclass(frozen=True)
class LinearOrigin:
    """One-sided slopes of P^k at d = 0 from the linearization.

    slope_right, slope_left : dP^k/dd at 0+ and 0- (inf where the linearized slip grows away
    without returning to stick: P^k(d)/d is unbounded; 0 where it decays onto the equilibrium
    set without returning: the next stick error is o(d)); first : (P'(0+), P'(0-)); t_stick :
    (t*-, t*+) [s] (None where there is no return)."""

    slope_right: float
    slope_left: float
    first: tuple
    t_stick: tuple


def linear_origin(loop: ServoLoop, iterate: int) -> LinearOrigin | None:
    """The slopes of P^k at the equilibrium set from :func:`linear_slip`; None when a side is
    not linearizable or the bounded search cannot tell how its slip phase ends."""
    first, times = {}, {}
    for side, direction in ((+1, -1), (-1, +1)):        # d > 0 slips in x2 < 0, d < 0 in x2 > 0
        ls = linear_slip(loop, direction)
        if ls is None:
            return None
        entry = stick_entry(ls)
        times[side] = entry.t
        if entry.kind == "unknown":
            return None
        first[side] = {"return": lambda: float(entry.z[0]), "grown": lambda: np.inf,
                       "decayed": lambda: 0.0}[entry.kind]()

    def compose(side: int) -> float:
        slope, s = 1.0, side
        for _ in range(int(iterate)):
            step = first[s]
            if step == 0.0:
                return 0.0
            slope *= step
            if not np.isfinite(slope):
                return np.inf
            s = s if step > 0 else -s
        return slope

    return LinearOrigin(compose(+1), compose(-1), (first[+1], first[-1]), (times[+1], times[-1]))


def force_length(loop: ServoLoop) -> float | None:
    """Fs / |cm kp + alpha| [position unit]: the error whose proportional force equals the
    static friction (the natural scale of stick errors); None without proportional action or
    for a system that is not a ServoLoop."""
    if not isinstance(loop, ServoLoop):
        return None
    c, pl = loop.controller, loop.plant
    alpha = 0.0 if pl.cogging is None else float(pl.cogging.slope(pl.setpoint)[0])
    k1 = abs(pl.motor_constant * c.kp + alpha)
    fs = min(loop.friction.curve.positive.Fs, loop.friction.curve.negative.Fs)
    return fs / k1 if k1 > 0 and fs > 0 else None
