"""``CompiledModel``: a description compiled into a :class:`~hunting.system.PiecewiseSystem`,
with its names, parameter layout and friction contacts."""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

import numpy as np

from ..errors import SystemDefinitionError, check_finite
from ..system import Mode, PiecewiseSystem
from . import cache
from .description import GENERATOR_VERSION, SLIP_VARIABLE, Spec
from .expressions import TIME, evaluate, first_non_finite, parse

PART_NAMES = ("slip+", "slip-", "stick")


@dataclass(frozen=True)
class Layout:
    """The one map between names and array slots.

    param_names : names of ``params[0:n_params]`` in order; state_names : names of ``x[0:n]``
    (the description's states, then LuGre bristle states, then linear-block states)."""

    param_names: tuple
    state_names: tuple

    def param(self, name: str) -> int:
        """Slot of parameter ``name`` in the flat parameter array."""
        return _index(self.param_names, name, "parameter")

    def state(self, name: str) -> int:
        """Index of state ``name`` in the state vector."""
        return _index(self.state_names, name, "state")


def _index(names: tuple, name: str, what: str) -> int:
    if name not in names:
        raise SystemDefinitionError(f"{what} {name!r} is not a {what} of this model: {what}s are {list(names)}")
    return names.index(name)


@dataclass(frozen=True)
class Contact:
    """One friction contact of a compiled model and the modes it is in.

    name, model ("switch" or "lugre"), force (the symbol of its force), velocity (the relative
    velocity expression w); index : position in ``CompiledModel.contacts``; surface_state : the
    state the stick entry moves so that w = 0 (w depends on it linearly); bristle_state : index
    of z (LuGre), else None; slip_pos_modes, slip_neg_modes, stick_modes : system mode indices
    where this contact slips with w > 0, with w < 0, or sticks (LuGre: w >= 0 / w < 0 and no
    stick modes); guards : its two guard indices (velocity zero / break-away upward, break-away
    downward)."""

    name: str
    model: str
    force: str
    velocity: str
    index: int
    surface_state: int
    bristle_state: int | None
    slip_pos_modes: tuple
    slip_neg_modes: tuple
    stick_modes: tuple
    guards: tuple

    def part(self, mode: int) -> str:
        """"slip+", "slip-" or "stick": what this contact does in system mode ``mode``."""
        if mode in self.stick_modes:
            return "stick"
        if mode in self.slip_pos_modes:
            return "slip+"
        if mode in self.slip_neg_modes:
            return "slip-"
        raise SystemDefinitionError(f"mode = {mode!r} is not a mode of contact {self.name!r}")

    def is_stick(self, mode: int) -> bool:
        return mode in self.stick_modes


def _contacts(spec: Spec, meta: dict) -> tuple:
    out = []
    parts = meta["mode_parts"]
    for i, (c, cm) in enumerate(zip(spec.contacts, meta["contacts"])):
        modes = lambda q: tuple(m for m, pt in enumerate(parts) if pt[i] == q)  # noqa: E731
        out.append(Contact(c.name, c.model, c.force, c.velocity.canonical, i, cm["surface"], cm["bristle"],
                           modes(0), modes(1), modes(2) if c.model == "switch" else (), (2 * i, 2 * i + 1)))
    return tuple(out)


class CompiledModel:
    """A model description compiled into a piecewise-smooth system.

    Attributes
    ----------
    system : PiecewiseSystem
        Every function of the library takes it (simulate, flow, shoot, continuation, ...).
    description : dict
        The validated, normalized description with the current parameter values (JSON-ready;
        ``hunting.model(m.description)`` rebuilds the same model).
    name : str
    layout : Layout
        Names <-> slots of parameters and states.
    state_names, param_names, mode_names, signal_names : tuple of str
        ``signal_names``: the signals, block outputs and friction forces ``signals()`` returns.
    contacts : tuple of Contact
    stick_modes : tuple of int
        Modes in which at least one contact sticks.
    cache_path : Path
        The generated module (its numba cache lives beside it).

    Parameter values never recompile: :meth:`with_params` shares the compiled functions.
    """

    def __init__(self, spec: Spec, module, meta: dict, params: np.ndarray, system: PiecewiseSystem | None = None):
        self._spec = spec
        self._module = module
        self._meta = meta
        self.layout = Layout(tuple(meta["param_names"]), tuple(meta["state_names"]))
        self.contacts = _contacts(spec, meta)
        self.mode_names = tuple(meta["mode_names"])
        self.signal_names = tuple(meta["signal_names"])
        self.cache_path = Path(module.__file__)
        if system is None:
            modes = []
            for m, pt in enumerate(meta["mode_parts"]):
                stuck = [c for c in self.contacts if c.is_stick(m)]
                modes.append(Mode(self.mode_names[m], "stick", stuck[0].surface_state) if stuck
                             else Mode(self.mode_names[m]))
            system = PiecewiseSystem(
                name=spec.name, state_names=self.layout.state_names, modes=tuple(modes),
                guard_names=tuple(meta["guard_names"]), param_names=self.layout.param_names,
                params=params if len(params) else np.zeros(1), vector_field=module.vf, guards=module.guards,
                transition=module.reset, mode_of=module.mode_of, jacobian=module.jac,
                units=dict(spec.description.get("units", {})),
                explain=self.explain_non_finite)
        self.system = system

    # ------------------------------------------------------------------ names and layout
    @property
    def name(self) -> str:
        return self._spec.name

    @property
    def state_names(self) -> tuple:
        return self.layout.state_names

    @property
    def param_names(self) -> tuple:
        return self.layout.param_names

    @property
    def n_states(self) -> int:
        return len(self.layout.state_names)

    @property
    def params(self) -> np.ndarray:
        """Current parameter values (a copy), in layout order."""
        return self.system.params[: len(self.param_names)].copy()

    @property
    def stick_modes(self) -> tuple:
        return tuple(sorted({m for c in self.contacts for m in c.stick_modes}))

    @property
    def description(self) -> dict:
        d = copy.deepcopy(self._spec.description)
        d["parameters"] = {k: float(v) for k, v in zip(self.param_names, self.params)}
        return d

    def param_index(self, name: str) -> int:
        """Slot of a parameter in the flat array (``layout.param``)."""
        return self.layout.param(name)

    def param_direction(self, name: str) -> np.ndarray:
        """d params / d mu for mu = the parameter ``name``: a unit vector at its slot."""
        d = np.zeros_like(self.system.params)
        d[self.layout.param(name)] = 1.0
        return d

    def params_with(self, values: Mapping[str, float] | None = None, /, **kw) -> np.ndarray:
        """The flat parameter array with named values replaced (checked, not stored)."""
        new = np.array(self.system.params, dtype=np.float64)
        for k, v in {**(values or {}), **kw}.items():
            slot = self.layout.param(k)
            val = check_finite(f"parameter {k}", v)
            new[slot] = val
        self._spec.check_parameter_values(dict(zip(self.param_names, new)))
        self._check_blocks(new)
        return new

    def _check_blocks(self, params: np.ndarray) -> None:
        """Raise when a parameter value makes a linear block's leading denominator coefficient
        zero (the block's realization divides by it)."""
        for b in self._meta.get("block_leads", ()):
            v = evaluate_or_nan(parse(b["lead"], "lead"), {f"p_{j}": float(x) for j, x in enumerate(params)})
            if v == 0 or not math.isfinite(v):
                used = ", ".join(f"{n} = {params[j]:g}" for j, n in enumerate(self.param_names)
                                 if f"p_{j}" in parse(b["lead"], "lead").names)
                raise SystemDefinitionError(
                    f"blocks[{b['output']!r}]: the leading coefficient of the denominator, {b['text']}, is {v:g} "
                    f"with {used}: the transfer function is not defined (allowed: parameter values that keep it "
                    "nonzero)")

    def with_params(self, values: Mapping[str, float] | None = None, /, **kw) -> "CompiledModel":
        """Copy with named parameter values replaced; nothing recompiles.

        Examples
        --------
        >>> import hunting
        >>> m = hunting.model({"parameters": {"k": 1.0, "c": 0.1}, "states": ["q", "v"],
        ...                    "equations": {"q": "v", "v": "-k*q - c*v"}})
        >>> m.with_params(k=3.0).system.param("k"), m.system.param("k")
        (3.0, 1.0)
        """
        new = copy.copy(self)
        new.system = self.system.with_param_array(self.params_with(values, **kw))
        return new

    def state(self, **named) -> np.ndarray:
        """State vector (n,) from named values; unnamed states are 0 (LuGre bristle states take
        their contact's z0, states given initial values in the description take those).

        Examples
        --------
        >>> import hunting
        >>> m = hunting.model({"parameters": {"k": 1.0, "c": 0.1}, "states": ["q", "v"],
        ...                    "equations": {"q": "v", "v": "-k*q - c*v"}})
        >>> m.state(q=0.1).tolist()
        [0.1, 0.0]
        """
        x = np.zeros(self.n_states)
        for k, v in self._spec.initial.items():
            x[self.layout.state(k)] = v
        for c in self._spec.contacts:
            if c.model == "lugre":
                x[self.layout.state(c.state)] = c.z0
        for k, v in named.items():
            x[self.layout.state(k)] = check_finite(f"state {k}", v)
        return self.system.check_state(x)

    # ------------------------------------------------------------------ evaluation
    def _mode(self, x, t, mode):
        return self.system.initial_mode(x, t) if mode is None else int(mode)

    def relative_velocity(self, x, t: float = 0.0, contact: int | str = 0) -> float:
        """w of a contact (index or name) at state x (n,), time t."""
        ci = contact if isinstance(contact, int) else next(
            (c.index for c in self.contacts if c.name == contact), None)
        if ci is None or not 0 <= ci < len(self.contacts):
            raise SystemDefinitionError(f"contact = {contact!r} is not a contact: contacts are "
                                        f"{[c.name for c in self.contacts]}")
        return float(self._module._w(ci, float(t), self.system.check_state(x, "x"), self.system.params))

    def signals(self, x, t: float = 0.0, mode: int | None = None) -> dict:
        """Values of the signals, block outputs and friction forces at x (n,), t, in ``mode``
        (default: the mode ``mode_of`` gives)."""
        x = self.system.check_state(x, "x")
        out = np.empty(max(1, len(self.signal_names)))
        self._module.signals(self._mode(x, t, mode), float(t), x, self.system.params, out)
        return dict(zip(self.signal_names, out.tolist()))

    def jacobian(self, x, t: float = 0.0, mode: int | None = None) -> np.ndarray:
        """d f / d x (n, n) of the mode's vector field (from symbolic differentiation)."""
        x = self.system.check_state(x, "x")
        J = np.zeros((self.n_states, self.n_states))
        self._module.jac(self._mode(x, t, mode), float(t), x, self.system.params, J)
        return J

    def param_jacobian(self, x, t: float = 0.0, mode: int | None = None) -> np.ndarray:
        """d f / d p (n, n_params) of the mode's vector field, columns in layout order."""
        x = self.system.check_state(x, "x")
        J = np.zeros((self.n_states, len(self.param_names)))
        self._module.pjac(self._mode(x, t, mode), float(t), x, self.system.params, J)
        return J

    def explain_non_finite(self, mode: int, t: float, x, p) -> str | None:
        """Which expression of the description is not finite at (mode, t, x, p), in words, or
        None when every signal, friction term and equation is finite there. Signals first (in
        the order they are computed), then each contact's velocity and force, then the
        equations: the first one named is the cause, the later ones inherit it.

        For example ``"equations['v'] = '(u - F)/m' is not finite: division by m = 0"``."""
        spec = self._spec
        x = np.ascontiguousarray(x, dtype=np.float64)
        p = np.ascontiguousarray(p, dtype=np.float64)
        values = {TIME: float(t), **{n: float(v) for n, v in zip(self.param_names, p)},
                  **{n: float(v) for n, v in zip(self.state_names, x)}}
        out = np.empty(max(1, len(self.signal_names)))
        self._module.signals(int(mode), float(t), x, p, out)
        values.update(zip(self.signal_names, out.tolist()))

        def why(where, expr, extra=None):
            detail = first_non_finite(expr, {**values, **(extra or {})})
            if detail is None:
                return None
            return f"{where} = {expr.text!r} is not finite: {detail}"

        for k in spec.signal_order:
            if k in spec.signals and not math.isfinite(values[k]):
                text = why(f"signals[{k!r}]", spec.signals[k])
                if text:
                    return text
        for b in spec.blocks:
            if not math.isfinite(values[b.output]):
                return (f"the output of blocks[{b.output!r}] is {values[b.output]} "
                        f"(its input {b.input.text!r} = {evaluate_or_nan(b.input, values):.6g})")
        for c, cc in zip(spec.contacts, self.contacts):
            w = float(self._module._w(cc.index, float(t), x, p))
            name = f"friction[{c.name!r}]"
            if not math.isfinite(w):
                return why(f"{name}.velocity", c.velocity) or f"{name}.velocity is {w}"
            if not math.isfinite(values[c.force]):
                part = cc.part(int(mode))
                laws = ([("slip", c.slip)] if part != "stick" else [("stick", c.stick[0]), ("stick", c.stick[1])]) \
                    if c.model == "switch" else [("level", c.level), ("sigma0", c.sigma0), ("sigma1", c.sigma1),
                                                 ("viscous", c.viscous)]
                for key, e in laws:
                    text = why(f"{name}.{key}", e, {SLIP_VARIABLE: w})
                    if text:
                        return text
                return f"the friction force {c.force} of {name} is {values[c.force]} ({part})"
        for s_, e in spec.equations.items():
            text = why(f"equations[{s_!r}]", e)
            if text:
                return text
        return None

    def summary(self) -> str:
        """Text listing of the model: states, parameters with values, signals, contacts, modes
        (for command-line listings)."""
        d = self._spec.description
        lines = [f"{self.name}: {self.n_states} states, {len(self.mode_names)} modes"]
        lines.append("  states: " + ", ".join(self.state_names))
        lines += [f"  {k:<16} = {v:<14.6g} parameter" for k, v in zip(self.param_names, self.params)]
        lines += [f"  {k:<16} = {v}" for k, v in d["signals"].items()]
        lines += [f"  d{k}/dt = {v}" for k, v in d["equations"].items()]
        for c, cd in zip(self.contacts, d["friction"]):
            law = (f"slip {cd['slip']}, stick [-({cd['stick'][0]}), {cd['stick'][1]}]" if c.model == "switch"
                   else f"level {cd['level']}, sigma0 {cd['sigma0']}, sigma1 {cd['sigma1']}, viscous {cd['viscous']}")
            lines.append(f"  contact {c.name} ({c.model}): force {c.force}, w = {c.velocity}; {law}")
        for b in d["blocks"]:
            what = b.get("tf") or (f"delay {b['delay']} (Pade {b['order']})" if "delay" in b
                                   else f"num {b['num']} / den {b['den']}")
            lines.append(f"  block {b['output']} = [{what}] ({b['input']})")
        lines.append("  modes: " + ", ".join(f"{i} {n}" for i, n in enumerate(self.mode_names)))
        return "\n".join(lines)

    def __repr__(self) -> str:
        return (f"CompiledModel({self.name!r}, states={list(self.state_names)}, "
                f"params={dict(zip(self.param_names, self.params.tolist()))}, modes={list(self.mode_names)})")


def compile_spec(spec: Spec):
    """(module, meta) of a checked description: from the cache, or built, generated and stored."""
    digest = spec.structure_hash
    hit = cache.lookup(digest)
    if hit is not None and hit[1].get("version") == GENERATOR_VERSION:
        return hit
    from . import codegen, symbolic
    sym = symbolic.build(spec)
    source = codegen.generate(sym, digest, GENERATOR_VERSION)
    meta = {"version": GENERATOR_VERSION, "state_names": list(sym.state_names), "param_names": list(sym.param_names),
            "mode_names": list(sym.mode_names), "guard_names": list(sym.guard_names),
            "mode_parts": [list(pt) for pt in sym.modes], "signal_names": list(sym.signal_names),
            "contacts": [{"surface": int(sym.surface[i]),
                          "bristle": sym.bristle_states.get(c.state) if c.model == "lugre" else None}
                         for i, c in enumerate(sym.contacts)],
            "block_leads": _block_leads(sym)}
    return cache.store(digest, source, meta)


def evaluate_or_nan(expr, values: dict) -> float:
    """``evaluate``, NaN where it fails (for messages about values that are already bad)."""
    try:
        return evaluate(expr, values)
    except SystemDefinitionError:
        return math.nan


def _block_leads(sym) -> list:
    """The leading denominator coefficients of the linear blocks that depend on parameters, as
    text in the parameter slots p_j (checked at every parameter change) and in their names."""
    import sympy as sp
    names = {p: sp.Symbol(n) for p, n in zip(sym.p, sym.param_names)}
    return [{"output": out, "lead": str(lead), "text": str(lead.subs(names))}
            for out, lead in sym.block_leads if lead.free_symbols]


def build_model(spec: Spec, overrides: Mapping[str, float] | None = None) -> CompiledModel:
    """Compile (or load) a checked description and apply parameter overrides."""
    module, meta = compile_spec(spec)
    params = np.array([spec.parameters[k] for k in meta["param_names"]], dtype=np.float64)
    m = CompiledModel(spec, module, meta, params)
    if overrides:
        return m.with_params(overrides)           # checks the values
    m._check_blocks(m.system.params)
    return m
