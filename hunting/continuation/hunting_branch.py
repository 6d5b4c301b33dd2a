"""Follow a cycle of any system in one parameter, named: :func:`follow`."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import ConvergenceError, SystemDefinitionError
from ..models import servo as S
from .branch import Branch, ContinuationOptions, continue_orbit
from .cycle import find_cycle
from .shooting import PeriodicOrbit, ShootingOptions
from .status import OrbitStatus
from .target import resolve
from .transient import StartOptions


def servo_amplitude(system, x0, T, fl) -> float:
    """max |x1| over a servo loop's orbit from its flow: x1' = x2 and x2 = 0 is an event of the
    exact Switch and LuGre loops (reversal, stick entry, the LuGre kink), so the extremes of
    x1 are among the event states and the ends (not for the banded Switch: no event at 0)."""
    a = max(abs(x0[0]), abs(fl.x[0]))
    if fl.event_states is not None and len(fl.event_states):
        a = max(a, float(np.max(np.abs(fl.event_states[:, 0]))))
    return float(a)


def _empty_branch(param, n, status, message, label, names) -> Branch:
    return Branch(param, np.empty(0), np.empty(0), np.empty(0), np.empty((0, n), dtype=complex),
                  np.empty(0, dtype=bool), np.empty((0, n)), [], [], status, message, label, names)


def follow(system, param: str, start: float, end: float, *, params: dict | None = None, x0=None,
           period_guess: float | None = None, stop_at: float | None = None,
           options: ContinuationOptions | None = None, shooting: ShootingOptions | None = None,
           start_options: StartOptions | None = None, orbit: PeriodicOrbit | None = None,
           throw: bool = False) -> Branch:
    """The branch of periodic orbits of ``system`` in the parameter called ``param``.

    Parameters
    ----------
    system : str or ServoLoop or compiled model or PiecewiseSystem
        What :func:`find_cycle` accepts.
    param : str
        The parameter's name (a preset parameter such as ``"K"`` or ``"P"``, or a system/model
        parameter); no hand-written ``system_at`` is needed.
    start, end : float
        The parameter range (different, finite).
    params : mapping name -> value, optional
        Other parameter overrides (must not contain ``param``).
    x0, period_guess : the start of the cycle search at ``start`` (see :func:`find_cycle`)
    stop_at : float, optional
        After a fold the branch is followed back until ``param`` reaches this (default: start).
    options, shooting, start_options : ContinuationOptions, ShootingOptions, StartOptions
    orbit : PeriodicOrbit, optional
        The cycle at ``start`` when already known.
    throw : raise ConvergenceError when no cycle is found at ``start``

    Returns
    -------
    Branch
        status NO_START (and no points) when no cycle was found at ``start``.

    Examples
    --------
    >>> from hunting import follow
    >>> br = follow("table8.1-switch", "K", 0.30, 0.31)
    >>> br.status.name, len(br.mu) >= 2, bool(br.stable.all())
    ('SUCCESS', True, True)
    """
    for name, v in (("start", start), ("end", end)):
        if not isinstance(v, (int, float, np.floating)) or not np.isfinite(v):
            raise SystemDefinitionError(f"{name} = {v!r} is not allowed: it must be a finite number")
    if start == end:
        raise SystemDefinitionError(f"start = end = {start!r}: the parameter range is empty; give the start "
                                    f"(--from) and the end (--to) of the range different values")
    params = dict(params or {})
    if param in params:
        raise SystemDefinitionError(f"param = {param!r} is also given in params: remove it there")
    target = resolve(system, params)
    lens = target.lens(param)                      # checks the name before any computation
    at_start = resolve(system, {**params, param: start})
    n = at_start.system.n_states
    label = target.label
    if orbit is None:
        res = find_cycle(system, x0, period_guess, {**params, param: start}, shooting=shooting, start=start_options)
        if not res.success:
            msg = f"no cycle at {param} = {start:g}: {res.message}"
            if throw:
                raise ConvergenceError(msg, res)
            return _empty_branch(param, n, OrbitStatus.NO_START, msg, label, at_start.state_names)
        orbit = res.orbit
    opt = options or ContinuationOptions()
    loop = at_start.loop
    contacts = getattr(at_start.source, "contacts", None) or ()
    lugre = ((loop is not None and loop.model_code == S.MODEL_LUGRE)
             or any(getattr(c, "model", None) == "lugre" for c in contacts))
    if opt.jacobian_method is None and lugre:
        opt = replace(opt, jacobian_method="radau")       # stiff LuGre bristles: implicit sensitivities
    exact_servo = loop is not None and loop.model_code != S.MODEL_BANDED
    br = continue_orbit(lens.system_at, orbit, start, end, param=param, options=opt, shooting=shooting,
                        stop_at_mu=start if stop_at is None else stop_at,
                        amplitude=servo_amplitude if exact_servo else None,
                        param_direction=lens.direction)
    return replace(br, label=label)
