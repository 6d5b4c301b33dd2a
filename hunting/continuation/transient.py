"""The transient before shooting: simulate until the return map on a section settles.

The motion is simulated in chunks from the user's state. A section x[s] = c (upward crossings)
is chosen from the first chunk that oscillates: the state with the largest range relative to
its size, c the middle of that range. Each return is located exactly (Newton on the crossing
time with short flows from the last output point before it), so the return map is measured
to the integration's accuracy. The map has settled when returns p apart (p = 1, 2, ...: returns
per period) agree to ``settle_tol`` in every state, scaled by that state's range. Each chunk
also checks the two other ends: the motion dies out (equilibrium or stick set) or grows without
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
        whole transient is at rest (status EQUILIBRIUM).
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
        for name in ("max_chunks", "max_multiplicity", "max_shots", "max_events", "max_steps"):
            v = getattr(self, name)
            if int(v) != v or v < 1:
                raise SystemDefinitionError(f"{name} = {v!r} is not allowed: it must be a positive integer")
        if self.method not in ("dop853", "dp5", "radau"):
            raise SystemDefinitionError(f"method = {self.method!r} is not allowed: use dop853, dp5 or radau")


@dataclass(frozen=True)
class Returns:
    """Consecutive returns to the section x[section] = level (upward).

    t : (k,) times; x : (k, n) states (x[:, section] = level exactly); section, level."""

    t: np.ndarray
    x: np.ndarray
    section: int
    level: float


@dataclass(frozen=True)
class Settled:
    """Where the transient led.

    status : OrbitStatus (SUCCESS: a settled or nearly settled return map); message;
    x0 : (n,) the last return (a shooting guess, x0[section] = level), period : time between
    returns ``multiplicity`` apart; section, level; mismatch : the scaled distance of returns
    ``multiplicity`` apart; t_end : transient time simulated; x_end : state at t_end."""

    status: OrbitStatus
    message: str
    x0: np.ndarray | None = None
    period: float = math.nan
    section: int = -1
    level: float = math.nan
    multiplicity: int = 0
    mismatch: float = math.inf
    t_end: float = 0.0
    x_end: np.ndarray | None = None


def _choose_section(x: np.ndarray, ok: np.ndarray):
    """(state index, level) for the return map from a chunk's output x (m, n): among the states
    that oscillate most (range relative to size at least half the largest), the one crossing
    the middle of its range upwards least often but at least twice (a clean section: a
    velocity crosses its middle several times a period, a position once); None when nothing
    oscillates."""
    lo, hi = x.min(axis=0), x.max(axis=0)
    rng = hi - lo
    rel = rng / (np.max(np.abs(x), axis=0) + 1e-300)
    best = None
    for i in np.flatnonzero((rng > 0) & (rel >= 0.5 * rel.max())):
        c = 0.5 * (lo[i] + hi[i])
        s = x[:, i]
        count = int(np.count_nonzero(ok & (s[:-1] < c) & (s[1:] >= c)))
        if count >= 2 and (best is None or count < best[0]):
            best = (count, int(i), float(c))
    return None if best is None else best[1:]


def _refine_return(system: PiecewiseSystem, xk, mode, h, s, c, amp, opt: StartOptions):
    """Time tau in (0, h] and state where x[s] crosses c upward on the smooth piece starting at
    xk in ``mode`` (no event inside): Newton on tau with bisection safeguards, on short flows."""
    a, b = 0.0, float(h)
    fa = xk[s] - c
    fl_b = flow(system, xk, b, mode0=mode, sensitivity=False, rtol=opt.rtol, atol=opt.atol)
    fb = fl_b.x[s] - c
    if not fl_b.ok or fa >= 0 or fb < 0:
        return None
    tau = b * (-fa) / (fb - fa)
    x = fl_b.x
    for _ in range(30):
        fl = flow(system, xk, tau, mode0=mode, sensitivity=False, rtol=opt.rtol, atol=opt.atol) if tau > 0 else None
        if fl is None or not fl.ok:
            return None
        x = fl.x
        g = x[s] - c
        if abs(g) <= 1e-12 * amp:
            break
        if g < 0:
            a = tau
        else:
            b = tau
        fs = fl.f[s]
        step = tau - g / fs if np.isfinite(fs) and fs > 0 else 0.5 * (a + b)
        new = step if a < step < b else 0.5 * (a + b)
        if abs(new - tau) <= 1e-15 * h:
            break
        tau = new
    x = x.copy()
    x[s] = c
    return tau, x


def _returns_in(system, tr, s, c, amp, opt, keep: int):
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
    on_candidate : callable (x0, period, section, level, mismatch) -> bool, optional
        Called when returns agree to ``try_tol`` (at most ``max_shots`` times); returning True
        ends the search with SUCCESS (the caller's shooting converged).

    Returns
    -------
    Settled
    """
    opt = options or StartOptions()
    x = system.check_state(x0).copy()
    n = system.n_states
    t_max = opt.t_max or (2000.0 * period_guess if period_guess else 1e4)
    L = opt.chunk or (4.0 * period_guess if period_guess else 1.0)
    L = min(L, t_max)
    t = 0.0
    mode = None
    section = None
    R_t, R_x = np.empty(0), np.empty((0, n))
    motion = np.zeros(n)
    size0 = float(np.max(np.abs(x)))
    shots = 0
    best = None
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
        if _chunk > 0 and np.all(rng <= opt.rest_tol * motion):
            return Settled(OrbitStatus.EQUILIBRIUM, f"the motion came to rest by t = {t_chunk_end:.6g} "
                           f"(every state moved less than {opt.rest_tol:g} of its motion over the last {span:.3g} time units)",
                           t_end=t_chunk_end, x_end=tr.x_final.copy())
        if section is None:
            ok = (tr.t[1:] > tr.t[:-1]) & (tr.mode[:-1] == tr.mode[1:])
            section = _choose_section(xs, ok)
        count = 0
        if section is not None:
            s, c = section
            keep = 2 * opt.max_multiplicity + 4
            rt, rx, count = _returns_in(system, tr, s, c, max(rng[s], 1e-300), opt, keep)
            if count > len(rt) or len(rt) == 0:
                R_t, R_x = t + rt, rx                 # not consecutive with the previous chunk's
            else:
                R_t, R_x = np.concatenate([R_t, t + rt])[-keep:], np.vstack([R_x, rx])[-keep:]
            if count == 0 and _chunk > 0 and rng[s] < 0.5 * (motion[s]):
                section = None                        # the oscillation moved away from the level
            scale = np.maximum(rng, 1e-12 * np.maximum(np.max(np.abs(xs), axis=0), 1e-300))
            found = None
            for p in range(1, opt.max_multiplicity + 1):
                d = _mismatch(R_t, R_x, p, scale)
                if d < math.inf and (best is None or d < best[4]):
                    best = (R_x[-1].copy(), float(R_t[-1] - R_t[-1 - p]), s, p, d, c)
                if d <= opt.try_tol:
                    found = (p, d, float(R_t[-1] - R_t[-1 - p]))       # the fewest returns per period
                    break
            if found is not None:
                p, d, T = found
                settled = d <= opt.settle_tol
                done = Settled(OrbitStatus.SUCCESS, f"returns to {system.state_names[s]} = {c:.6g} agree to "
                               f"{d:.2g} ({p} per period) at t = {t_chunk_end:.6g}",
                               R_x[-1].copy(), T, s, c, p, d, t_chunk_end, tr.x_final.copy())
                if on_candidate is None:
                    if settled:
                        return done
                # early tries keep one shot in reserve for the settled map
                elif shots < opt.max_shots and (settled or shots < opt.max_shots - 1):
                    shots += 1
                    if on_candidate(R_x[-1].copy(), T, s, c, d, settled):
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
        msg = f"the motion did not oscillate (no state crossed the middle of its range twice) by t = {t:.6g}"
    else:
        where = f"{system.state_names[section[0]]} = {section[1]:.6g}"
        msg = (f"returns to {where} did not repeat within t = {t:.6g} (best agreement "
               f"{best[4]:.2g} with {best[3]} returns per period)" if best else
               f"fewer than three returns to {where} by t = {t:.6g}")
    if best is not None:
        return Settled(OrbitStatus.NO_RECURRENCE, msg, best[0], best[1], best[2], best[5], best[3], best[4], t, x)
    return Settled(OrbitStatus.NO_RECURRENCE, msg, t_end=t, x_end=x)
