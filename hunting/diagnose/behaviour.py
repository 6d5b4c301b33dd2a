"""The behaviour view of a diagnosis: what a run does, measured or re-simulated, in the terms a
servo engineer judges a friction model by, and the errors of a simulation against the measurement.

Stick phases are read from positions as the thesis reads them from its experiments: maximal runs
where the position stays within ``counts`` encoder counts for at least ``window`` seconds (after
moving more than ``moved`` from the previous stick). The hunting cycle is judged on the final
stretch of constant reference (a regulator task): its amplitude (half the peak-to-peak error),
its period (first autocorrelation maximum of the error) and whether the loop ended at rest (the
position stays within ``rest_counts`` counts over the last fifth: the equilibrium set attracts).

The measured event map (thesis sections 9.4 and 10.4.3): d_n is the position error during the
n-th stick phase (its mean over the phase), and the pairs (d_n, d_{n+1}) of consecutive stick
phases under the same constant reference are points of the stick-to-stick map P; a sampled
simulation's pairs approach the exact map of :mod:`hunting.eventmap` as the sample time goes to
zero (tests). Its contraction |d_{n+1}| / |d_n| (median over the pairs) says at a glance what the
map does: below 1 the sticks approach the setpoint, near 1 the loop hunts on a cycle."""
from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view


def stick_phases(y: np.ndarray, dt: float, resolution: float, *, window: float = 0.03, counts: int = 2,
                 moved: float = 0.0, origin: float | None = None) -> list[tuple[int, int]]:
    """Stick phases in sampled positions y (n,) [m] at interval dt [s]: (first, last) sample
    indices of maximal runs staying within ``counts`` counts (of ``resolution`` [m]) for at least
    ``window`` s, each beginning more than ``moved`` [m] away from where the previous one ended
    (the first one away from ``origin`` when given)."""
    w = max(2, int(round(window / dt)))
    tol = counts * max(resolution, 0.0) + 1e-12
    n = y.size
    if n < w:
        return []
    win = sliding_window_view(y, w)
    still = (win.max(axis=1) - win.min(axis=1)) <= tol
    phases, k = [], 0
    last = origin
    while k < still.size:
        if still[k] and (last is None or abs(y[k] - last) > moved):
            j = k
            while j + 1 < still.size and still[j + 1]:
                j += 1
            phases.append((k, j + w - 1))
            last = y[j + w - 1]
            k = j + w
        else:
            k += 1
    return phases


def stick_errors(q: np.ndarray, q_ref: np.ndarray, phases: list) -> tuple:
    """(d, stretch): the position error d_n [m] of each stick phase (first, last index) of q (n,)
    (mean of q - q_ref over the phase) and the index of the constant-reference stretch it lies in
    (-1 when q_ref changes during the phase)."""
    piece = np.concatenate([[0], np.cumsum(np.abs(np.diff(q_ref)) > 1e-12)])
    d, stretch = [], []
    for a, b in phases:
        d.append(float(np.mean(q[a:b + 1] - q_ref[a:b + 1])))
        stretch.append(int(piece[a]) if piece[a] == piece[b] else -1)
    return np.array(d), np.array(stretch, dtype=np.int64)


def event_map_points(d: np.ndarray, stretch: np.ndarray) -> np.ndarray:
    """Points (d_n, d_{n+1}) of the measured event map (m, 2): consecutive stick phases under the
    same constant reference."""
    same = (stretch[:-1] == stretch[1:]) & (stretch[:-1] >= 0)
    return np.column_stack([d[:-1][same], d[1:][same]]) if d.size > 1 else np.zeros((0, 2))


def map_contraction(points: np.ndarray, resolution: float, counts: int = 2) -> float | None:
    """Median of |d_{n+1}| / |d_n| over the event-map points with |d_n| above ``counts`` counts
    (None without such points)."""
    keep = np.abs(points[:, 0]) > counts * max(resolution, 1e-12)
    if not keep.any():
        return None
    return float(np.median(np.abs(points[keep, 1]) / np.abs(points[keep, 0])))


@dataclass(frozen=True)
class Behaviour:
    """sticks : number of stick phases; stick_time [s] : their mean duration; stick_error [m] :
    RMS of the position error q - q_ref at the start of each stick; cycle_amplitude [m] and
    cycle_period [s] on the final constant-reference stretch (period None when at rest or not
    periodic); at_rest : the loop ends at rest there; final_error [m] : mean error over the
    last fifth of it. None where the run has no such stretch. event_map : the measured event
    map's points [[d_n, d_{n+1}], ...] [m]; map_contraction : median |d_{n+1}| / |d_n| (None
    without points)."""

    sticks: int
    stick_time: float | None
    stick_error: float | None
    cycle_amplitude: float | None
    cycle_period: float | None
    at_rest: bool | None
    final_error: float | None
    event_map: list = field(default_factory=list)
    map_contraction: float | None = None

    def as_dict(self) -> dict:
        return asdict(self)


def _final_stretch(q_ref: np.ndarray, min_samples: int) -> int | None:
    """First index of the last stretch of constant reference (None when shorter than min_samples)."""
    changed = np.flatnonzero(np.abs(np.diff(q_ref)) > 1e-12)
    start = 0 if changed.size == 0 else int(changed[-1]) + 1
    return start if q_ref.size - start >= min_samples else None


def behaviour(t: np.ndarray, q: np.ndarray, q_ref: np.ndarray, resolution: float, *, rest_counts: int = 25,
              **stick_kw) -> Behaviour:
    """The behaviour of one run (see the module docstring); t, q, q_ref (n,)."""
    dt = float(t[1] - t[0])
    e = q - q_ref
    ph = stick_phases(q, dt, resolution, **stick_kw)
    d, stretch = stick_errors(q, q_ref, ph)
    pts = event_map_points(d, stretch)
    emap = dict(event_map=pts.tolist(), map_contraction=map_contraction(pts, resolution))
    stick_time = float(np.mean([(b - a + 1) * dt for a, b in ph])) if ph else None
    stick_error = float(np.sqrt(np.mean([e[a] ** 2 for a, _ in ph]))) if ph else None
    k0 = _final_stretch(q_ref, max(int(1.0 / dt), 20))
    if k0 is None:
        return Behaviour(len(ph), stick_time, stick_error, None, None, None, None, **emap)
    tail = e[k0 + (q.size - k0) // 2:]
    last = e[q.size - (q.size - k0) // 5:]
    at_rest = bool(np.ptp(last) <= rest_counts * max(resolution, 1e-9))
    amp = 0.5 * float(np.ptp(tail))
    period = None
    if not at_rest and tail.size > 20:
        x = tail - tail.mean()
        ac = np.correlate(x, x, "full")[x.size - 1:]
        ac = ac / max(ac[0], 1e-300)
        neg = np.flatnonzero(ac < 0)
        if neg.size:
            j = int(neg[0] + np.argmax(ac[neg[0]:]))
            if ac[j] > 0.5 and j < x.size - 1:
                period = j * dt
    return Behaviour(len(ph), stick_time, stick_error, amp, period, at_rest, float(np.mean(last)), **emap)


def simulation_errors(meas, sim, cm: float) -> dict:
    """Errors of a re-simulation against the measurement: position RMS [m] and drive-force RMS
    [N] (cm times the controller-output difference), over the samples both have."""
    n = sim.q.size
    return {"position_rms": float(np.sqrt(np.mean((sim.q - meas.q[:n]) ** 2))),
            "force_rms": float(cm * np.sqrt(np.mean((sim.u - meas.u[:n]) ** 2)))}


def compare(meas, sims: dict, cm: float, resolution: float, **kw) -> dict:
    """The behaviour of the measurement and of each simulation in ``sims`` ({label: Simulation}),
    with the simulations' errors: {"measured": {...}, label: {..., "position_rms", "force_rms",
    "ok"}}."""
    out = {"measured": behaviour(meas.t, meas.q, meas.q_ref, resolution, **kw).as_dict()}
    for label, sim in sims.items():
        row = behaviour(sim.t, sim.q, meas.q_ref[:sim.q.size], resolution, **kw).as_dict() if sim.q.size > 2 else {}
        row.update(simulation_errors(meas, sim, cm), ok=sim.ok)
        out[label] = row
    return out

