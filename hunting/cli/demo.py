"""``hunting demo``: short simulations of chapters 4, 8 and 9, checked against the thesis."""
from __future__ import annotations

from pathlib import Path

from .boundary import Output

NAME = "demo"
HELP = "hunting cycles of chapters 8 and 9, checked against the thesis"


def add_arguments(p) -> None:
    p.add_argument("--out", default="out/demo", metavar="DIR", help="directory for figures and JSON")


def files(args):
    return [Output("--out", args.out, "dir")], []


def kernels(args) -> tuple[str, ...]:
    """The kernels the demo runs, in order (its simulations', its Radau run's), compiled ahead
    on a fresh install."""
    return ("lean", "full")


def run(args, results) -> int:
    from ..demo import run_demo
    return run_demo(Path(args.out))
