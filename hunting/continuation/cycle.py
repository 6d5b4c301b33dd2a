"""Find a periodic orbit of any system from a rough start: :func:`find_cycle` and its result.

Three ways in, tried in this order:

1. without a user start, the stick-to-stick event map (:func:`stick_map`): a servo loop's
   exact-Switch twin, or the stick family of a model with one Switch contact, over the whole
   stick-error range the map reaches (:func:`stick_error_range`), gives the stick error of the
   cycle and a shooting guess (or says that the equilibrium set attracts and there is none);
2. with a period guess, shooting straight from the user's state (this reaches unstable cycles
   a simulation never settles on);
3. a transient simulation from the user's state until the return map settles
   (:mod:`hunting.continuation.transient`), shooting from inside the settled orbit.

Every orbit found is reduced to its minimal period and checked for events its flow stepped
over. When none succeeds, the result says why with an :class:`OrbitStatus`: the motion came to
rest (EQUILIBRIUM), grew without bound (ESCAPE), did not recur (NO_RECURRENCE), or shooting
failed (SINGULAR_JACOBIAN, NOT_CONVERGED, INTEGRATION_FAILED).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import ConvergenceError, SystemDefinitionError
from ..integrate.simulate import simulate
from ..models import servo as S
from ..system import PiecewiseSystem
from .flow import flow
from .shooting import (STEPS_PER_PERIOD, PeriodicOrbit, ShootingOptions, guess_from_stick_error, minimal_period,
                       missed_event, shoot)
from .status import OrbitStatus
from .target import Target, resolve
from .transient import StartOptions, settle


@dataclass(frozen=True)
class Phase:
    """One phase of a friction contact along the orbit.

    kind : "stick" or "slip"; duration [time unit]; start : time from the orbit's x0 at which
    the phase begins (in [0, period)); contact : the contact's name; modes : names of the
    system modes passed through (for a LuGre contact's stick phase, which has no mode of its
    own, the velocity bound that defines it: |w| below PRESLIDING_FRACTION of its largest value
    over the orbit)."""

    kind: str
    duration: float
    start: float
    contact: str
    modes: tuple

    def as_dict(self, with_contact: bool = False) -> dict:
        d = dict(kind=self.kind, duration=float(self.duration))
        if with_contact:
            d["contact"] = self.contact
        return d


@dataclass(frozen=True)
class CycleResult:
    """A periodic orbit found by :func:`find_cycle`, by state name.

    Attributes
    ----------
    status : OrbitStatus
        SUCCESS, or why no orbit was found (see the module notes).
    message : str
        How the orbit was found, or what went wrong and what to change.
    label : str
        The system's name.
    state_names : tuple of str
    period : float
        T [time unit]; NaN unless status is SUCCESS.
    x0 : dict state name -> value
        A state on the orbit (on the section x[section] = x0[section]); empty unless SUCCESS.
    multipliers : (n,) complex
        Floquet multipliers, sorted by modulus, largest first (the trivial one, 1, included).
    trivial_error : float
        |lambda_trivial - 1| (an accuracy check of the monodromy matrix).
    minimum, maximum : dict state name -> value
        Extremes of each state over one period.
    phases : tuple of Phase
        Stick and slip phases of each friction contact in order along one period, starting
        with the first phase that begins after x0.
    stable : bool
        Every non-trivial multiplier inside the unit circle.
    orbit : PeriodicOrbit or None
        The shooting result (monodromy, event times, mode sequence); continuation starts from it.
    start : str
        Which way in found it (event map, shooting from x0, transient).
    mode0 : int or None
        The mode at x0 when the system's ``mode_of`` would not give it (x0 on a switching
        surface, e.g. a break-away state), else None.
    """

    status: OrbitStatus
    message: str
    label: str
    state_names: tuple
    period: float = math.nan
    x0: dict = field(default_factory=dict)
    multipliers: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=complex))
    trivial_error: float = math.nan
    minimum: dict = field(default_factory=dict)
    maximum: dict = field(default_factory=dict)
    phases: tuple = ()
    stable: bool = False
    orbit: PeriodicOrbit | None = field(default=None, repr=False)
    start: str = ""
    mode0: int | None = None

    @property
    def success(self) -> bool:
        return self.status == OrbitStatus.SUCCESS

    @property
    def x0_array(self) -> np.ndarray:
        """x0 as an array in state order."""
        return np.array([self.x0[k] for k in self.state_names]) if self.x0 else np.empty(0)

    def as_dict(self) -> dict:
        """JSON-ready: period, x0 and min/max by state name, multipliers as [re, im] (largest
        modulus first), phases as {kind, duration} (with ``contact`` when there are several),
        stable, status, message."""
        several = len({p.contact for p in self.phases}) > 1
        out = dict(system=self.label, status=self.status.name, message=self.message, start=self.start)
        if self.success:
            out.update(period=float(self.period), x0={k: float(v) for k, v in self.x0.items()},
                       multipliers=[[float(z.real), float(z.imag)] for z in self.multipliers],
                       min={k: float(v) for k, v in self.minimum.items()},
                       max={k: float(v) for k, v in self.maximum.items()},
                       phases=[p.as_dict(several) for p in self.phases], stable=bool(self.stable),
                       trivial_error=float(self.trivial_error))
        return out

    def summary(self, states=None) -> str:
        """A few lines for a terminal; ``states`` (names) limits the ranges listed, e.g. to a
        model's mechanical states (the others are counted)."""
        if not self.success:
            return f"{self.label}: no cycle ({self.status.name}): {self.message}"
        lam = ", ".join(f"{abs(z):.4g}" for z in self.multipliers)
        shown = [k for k in self.state_names if states is None or k in states] or list(self.state_names)
        lines = [f"{self.label}: {'stable' if self.stable else 'unstable'} cycle, period {self.period:.8g}",
                 f"  |multipliers| {lam}  (|lambda_trivial - 1| = {self.trivial_error:.1e})",
                 "  " + "  ".join(f"{k} in [{self.minimum[k]:.6g}, {self.maximum[k]:.6g}]" for k in shown)]
        if len(shown) < len(self.state_names):
            lines[-1] += f"  (+ {len(self.state_names) - len(shown)} internal block states)"
        if self.phases:
            several = len({p.contact for p in self.phases}) > 1
            lines.append("  phases: " + ", ".join((f"{p.contact} " if several else "") + f"{p.kind} {p.duration:.6g}"
                                                  for p in self.phases))
        lines.append(f"  found by: {self.start}")
        return "\n".join(lines)


# ------------------------------------------------------------------ the orbit's description
#: a contact without a stick mode (LuGre) sticks where |w| is below PRESLIDING_FRACTION of its
#: largest value over the orbit (presliding: on the chapter-8 loop the creep in stick is 3e-5
#: of the slip speed); a stretch above it counts as slip only when |w| reaches SLIP_FRACTION of
#: the largest value there (the bristles' ringing after a stop reaches 1 %: it is not slip)
PRESLIDING_FRACTION = 1e-3
SLIP_FRACTION = 0.1


def _pieces(segs, T) -> list:
    """Merge segments (start, end, kind, label) into phases, join the two ends of a phase the
    period starts inside, and start the list at the first phase that begins after x0."""
    pieces = []          # [kind, start, end, labels]
    for a, b, kind, name in segs:
        if pieces and pieces[-1][0] == kind:
            pieces[-1][2] = b
            if pieces[-1][3][-1] != name:
                pieces[-1][3].append(name)
        else:
            pieces.append([kind, a, b, [name]])
    if len(pieces) > 1 and pieces[0][0] == pieces[-1][0]:
        last = pieces.pop()
        first = pieces[0]
        pieces[0] = [first[0], last[1] - T, first[2], last[3] + [m for m in first[3] if m not in last[3]]]
    start_idx = next((i for i, p in enumerate(pieces) if p[1] >= 0), 0)
    return pieces[start_idx:] + pieces[:start_idx]


def _presliding_segments(c, tr, T) -> list:
    """(start, end, kind, label) of a contact without stick modes from |w| on a sampled period."""
    w = np.abs(np.array([c.velocity(x, t) for t, x in zip(tr.t, tr.x)]))
    thr = PRESLIDING_FRACTION * float(np.max(w)) if len(w) else 0.0
    label = f"|w| < {thr:.3g}"
    g = w - thr                                   # < 0: stick
    t = tr.t
    cuts = [0.0]
    for k in np.flatnonzero(np.sign(g[:-1]) != np.sign(g[1:])):
        cuts.append(float(t[k] + (t[k + 1] - t[k]) * g[k] / (g[k] - g[k + 1])) if g[k] != g[k + 1] else float(t[k]))
    cuts.append(T)
    peaks = []
    for a, b in zip(cuts[:-1], cuts[1:]):
        inside = (t >= a) & (t <= b)
        peaks.append(float(np.max(w[inside])) if np.any(inside) else 0.0)
    if len(peaks) > 1 and g[0] >= 0 and g[-1] >= 0:
        peaks[0] = peaks[-1] = max(peaks[0], peaks[-1])      # one stretch across the period's end
    segs = []
    for (a, b), peak in zip(zip(cuts[:-1], cuts[1:]), peaks):
        slip = peak >= SLIP_FRACTION * float(np.max(w))
        segs.append((a, b, "slip" if slip else "stick", "slip" if slip else label))
    return segs


def phases_of(target: Target, period: float, event_times, modes, tr=None) -> tuple:
    """Stick and slip phases of every contact in order along one period (by start time; see
    Phase), from the mode
    sequence ``modes`` (k + 1,) between the event times (k,) in [0, period]; for a contact
    without stick modes (LuGre) whose relative velocity is known, from |w| on the sampled
    period ``tr`` (below PRESLIDING_FRACTION of its largest value: stick)."""
    sys_ = target.system
    T = float(period)
    bounds = np.concatenate([[0.0], np.asarray(event_times, dtype=float), [T]])
    modes = [int(m) for m in modes]
    segs = [(bounds[i], bounds[i + 1], modes[i]) for i in range(len(modes)) if bounds[i + 1] >= bounds[i]]
    out = []
    for c in target.contacts:
        if not c.stick and c.velocity is not None and tr is not None:
            pieces = _pieces(_presliding_segments(c, tr, T), T)
        else:
            pieces = _pieces([(a, b, "stick" if m in c.stick else "slip",
                               sys_.modes[m].name if 0 <= m < sys_.n_modes else str(m)) for a, b, m in segs], T)
        for kind, a, b, names in pieces:
            out.append(Phase(kind, float(b - a), float(a % T) if T > 0 else 0.0, c.name, tuple(names)))
    order = {c.name: k for k, c in enumerate(target.contacts)}
    return tuple(sorted(out, key=lambda p: (p.start, order.get(p.contact, 0))))      # along the period


def one_period(system: PiecewiseSystem, x0, T: float, mode0: int | None = None, n: int = 4001,
               max_step: float = math.inf):
    """A simulation of one period sampled at n points (plus both sides of every event)."""
    return simulate(system, x0, (0.0, T), t_eval=np.linspace(0.0, T, n), rtol=1e-10, atol=1e-13, mode0=mode0,
                    max_step=max_step)


def _peak(system: PiecewiseSystem, x_start, mode: int, h: float, i: int) -> float | None:
    """x_i where its rate f_i vanishes on the smooth piece of length h from x_start in ``mode``
    (Illinois on the time, short flows); None when f_i does not change sign there."""
    def rate(tau):
        if tau == 0.0:
            return float(system.evaluate(x_start, mode)[i]), x_start
        fl = flow(system, x_start, tau, mode0=mode, sensitivity=False, rtol=1e-12, atol=1e-15)
        return (float(fl.f[i]), fl.x) if fl.ok and fl.mode == mode else (math.nan, None)
    a, b = 0.0, float(h)
    (fa, xa), (fb, xb) = rate(a), rate(b)
    if not (np.isfinite(fa) and np.isfinite(fb)) or fa * fb > 0:
        return None
    x = xa if abs(fa) < abs(fb) else xb
    for _ in range(60):
        c = b - fb * (b - a) / (fb - fa) if fb != fa else 0.5 * (a + b)
        if not min(a, b) < c < max(a, b):
            c = 0.5 * (a + b)
        fc, xc = rate(c)
        if xc is None:
            return None
        x = xc
        if fc == 0 or abs(b - a) <= 1e-14 * h:
            break
        if fc * fb < 0:
            a, fa = b, fb
        else:
            fa *= 0.5                    # Illinois: the end kept twice in a row is halved
        b, fb = c, fc
    return float(x[i])


def _extremes(tr, system: PiecewiseSystem | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(min, max) per state over a sampled period: the samples, both sides of every event, and
    at each interior extreme sample the state where its rate vanishes between the neighbouring
    samples (located on short flows of ``system``; a parabola through the three samples, whose
    vertex overshoots sharp peaks such as a LuGre bristle state's, without a system)."""
    x = tr.x
    lo, hi = x.min(axis=0), x.max(axis=0)
    t = tr.t
    for i in range(x.shape[1]):
        for k, better in ((int(np.argmin(x[:, i])), min), (int(np.argmax(x[:, i])), max)):
            if 0 < k < len(t) - 1 and t[k - 1] < t[k] < t[k + 1] and tr.mode[k - 1] == tr.mode[k] == tr.mode[k + 1]:
                v = None
                if system is not None:
                    v = _peak(system, np.ascontiguousarray(x[k - 1]), int(tr.mode[k]), t[k + 1] - t[k - 1], i)
                else:
                    c = np.polyfit(t[k - 1:k + 2] - t[k], x[k - 1:k + 2, i], 2)
                    if c[0] != 0:
                        tv = -c[1] / (2 * c[0])
                        if t[k - 1] - t[k] < tv < t[k + 1] - t[k]:
                            v = float(np.polyval(c, tv))
                if v is not None:
                    lo[i], hi[i] = (better(lo[i], v), hi[i]) if better is min else (lo[i], better(hi[i], v))
    if len(tr.events):
        ev = np.vstack([tr.events.x_before, tr.events.x_after])
        lo, hi = np.minimum(lo, ev.min(axis=0)), np.maximum(hi, ev.max(axis=0))
    return lo, hi


def _described(target: Target, status, message, period, x0, lam, trivial_error, tr, event_times, modes,
               stable, orbit, start, mode0=None) -> CycleResult:
    names = target.state_names
    lam = np.asarray(lam)
    lam = lam[np.argsort(-np.abs(lam), kind="stable")]
    lo, hi = _extremes(tr, target.system if orbit is None or orbit.params is None
                       else target.system.with_param_array(orbit.params))
    return CycleResult(status, message, target.label, names, float(period), dict(zip(names, map(float, x0))),
                       lam, float(trivial_error), dict(zip(names, map(float, lo))), dict(zip(names, map(float, hi))),
                       phases_of(target, period, event_times, modes, tr), bool(stable), orbit, start, mode0)


def _result(target: Target, orbit: PeriodicOrbit, start: str, shooting: ShootingOptions | None = None) -> CycleResult:
    """The CycleResult of a converged orbit. When the orbit's flow stepped over a short event
    (a stick guard that dips through zero between two steps: :func:`missed_event` on the
    sampled period), it is shot again with STEPS_PER_PERIOD steps per period at least."""
    sys_ = target.system if orbit.params is None else target.system.with_param_array(orbit.params)
    tr = one_period(sys_, orbit.x0, orbit.period, max_step=orbit.max_step)
    h = orbit.period / STEPS_PER_PERIOD
    if orbit.max_step > h and missed_event(sys_, tr):
        sopt = replace(shooting or ShootingOptions(), max_step=h)
        po = shoot(sys_, orbit.x0, orbit.period, section=orbit.section, options=sopt)
        if po.success:
            po = minimal_period(sys_, po, sopt)
            orbit = replace(po, message=f"{po.message} (shot again with steps of at most T / {STEPS_PER_PERIOD}: "
                                        f"the first flow stepped over a short event)")
            tr = one_period(sys_, orbit.x0, orbit.period, max_step=orbit.max_step)
    return _described(target, OrbitStatus.SUCCESS, orbit.message, orbit.period, orbit.x0, orbit.multipliers,
                      orbit.trivial_error, tr, orbit.event_times, orbit.modes, orbit.stable, orbit, start)


def _result_from_map(target: Target, twin, fp, why: str) -> CycleResult:
    """A Switch loop's cycle from its event map's fixed point alone (when shooting cannot run,
    e.g. beta < 1, whose flow sensitivities are unbounded at break-away): x0 the break-away
    state, period the map's slip and stick times, multipliers 1, dP^k/dd and zeros (stick
    projects out the velocity; the non-trivial multiplier of a Switch loop is the map's slope)."""
    from ..eventmap import evaluate_map
    d = fp.d
    mv = evaluate_map(twin, [d], fp.iterate)
    X0, mode0 = twin.breakaway_state([d])
    # from break-away to the k-th stick entry (intermediate stick phases included), then that stick
    to_stick = simulate(target.system, X0[0], (0.0, 1e3 * (mv.slip_time[0] + mv.stick_time[0])), mode0=int(mode0[0]),
                        stop_mode=twin.stick_mode, stop_count=fp.iterate, rtol=1e-12, atol=1e-15)
    T = float(to_stick.t_final + mv.stick_time[0])
    tr = one_period(target.system, X0[0], T, mode0=int(mode0[0]))
    ev = tr.events
    inside = ev.t < T
    modes = np.concatenate([[int(mode0[0])], ev.mode_to[inside]])
    lam = np.zeros(target.system.n_states, dtype=complex)
    lam[0], lam[1] = 1.0, fp.slope
    return _described(target, OrbitStatus.SUCCESS,
                      f"multipliers from the event map's slope dP^{fp.iterate}/dd (shooting: {why})", T, X0[0], lam,
                      0.0, tr, ev.t[inside], modes, fp.stable, None,
                      f"event map of the Switch loop (stick error d = {d:.8g}, {fp.iterate} stick phases per period)",
                      int(mode0[0]))


def _failure(target: Target, status: OrbitStatus, message: str, throw: bool) -> CycleResult:
    res = CycleResult(status, message, target.label, target.state_names)
    if throw:
        raise ConvergenceError(f"{target.label}: no cycle ({status.name}): {message}", res)
    return res


# ------------------------------------------------------------------ servo loops: the event map
def stick_twin(target: Target):
    """The exact-Switch ServoLoop with the target's parameters (event maps), or None when the
    target is not a servo loop or has no time-invariant stick map with integral action."""
    from ..models.friction import Switch
    from ..models.loop import ServoLoop
    loop = target.loop
    if loop is None:
        return None
    if target.preset is not None:
        from ..models.presets import preset as build_preset
        name, overrides = target.preset
        twin = build_preset(name, **{**overrides, "model": "switch"})
    else:
        twin = ServoLoop(loop.plant, Switch(loop.friction.curve), loop.controller, name=loop.name, units=loop.units)
    try:
        twin.require_stick_map()
    except SystemDefinitionError:
        return None
    return twin


def stick_map(target: Target):
    """What the event-map start works on: a servo loop's exact-Switch twin (:func:`stick_twin`),
    or the :class:`~hunting.eventmap.StickFamily` of a compiled model or system with one Switch
    contact whose stick phases form a one-parameter family (a PID servo written as equations);
    None otherwise (belts, several contacts, LuGre, time-dependent systems)."""
    if target.loop is not None:
        return stick_twin(target)
    from ..eventmap.family import stick_family
    try:
        return stick_family(target.source)
    except SystemDefinitionError:
        return None


def _is_family(smap) -> bool:
    from ..eventmap.family import StickFamily
    return isinstance(smap, StickFamily)


def stick_error_range(loop, max_doublings: int = 12) -> float:
    """The largest stick error worth searching for cycles of a stick map.

    Starts at the force scale D (a servo loop's Fs / (cm kp): the error whose proportional
    force alone reaches the static level; a StickFamily's :meth:`force_scale`) and doubles D
    while |P^2(+-D)| >= D (the map does not yet pull large errors inwards, so a cycle may lie
    beyond), at most ``max_doublings`` times.

    Examples
    --------
    >>> from hunting import preset
    >>> from hunting.continuation import stick_error_range
    >>> round(stick_error_range(preset("table9.1")), 6)
    0.4
    """
    from ..eventmap import evaluate_map
    D = loop.force_scale() if _is_family(loop) else _servo_force_scale(loop)
    for _ in range(max_doublings):
        mv = evaluate_map(loop, [D] if loop.odd else [D, -D], 2)
        if np.all(mv.ok) and np.all(np.abs(mv.image) < D):
            break
        D *= 2.0
    return float(D)


def search_grid(D: float, n: int = 801, n_log: int = 121, signed: bool = False) -> np.ndarray:
    """Stick errors on [0, D]: n evenly spaced plus n_log geometric ones on [1e-5 D, D / 100]
    (small cycles near the equilibrium set, such as the unstable ones of chapter 8); with
    ``signed`` their mirror images too (maps without symmetry)."""
    g = np.unique(np.concatenate([np.linspace(0.0, D, n), np.geomspace(1e-5 * D, 1e-2 * D, n_log)]))
    return np.unique(np.concatenate([-g, g])) if signed else g


@dataclass(frozen=True)
class MapStart:
    """What the event-map start found: orbit (None when not shot or shooting failed), how
    (text), hint (a state near the cycle to start a transient from, or None), fixed_point,
    twin (the stick map: a ServoLoop twin or a StickFamily), period (the Switch cycle's period,
    a guess), equilibrium (the map's FixedPoint at d = 0, when the grid reached it)."""

    orbit: PeriodicOrbit | None
    how: str
    hint: np.ndarray | None = None
    fixed_point: object = None
    twin: object = None
    period: float | None = None
    equilibrium: object = None


def _family_guess(target: Target, fam, fp, shooting: ShootingOptions | None):
    """(x, T, section) to shoot from for a StickFamily's cycle with stick error fp.d: from its
    break-away state to the k-th stick entry plus that stick phase is T; x lies inside the
    longest smooth stretch of that period (never on a switching surface)."""
    from ..eventmap import evaluate_map
    from .transient import _shooting_start
    sys_ = target.system
    mv = evaluate_map(fam, [fp.d], fp.iterate)
    X0, mode0 = fam.breakaway_state([fp.d])
    X0, mode0 = X0[0], int(mode0[0])
    bound = 1e3 * (mv.slip_time[0] + mv.stick_time[0])
    to_stick = simulate(sys_, X0, (0.0, bound), mode0=mode0, stop_mode=fam.stick_mode, stop_count=fp.iterate,
                        rtol=1e-12, atol=1e-15)
    T = float(to_stick.t_final + mv.stick_time[0])
    tr = one_period(sys_, X0, T, mode0=mode0, n=2001)
    rng = np.ptp(tr.x, axis=0)
    sopt = shooting or ShootingOptions()
    start = _shooting_start(sys_, X0, T, np.maximum(rng, 1e-12 * max(float(rng.max()), 1e-300)),
                            StartOptions(rtol=sopt.rtol, atol=sopt.atol), mode0=mode0)
    if start is None:
        return X0, T, int(np.argmax(rng)), mode0
    return start[0], T, start[1], None


def event_map_start(target: Target, which: str = "stable", d_max: float | None = None,
                    shooting: ShootingOptions | None = None) -> MapStart:
    """A cycle from the stick-to-stick event map: a servo loop's Switch twin, or the stick
    family of a model with one Switch contact (:func:`stick_map`).

    The fixed points of P^2 on [0, d_max] ([-d_max, d_max] for maps without symmetry; default
    :func:`stick_error_range`) give the stick error of the stable (largest) or unstable
    (smallest) cycle; a short simulation from its break-away state the shooting guess (for
    LuGre the bristle state starts at its steady-state value); shooting converges on the
    system's own cycle.

    Examples
    --------
    >>> from hunting.continuation import event_map_start, resolve
    >>> ms = event_map_start(resolve("table9.1", {"P": 10}))
    >>> round(ms.fixed_point.d, 4), ms.orbit.stable
    (0.2523, True)
    """
    from ..eventmap import fixed_points
    twin = stick_map(target)
    if twin is None:
        return MapStart(None, "no stick map (not a time-invariant servo loop with integral action, nor a model "
                              "with one Switch contact whose stick phases form a one-parameter family)")
    family = _is_family(twin)
    D = float(d_max) if d_max is not None else stick_error_range(twin)
    fps = fixed_points(twin, search_grid(D, signed=not twin.odd), 2)
    eq = next((f for f in fps if f.kind == "equilibrium"), None)
    fps = [f for f in fps if f.kind == "cycle"]
    cand = [f for f in fps if f.stable == (which == "stable")]
    if family:
        names = twin.system.state_names
        what = f"event map of its stick phases ({names[twin.d_state]} frozen, {names[twin.drift_state]} drifting)"
        span = f"[{-D:.6g}, {D:.6g}]" if not twin.odd else f"[0, {D:.6g}]"
    else:
        what, span = "event map of the Switch twin", f"[0, {D:.6g}]"
    if not cand:
        found = ", ".join(f"d = {f.d:.6g} ({'stable' if f.stable else 'unstable'})" for f in fps) or "none"
        return MapStart(None, f"the {what} has no {which} cycle on {span} (cycles: {found})", twin=twin,
                        equilibrium=eq)
    pick = (lambda c: abs(c.d))
    f = max(cand, key=pick) if which == "stable" else min(cand, key=pick)
    how = f"{what} (stick error d = {f.d:.8g} on {span})"
    if family:
        x0, T, s, mode0 = _family_guess(target, twin, f, shooting)
        po = shoot(target.system, x0, T, section=s, options=shooting) if mode0 is None else None
        how += ", then shooting"
        if po is not None and po.success:
            return MapStart(minimal_period(target.system, po, shooting), how, None, f, twin, T, eq)
        why = po.message if po is not None else "no start inside the orbit"
        return MapStart(None, f"{how} failed: {why}", x0 if mode0 is None else None, f, twin, T, eq)
    x0, T = guess_from_stick_error(twin, f.d)
    loop = target.loop
    if loop.n_states == 4:
        # LuGre: the Switch cycle's slip state with the bristles at their steady state starts a
        # transient (the LuGre cycle's stick phases creep, so shooting straight from the Switch
        # guess often drifts to the equilibrium set)
        c = loop.friction.curve.positive
        g = float(c.level(x0[1])) if x0[1] != 0 else c.Fs
        return MapStart(None, how, np.append(x0, g / loop.friction.sigma0), f, twin, T, eq)
    po = shoot(target.system, x0, T, options=shooting)
    how += ", then shooting"
    if po.success:
        return MapStart(po, how, None, f, twin, T, eq)
    return MapStart(None, f"{how} failed: {po.message}", x0, f, twin, T, eq)


def _default_start(target: Target, smap=None) -> np.ndarray:
    """A servo loop's regulator task (from q = 0 to q_d, or an error of the stick scale when
    q_d = 0); for a stick family, its stick state at the force scale (a model's initial values
    are often its equilibrium); zeros (or the model's initial values) otherwise."""
    loop = target.loop
    if loop is None:
        if smap is not None and _is_family(smap):
            x = np.zeros(target.system.n_states)
            x[smap.surface_state] = smap.surface_value
            x[smap.d_state] = smap.d0 - 1.5 * smap.force_scale()
            return x
        return target.state(None)
    qd = loop.plant.setpoint
    if qd != 0:
        return loop.state(x1=-qd)
    return loop.state(x1=-_servo_force_scale(loop))


def _servo_force_scale(loop) -> float:
    """A servo loop's stick-error scale [position unit]: the larger stick bound over cm kp (the
    error whose proportional force alone reaches it); 1.0 without proportional action."""
    lo, hi = loop.friction.stick_set
    k = loop.plant.motor_constant * loop.controller.kp
    return max(abs(lo), abs(hi)) / k if k > 0 else 1.0


def _section_at(system: PiecewiseSystem, x: np.ndarray, T: float) -> int:
    """The state along which the flow at x moves fastest relative to the state's range over a
    simulation of length T from x (states whose range is integration noise excluded)."""
    from .transient import noise_floor
    f = system.evaluate(x)
    tr = simulate(system, x, (0.0, T), rtol=1e-10, atol=1e-13, max_events=20_000)
    rng = np.ptp(tr.x, axis=0) if tr.x.shape[0] > 1 else np.zeros_like(x)
    floor = noise_floor(StartOptions())
    if not np.any(rng > floor):
        scale = np.maximum(np.abs(x), 1e-3 * max(float(np.max(np.abs(x))), 1e-300))
        return int(np.argmax(np.abs(f) / scale))
    return int(np.argmax(np.where(rng > floor, np.abs(f) / np.maximum(rng, floor), -1.0)))


def _transient(target: Target, xs, period_guess, start: StartOptions | None, shooting: ShootingOptions | None,
               throw: bool = False) -> CycleResult:
    """The transient from xs until the return map settles, shooting from its returns."""
    sys_ = target.system
    tried = []
    sopt = shooting or ShootingOptions()
    early = replace(sopt, max_iter=min(sopt.max_iter, 12))

    def try_shoot(x, T, s, mismatch, settled):
        po = shoot(sys_, x, T, section=s, options=sopt if settled else early)
        if po.success:
            po = minimal_period(sys_, po, sopt)
        tried.append(po)
        return po.success and (po.stable or settled)

    st = settle(sys_, xs, period_guess=period_guess, options=start, on_candidate=try_shoot)
    if st.status == OrbitStatus.SUCCESS:
        how = (f"transient simulation to t = {st.t_end:.6g} ({st.returns.describe(sys_)} agree to "
               f"{st.mismatch:.1e}), then shooting")
        return _result(target, tried[-1], how, shooting)
    if tried and st.status == OrbitStatus.NO_RECURRENCE:
        last = tried[-1]
        status = last.status if not last.success else OrbitStatus.NO_RECURRENCE
        msg = (f"{st.message}; shooting from the returns gave {last.status.name}: {last.message}" if not last.success
               else f"{st.message}; shooting from a return converged to an unstable cycle only")
    else:
        status, msg = st.status, st.message
        if tried and not tried[-1].success:
            msg += f"; shooting from the returns gave {tried[-1].status.name}: {tried[-1].message}"
    return _failure(target, status, _with_advice(msg, status), throw)


def _with_advice(msg: str, status: OrbitStatus) -> str:
    """The message with the status' advice appended once."""
    advice = status.advice
    if advice in msg:
        return msg
    return f"{msg}. {advice[0].upper()}{advice[1:]}"


# ------------------------------------------------------------------ the front end
def find_cycle(system, x0=None, period_guess: float | None = None, params: dict | None = None, *,
               which: str = "stable", d_max: float | None = None, start: StartOptions | None = None,
               shooting: ShootingOptions | None = None, throw: bool = False) -> CycleResult:
    """A periodic orbit of a system, from a rough start or none.

    Parameters
    ----------
    system : str or ServoLoop or compiled model or PiecewiseSystem
        A preset name (``"table8.1-lugre"``), a ServoLoop, a model from ``hunting.model(...)``
        or any autonomous PiecewiseSystem.
    x0 : mapping state name -> value, or (n,) array, optional
        Where to start (unnamed states start at 0). Default: for servo loops the Switch twin's
        event map (then the regulator task q: 0 -> q_d); otherwise zeros.
    period_guess : float, optional
        With it, shooting is tried straight from x0 first (this reaches unstable cycles), and
        the transient's chunks and bound scale with it.
    params : mapping name -> value, optional
        Parameter overrides by name (preset parameters for a preset name).
    which : "stable" or "unstable"
        Which cycle of a servo loop's event map (the unstable one is reached only this way or
        by shooting from x0 with period_guess).
    d_max : float, optional
        Largest stick error searched on the event map (default: the whole range the map
        reaches, :func:`stick_error_range`).
    start : StartOptions
        Bounds and tolerances of the transient.
    shooting : ShootingOptions
    throw : bool
        Raise ConvergenceError (carrying the CycleResult) when no cycle is found.

    Returns
    -------
    CycleResult

    Examples
    --------
    The chapter-8 LuGre loop at K = 0.04 from the regulator task of Fig. 8.2:

    >>> from hunting import find_cycle
    >>> res = find_cycle("table8.1-lugre", {"x1": -1.0}, params={"K": 0.04})
    >>> res.status.name, round(res.period, 3), res.stable
    ('SUCCESS', 10.379, True)
    >>> round(res.maximum["x1"], 4)
    0.0495

    A start inside the stick set stays there:

    >>> find_cycle("table9.1", {"x3": 0.01}).status.name
    'EQUILIBRIUM'
    """
    if which not in ("stable", "unstable"):
        raise SystemDefinitionError(f"which = {which!r} is not allowed: use 'stable' or 'unstable'")
    if period_guess is not None and not (np.isfinite(period_guess) and period_guess > 0):
        raise SystemDefinitionError(f"period_guess = {period_guess!r} is not allowed: it must be a finite number > 0")
    if d_max is not None and not (np.isfinite(d_max) and d_max > 0):
        raise SystemDefinitionError(f"d_max = {d_max!r} is not allowed: it must be a finite number > 0")
    target = resolve(system, params)
    sys_ = target.system
    _require_autonomous(target)
    notes = []
    hint = None
    smap = None
    if x0 is None and period_guess is None:
        try:
            ms = event_map_start(target, which, d_max, shooting)
        except (SystemDefinitionError, ConvergenceError) as e:
            if target.loop is not None:
                raise
            # a model's stick family whose map cannot be evaluated somewhere: the transient decides
            ms = MapStart(None, f"the event map of its stick phases failed ({e})")
        smap = ms.twin
        if ms.orbit is not None:
            return _result(target, ms.orbit, ms.how, shooting)
        exact = _is_family(smap) or (target.loop is not None and target.loop.model_code == S.MODEL_SWITCH)
        if ms.fixed_point is not None and target.loop is not None and target.loop.model_code == S.MODEL_SWITCH:
            return _result_from_map(target, ms.twin, ms.fixed_point, ms.how)
        eq = ms.equilibrium
        if (smap is not None and exact and which == "stable" and ms.fixed_point is None and eq is not None
                and eq.stable):
            # the map covers every stick error up to the range where it pulls errors inwards:
            # with no cycle there and an attracting equilibrium set, every motion ends at rest
            return _failure(target, OrbitStatus.EQUILIBRIUM,
                            f"{ms.how}, and its equilibrium set d = 0 attracts (|dP^2/dd| = {abs(eq.slope):.3g} "
                            f"< 1 there): every motion from that range ends at rest in the stick set. There is "
                            f"no cycle at these parameters: change them (e.g. the gains)", throw)
        hint = ms.hint
        if smap is not None or ms.how.startswith("the event map of its stick phases failed"):
            notes.append(ms.how)
        if which == "unstable":
            # a transient never settles on an unstable cycle: shoot from the map's guess or stop
            if hint is None:
                why = (_with_advice(ms.how, OrbitStatus.NO_CYCLE) if smap is not None else
                       f"{ms.how}: give x0 and period_guess near the unstable cycle to shoot "
                       f"from there (a simulation never settles on it)")
                return _failure(target, OrbitStatus.NO_CYCLE, why, throw)
            po = shoot(sys_, hint, ms.period, section=_section_at(sys_, hint, ms.period), options=shooting)
            if po.success and not po.stable:
                return _result(target, po, f"{ms.how}, then shooting", shooting)
            why = po.message if not po.success else "shooting converged on a stable cycle"
            return _failure(target, po.status if not po.success else OrbitStatus.NOT_CONVERGED,
                            f"{ms.how}, then shooting: {why}", throw)
        if hint is not None and ms.period:
            # a transient from the cycle's neighbourhood, chunks scaled by the Switch period
            st_res = _transient(target, hint, ms.period, start, shooting)
            if st_res.success:
                return replace(st_res, start=f"{ms.how}, then a {st_res.start}")
            notes.append(f"a transient from there: {st_res.status.name}")
    if x0 is not None:
        xs = target.state(x0)
    elif hint is not None:
        xs = hint
    else:
        xs = _default_start(target, smap)
    if period_guess is not None:
        s = _section_at(sys_, xs, float(period_guess))
        po = shoot(sys_, xs, float(period_guess), section=s, options=shooting)
        how = f"shooting from x0 with period guess {period_guess:g} (section {sys_.state_names[s]})"
        if po.success:
            return _result(target, minimal_period(sys_, po, shooting), how, shooting)
        notes.append(f"{how} failed: {po.message}")
    res = _transient(target, xs, period_guess, start, shooting)
    if res.success:
        return res
    if notes:
        res = replace(res, message="; ".join(notes) + "; then " + res.message)
    if throw:
        raise ConvergenceError(f"{target.label}: no cycle ({res.status.name}): {res.message}", res)
    return res


def _require_autonomous(target: Target) -> None:
    """Raise when the vector field depends on t (a periodic orbit of a time-forced system has
    the forcing's phase as well: the search here assumes f(x) alone)."""
    sys_ = target.system
    rng = np.random.default_rng(1)
    n = sys_.n_states
    mode = sys_.time_dependent_mode([target.state(None), rng.normal(size=n), rng.normal(size=n)])
    if mode is not None:
        raise SystemDefinitionError(
            f"{target.label} depends on the time t (its vector field changes with t in mode "
            f"{sys_.modes[mode].name!r}): the cycle search needs an autonomous system. Write the drive "
            f"as states (e.g. a coordinate relative to a moving reference, q - vd*t, as a state), or "
            f"simulate the forced response instead")
