"""Validation of a model description: from a user's dict to a checked :class:`Spec`.

The description (the same in JSON, YAML and Python)::

    {"name": "belt",                                   # optional label
     "parameters": {"m": 1.0, "k": 2.0, ...},          # name -> default value (the layout order)
     "states": ["q", "v"],                             # or {"q": 0.0, "v": 0.0}: initial values
     "signals": {"u": "-k*q"},                         # name -> expression (any order, no cycles)
     "equations": {"q": "v", "v": "(u - F)/m"},        # one right-hand side per state
     "friction": {...} or [{...}, ...],                # contacts (below), optional
     "blocks": [{...}, ...],                           # linear blocks (below), optional
     "units": {"q": "m", "v": "m/s", "F": "N", "t": "s"}}  # optional: figure labels only

A friction contact::

    {"name": "belt",                  # optional (default "friction", or "friction1", ... for several)
     "force": "F",                    # the symbol the equations use for this contact's force
     "velocity": "v - vb",            # relative velocity w: an expression of t, parameters, states
     "model": "switch",
     "slip": "sign(w)*(Fc + (Fs - Fc)*exp(-abs(w)/vs))",   # force while slipping, in w
     "stick": "Fs"}                   # stick set [-Fs, Fs]; or ["Fs_neg", "Fs_pos"]: [-Fs_neg, Fs_pos]

    {"force": "F", "velocity": "v", "model": "lugre",
     "level": "Fc + (Fs - Fc)*exp(-(w/vs)**2)",   # g(w) > 0
     "sigma0": "sigma0", "sigma1": "sigma1",     # expressions (sigma1 may use w)
     "viscous": "b*w",                           # optional, default 0
     "state": "z", "z0": 0.0}                    # optional: bristle state name and initial value

A linear block (output is a new signal; its states are added after the states above)::

    {"output": "u", "input": "r - q", "tf": "K*(1 + 1/(tau_i*s) + tau_d*s)/(1 + s/wlp)"}
    {"output": "u", "input": "e", "num": ["kd", "kp"], "den": ["tf", 1]}      # descending powers of s
    {"output": "ud", "input": "u", "delay": "Td", "order": 3}                 # Pade approximation

Nothing here imports sympy: a description whose compiled form is cached is loaded without it.
"""
from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass, field

from ..errors import SystemDefinitionError
from .expressions import CONSTANTS, FUNCTIONS, TIME, Expr, evaluate, parse

#: bump when the generated code changes so cached modules from older versions are not reused
GENERATOR_VERSION = 1
#: the most friction contacts a description may have (modes are the product: 3 per Switch contact)
MAX_CONTACTS = 4
#: the largest Pade order of a delay block
MAX_PADE_ORDER = 10
SLIP_VARIABLE = "w"
TF_VARIABLE = "s"
_TOP_KEYS = ("name", "parameters", "states", "signals", "equations", "friction", "blocks", "units")
_SWITCH_KEYS = ("name", "force", "velocity", "model", "slip", "stick")
_LUGRE_KEYS = ("name", "force", "velocity", "model", "level", "sigma0", "sigma1", "viscous", "state", "z0")
_RESERVED = set(FUNCTIONS) | set(CONSTANTS) | {TIME}


@dataclass(frozen=True)
class ContactSpec:
    """One friction contact of a checked description (see the module docstring)."""

    name: str
    model: str
    force: str
    velocity: Expr
    slip: Expr | None = None
    stick: tuple | None = None            # (neg, pos): stick set [-neg, pos]
    level: Expr | None = None
    sigma0: Expr | None = None
    sigma1: Expr | None = None
    viscous: Expr | None = None
    state: str | None = None              # LuGre bristle state
    z0: float = 0.0


@dataclass(frozen=True)
class BlockSpec:
    """One linear block: ``tf`` (an expression in s) or ``num``/``den`` (descending powers of s),
    or a Pade ``delay`` of ``order``."""

    output: str
    input: Expr
    tf: Expr | None = None
    num: tuple = ()
    den: tuple = ()
    delay: Expr | None = None
    order: int = 0


@dataclass(frozen=True)
class Spec:
    """A checked description.

    parameters : dict name -> default (layout order); states : user states in order;
    initial : dict state -> initial value; signals : dict name -> Expr (user order);
    signal_order : signal and block-output names in an order where each uses only earlier
    ones; equations : dict state -> Expr; contacts : tuple of ContactSpec; blocks : tuple of
    BlockSpec; description : the normalized, JSON-serializable description."""

    name: str
    parameters: dict
    states: tuple
    initial: dict
    signals: dict
    signal_order: tuple
    equations: dict
    contacts: tuple
    blocks: tuple
    description: dict = field(repr=False)

    @property
    def forces(self) -> tuple:
        return tuple(c.force for c in self.contacts)

    @property
    def structure_hash(self) -> str:
        """Hash of everything that changes the generated code: not the parameter values, the
        initial values or the name (those live in arrays and labels, so they never recompile)."""
        d = dict(self.description)
        d.pop("name", None)
        d.pop("units", None)            # labels only
        d["parameters"] = list(d["parameters"])
        d["states"] = list(d["states"])
        for c in d.get("friction", []):
            c.pop("z0", None)
        text = json.dumps({"v": GENERATOR_VERSION, "g": _generator_digest(), "d": d}, sort_keys=True,
                          separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:20]

    def check_parameter_values(self, values: dict) -> None:
        """Raise when a stick bound that depends on parameters only is negative at ``values``,
        or lower than the slip force next to w = 0 (where both depend on parameters only)."""
        known = set(self.parameters) | set(CONSTANTS)
        for c in self.contacts:
            if c.stick is None:
                continue
            bounds = []
            for side, e in zip(("negative-direction", "positive-direction"), c.stick):
                if e.names <= known:
                    v = evaluate(e, values)
                    if not (v >= 0 and math.isfinite(v)):
                        raise SystemDefinitionError(
                            f"friction[{c.name!r}].stick = {e.text!r} is {v!r} at the parameter values: "
                            f"the {side} stick bound must be a finite number >= 0")
                    bounds.append(v)
            if len(bounds) == 2 and c.slip.names <= known | {SLIP_VARIABLE}:
                _check_break_away(c, bounds, values)


_W_NEAR_ZERO = 1e-12     # [velocity] where the slip force next to w = 0 is read


def _check_break_away(c: "ContactSpec", bounds: list, values: dict) -> None:
    """A Switch contact leaves stick when its force reaches a stick bound; the slip force just
    after must not exceed that bound, or the contact is pushed straight back onto w = 0 and
    chatters between stick and slip (a Zeno run). Static friction >= kinetic, in the model's
    words: |slip(0+)| <= stick bound (positive side), |slip(0-)| <= stick bound (negative)."""
    for k, (side, s) in enumerate((("negative", -1.0), ("positive", 1.0))):
        try:
            f = s * evaluate(c.slip, {**values, SLIP_VARIABLE: s * _W_NEAR_ZERO})
        except SystemDefinitionError:
            return                      # a law not defined at w -> 0: the run will say
        if f > bounds[k] * (1 + 1e-9) + 1e-12:
            stick = c.stick[k].text
            raise SystemDefinitionError(
                f"friction[{c.name!r}]: the slip force at w -> 0{'+' if s > 0 else '-'} is {f:.6g}, more than the "
                f"{side}-direction stick bound {stick!r} = {bounds[k]:.6g}: a contact that breaks free would be "
                "pushed straight back to w = 0 and chatter (allowed: stick bounds >= the slip force at w = 0, "
                "static friction at least the kinetic)")


_GEN_DIGEST: list = []


def _default_contact_name(i: int, n: int) -> str:
    """The name of the i-th of n contacts that gives none: 'friction' alone, else 'friction<i+1>'."""
    return "friction" if n == 1 else f"friction{i + 1}"


def contact_label(i: int, c, n: int) -> str:
    """How every description error names a friction contact: friction['<name>'] (its name, or the
    default name of its place when it gives none or none that is a name), never its index."""
    name = c.get("name") if isinstance(c, dict) else None
    if not (isinstance(name, str) and name.isidentifier()):
        name = _default_contact_name(i, n)
    return f"friction[{name!r}]"


def _generator_digest() -> str:
    """Hash of the generator's own source (symbolic.py, codegen.py): a changed generator never
    reuses modules generated by an older one."""
    if not _GEN_DIGEST:
        from pathlib import Path
        here = Path(__file__).parent
        h = hashlib.sha256()
        for f in ("symbolic.py", "codegen.py"):
            h.update((here / f).read_bytes())
        _GEN_DIGEST.append(h.hexdigest()[:12])
    return _GEN_DIGEST[0]


def _identifier(name, where) -> str:
    if not isinstance(name, str) or not name.isidentifier() or name.startswith("_"):
        raise SystemDefinitionError(f"{where} = {name!r} is not allowed: names must be identifiers "
                                    "(letters, digits, underscore; not starting with a digit or '_')")
    if name in _RESERVED:
        raise SystemDefinitionError(f"{where} = {name!r} is reserved ({sorted(_RESERVED)} are taken)")
    return name


def _expr(text, where, allowed: set, what: str) -> Expr:
    e = parse(text, where)
    bad = sorted(e.names - allowed - set(CONSTANTS) - {TIME})
    if bad:
        raise SystemDefinitionError(
            f"{where} = {e.text!r}: unknown name{'s' if len(bad) > 1 else ''} {', '.join(map(repr, bad))} "
            f"({what})")
    return e


def _mapping(desc, key, where="description") -> dict:
    v = desc.get(key, {})
    if v is None:
        return {}
    if not isinstance(v, dict):
        raise SystemDefinitionError(f"{where}[{key!r}] = {v!r} must be a mapping of names to values")
    return v


def validate(desc) -> Spec:
    """Check a description dict and return its :class:`Spec`; every problem is a
    SystemDefinitionError that names the entry, its text and what is allowed."""
    if not isinstance(desc, dict):
        raise SystemDefinitionError(f"a model description must be a mapping, got {type(desc).__name__}")
    unknown = [k for k in desc if k not in _TOP_KEYS]
    if unknown:
        raise SystemDefinitionError(f"description keys {unknown} are not known: allowed keys are {list(_TOP_KEYS)}")
    name = desc.get("name", "model")
    if not isinstance(name, str) or not name:
        raise SystemDefinitionError(f"name = {name!r} must be a non-empty string")

    taken: dict = {}                       # name -> what it is (for clash messages)

    def claim(n, what, where):
        _identifier(n, where)
        if n in taken:
            raise SystemDefinitionError(f"{where} = {n!r} is already used as a {taken[n]}")
        taken[n] = what

    # parameters
    params = {}
    for k, v in _mapping(desc, "parameters").items():
        claim(k, "parameter", f"parameters[{k!r}]")
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise SystemDefinitionError(f"parameters[{k!r}] = {v!r} is not allowed: a default value must be a finite number")
        params[k] = float(v)

    # states
    raw_states = desc.get("states")
    if raw_states is None or (isinstance(raw_states, (list, tuple, dict)) and len(raw_states) == 0):
        raise SystemDefinitionError("states is missing or empty: list the state names, e.g. \"states\": [\"q\", \"v\"]")
    if isinstance(raw_states, dict):
        items = list(raw_states.items())
    elif isinstance(raw_states, (list, tuple)):
        items = [(s, 0.0) for s in raw_states]
    else:
        raise SystemDefinitionError(f"states = {raw_states!r} must be a list of names or a mapping name -> initial value")
    states, initial = [], {}
    for s, v in items:
        claim(s, "state", f"states[{s!r}]" if isinstance(s, str) else "states")
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise SystemDefinitionError(f"states[{s!r}] = {v!r}: an initial value must be a finite number")
        states.append(s)
        initial[s] = float(v)

    # contacts: names first (forces and bristle states are names the rest may use)
    raw_f = desc.get("friction", [])
    if raw_f is None:
        raw_f = []
    if isinstance(raw_f, dict):
        raw_f = [raw_f]
    if not isinstance(raw_f, (list, tuple)):
        raise SystemDefinitionError(f"friction = {raw_f!r} must be a contact (mapping) or a list of contacts")
    if len(raw_f) > MAX_CONTACTS:
        raise SystemDefinitionError(
            f"friction has {len(raw_f)} contacts: at most {MAX_CONTACTS} are supported (the modes are the "
            f"product of the contacts' modes, 3 per Switch contact: {3 ** MAX_CONTACTS} at most)")
    labels = [contact_label(i, c, len(raw_f)) for i, c in enumerate(raw_f)]
    for c, w in zip(raw_f, labels):
        if not isinstance(c, dict):
            raise SystemDefinitionError(f"{w} = {c!r} must be a mapping")
        model = c.get("model")
        if model not in ("switch", "lugre"):
            raise SystemDefinitionError(f"{w}.model = {model!r} is not allowed: use 'switch' or 'lugre'")
        keys = _SWITCH_KEYS if model == "switch" else _LUGRE_KEYS
        bad = [k for k in c if k not in keys]
        if bad:
            raise SystemDefinitionError(f"{w} ({model}) keys {bad} are not known: allowed keys are {list(keys)}")
        for k in ("force", "velocity") + (("slip", "stick") if model == "switch" else ("level", "sigma0", "sigma1")):
            if k not in c:
                raise SystemDefinitionError(f"{w} ({model}) needs {k!r}")
    cnames = []
    for i, (c, w) in enumerate(zip(raw_f, labels)):
        cn = c.get("name", _default_contact_name(i, len(raw_f)))
        if not isinstance(cn, str) or not cn.isidentifier():
            raise SystemDefinitionError(f"{w}.name = {cn!r} must be an identifier")
        if cn in cnames:
            raise SystemDefinitionError(f"{w}.name = {cn!r} is used by two contacts")
        cnames.append(cn)
        claim(c["force"], "friction force", f"friction[{cn!r}].force")
        if c["model"] == "lugre":
            st = c.get("state", "z" if len(raw_f) == 1 else f"z_{cn}")
            claim(st, "bristle state", f"friction[{cn!r}].state")

    # blocks: output names
    raw_b = desc.get("blocks", [])
    if raw_b is None:
        raw_b = []
    if not isinstance(raw_b, (list, tuple)):
        raise SystemDefinitionError(f"blocks = {raw_b!r} must be a list of blocks")
    for i, b in enumerate(raw_b):
        if not isinstance(b, dict):
            raise SystemDefinitionError(f"blocks[{i}] = {b!r} must be a mapping")
        if "output" not in b or "input" not in b:
            raise SystemDefinitionError(f"blocks[{i}] needs 'output' (a new signal name) and 'input' (an expression)")
        claim(b["output"], "block output", f"blocks[{i}].output")

    # signals
    sigs_raw = _mapping(desc, "signals")
    for k in sigs_raw:
        claim(k, "signal", f"signals[{k!r}]")
    forces = {c["force"] for c in raw_f}
    bristles = {n for n, w in taken.items() if w == "bristle state"}
    block_out = {b["output"] for b in raw_b}
    everything = set(params) | set(states) | bristles | set(sigs_raw) | block_out | forces
    what = "names must be parameters, states, signals, block outputs, friction forces, t or pi"
    signals = {k: _expr(v, f"signals[{k!r}]", everything, what) for k, v in sigs_raw.items()}

    blocks = []
    for i, b in enumerate(raw_b):
        blocks.append(_block(b, i, everything, set(params), what))

    # the order of signals: each after the signals it uses (cycles are errors). Block outputs
    # are sources here: a strictly proper block breaks a loop through its states; a loop through
    # a block's direct feed-through is found when the block is expanded (compile time).
    deps = {k: e.names & set(signals) for k, e in signals.items()}
    order = _topological(deps, list(sigs_raw)) + tuple(b.output for b in blocks)
    used = {k: e.names for k, e in signals.items()}
    used.update({b.output: b.input.names for b in blocks})

    def reaches(k, targets, seen):
        """True when signal/block output k uses a name in targets, directly or through others."""
        if k in seen:
            return False
        seen.add(k)
        return bool(used[k] & targets) or any(reaches(d, targets, seen) for d in used[k] if d in used)

    uses_force = {k: reaches(k, forces, set()) for k in order}
    uses_state = {k: k in block_out or reaches(k, set(states) | bristles | block_out, set()) for k in order}

    # equations
    eqs_raw = _mapping(desc, "equations")
    if not eqs_raw:
        raise SystemDefinitionError("equations is missing or empty: give one right-hand side per state, "
                                    "e.g. \"equations\": {\"q\": \"v\", \"v\": \"(u - F)/m\"}")
    extra = [k for k in eqs_raw if k not in states]
    if extra:
        hint = ""
        auto = [k for k in extra if k in bristles]
        if auto:
            hint = f" ({auto} are bristle states: their equation is added by the LuGre contact)"
        raise SystemDefinitionError(f"equations for {extra} but they are not states{hint}: states are {states}")
    missing = [s for s in states if s not in eqs_raw]
    if missing:
        raise SystemDefinitionError(f"state{'s' if len(missing) > 1 else ''} {missing} "
                                    f"{'have' if len(missing) > 1 else 'has'} no equation: add it under \"equations\"")
    equations = {s: _expr(eqs_raw[s], f"equations[{s!r}]", everything, what) for s in states}

    # contacts
    free = set(params) | set(states) | bristles | {k for k in order if not uses_force[k]}
    contacts = []
    for i, c in enumerate(raw_f):
        cn = cnames[i]
        w = f"friction[{cn!r}]"
        vel = parse(c["velocity"], f"{w}.velocity")
        bad_f = sorted(vel.names & forces) + sorted(k for k in vel.names if uses_force.get(k))
        if bad_f:
            raise SystemDefinitionError(f"{w}.velocity = {vel.text!r} uses {bad_f}, which depend on friction forces: "
                                        "a relative velocity is kinematic (states, parameters, t)")
        vel = _expr(c["velocity"], f"{w}.velocity", free, "a velocity uses parameters, states, t and signals "
                    "that do not depend on friction forces")
        if not (vel.names & (set(states) | bristles) or any(uses_state.get(k) for k in vel.names)):
            raise SystemDefinitionError(f"{w}.velocity = {vel.text!r} depends on no state: the relative velocity "
                                        "of a contact must depend on the motion (e.g. \"v\" or \"v - vb\")")
        law_names = free | {SLIP_VARIABLE}
        law_what = "friction laws use w (the relative velocity), parameters, states, t and force-free signals"
        if SLIP_VARIABLE in taken:
            raise SystemDefinitionError(f"{SLIP_VARIABLE!r} is used as a {taken[SLIP_VARIABLE]} but it is the "
                                        "relative velocity inside friction laws: rename it")
        if c["model"] == "switch":
            slip = _expr(c["slip"], f"{w}.slip", law_names, law_what)
            st = c["stick"]
            stick_what = "stick bounds use parameters, t and signals that depend on neither forces nor states"
            if isinstance(st, (list, tuple)):
                if len(st) != 2:
                    raise SystemDefinitionError(f"{w}.stick = {st!r}: give one bound (symmetric) or two, [neg, pos] "
                                                "(the stick set is [-neg, pos])")
                pair = tuple(_expr(e, f"{w}.stick[{j}]", free, stick_what) for j, e in enumerate(st))
                where_st = [f"{w}.stick[{j}]" for j in range(2)]
            else:
                e = _expr(st, f"{w}.stick", free, stick_what)
                pair, where_st = (e, e), [f"{w}.stick"] * 2
            for e, where in zip(pair, where_st):
                # the stick set is fixed while the contact sticks: a bound that moves with the
                # state crosses the stick force (or the slip force) as the free states drift,
                # and the contact chatters between stick and slip
                moving = sorted(e.names & (set(states) | bristles)) + sorted(k for k in e.names if uses_state.get(k))
                if moving:
                    raise SystemDefinitionError(
                        f"{where} = {e.text!r} depends on the state through {', '.join(moving)} (allowed: {stick_what}; "
                        "a stick bound is fixed while the contact sticks)")
            contacts.append(ContactSpec(cn, "switch", c["force"], vel, slip=slip, stick=pair))
        else:
            z0 = c.get("z0", 0.0)
            if isinstance(z0, bool) or not isinstance(z0, (int, float)) or not math.isfinite(z0):
                raise SystemDefinitionError(f"{w}.z0 = {z0!r} must be a finite number")
            st = c.get("state", "z" if len(raw_f) == 1 else f"z_{cn}")
            lug = {k: _expr(c[k], f"{w}.{k}", law_names, law_what) for k in ("level", "sigma0", "sigma1")}
            visc = _expr(c.get("viscous", 0), f"{w}.viscous", law_names, law_what)
            contacts.append(ContactSpec(cn, "lugre", c["force"], vel, level=lug["level"], sigma0=lug["sigma0"],
                                        sigma1=lug["sigma1"], viscous=visc, state=st, z0=float(z0)))

    units = _units(desc.get("units"), set(taken) | {TIME})

    norm = {"name": name, "parameters": dict(params), "states": dict(initial),
            "signals": {k: e.canonical for k, e in signals.items()},
            "equations": {k: e.canonical for k, e in equations.items()},
            "friction": [_contact_dict(c) for c in contacts],
            "blocks": [_block_dict(b) for b in blocks]}
    if units:
        norm["units"] = units
    spec = Spec(name, params, tuple(states), initial, signals, tuple(order), equations, tuple(contacts),
                tuple(blocks), norm)
    spec.check_parameter_values(params)
    return spec


def _units(raw, names: set) -> dict:
    """The optional ``units`` map: name (a state, parameter, signal, block output, friction
    force or t) -> unit text (figure and table labels only; nothing is converted)."""
    if raw is None:
        return {}
    if not isinstance(raw, dict):
        raise SystemDefinitionError(f"units = {raw!r} must be a mapping name -> unit text, e.g. "
                                    f"{{\"q\": \"m\", \"t\": \"s\"}}")
    out = {}
    for k, v in raw.items():
        if k not in names:
            raise SystemDefinitionError(f"units[{k!r}]: {k!r} is not a name of this model (allowed: states, "
                                        f"parameters, signals, block outputs, friction forces, t)")
        if not isinstance(v, str) or len(v) > 40 or any(ch in v for ch in "\n\r\t"):
            raise SystemDefinitionError(f"units[{k!r}] = {v!r} is not allowed: give the unit as a short text "
                                        f"(at most 40 characters), e.g. \"m/s\"")
        out[str(k)] = v
    return out


def _block(b, i, everything, params, what) -> BlockSpec:
    keys = {"output", "input", "tf", "num", "den", "delay", "order"}
    bad = [k for k in b if k not in keys]
    if bad:
        raise SystemDefinitionError(f"blocks[{i}] keys {bad} are not known: allowed keys are {sorted(keys)}")
    w = f"blocks[{b['output']!r}]"
    inp = _expr(b["input"], f"{w}.input", everything, what)
    kinds = [k for k in ("tf", "num", "delay") if k in b]
    if len(kinds) != 1 or ("num" in b) != ("den" in b):
        raise SystemDefinitionError(f"{w}: give exactly one of 'tf' (an expression in s), 'num' and 'den' "
                                    "(coefficient lists, descending powers of s) or 'delay' (with 'order')")
    coeff = "coefficients use parameters only"
    if "tf" in b:
        if TF_VARIABLE in params:
            raise SystemDefinitionError(f"{w}.tf: the parameter {TF_VARIABLE!r} has the name of the Laplace variable "
                                        "of transfer functions: rename it")
        tf = _expr(b["tf"], f"{w}.tf", params | {TF_VARIABLE}, "a transfer function uses s and parameters")
        return BlockSpec(b["output"], inp, tf=tf)
    if "num" in b:
        out = []
        for key in ("num", "den"):
            lst = b[key]
            if not isinstance(lst, (list, tuple)) or not lst:
                raise SystemDefinitionError(f"{w}.{key} = {lst!r} must be a non-empty list of coefficients "
                                            "(descending powers of s)")
            out.append(tuple(_expr(e, f"{w}.{key}[{j}]", params, coeff) for j, e in enumerate(lst)))
        return BlockSpec(b["output"], inp, num=out[0], den=out[1])
    order = b.get("order", 3)
    if isinstance(order, bool) or not isinstance(order, int) or not 1 <= order <= MAX_PADE_ORDER:
        raise SystemDefinitionError(f"{w}.order = {order!r} is not allowed: a Pade order is an integer in "
                                    f"[1, {MAX_PADE_ORDER}]")
    return BlockSpec(b["output"], inp, delay=_expr(b["delay"], f"{w}.delay", params, "a delay uses parameters"),
                     order=order)


def _topological(deps: dict, names: list) -> tuple:
    """Names ordered so each comes after its dependencies; a cycle is an error naming it."""
    order, state = [], {}

    def visit(n, path):
        if state.get(n) == "done":
            return
        if state.get(n) == "active":
            cyc = path[path.index(n):] + [n]
            raise SystemDefinitionError(f"signals form a cycle: {' -> '.join(cyc)} (an algebraic loop: "
                                        "break it with a state, e.g. a filter block)")
        state[n] = "active"
        for d in sorted(deps.get(n, ())):
            visit(d, path + [n])
        state[n] = "done"
        order.append(n)

    for n in names:
        visit(n, [])
    return tuple(order)


def _contact_dict(c: ContactSpec) -> dict:
    d = {"name": c.name, "model": c.model, "force": c.force, "velocity": c.velocity.canonical}
    if c.model == "switch":
        d["slip"] = c.slip.canonical
        d["stick"] = [c.stick[0].canonical, c.stick[1].canonical]
    else:
        d.update(level=c.level.canonical, sigma0=c.sigma0.canonical, sigma1=c.sigma1.canonical,
                 viscous=c.viscous.canonical, state=c.state, z0=c.z0)
    return d


def _block_dict(b: BlockSpec) -> dict:
    d = {"output": b.output, "input": b.input.canonical}
    if b.tf is not None:
        d["tf"] = b.tf.canonical
    elif b.delay is not None:
        d.update(delay=b.delay.canonical, order=b.order)
    else:
        d.update(num=[e.canonical for e in b.num], den=[e.canonical for e in b.den])
    return d
