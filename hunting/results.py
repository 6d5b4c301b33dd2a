"""Result objects: frozen dataclasses with documented shapes (time-major)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .errors import Status, status_message


@dataclass(frozen=True)
class EventLog:
    """Mode transitions along a trajectory, in time order.

    t : (k,) event times [s]
    x_before : (k, n) state at the event in the old mode
    x_after : (k, n) state after the transition (reset) function
    guard : (k,) index of the guard that fired
    mode_from, mode_to : (k,) mode indices (mode_to = -1: the transition stopped integration)
    """

    t: np.ndarray
    x_before: np.ndarray
    x_after: np.ndarray
    guard: np.ndarray
    mode_from: np.ndarray
    mode_to: np.ndarray

    def __len__(self) -> int:
        return int(self.t.size)

    def entering(self, mode: int) -> np.ndarray:
        """Indices of the events that enter ``mode``."""
        return np.flatnonzero(self.mode_to == mode)


@dataclass(frozen=True)
class Trajectory:
    """A simulated trajectory of a piecewise-smooth system.

    t : (m,) times [s]; at an event the time appears twice (before and after the transition)
        unless output was requested at ``t_eval`` only
    x : (m, n) states, time-major
    mode : (m,) mode index at each output point
    events : EventLog
    status : Status; message : str saying what happened and, on failure, what to change
    stats : dict with n_steps, n_rejected, n_fev, n_jac
    """

    t: np.ndarray
    x: np.ndarray
    mode: np.ndarray
    events: EventLog
    status: Status
    message: str
    state_names: tuple = ()
    mode_names: tuple = ()
    stats: dict = field(default_factory=dict)

    @property
    def success(self) -> bool:
        return self.status.ok

    @property
    def t_final(self) -> float:
        return float(self.t[-1])

    @property
    def x_final(self) -> np.ndarray:
        return self.x[-1]

    @property
    def mode_final(self) -> int:
        return int(self.mode[-1])

    def __getitem__(self, name: str) -> np.ndarray:
        """A state's time series by name, e.g. ``traj["x1"]``."""
        try:
            return self.x[:, self.state_names.index(name)]
        except ValueError:
            raise KeyError(f"{name!r} is not a state name: states are {list(self.state_names)}") from None

    def stick_intervals(self, stick_modes) -> np.ndarray:
        """(k, 2) array of [start, end] times of the phases spent in any of ``stick_modes``.

        A phase still running at the end of the trajectory ends at ``t_final``."""
        stick_modes = np.atleast_1d(stick_modes)
        ev = self.events
        intervals = []
        start = self.t[0] if np.isin(self.mode[0], stick_modes) else None
        for k in range(len(ev)):
            into = np.isin(ev.mode_to[k], stick_modes)
            was = np.isin(ev.mode_from[k], stick_modes)
            if into and not was:
                start = ev.t[k]
            elif was and not into and start is not None:
                intervals.append((start, ev.t[k]))
                start = None
        if start is not None:
            intervals.append((start, self.t_final))
        return np.asarray(intervals, dtype=float).reshape(-1, 2)

    def summary(self) -> str:
        return (f"{self.status.name}: {self.message}; {len(self.t)} points, {len(self.events)} events, "
                f"{self.stats.get('n_steps', 0)} steps ({self.stats.get('n_rejected', 0)} rejected), "
                f"t = {self.t[0]:.6g} .. {self.t[-1]:.6g}")


def make_status(code: int, t: float | None = None) -> tuple[Status, str]:
    s = Status(int(code))
    return s, status_message(s, t)


@dataclass(frozen=True)
class SpecialPoint:
    """A bifurcation or structural change found along a parameter sweep or branch.

    kind : e.g. "fold", "equilibrium_stability", "period_doubling", "grazing"
    index : index of the sweep point / branch point just before it
    param : best estimate of the parameter value; interval : (lo, hi) bracketing it
    precision : hi - lo; data : extra numbers (e.g. the stick error at the fold)"""

    kind: str
    index: int
    param: float
    interval: tuple
    precision: float
    data: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return dict(kind=self.kind, index=self.index, param=self.param, interval=list(self.interval),
                    precision=self.precision, **{k: (float(v) if np.isscalar(v) else v) for k, v in self.data.items()})
