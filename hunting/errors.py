"""Exceptions and the status codes every kernel reports.

Kernels never raise on numerical failure: they return an integer status (a :class:`Status`
value). Front ends wrap the status in a result object and raise :class:`ConvergenceError` only
when asked to (``throw=True``).
"""
from __future__ import annotations

import enum
import math
from typing import Any


class HuntingError(Exception):
    """Base class of every error raised by ``hunting``."""


class SystemDefinitionError(HuntingError, ValueError):
    """A system, model or option was defined with values that are not allowed."""


class ConvergenceError(HuntingError, RuntimeError):
    """A numerical method did not succeed; ``.result`` carries what it computed."""

    def __init__(self, message: str, result: Any = None):
        super().__init__(message)
        self.result = result


class Status(enum.IntEnum):
    """Outcome of a kernel run. Values are shared with the numba kernels."""

    SUCCESS = 0            #: reached the end of the requested interval
    STOPPED = 1            #: a requested stop condition was met (stop mode reached, transition asked to stop)
    MAX_STEPS = 2          #: the bound on accepted + rejected steps was reached
    MAX_EVENTS = 3         #: the bound on events was reached
    ZENO = 4               #: events accumulate in time (Zeno behaviour)
    STEP_TOO_SMALL = 5     #: the step size fell below the floating point resolution of t
    NEWTON_FAILED = 6      #: the implicit method's Newton iteration failed at the smallest step
    NON_FINITE = 7         #: the vector field returned NaN or inf
    BUFFER_FULL = 8        #: internal: output buffers full (the front end resumes)
    INVALID_MODE = 9       #: a transition or mode function returned a mode out of range
    DIVERGED = 10          #: the state grew by orders of magnitude (front end: simulate's ``growth``)
    OUT_OF_BOUNDS = 11     #: the state left the bounds the caller gave (front end: simulate's ``bounds``)

    @property
    def ok(self) -> bool:
        return self in (Status.SUCCESS, Status.STOPPED)


_ADVICE = {
    Status.SUCCESS: "integration reached the end of the interval",
    Status.STOPPED: "integration stopped at the requested condition",
    Status.MAX_STEPS: "the step bound was reached: raise max_steps or loosen rtol/atol",
    Status.MAX_EVENTS: "the event bound was reached: raise max_events or shorten t_span",
    Status.ZENO: ("events accumulate (Zeno): the trajectory chatters on a switching surface; "
                  "declare a sliding/stick mode for that surface or check the transition function"),
    Status.STEP_TOO_SMALL: ("the step size fell below the resolution of t: the system is too stiff for "
                            "an explicit method (use method='radau') or the vector field is discontinuous "
                            "inside a mode (add a guard for the discontinuity)"),
    Status.NEWTON_FAILED: ("Newton iteration of the implicit method failed even at the smallest step: "
                           "check the Jacobian or loosen rtol"),
    Status.NON_FINITE: "the vector field returned NaN or inf: check parameters and the state's range",
    Status.BUFFER_FULL: "output buffer full",
    Status.INVALID_MODE: "a transition or initial-mode function returned a mode index out of range",
    Status.DIVERGED: ("the state grew by orders of magnitude: the loop is unstable with these parameters "
                      "(check the controller gains, e.g. a negative or too small gain) or the run diverges; "
                      "if growth is what you study, allow more (simulate's growth; None, or --growth 0: no check)"),
    Status.OUT_OF_BOUNDS: ("the state left the bounds given: widen them if the motion is meant to go there, "
                           "else check the parameters"),
}


def status_message(status: Status, t: float | None = None) -> str:
    """Human readable message for a status, with the time where it happened."""
    text = _ADVICE[Status(status)]
    if t is not None and math.isfinite(t) and not Status(status).ok:
        text = f"at t = {t:.12g}: {text}"
    return text


def check_finite_positive(name: str, value: float, *, allow_zero: bool = False,
                          allow_inf: bool = False) -> float:
    """Validate a scalar parameter; raise SystemDefinitionError naming it when not allowed."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise SystemDefinitionError(f"{name} = {value!r} is not a number") from None
    if math.isnan(v) or (math.isinf(v) and not (allow_inf and v > 0)):
        allowed = "a finite number" if not allow_inf else "a number or +inf"
        raise SystemDefinitionError(f"{name} = {value!r} is not allowed: {name} must be {allowed}")
    if v < 0 or (v == 0 and not allow_zero):
        bound = ">= 0" if allow_zero else "> 0"
        raise SystemDefinitionError(f"{name} = {value!r} is not allowed: {name} must be {bound}")
    return v


def check_finite(name: str, value: float) -> float:
    """Validate a finite real scalar (any sign)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise SystemDefinitionError(f"{name} = {value!r} is not a number") from None
    if not math.isfinite(v):
        raise SystemDefinitionError(f"{name} = {value!r} is not allowed: {name} must be finite")
    return v
