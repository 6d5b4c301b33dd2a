"""Stick-to-stick event maps d_{n+1} = P(d_n) (thesis sections 9.4 and 10.4.3).

d is the position error x1 during a stick phase. One evaluation starts at the exact break-away
state of the stick phase with error d and integrates the closed loop (velocity reversals without
sticking included) until it enters stick for the k-th time; P^k(d) is x1 there. Iterates are the
true map composed in one integration, never an interpolation of a grid. All grid points run in
parallel in compiled code (hunting.integrate._batch).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import Status, SystemDefinitionError
from ..integrate._batch import B_T_END, B_T_IN_STOP, run_batch
from ..models.loop import ServoLoop
from .family import StickFamily, as_stick_map

DEFAULT_RTOL = 1e-12


@dataclass(frozen=True)
class MapOptions:
    """Accuracy and bounds of one map evaluation.

    rtol : relative tolerance of the integration; atol is rtol * max(|d|, d_floor) so maps on
        small amplitudes keep their relative accuracy
    t_max : time limit per evaluation [s]; max_events : bound on events per evaluation
    fd_step : relative step of the central differences for dP/dd (h = fd_step * max(|d|, d_floor));
        small, because maps near a fold are strongly curved (1e-5 gave a slope 20 % off there)
    """

    rtol: float = DEFAULT_RTOL
    d_floor: float = 1e-9
    t_max: float = 1e12
    max_events: int = 400
    max_steps: int = 400_000
    fd_step: float = 1e-7

    def __post_init__(self):
        for name in ("rtol", "d_floor", "t_max", "fd_step"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise SystemDefinitionError(f"{name} = {v!r} is not allowed: it must be a finite number > 0")
        for name in ("max_events", "max_steps"):
            v = getattr(self, name)
            if int(v) != v or v < 1:
                raise SystemDefinitionError(f"{name} = {v!r} is not allowed: it must be a positive integer")


@dataclass(frozen=True)
class MapValues:
    """P^k on a set of points.

    d : (m,) stick errors; image : (m,) P^k(d) (meaningful where ok); status : (m,) Status codes;
    slip_time : (m,) time from break-away to the k-th stick entry, minus the intermediate stick
    phases [s]; stick_time : (m,) duration of the stick phase entered at the image [s];
    n_events : (m,) events on the way; entry : (m, n) state at the k-th stick entry."""

    d: np.ndarray
    image: np.ndarray
    status: np.ndarray
    slip_time: np.ndarray
    stick_time: np.ndarray
    n_events: np.ndarray
    entry: np.ndarray

    @property
    def ok(self) -> np.ndarray:
        return self.status == Status.STOPPED


def evaluate_map(loop: ServoLoop, d, iterate: int = 1, options: MapOptions | None = None) -> MapValues:
    """P^k(d) for an array of stick errors d (true map, parallel over points).

    For an odd loop (symmetric friction, no cogging, no external force: ``loop.odd``) each |d|
    is integrated once and P^k(-d) = -P^k(d) is used; otherwise every point is integrated.
    ``loop`` may also be a preset name, a compiled model or a PiecewiseSystem with one sticking
    contact (:func:`hunting.eventmap.stick_family`)."""
    loop = as_stick_map(loop)
    opt = options or MapOptions()
    if int(iterate) != iterate or iterate < 1:
        raise SystemDefinitionError(f"iterate = {iterate!r} is not allowed: it must be an integer >= 1")
    d = np.atleast_1d(np.asarray(d, dtype=float)).ravel()
    if not np.all(np.isfinite(d)):
        raise SystemDefinitionError("d must be finite")
    if loop.odd and np.any(d < 0):
        mags, inv = np.unique(np.abs(d), return_inverse=True)
        if mags.size < d.size:
            half = _evaluate(loop, mags, iterate, opt)
            sgn = np.where(d < 0, -1.0, 1.0)
            entry = half.entry[inv] * sgn[:, None]
            return MapValues(d, half.image[inv] * sgn, half.status[inv], half.slip_time[inv],
                             half.stick_time[inv], half.n_events[inv], entry)
    return _evaluate(loop, d, iterate, opt)


def _evaluate(loop: ServoLoop, d: np.ndarray, iterate: int, opt: MapOptions) -> MapValues:
    X0, mode0 = loop.breakaway_state(d)
    system = loop.system
    image = np.zeros_like(d)
    status = np.full(d.size, int(Status.STOPPED))
    slip = np.zeros_like(d)
    stick = np.full(d.size, np.inf)
    n_ev = np.zeros(d.size, dtype=np.int64)
    entry = X0.copy()
    run = d != 0                        # d = 0 is the equilibrium set: P^k(0) = 0
    if np.any(run):
        atol = opt.rtol * np.maximum(np.abs(d[run]), opt.d_floor)
        Xe, me, st, ne, fo = run_batch(system, X0[run], mode0[run], t_max=opt.t_max, atol=atol,
                                       rtol=opt.rtol, max_steps=opt.max_steps,
                                       max_events=opt.max_events, guard_tol=atol,
                                       stop_mode=loop.stick_mode, stop_count=int(iterate))
        image[run] = Xe[:, 0] if not isinstance(loop, StickFamily) else loop.stick_error(Xe)
        status[run] = st
        n_ev[run] = ne
        entry[run] = Xe
        slip[run] = fo[:, B_T_END] - fo[:, B_T_IN_STOP]   # minus intermediate stick phases
        ok = st == Status.STOPPED
        st_time = np.full(int(run.sum()), np.nan)
        if np.any(ok):
            st_time[ok] = loop.stick_duration(Xe[ok])
        stick[run] = st_time
    return MapValues(d, image, status, slip, stick, n_ev, entry)


@dataclass(frozen=True)
class EventMap:
    """An event map P^k on a grid.

    grid : (m,) stick errors d [m]; image : (m,) P^k(d), NaN only where ``status`` says why;
    status : (m,) hunting.Status codes (STOPPED = a stick phase was reached);
    slip_time, stick_time : (m,) [s] (see MapValues); derivative : (m,) dP^k/dd or None;
    derivative_method : how the derivative was computed; iterate : k; loop : the ServoLoop."""

    grid: np.ndarray
    image: np.ndarray
    status: np.ndarray
    slip_time: np.ndarray
    stick_time: np.ndarray
    derivative: np.ndarray | None
    derivative_method: str
    iterate: int
    loop: ServoLoop = field(repr=False)
    options: MapOptions = field(default_factory=MapOptions, repr=False)

    @property
    def ok(self) -> np.ndarray:
        return self.status == Status.STOPPED

    def status_names(self) -> list[str]:
        return [Status(int(s)).name for s in self.status]


def event_map(loop: ServoLoop, grid, iterate: int = 1, *, derivative: bool = True,
              options: MapOptions | None = None) -> EventMap:
    """The event map P^k on a grid of stick errors, with dP^k/dd by central differences.

    Parameters
    ----------
    loop : ServoLoop with the exact Switch model (``model="switch"``)
    grid : array (m,) of stick errors d [position unit]
    iterate : k, the number of stick phases per map application
    derivative : also compute dP^k/dd by central differences of the true map with step
        h = fd_step * max(|d|, d_floor) (two more evaluations per point)

    ``loop`` may also be a preset name, a compiled model or a PiecewiseSystem with one sticking
    contact whose stick states form a one-parameter family (:func:`hunting.eventmap.stick_family`).
    """
    loop = as_stick_map(loop)
    opt = options or MapOptions()
    grid = np.asarray(grid, dtype=float).ravel()
    mv = evaluate_map(loop, grid, iterate, opt)
    image = np.where(mv.ok, mv.image, np.nan)
    deriv = None
    method = "none"
    if derivative:
        h = opt.fd_step * np.maximum(np.abs(grid), opt.d_floor)
        plus = evaluate_map(loop, grid + h, iterate, opt)
        minus = evaluate_map(loop, grid - h, iterate, opt)
        deriv = (plus.image - minus.image) / (2 * h)
        deriv = np.where(plus.ok & minus.ok & mv.ok, deriv, np.nan)
        method = f"central differences of the true map, h = {opt.fd_step:g} * max(|d|, {opt.d_floor:g})"
    return EventMap(grid, image, mv.status, mv.slip_time, mv.stick_time, deriv, method, int(iterate), loop, opt)


def stick_map(loop: ServoLoop, d: float, iterate: int = 1, options: MapOptions | None = None) -> tuple[float, Status]:
    """P^k(d) for one stick error: (image, status)."""
    mv = evaluate_map(loop, [float(d)], iterate, options)
    return float(mv.image[0]), Status(int(mv.status[0]))
