"""``hunting models``: the presets with every parameter and its unit."""
from __future__ import annotations

NAME = "models"
HELP = "list presets with parameters and units"


def add_arguments(p) -> None:
    pass


def run(args, results) -> int:
    from ..models.presets import describe_presets
    print(describe_presets())
    return 0
