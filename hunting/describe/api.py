"""Entry points: ``model`` (dict, JSON/YAML file, JSON text or preset name), ``load_model``
and the fluent ``ModelBuilder``."""
from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Mapping

from ..errors import SystemDefinitionError
from .compiled import CompiledModel, build_model
from .description import validate


def read_description(path) -> dict:
    """The description dict in a JSON or YAML file (by suffix; other suffixes: JSON, then YAML)."""
    p = Path(path)
    if p.is_dir():
        raise SystemDefinitionError(f"model file {str(p)!r} is a directory (allowed: a JSON or YAML file)")
    if not p.is_file():
        raise SystemDefinitionError(f"model file {str(p)!r} does not exist")
    text = p.read_text()
    suffix = p.suffix.lower()
    if suffix in (".yaml", ".yml"):
        return _yaml(text, p)
    try:
        return json.loads(text)
    except ValueError as e:
        if suffix == ".json":
            raise SystemDefinitionError(f"model file {str(p)!r} is not valid JSON: {e}") from None
        return _yaml(text, p)


# YAML 1.2's floats: PyYAML reads YAML 1.1, where 1e5, 1.0e5 and 2E-3 (no dot, or an exponent
# without a sign) are strings. Matched after YAML 1.1's own int and float forms, so 100 stays an
# int and 1_000.5 a float; converted by the safe constructor (float(), never eval).
_YAML12_FLOAT = r"^[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?$"


def _yaml_loader():
    import re

    import yaml

    class Loader(yaml.SafeLoader):
        """yaml.SafeLoader that also reads YAML 1.2 floats (1e5, 1.0e5, -2E-3) as numbers."""

    Loader.add_implicit_resolver("tag:yaml.org,2002:float", re.compile(_YAML12_FLOAT), list("-+0123456789."))
    return Loader


def _yaml(text: str, p: Path) -> dict:
    try:
        import yaml
    except ImportError:
        raise SystemDefinitionError(f"model file {str(p)!r} is YAML: install pyyaml (pip install pyyaml) "
                                    "or write it as JSON") from None
    try:
        return yaml.load(text, Loader=_yaml_loader())       # noqa: S506 -- a SafeLoader subclass
    except yaml.YAMLError as e:
        raise SystemDefinitionError(f"model file {str(p)!r} is not valid YAML: {e}") from None


def load_model(path, **overrides) -> CompiledModel:
    """Compile the model description in a JSON or YAML file; ``overrides`` set parameter values.

    Examples
    --------
    >>> import hunting
    >>> m = hunting.load_model("examples/belt.json", k=2.5)      # doctest: +SKIP
    """
    return model(read_description(path), **overrides)


def model(description, /, **overrides) -> CompiledModel:
    """Compile a model description into a :class:`CompiledModel` (its ``.system`` is a
    PiecewiseSystem every function of the library takes).

    Parameters
    ----------
    description : dict, str or Path
        A description dict (see :mod:`hunting.describe.description` and docs/architecture.md),
        a path to a JSON/YAML file, JSON text, or the name of a thesis preset ("table9.1",
        "table8.1-lugre", ...: the preset written as a description).
    **overrides : float
        Parameter values replacing the description's defaults (for a preset name: the preset's
        overrides, e.g. ``beta=float("inf")`` or ``model="lugre"``).

    The generated code is cached on disk by the description's structure (parameter values are
    not part of it), so a second process, or the same model at other parameter values, does
    not recompile.

    Examples
    --------
    >>> import hunting
    >>> m = hunting.model({"parameters": {"k": 1.0, "c": 0.1}, "states": ["q", "v"],
    ...                    "equations": {"q": "v", "v": "-k*q - c*v"}})
    >>> m.state_names, m.param_names
    (('q', 'v'), ('k', 'c'))
    >>> float(m.system.evaluate(m.state(q=1.0))[1])
    -1.0
    """
    if isinstance(description, Mapping):
        desc = copy.deepcopy(dict(description))
    elif isinstance(description, (str, Path)):
        s = str(description)
        if isinstance(description, str) and s.lstrip().startswith("{"):
            try:
                desc = json.loads(s)
            except ValueError as e:
                raise SystemDefinitionError(f"the model description text is not valid JSON: {e}") from None
        elif not Path(s).exists() and isinstance(description, str):
            from ..models.presets import PRESETS, preset_description
            if s in PRESETS:         # preset overrides may change the structure (model=, beta=inf)
                return model(preset_description(s, **overrides))
            raise SystemDefinitionError(f"model = {s!r} is neither a model file nor a preset: presets are "
                                        f"{sorted(PRESETS)}")
        else:
            desc = read_description(s)
    else:
        raise SystemDefinitionError(f"model description = {description!r} must be a dict, a file path or a preset name")
    return build_model(validate(desc), overrides)


class ModelBuilder:
    """Build a description in Python, call by call; ``.description`` is the same dict a JSON
    file would hold and ``.build()`` compiles it.

    Examples
    --------
    >>> import hunting
    >>> b = (hunting.ModelBuilder("belt")
    ...      .parameters(m=1.0, k=2.0, Fc=0.3, Fs=0.5, vs=0.05, vb=0.1)
    ...      .states("q", "v")
    ...      .signal("u", "-k*q")
    ...      .equations(q="v", v="(u - F)/m")
    ...      .friction(force="F", velocity="v - vb", model="switch",
    ...                slip="sign(w)*(Fc + (Fs - Fc)*exp(-abs(w)/vs))", stick="Fs"))
    >>> sorted(b.description)
    ['equations', 'friction', 'name', 'parameters', 'signals', 'states']
    """

    def __init__(self, name: str = "model"):
        self._d: dict = {"name": name, "parameters": {}, "states": [], "signals": {}, "equations": {}}

    def parameters(self, **values: float) -> "ModelBuilder":
        """Parameters and their default values (in layout order)."""
        self._d["parameters"].update(values)
        return self

    def states(self, *names: str, **initial: float) -> "ModelBuilder":
        """State names in order; keyword form gives initial values."""
        st = self._d["states"]
        if initial:
            if isinstance(st, list):
                st = {k: 0.0 for k in st}
            st.update(initial)
        for n in names:
            if isinstance(st, dict):
                st.setdefault(n, 0.0)
            elif n not in st:
                st.append(n)
        self._d["states"] = st
        return self

    def signal(self, name: str, expression: str) -> "ModelBuilder":
        """A named intermediate expression (may use parameters, states, t, other signals, forces)."""
        self._d["signals"][name] = expression
        return self

    def equation(self, state: str, rhs: str) -> "ModelBuilder":
        """d state / dt = rhs."""
        self._d["equations"][state] = rhs
        return self

    def equations(self, **rhs: str) -> "ModelBuilder":
        self._d["equations"].update(rhs)
        return self

    def friction(self, **contact) -> "ModelBuilder":
        """Add a friction contact (keys as in a description: force, velocity, model, slip,
        stick or level, sigma0, sigma1, viscous, state, z0, name)."""
        self._d.setdefault("friction", []).append(dict(contact))
        return self

    def transfer(self, output: str, input: str, tf: str | None = None, *, num=None, den=None) -> "ModelBuilder":
        """A linear block output = H(s) input, H as an expression in s or as num/den lists."""
        b = {"output": output, "input": input}
        if tf is not None:
            b["tf"] = tf
        else:
            b.update(num=list(num or []), den=list(den or []))
        self._d.setdefault("blocks", []).append(b)
        return self

    def delay(self, output: str, input: str, delay: str, order: int = 3) -> "ModelBuilder":
        """output = input delayed by ``delay`` (a Pade approximation of ``order``)."""
        self._d.setdefault("blocks", []).append({"output": output, "input": input, "delay": delay, "order": order})
        return self

    @property
    def description(self) -> dict:
        return copy.deepcopy(self._d)

    def build(self, **overrides) -> CompiledModel:
        return model(self._d, **overrides)
