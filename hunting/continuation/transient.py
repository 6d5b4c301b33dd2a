"""The transient before shooting: simulate until the return map on a section settles.

The motion is simulated in chunks from the user's state. Returns are counted on a section
chosen from the first chunk that moves:

- a **stick entry** of a friction contact when one recurs: the integrator locates events
  exactly, the state after a stick entry lies on the switching surface, and states that are
  numerical noise (block states of size 1e-23, say) play no part in the choice;
- else upward crossings of x[s] = c, with s among the states that move well above the
  integration's noise (range at least ``NOISE_ATOL`` absolute tolerances) and c the middle of
  its range; each crossing is located exactly (Newton on the crossing time with short flows).

The map has settled when returns p apart (p = 1, 2, ...: returns per period) agree to
``settle_tol`` in every state, scaled by that state's range (noise states by a floor), and in
the time between them. Shooting then starts inside the orbit's longest smooth stretch (the
middle of the longest time between two events), with the section on the state moving fastest
there relative to its range, so the start never sits on a switching surface.

Each chunk also checks the other ends: the motion dies out (every state at rest; or the
contacts stuck with everything else frozen or drifting so slowly that no stick guard is reached
within the bound; or returns that converge while the time between them grows geometrically:
the motion creeps onto the equilibrium set through ever longer stick phases), or grows without
bound (escape). Every loop is bounded: transient time, chunks, returns examined.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import SystemDefinitionError, status_message
from ..integrate.simulate import simulate
from ..system import PiecewiseSystem
from .flow import flow
from .status import OrbitStatus

#: a state whose range is below NOISE_ATOL absolute tolerances is integration noise: it is not
#: chosen as a section and its differences are measured against that floor
NOISE_ATOL = 1e4
#: modes in which a friction contact is held (a stuck system may be at rest in them)
_STICK_KINDS = ("stick", "filippov")


@dataclass(frozen=True)
class StartOptions:
    """Bounds and tolerances of the transient that precedes shooting.

    Parameters
    ----------
    t_max : float, optional
        Bound on the simulated transient [time unit of the system]; default 2000 period guesses
        when a period guess is given, else 1e4.
    chunk : float, optional
        First chunk length; default 4 period guesses, else 1. A chunk with fewer than three
        returns doubles the next one; one with more than 60 shortens it.
    max_chunks : int
        Bound on the number of chunks.
    settle_tol : float
        Returns p apart that agree to this (max-norm, each state scaled by its range over the
        last chunk) are settled: shooting starts there.
    try_tol : float
        Shooting is tried early once returns agree to this, and its result is kept when it is a
        stable orbit (an unstable one is kept only once the returns agree to ``settle_tol``).
    max_multiplicity : int
        Largest number of returns per period tried.
    rest_tol : float
        A chunk in which every state moves less than ``rest_tol`` times its motion over the
        whole transient (or less than the noise floor) is at rest (status EQUILIBRIUM).
    creep_ratio : float
        Returns that converge while each time between returns p apart is at least
        ``creep_ratio`` times the one before (over ``creep_returns`` returns, not slowing
        down) creep onto the equilibrium set (status EQUILIBRIUM).
    creep_returns : int
    escape : float
        max |x| beyond ``escape`` times the start's size (the larger of |x0| and the first
        chunk's range) is an escape (status ESCAPE).
    max_shots : int
        Bound on shooting attempts from the transient.
    max_events, max_steps : int
        Bounds per chunk; a chunk that reaches one ends early and the next is shorter (a LuGre
        loop coming to rest chatters on v = 0 at the tolerance's level).
    method, rtol, atol : integration of the transient.

    Examples
    --------
    >>> from hunting.continuation import StartOptions
    >>> StartOptions(t_max=500.0).settle_tol
    1e-06
    """

    t_max: float | None = None
    chunk: float | None = None
    max_chunks: int = 60
    settle_tol: float = 1e-6
    try_tol: float = 1e-3
    max_multiplicity: int = 8
    rest_tol: float = 1e-7
    creep_ratio: float = 1.05
    creep_returns: int = 5
    escape: float = 1e6
    max_shots: int = 4
    max_events: int = 20_000
    max_steps: int = 200_000
    method: str = "dop853"
    rtol: float = 1e-10
    atol: float = 1e-13

    def __post_init__(self):
        for name in ("t_max", "chunk"):
            v = getattr(self, name)
            if v is not None and not (np.isfinite(v) and v > 0):
                raise SystemDefinitionError(f"{name} = {v!r} is not allowed: it must be a finite number > 0 or None")
        for name in ("settle_tol", "try_tol", "rest_tol", "escape", "rtol", "atol"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise SystemDefinitionError(f"{name} = {v!r} is not allowed: it must be a finite number > 0")
        if not (np.isfinite(self.creep_ratio) and self.creep_ratio > 1):
            raise SystemDefinitionError(f"creep_ratio = {self.creep_ratio!r} is not allowed: it must be a finite "
                                        f"number > 1")
        for name in ("max_chunks", "max_multiplicity", "max_shots", "max_events", "max_steps", "creep_returns"):
            v = getattr(self, name)
            if int(v) != v or v < 1:
                raise SystemDefinitionError(f"{name} = {v!r} is not allowed: it must be a positive integer")
        if self.method not in ("dop853", "dp5", "radau"):
            raise SystemDefinitionError(f"method = {self.method!r} is not allowed: use dop853, dp5 or radau")


@dataclass(frozen=True)
class Section:
    """Where the transient counts returns.

    kind : "event" (returns are the states after the events ``key`` = (mode_from, guard,
    mode_to), located by the integrator) or "state" (upward crossings of x[state] = level)."""

    kind: str
    state: int = -1
    level: float = math.nan
    key: tuple = ()

    def describe(self, system: PiecewiseSystem) -> str:
        """E.g. "entries into stick from slip-" or "returns to v = 0.0123"."""
        if self.kind == "event":
            a, _, b = self.key
            return f"entries into {system.modes[b].name} from {system.modes[a].name}"
        return f"returns to {system.state_names[self.state]} = {self.level:.6g}"


@dataclass(frozen=True)
class Settled:
    """Where the transient led.

    status : OrbitStatus (SUCCESS: a settled or nearly settled return map); message;
    x0 : (n,) the shooting start (inside the orbit's longest smooth stretch), period : time
    between returns ``multiplicity`` apart; section : the state held fixed when shooting from
    x0; returns : the Section the returns were counted on; mismatch : the scaled distance of
    returns ``multiplicity`` apart; t_end : transient time simulated; x_end : state at t_end."""

    status: OrbitStatus
    message: str
    x0: np.ndarray | None = None
    period: float = math.nan
    section: int = -1
    returns: Section | None = None
    multiplicity: int = 0
    mismatch: float = math.inf
    t_end: float = 0.0
    x_end: np.ndarray | None = None


def noise_floor(opt: StartOptions) -> float:
    """Ranges below this are integration noise (NOISE_ATOL absolute tolerances)."""
    return NOISE_ATOL * opt.atol


def _choose_event(tr, system: PiecewiseSystem):
    """The event key (mode_from, guard, mode_to) to count returns on, from a chunk's events:
    among the entries into a stick mode that recur and occur in the chunk's second half, the
    one with the fewest occurrences (but at least two). None when there is none. (Other events
    make poorer sections: a LuGre loop's velocity crosses zero a varying number of times while
    its bristles ring at the start of a stick phase.)"""
    ev = tr.events
    if len(ev) < 2:
        return None
    keys = list(zip(ev.mode_from.tolist(), ev.guard.tolist(), ev.mode_to.tolist()))
    late = set(k for k, t in zip(keys, ev.t) if t >= 0.5 * tr.t_final)
    counts = {}
    for k in keys:
        counts[k] = counts.get(k, 0) + 1
    cands = [k for k in late if counts[k] >= 2 and k[2] >= 0 and system.modes[k[2]].kind in _STICK_KINDS]
    if not cands:
        return None
    return min(cands, key=lambda k: (counts[k], k))


def _enters_stick(tr, system: PiecewiseSystem) -> bool:
    """Whether a chunk has a stick entry (then wait for one that recurs before choosing a state
    section)."""
    to = tr.events.mode_to
    return bool(np.any([0 <= m < system.n_modes and system.modes[m].kind in _STICK_KINDS for m in to]))


def _choose_state(x: np.ndarray, ok: np.ndarray, floor: float):
    """(state index, level) for a state section from a chunk's output x (m, n): among the states
    that move above the noise floor and oscillate most (range relative to size at least half the
    largest), the one crossing the middle of its range upwards least often but at least twice (a
    clean section: a velocity crosses its middle several times a period, a position once); None
    when nothing oscillates."""
    lo, hi = x.min(axis=0), x.max(axis=0)
    rng = hi - lo
    moving = rng > floor
    if not np.any(moving):
        return None
    rel = np.where(moving, rng / (np.max(np.abs(x), axis=0) + 1e-300), 0.0)
    best = None
    for i in np.flatnonzero(moving & (rel >= 0.5 * rel.max())):
        c = 0.5 * (lo[i] + hi[i])
        s = x[:, i]
        count = int(np.count_nonzero(ok & (s[:-1] < c) & (s[1:] >= c)))
        if count >= 2 and (best is None or count < best[0]):
            best = (count, int(i), float(c))
    return None if best is None else best[1:]


def _refine_return(system: PiecewiseSystem, xk, mode, h, s, c, amp, opt: StartOptions, direction: int = 1):
    """Time tau in (0, h] and state where x[s] crosses c upward (``direction`` 1; -1:
    downward) on the smooth piece starting at xk in ``mode`` (no event inside): Newton on tau
    with bisection safeguards, on short flows."""
    a, b = 0.0, float(h)
    sg = 1.0 if direction >= 0 else -1.0
    fa = sg * (xk[s] - c)
    fl_b = flow(system, xk, b, mode0=mode, sensitivity=False, rtol=opt.rtol, atol=opt.atol)
    fb = sg * (fl_b.x[s] - c)
    if not fl_b.ok or fa >= 0 or fb < 0:
        return None
    tau = b * (-fa) / (fb - fa)
    x = fl_b.x
    for _ in range(30):
        fl = flow(system, xk, tau, mode0=mode, sensitivity=False, rtol=opt.rtol, atol=opt.atol) if tau > 0 else None
        if fl is None or not fl.ok:
            return None
        x = fl.x
        g = sg * (x[s] - c)
        if abs(g) <= 1e-12 * amp:
            break
        if g < 0:
            a = tau
        else:
            b = tau
        fs = sg * fl.f[s]
        step = tau - g / fs if np.isfinite(fs) and fs > 0 else 0.5 * (a + b)
        new = step if a < step < b else 0.5 * (a + b)
        if abs(new - tau) <= 1e-15 * h:
            break
        tau = new
    x = x.copy()
    x[s] = c
    return tau, x


def _state_returns(system, tr, s, c, amp, opt, keep: int):
    """The last ``keep`` upward crossings of x[s] = c in a chunk's trajectory, located exactly,
    and the total count. Crossings at an event (a reset that jumps through c) do not count."""
    xs = tr.x[:, s]
    t = tr.t
    idx = np.flatnonzero((xs[:-1] < c) & (xs[1:] >= c) & (t[1:] > t[:-1]) & (tr.mode[:-1] == tr.mode[1:]))
    out_t, out_x = [], []
    for k in idx[-keep:]:
        r = _refine_return(system, tr.x[k], int(tr.mode[k]), t[k + 1] - t[k], s, c, amp, opt)
        if r is None:
            continue
        out_t.append(t[k] + r[0])
        out_x.append(r[1])
    return np.array(out_t), np.array(out_x).reshape(-1, system.n_states), idx.size


def _event_returns(tr, key, keep: int):
    """Times and states after the chunk's events ``key`` (the last ``keep``), and their count."""
    ev = tr.events
    sel = np.flatnonzero((ev.mode_from == key[0]) & (ev.guard == key[1]) & (ev.mode_to == key[2]))
    return ev.t[sel[-keep:]], ev.x_after[sel[-keep:]], sel.size


def _mismatch(R_t, R_x, p, scale):
    """Scaled distance of returns p apart over the last two comparisons (states and periods)."""
    k = len(R_t)
    if k < p + 2:
        return math.inf
    d = 0.0
    for j in (k - 1, k - 2):
        d = max(d, float(np.max(np.abs(R_x[j] - R_x[j - p]) / scale)))
    T1, T2 = R_t[k - 1] - R_t[k - 1 - p], R_t[k - 2] - R_t[k - 2 - p]
    return max(d, abs(T1 - T2) / max(T1, 1e-300))


def _creeping(R_t, R_x, scale, opt: StartOptions):
    """(p, growth) when the times between returns p apart (p = 1, 2) grow by at least
    ``creep_ratio`` from one to the next over the last ``creep_returns`` of them without slowing
    down, while the returns' states converge: the motion creeps onto a set of rest through ever
    longer phases (e.g. a PID servo whose stick errors shrink and stick phases lengthen).
    A transient converging to a cycle has period ratios that approach 1 instead."""
    m = opt.creep_returns
    for p in (1, 2):
        k = len(R_t)
        if k < p + m + 1:
            continue
        idx = np.arange(k - m, k)
        T = R_t[idx] - R_t[idx - p]
        r = T[1:] / T[:-1]
        if not (np.all(r >= opt.creep_ratio) and r[-1] >= 0.98 * r[0]):
            continue
        d = np.array([np.max(np.abs(R_x[j] - R_x[j - p]) / scale) for j in idx])
        if d[-1] < d[0]:
            return p, float(np.exp(np.mean(np.log(r))))
    return None


def _stuck(system, tr, motion, t_now, t_max, opt: StartOptions):
    """Predicted time to break-away (from now) when a chunk without events stays in a stick
    mode with every state frozen (range at most 1e-3 of its motion) or drifting monotonically:
    the mode's guards extrapolated linearly over the chunk; None when that does not apply."""
    mode = tr.mode_final
    if len(tr.events) or not 0 <= mode < system.n_modes or system.modes[mode].kind not in _STICK_KINDS:
        return None
    x = tr.x
    if x.shape[0] < 2 or tr.t_final <= 0:
        return None
    rng = np.ptp(x, axis=0)
    dx = np.diff(x, axis=0)
    mono = np.all(dx >= 0, axis=0) | np.all(dx <= 0, axis=0)
    if not np.all((rng <= 1e-3 * motion + noise_floor(opt)) | mono):
        return None
    g0 = system.guard_values(x[0], mode)
    g1 = system.guard_values(x[-1], mode)
    rate = (g1 - g0) / tr.t_final
    fire = system.directions[mode]
    t_hit = math.inf
    for i in range(system.n_guards):
        g, r = g1[i], rate[i]
        if r == 0 or not np.isfinite(r):
            continue
        if (fire[i] <= 0 and g > 0 and r < 0) or (fire[i] >= 0 and g < 0 and r > 0):
            t_hit = min(t_hit, abs(g / r))
    return t_hit if t_now + t_hit > t_max else None


def _shooting_start(system: PiecewiseSystem, x_ret, T, scale, opt: StartOptions, mode0: int | None = None,
                    n: int = 401):
    """(x, section): where to shoot from on the orbit through x_ret (one period T; ``mode0``
    the mode at x_ret when it lies on a switching surface).

    The section is x[s] = c with c the middle of the range of a state s that moves well above
    the noise floor: among those states, the one crossing its middle least often (a position crosses twice a period,
    so the section stays transversal while a continuation changes the orbit), ties to the first
    in state order (positions usually come first: the continuation takes fewer, longer steps on
    them); x is one of its crossings, located exactly. Crossings in a stick mode (its
    surface state is fixed: Newton would move it off, and the mode at the start would become
    ambiguous) or within T / 200 of an event are not taken. Without such a crossing: the
    sample where the orbit moves fastest relative to ``scale``. None when the simulation
    fails."""
    tr = simulate(system, x_ret, (0.0, T), t_eval=np.linspace(0.0, T, n), mode0=mode0, rtol=opt.rtol, atol=opt.atol,
                  max_events=opt.max_events, max_steps=opt.max_steps)
    if not tr.success:
        return None
    x, t, md = tr.x, tr.t, tr.mode.astype(np.int64)
    ev = tr.events.t
    floor = noise_floor(opt)
    free = np.array([0 <= m < system.n_modes and system.modes[m].kind not in _STICK_KINDS for m in md])
    if len(ev):
        free &= np.min(np.abs(t[:, None] - ev[None, :]), axis=1) >= T / 200
    ok = free[:-1] & free[1:] & (md[:-1] == md[1:]) & (t[1:] > t[:-1])
    lo, hi = x.min(axis=0), x.max(axis=0)
    rng = hi - lo
    moving = rng > floor
    best = None
    if np.any(moving):
        for i in np.flatnonzero(moving):
            c = 0.5 * (lo[i] + hi[i])
            up = (x[:-1, i] < c) & (x[1:, i] >= c)
            down = (x[:-1, i] > c) & (x[1:, i] <= c)
            count = int(np.count_nonzero(up | down))          # how often it crosses, anywhere
            ks = np.flatnonzero(ok & (up | down))             # where a start may lie
            if ks.size == 0:
                continue
            if best is None or count < best[0]:
                best = (count, i, int(ks[0]), c, 1 if up[ks[0]] else -1)
    if best is not None:
        _, i, k, c, direction = best
        r = _refine_return(system, x[k], int(md[k]), t[k + 1] - t[k], i, c, rng[i], opt, direction)
        if r is not None:
            return r[1], int(i)
    # no clean crossing: the free sample where the orbit moves fastest
    sc = np.where(moving, np.maximum(scale, floor), np.inf)
    speeds = [(float(np.max(np.abs(system.evaluate(x[k], int(md[k]))) / sc)), k) for k in np.flatnonzero(free)]
    if not speeds:
        return np.asarray(x_ret, dtype=float).copy(), int(np.argmax(rng))
    _, k = max(speeds)
    f = np.abs(system.evaluate(x[k], int(md[k]))) / sc
    return x[k].copy(), int(np.argmax(f))


def settle(system: PiecewiseSystem, x0, *, period_guess: float | None = None, options: StartOptions | None = None,
           on_candidate=None) -> Settled:
    """Simulate from ``x0`` until the return map on a section settles (see the module notes).

    Parameters
    ----------
    system : PiecewiseSystem (autonomous)
    x0 : (n,) start
    period_guess : float, optional
        Sets the first chunk (4 periods) and the default bound (2000 periods).
    options : StartOptions
    on_candidate : callable (x0, period, section, mismatch, settled) -> bool, optional
        Called when returns agree to ``try_tol`` (at most ``max_shots`` times) with a shooting
        start (x0 inside the orbit, ``section`` the state to hold fixed); returning True ends
        the search with SUCCESS (the caller's shooting converged).

    Returns
    -------
    Settled

    Examples
    --------
    A start on the chapter-9 cycle settles on its first returns (entries into stick):

    >>> from hunting import preset
    >>> from hunting.continuation import settle
    >>> st = settle(preset("table9.1").system, [-0.25, 0.0, 0.0])
    >>> st.status.name, st.returns.describe(preset("table9.1").system), round(st.period, 4)
    ('SUCCESS', 'entries into stick from slip+', 2.4053)
    """
    opt = options or StartOptions()
    x = system.check_state(x0).copy()
    n = system.n_states
    t_max = opt.t_max or (2000.0 * period_guess if period_guess else 1e4)
    L = opt.chunk or (4.0 * period_guess if period_guess else 1.0)
    L = min(L, t_max)
    floor = noise_floor(opt)
    t = 0.0
    mode = None
    section: Section | None = None
    R_t, R_x = np.empty(0), np.empty((0, n))
    motion = np.zeros(n)
    size0 = float(np.max(np.abs(x)))
    shots = 0
    best = None
    keep = 2 * opt.max_multiplicity + 4
    for _chunk in range(opt.max_chunks):
        if t >= t_max:
            break
        span = min(L, t_max - t)
        tr = simulate(system, x, (0.0, span), method=opt.method, rtol=opt.rtol, atol=opt.atol, mode0=mode,
                      max_events=opt.max_events, max_steps=opt.max_steps, growth=None)   # escape: checked below
        xs = tr.x
        finite = np.all(np.isfinite(xs))
        if not finite or tr.status.name == "NON_FINITE":
            return Settled(OrbitStatus.ESCAPE, f"the state became non-finite at t = {t + tr.t_final:.6g}",
                           t_end=t + tr.t_final, x_end=tr.x_final.copy())
        if _chunk == 0:
            size0 = max(size0, float(np.max(xs.max(axis=0) - xs.min(axis=0))), 1e-300)
            first = float(tr.t_final)
        big = float(np.max(np.abs(xs)))
        if big > opt.escape * size0:
            return Settled(OrbitStatus.ESCAPE, f"max |x| = {big:.3g} by t = {t + tr.t_final:.6g}: more than "
                           f"{opt.escape:g} times the start's size ({size0:.3g}: the larger of |x0| and the range "
                           f"of the first {first:.3g} time units)", t_end=t + tr.t_final, x_end=tr.x_final.copy())
        partial = tr.status.name in ("MAX_EVENTS", "MAX_STEPS")     # the chunk ended early: shorter ones next
        if not tr.success and not partial:
            return Settled(OrbitStatus.INTEGRATION_FAILED, f"the transient's integration stopped at t = "
                           f"{t + tr.t_final:.6g} with {tr.status.name}: {status_message(tr.status)}",
                           t_end=t + tr.t_final, x_end=tr.x_final.copy())
        rng = xs.max(axis=0) - xs.min(axis=0)
        motion = np.maximum(motion, np.abs(xs - x).max(axis=0))
        t_chunk_end = t + tr.t_final
        if _chunk > 0 and np.all(rng <= opt.rest_tol * motion + floor):
            return Settled(OrbitStatus.EQUILIBRIUM, f"the motion came to rest by t = {t_chunk_end:.6g} "
                           f"(every state moved less than {opt.rest_tol:g} of its motion over the last {span:.3g} time units)",
                           t_end=t_chunk_end, x_end=tr.x_final.copy())
        if _chunk > 0:
            t_hit = _stuck(system, tr, motion, t_chunk_end, t_max, opt)
            if t_hit is not None:
                return Settled(OrbitStatus.EQUILIBRIUM, f"the motion stuck ({system.modes[tr.mode_final].name}) by "
                               f"t = {t:.6g} and stays: at the drift of the last {tr.t_final:.3g} time units no stick "
                               f"guard is reached before t = {t_chunk_end + t_hit:.3g} (the transient's bound is "
                               f"{t_max:.3g})", t_end=t_chunk_end, x_end=tr.x_final.copy())
        # the section: an event of the system when one recurs, else a state that moves
        if section is None or section.kind == "state":
            # events are the better section: switch to one as soon as one recurs; a state
            # section only while the chunks have no events (or none that recurs yet)
            key = _choose_event(tr, system)
            if key is not None:
                section = Section("event", key=key)
                R_t, R_x = np.empty(0), np.empty((0, n))
            elif section is None and not _enters_stick(tr, system):
                ok = (tr.t[1:] > tr.t[:-1]) & (tr.mode[:-1] == tr.mode[1:])
                sc = _choose_state(xs, ok, floor)
                section = Section("state", sc[0], sc[1]) if sc is not None else None
                R_t, R_x = np.empty(0), np.empty((0, n))
        count = 0
        if section is not None:
            if section.kind == "event":
                rt, rx, count = _event_returns(tr, section.key, keep)
                lost = count == 0 and _enters_stick(tr, system)
            else:
                s, c = section.state, section.level
                rt, rx, count = _state_returns(system, tr, s, c, max(rng[s], 1e-300), opt, keep)
                lost = count == 0 and _chunk > 0 and rng[s] < 0.5 * motion[s]
            if count > len(rt) or len(rt) == 0:
                R_t, R_x = t + rt, rx                 # not consecutive with the previous chunk's
            else:
                R_t, R_x = np.concatenate([R_t, t + rt])[-keep:], np.vstack([R_x, rx])[-keep:]
            if lost:
                section = None                        # the oscillation moved away from the section
            scale = np.maximum(rng, max(floor, 1e-12 * float(np.max(rng))))
            creep = _creeping(R_t, R_x, scale, opt)
            if creep is not None:
                p, growth = creep
                where = section.describe(system) if section is not None else "the returns"
                return Settled(OrbitStatus.EQUILIBRIUM, f"the motion creeps onto a set of rest: {where} converge "
                               f"while the time between them grows by a factor of {growth:.3g} each "
                               f"(t = {t_chunk_end:.6g}; e.g. stick errors that shrink while the stick phases "
                               f"lengthen)", t_end=t_chunk_end, x_end=tr.x_final.copy())
            found = None
            for p in range(1, opt.max_multiplicity + 1):
                d = _mismatch(R_t, R_x, p, scale)
                if d < math.inf and (best is None or d < best[4]):
                    best = (R_x[-1].copy(), float(R_t[-1] - R_t[-1 - p]), section, p, d, scale)
                if d <= opt.try_tol:
                    found = (p, d, float(R_t[-1] - R_t[-1 - p]))       # the fewest returns per period
                    break
            if found is not None:
                p, d, T = found
                settled = d <= opt.settle_tol
                start = _shooting_start(system, R_x[-1], T, scale, opt)
                if start is not None:
                    xs0, s0 = start
                    done = Settled(OrbitStatus.SUCCESS, f"{section.describe(system)} agree to {d:.2g} ({p} per "
                                   f"period) at t = {t_chunk_end:.6g}", xs0, T, s0, section, p, d, t_chunk_end,
                                   tr.x_final.copy())
                    if on_candidate is None:
                        if settled:
                            return done
                    # early tries keep one shot in reserve for the settled map
                    elif shots < opt.max_shots and (settled or shots < opt.max_shots - 1):
                        shots += 1
                        if on_candidate(xs0, T, s0, d, settled):
                            return done
        # next chunk: about 3 to 60 returns
        if partial:
            L = max(0.5 * tr.t_final, 1e-12 * max(t, 1.0))
        elif count < 3:
            L = 2.0 * L
        elif count > 60:
            L = L * 30.0 / count
        x = tr.x_final.copy()
        mode = tr.mode_final
        t = t_chunk_end
    if section is None:
        msg = f"the motion did not oscillate (no event recurred and no state crossed the middle of its range twice) by t = {t:.6g}"
    else:
        where = section.describe(system)
        msg = (f"{where} did not repeat within t = {t:.6g} (best agreement {best[4]:.2g} with {best[3]} returns "
               f"per period)" if best else f"fewer than three {where} by t = {t:.6g}")
    if best is not None:
        start = _shooting_start(system, best[0], best[1], best[5], opt)
        xs0, s0 = start if start is not None else (best[0], -1)
        return Settled(OrbitStatus.NO_RECURRENCE, msg, xs0, best[1], s0, best[2], best[3], best[4], t, x)
    return Settled(OrbitStatus.NO_RECURRENCE, msg, t_end=t, x_end=x)
