"""Which system a command works on: the one place that turns arguments into a closed loop.

A system is a preset name or a model file (``--model FILE``, JSON or YAML, see
docs/architecture.md), plus ``--set NAME=VALUE`` overrides of its parameters. A new way to name
a system adds its arguments in :func:`add_system_arguments` and its branch in
:func:`resolve_system`; the commands only see a :class:`SystemChoice`.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

from .boundary import UsageError, collect_pairs, name_value

log = logging.getLogger("hunting.cli")


@dataclass(frozen=True)
class SystemChoice:
    """The system a command was asked for.

    preset : preset name (None for a model file); overrides : {name: value as typed} from
    --set; loop : the ServoLoop built from them (None for a model file); label : how results
    name it; warnings : unstable linear parts, reported up front (allowed: an unstable loop may
    be the study); model : the compiled model of --model (its parameters already set), else
    None."""

    preset: str | None
    overrides: dict
    loop: object
    label: str
    warnings: tuple = ()
    model: object = None

    @property
    def system(self):
        """The PiecewiseSystem."""
        return self.model.system if self.model is not None else self.loop.system

    @property
    def source(self):
        """What the library's front ends (find_cycle, follow, event maps) take: the preset name
        (with ``params`` = the overrides) or the compiled model."""
        return self.model if self.model is not None else self.preset

    @property
    def params(self) -> dict:
        """Overrides to pass with ``source`` (a model carries its own)."""
        return {} if self.model is not None else dict(self.overrides)


def add_system_arguments(p, *, model: bool = True) -> None:
    """The arguments that name a system: PRESET or --model FILE, and repeated --set NAME=VALUE."""
    p.add_argument("preset", nargs="?" if model else None, metavar="PRESET",
                   help="a preset name (list them with 'hunting models')" + (", or --model FILE" if model else ""))
    if model:
        p.add_argument("--model", metavar="FILE", help="a model description (JSON or YAML; see the README, "
                       "'Your own system') instead of a preset")
    p.add_argument("--set", action="append", type=name_value, metavar="NAME=VALUE", default=[],
                   help="override a parameter (repeatable), e.g. --set P=20 --set beta=1")


def names_lugre(args) -> bool:
    """Whether the system the arguments name has a LuGre contact, read without compiling it (a
    preset's friction model with its --set overrides, a model file's friction entries); False
    where that cannot be read (the command itself then reports what is wrong)."""
    from ..errors import HuntingError
    try:
        model_file = getattr(args, "model", None)
        if model_file:
            from ..describe import read_description
            description = read_description(model_file)
            friction = (description.get("friction") or []) if isinstance(description, dict) else []
            contacts = [friction] if isinstance(friction, dict) else friction
            return isinstance(contacts, list) and any(isinstance(c, dict) and c.get("model") == "lugre"
                                                      for c in contacts)
        from ..models.presets import PRESETS, resolve_parameters
        if args.preset not in PRESETS:
            return False
        return resolve_parameters(args.preset, collect_pairs(args.set, "--set")).get("model") == "lugre"
    except (HuntingError, ValueError, OSError):
        return False


def resolve_system(args, *, warn: bool = True, **extra) -> SystemChoice:
    """The SystemChoice of parsed arguments; ``extra`` are overrides the command adds itself
    (e.g. the continuation parameter at its start value; a SystemDefinitionError they cause is
    left for the caller to name). Warns (log, unless ``warn`` is
    False) about unstable linear parts of the loop. Raises SystemDefinitionError/UsageError
    naming a bad name or value."""
    from ..analysis import unstable_linear_parts
    from ..errors import SystemDefinitionError
    from ..models import preset
    from ..models.presets import PRESETS
    model_file = getattr(args, "model", None)
    if model_file and args.preset:
        raise UsageError(f"PRESET {args.preset!r} and --model {model_file!r}: give one of them")
    if model_file:
        return _model_choice(args, model_file, extra)
    if not args.preset:
        raise UsageError("no system: give a PRESET ('hunting models' lists them) or --model FILE")
    if args.preset not in PRESETS:
        raise UsageError(f"PRESET {args.preset!r} is not known (allowed: {', '.join(PRESETS)}; "
                         "'hunting models' lists them)")
    overrides = collect_pairs(args.set, "--set")
    try:
        loop = preset(args.preset, **overrides)
    except SystemDefinitionError as e:
        if not overrides:
            raise
        given = " ".join(f"{k}={v}" for k, v in overrides.items())
        raise UsageError(f"--set {given}: {e}") from None
    if extra:                   # an error here is the caller's argument: it names it
        loop = preset(args.preset, **{**overrides, **extra})
    warnings = tuple(unstable_linear_parts(loop))
    for w in warnings if warn else ():
        log.warning(w)
    label = args.preset + "".join(f" {k}={v}" for k, v in overrides.items())
    return SystemChoice(args.preset, overrides, loop, label, warnings)


def _model_choice(args, path: str, extra: dict) -> SystemChoice:
    """The SystemChoice of --model FILE with --set overrides (model parameters) and ``extra``."""
    from ..describe import load_model
    from ..errors import SystemDefinitionError
    overrides = collect_pairs(args.set, "--set")
    try:
        m = load_model(path)
    except SystemDefinitionError as e:
        raise UsageError(f"--model {path!r}: {e}") from None
    try:
        m = m.with_params(**overrides) if overrides else m
    except SystemDefinitionError as e:
        given = " ".join(f"{k}={v}" for k, v in overrides.items())
        raise UsageError(f"--set {given}: {e}") from None
    if extra:                   # an error here is the caller's argument: it names it
        m = m.with_params(**extra)
    label = m.name + "".join(f" {k}={v}" for k, v in overrides.items())
    return SystemChoice(None, overrides, None, label, (), m)
