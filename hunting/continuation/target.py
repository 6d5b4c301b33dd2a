"""What a periodic-orbit method works on: a preset name, a ServoLoop, a compiled model or any
PiecewiseSystem, resolved to one compiled system with its names, and parameters by name.

A :class:`ParameterLens` is the one way a method changes a parameter (like BifurcationKit's
lens): ``system_at(mu)`` gives the system with that parameter at ``mu`` (the compiled functions
are shared; only the flat parameter array changes) and ``direction(mu)`` the derivative of the
flat array in mu. Where the array is affine in the parameter (every direct slot, and the preset
gains such as ``P`` or ``K``) the lens is exact and never rebuilds a system; otherwise it asks
the builder at each value.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Mapping

import numpy as np

from ..errors import SystemDefinitionError
from ..system import PiecewiseSystem

STICK_KINDS = ("stick", "filippov")


@dataclass(frozen=True)
class Contact:
    """One friction contact: ``name``, ``stick`` (indices of the system's modes in which it
    sticks; empty for LuGre), ``velocity`` (callable (x, t) -> its relative velocity w, when
    known: compiled models and the servo loops; else None)."""

    name: str
    stick: frozenset
    velocity: Callable | None = field(default=None, repr=False, compare=False)


@dataclass(frozen=True)
class ParameterLens:
    """One named parameter of a target, as a map mu -> flat parameter array.

    Parameters
    ----------
    name : str
        The parameter's name (a preset parameter such as ``"K"`` or a system/model parameter).
    value : float
        Its value in the target as resolved.
    base : PiecewiseSystem
        The system at ``value``.
    params_at : callable float -> ndarray
        The flat parameter array at mu.
    affine : bool
        True when the array is affine in mu.
    slope : ndarray or None
        d params / d mu when affine (then ``direction`` returns it: exact and constant).

    Examples
    --------
    >>> from hunting.continuation import resolve
    >>> lens = resolve("table9.1").lens("P")
    >>> lens.value, lens.affine
    (10.0, True)
    >>> float(lens.system_at(12.0).param("kp"))
    12.0
    """

    name: str
    value: float
    base: PiecewiseSystem
    params_at: Callable[[float], np.ndarray] = field(repr=False)
    affine: bool = False
    slope: np.ndarray | None = field(default=None, repr=False)

    def system_at(self, mu: float) -> PiecewiseSystem:
        """The system with this parameter at ``mu`` (no recompilation)."""
        return self.base.with_param_array(self.params_at(float(mu)))

    def direction(self, mu: float, rel: float = 1e-8) -> np.ndarray:
        """d params / d mu at mu (the exact slope when ``affine``, else central differences)."""
        if self.slope is not None:
            return self.slope.copy()
        h = rel * max(abs(mu), 1e-3)
        return (self.params_at(mu + h) - self.params_at(mu - h)) / (2 * h)


def _affine_lens(name: str, value: float, base: PiecewiseSystem, build: Callable[[float], np.ndarray]) -> ParameterLens:
    """A lens from a builder mu -> params: affine (two builds, then linear) when three builds
    at spread values agree with a line, else one build per value."""
    p0 = np.asarray(build(value), dtype=float)
    h = 0.25 * abs(value) if value != 0 else 1.0     # probes keep the sign of the value
    try:
        p1 = np.asarray(build(value + h), dtype=float)
        p2 = np.asarray(build(value - 0.5 * h), dtype=float)
    except SystemDefinitionError:                    # a probe left the allowed range
        p1 = p2 = None
    if p1 is not None:
        slope = (p1 - p0) / h
        pred = p0 - 0.5 * h * slope
        scale = np.maximum(np.maximum(np.abs(p0), np.abs(p1)), 1e-300)
        if np.all(np.abs(pred - p2) <= 1e-13 * scale):
            if not np.any(slope):
                raise SystemDefinitionError(f"parameter {name!r} does not change the system at {value!r} "
                                            f"(is it used by this model?)")
            return ParameterLens(name, value, base, lambda mu: p0 + (mu - value) * slope, True, slope)
    return ParameterLens(name, value, base, lambda mu: np.asarray(build(mu), dtype=float), False)


@dataclass(frozen=True)
class Target:
    """A system to find orbits of, with its names.

    system : PiecewiseSystem at the resolved parameters; label : name for messages;
    state_names : tuple; contacts : tuple of Contact; loop : the ServoLoop when the target is a
    preset or a ServoLoop (event-map starts, exact amplitudes), else None; preset : (name,
    overrides) for presets; source : what was given."""

    system: PiecewiseSystem
    label: str
    contacts: tuple
    loop: object = None
    preset: tuple | None = None
    source: object = field(default=None, repr=False)

    @property
    def state_names(self) -> tuple:
        return self.system.state_names

    def state(self, x0=None) -> np.ndarray:
        """A full state vector from None (zeros), a mapping state name -> value (unnamed states
        start at 0, or at a compiled model's initial values) or an array of all states.

        Examples
        --------
        >>> from hunting.continuation import resolve
        >>> resolve("table9.1").state({"x1": -0.2}).tolist()
        [-0.2, 0.0, 0.0]
        """
        n = self.system.n_states
        defaults = getattr(self.source, "state", None) if _is_model(self.source) else None
        if x0 is None:
            return np.asarray(defaults(), dtype=float) if defaults else np.zeros(n)
        if isinstance(x0, Mapping):
            x = np.asarray(defaults(), dtype=float).copy() if defaults else np.zeros(n)
            for k, v in x0.items():
                if k not in self.state_names:
                    raise SystemDefinitionError(f"x0 names {k!r}, which is not a state of {self.label}: "
                                                f"states are {list(self.state_names)}")
                try:
                    x[self.state_names.index(k)] = float(v)
                except (TypeError, ValueError):
                    raise SystemDefinitionError(f"x0[{k!r}] = {v!r} is not a number") from None
            return self.system.check_state(x)
        if isinstance(x0, str):
            raise SystemDefinitionError(f"x0 = {x0!r} is not allowed: give a mapping state name -> value "
                                        f"or an array of {n} numbers")
        try:
            return self.system.check_state(x0)
        except (TypeError, ValueError) as e:
            if isinstance(e, SystemDefinitionError):
                raise
            raise SystemDefinitionError(f"x0 = {x0!r} is not allowed: give a mapping state name -> value "
                                        f"or an array of {n} numbers") from None

    def lens(self, name: str) -> ParameterLens:
        """The parameter called ``name`` as a :class:`ParameterLens`."""
        if not isinstance(name, str):
            raise SystemDefinitionError(f"param = {name!r} must be a parameter name (a string)")
        if self.preset is not None:
            from ..models.presets import ALIASES, STRING_PARAMS, preset as build_preset, resolve_parameters
            pname, overrides = self.preset
            if ALIASES.get(name, name) in STRING_PARAMS:
                raise SystemDefinitionError(f"param = {name!r} is a choice {STRING_PARAMS[ALIASES.get(name, name)]}, "
                                            f"not a number: continuation needs a numerical parameter")
            resolve_parameters(pname, {**overrides, name: 1.0})     # raises naming the parameters if unknown
            values = resolve_parameters(pname, overrides)
            key = ALIASES.get(name, name)
            value = values.get(key, values.get(key[:-4], 0.0) if key.endswith("_neg") else 0.0)
            return _affine_lens(name, float(value), self.system,
                                lambda mu: build_preset(pname, **{**overrides, name: mu}).param_array())
        # a PiecewiseSystem, or a compiled model: its system's parameter names are the model's
        # layout, one slot per name
        value = self.system.param(name)          # raises naming the parameters when unknown
        i = self.system.param_names.index(name)
        p0 = self.system.params.copy()

        def at(mu, p0=p0, i=i):
            p = p0.copy()
            p[i] = mu
            return p
        slope = np.zeros_like(p0)
        slope[i] = 1.0
        return ParameterLens(name, value, self.system, at, True, slope)


def _is_model(obj) -> bool:
    """A compiled model (hunting.model(...)): has a PiecewiseSystem ``.system`` and ``with_params``."""
    return (not isinstance(obj, PiecewiseSystem) and isinstance(getattr(obj, "system", None), PiecewiseSystem)
            and callable(getattr(obj, "with_params", None)))


def _contacts_of(system: PiecewiseSystem, source) -> tuple:
    """Per friction contact, the modes in which it sticks: from a compiled model's ``contacts``
    when it has them, else one contact made of the system's stick/filippov modes."""
    cts = getattr(source, "contacts", None) if source is not None else None
    out = []
    if cts:
        for k, c in enumerate(cts):
            name = getattr(c, "name", None) or (c.get("name") if isinstance(c, Mapping) else None) or f"contact{k + 1}"
            stick = getattr(c, "stick_modes", None)
            if stick is None and isinstance(c, Mapping):
                stick = c.get("stick_modes", c.get("stick"))
            if stick is None:
                continue
            w = None
            if callable(getattr(source, "relative_velocity", None)):
                w = (lambda x, t, k=k: source.relative_velocity(x, t, k))
            out.append(Contact(str(name), frozenset(int(m) for m in stick), w))
        if out:
            return tuple(out)
    stick = frozenset(i for i, m in enumerate(system.modes) if m.kind in STICK_KINDS)
    loop = source if hasattr(source, "model_code") else None
    w = (lambda x, t: x[1]) if loop is not None else None          # the servo loops: w = x2
    return (Contact("friction", stick, w),)


def resolve(target, params: Mapping | None = None) -> Target:
    """Resolve what a user gave (preset name, ServoLoop, compiled model, PiecewiseSystem) with
    parameter overrides by name into a :class:`Target`.

    Parameters
    ----------
    target : str or ServoLoop or compiled model or PiecewiseSystem
    params : mapping name -> value, optional
        Overrides: preset parameters (``P``, ``K``, ``model``, ...) for a preset name, system
        parameters (``kp``, ...) for a ServoLoop or PiecewiseSystem, model parameters for a
        compiled model.

    Examples
    --------
    >>> from hunting.continuation import resolve
    >>> t = resolve("table8.1-lugre", {"K": 0.04})
    >>> t.state_names, t.label
    (('x1', 'x2', 'x3', 'x4'), 'table8.1-lugre(K=0.04)')
    """
    from ..models.loop import ServoLoop
    params = dict(params or {})
    if isinstance(target, str):
        from ..models.presets import PRESETS, preset as build_preset
        if target not in PRESETS:
            raise SystemDefinitionError(f"preset = {target!r} is not known: presets are {sorted(PRESETS)}")
        loop = build_preset(target, **params)
        return Target(loop.system, loop.name, _contacts_of(loop.system, loop), loop, (target, params), target)
    if isinstance(target, ServoLoop):
        if params:
            sys_ = target.system.with_params(params)
            return Target(sys_, target.name, _contacts_of(sys_, target), None, None, sys_)
        return Target(target.system, target.name, _contacts_of(target.system, target), target, None, target)
    if _is_model(target):
        model = target.with_params(**params) if params else target
        label = getattr(model, "name", None) or model.system.name
        return Target(model.system, str(label), _contacts_of(model.system, model), None, None, model)
    if isinstance(target, PiecewiseSystem):
        sys_ = target.with_params(params) if params else target
        return Target(sys_, sys_.name, _contacts_of(sys_, None), None, None, sys_)
    raise SystemDefinitionError(f"system = {target!r} is not allowed: give a preset name, a ServoLoop, a compiled "
                                f"model (hunting.model(...)) or a PiecewiseSystem")
