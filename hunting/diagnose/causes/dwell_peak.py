"""The dwell effect in the seven-parameter form (Armstrong-Helouvry; thesis section 2.2): the
static level of the Stribeck curve each slip starts from grows with the rest before it,
Fs + gain (1 - exp(-t_r / time)), and the friction decays from there along the curve's own
shape, c(v) = Fc + (Fs + growth - Fc) exp(-(|v| / vs)^beta) + b |v|, until the next stop. Where
Kato's form (the own-channel cause ``dwell``) grows only the force a rest breaks away at, this
one changes the sliding friction of every slip: the force channel sees it.

A force-channel cause: its regressor on a sliding sample is sign(v) exp(-(|v| / vs)^beta)
(1 - exp(-t_r / time)), the nominal curve's shape of that direction times the growth after the
rest that began the sample's slip (:func:`slip_rests`), linear in ``gain`` [N]; ``time`` [s] is the
hyper-parameter (a logarithmic grid over the record's rest durations). A slip that began at a
turnaround without a rest grows nothing; the slip out of a rest at the record's start has its
growth in full (the contact rested before the record, as the re-simulation assumes).

It needs a nominal curve with a Stribeck dip (Fs > Fc): the growth decays along it. Against a
Stribeck change (``stribeck``: a static level the same after every rest) it wins only where the
peaks differ with the rests before them as the growth says.

The extension is the model's :class:`~hunting.diagnose.model.Dwell` with ``sliding`` True, level 0."""
import numpy as np

from ..model import Dwell
from ._words import _q
from .dwell import kinematics_rests

NAME = "dwell_peak"
DESCRIPTION = "dwell in the seven-parameter form: the Stribeck peak of each slip grows with the rest before it"
FAMILY = "break-away"
FRICTION_FORCE = True
HYPERS = 1
HYPER_KEYS = ("time",)
EXCLUDES = ("reversal",)      # LuGre bristles' re-simulation holds no dwell growth
UNITS = {"gain": "N", "time": "s"}
TIMES = 12             # time constants searched
MIN_RESTS = 3          # rests ending in a slip the record must have


def slip_rests(kin) -> np.ndarray:
    """The duration [s] (n,) of the rest that began each sample's slip: the last rest (the
    position within two counts of the sensor's step or noise band for dwell's REST_WINDOW,
    :func:`~hunting.diagnose.causes.dwell.rest_phases`) that ended
    before the sample with no turnaround since; 0 after a turnaround without a rest (the
    velocity, where above TURN_SPEED of its largest value, changes sign with no rest between), inf
    in a slip out of a rest at the record's start, 0 before the first event, NaN in the rests."""
    hit = _CACHE.get(id(kin))
    if hit is not None and hit[0] is kin:
        return hit[1]
    n = kin.t.size
    phases = kinematics_rests(kin)
    ends = np.array([b for _, b in phases], dtype=int)
    durations = np.array([np.inf if a == 0 else (b - a + 1) * kin.dt for a, b in phases])
    fast = np.flatnonzero(np.abs(kin.vf) > TURN_SPEED * np.max(np.abs(kin.vf)))
    sg = np.sign(kin.vf[fast])
    ch = np.flatnonzero(sg[1:] != sg[:-1])
    lo, hi = fast[ch], fast[ch + 1]
    # a sign change with a rest between is that rest's slip, not a turnaround
    no_rest = np.searchsorted(ends, lo, side="left") == np.searchsorted(ends, hi, side="left")
    pos = np.concatenate([ends + 1, hi[no_rest]])
    val = np.concatenate([durations, np.zeros(int(no_rest.sum()))])
    order = np.argsort(pos, kind="stable")
    pos, val = pos[order], val[order]
    i = np.searchsorted(pos, np.arange(n), side="right") - 1
    out = np.where(i >= 0, val[np.maximum(i, 0)], 0.0) if pos.size else np.zeros(n)
    for a, b in phases:
        out[a:b + 1] = np.nan
    out.setflags(write=False)
    if len(_CACHE) >= 8:
        _CACHE.clear()
    _CACHE[id(kin)] = (kin, out)
    return out


TURN_SPEED = 0.02     # of the largest speed: a turnaround's velocity passes this on both sides
_CACHE: dict = {}     # slip_rests of the records being diagnosed, by the identity of their kinematics


def untestable(kin, model) -> str | None:
    c = (model.curve.positive, model.curve.negative)
    if not all(x.Fs > x.Fc for x in c):
        return "the nominal curve has no Stribeck dip (Fs > Fc) for a grown static level to decay along"
    if any(x.discontinuous for x in c):
        return "the nominal curve is discontinuous (Fc at any speed): a grown static level has no shape to decay along"
    if model.law == "lugre":
        return "the nominal model has LuGre bristles, whose re-simulation holds no dwell growth"
    if model.dwell is not None:
        return "the nominal model has a dwell effect already"
    r = slip_rests(kin)
    ends = np.count_nonzero(np.diff(np.isnan(r).astype(np.int8)) == -1)
    if ends < MIN_RESTS:
        return f"{ends} rests end in a slip (at least {MIN_RESTS} needed)"
    return None


def _rest_span(kin) -> tuple[float, float] | None:
    """(shortest, longest) [s] of the record's rests that end in a slip (the shortest at least two
    samples); None without one."""
    r = slip_rests(kin)
    d = r[np.isfinite(r) & (r > 0)]
    if d.size == 0:
        return None
    lo = max(float(np.min(d)), 2 * kin.dt)
    return lo, max(float(np.max(d)), lo)


def hypers(kin, model) -> list:
    span = _rest_span(kin)
    if span is None:
        return []
    return [{"time": float(x)} for x in np.geomspace(span[0] / 3.0, 3.0 * span[1], TIMES)]


def hyper_bounds(kin, model) -> dict:
    lo, hi = _rest_span(kin) or (kin.dt, 1.0)
    return {"time": (lo / 10.0, 10.0 * hi)}


def design(kin, model, hyper):
    v = kin.vf
    r = slip_rests(kin)
    grow = np.where(np.isnan(r), 0.0, 1.0 - np.exp(-np.nan_to_num(r, nan=0.0, posinf=np.inf) / hyper["time"]))
    pos, neg = model.curve.positive, model.curve.negative
    shape = np.where(v > 0, np.exp(-(np.abs(v) / pos.vs) ** pos.beta), np.exp(-(np.abs(v) / neg.vs) ** neg.beta))
    return kin.sliding(np.sign(v) * shape * grow)[:, None]


def unphysical(theta, hyper, model) -> str | None:
    if theta[0] < 0:
        return f"gain = {theta[0]:.3g} N < 0: the peaks fall with the rest before them, not a dwell effect"
    return None


def parameters(theta, hyper, model) -> dict:
    return {"gain": float(theta[0]), "time": float(hyper["time"])}


def extend(model, theta, hyper):
    return model.replace(dwell=Dwell(0.0, max(float(theta[0]), 0.0), float(hyper["time"]), sliding=True))


def sentence(p, inc, model) -> str:
    return (f"the friction peak of each slip grows with the rest before it: static level Fs + "
            f"{_q(p['gain'], None, 'N')} (1 - exp(-t_rest / {_q(p['time'], None, 's')})) at the start of the slip, "
            "decaying along the Stribeck curve (the seven-parameter model's dwell)")
