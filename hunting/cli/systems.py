"""Which system a command works on: the one place that turns arguments into a closed loop.

Today a system is a preset name plus ``--set NAME=VALUE`` overrides. A new way to name a system
(a model file, say) adds its arguments in :func:`add_system_arguments` and its branch in
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

    preset : preset name; overrides : {name: value as typed} from --set; loop : the ServoLoop
    built from them; label : how results name it; warnings : unstable linear parts, reported
    up front (allowed: an unstable loop may be the study)."""

    preset: str
    overrides: dict
    loop: object
    label: str
    warnings: tuple = ()


def add_system_arguments(p) -> None:
    """The arguments that name a system: PRESET and repeated --set NAME=VALUE."""
    p.add_argument("preset", help="a preset name (list them with 'hunting models')")
    p.add_argument("--set", action="append", type=name_value, metavar="NAME=VALUE", default=[],
                   help="override a preset parameter (repeatable), e.g. --set P=20 --set beta=1")


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
