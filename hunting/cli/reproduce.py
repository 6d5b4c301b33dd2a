"""``hunting reproduce``: a thesis chapter's tables and figures, checked against the thesis."""
from __future__ import annotations

from pathlib import Path

from .boundary import Output

NAME = "reproduce"
HELP = "reproduce a thesis chapter (tables, figures, checks)"
CHAPTERS = ("ch8", "ch9", "ch10")


def add_arguments(p) -> None:
    p.add_argument("chapter", choices=CHAPTERS, help="the chapter: " + ", ".join(CHAPTERS))
    p.add_argument("--out", metavar="DIR", help="directory for figures and JSON (default out/CHAPTER)")


def _out(args) -> str:
    return args.out or f"out/{args.chapter}"


def files(args):
    return [Output("--out", _out(args), "dir")], []


# the kernels each chapter runs, compiled ahead on a fresh install (the variational one first
# where it stands in for the lean one: hunting.integrate._kernel.plain_kind)
AHEAD = {"ch8": ("variational", "full", "lean"), "ch9": ("lean",), "ch10": ("lean", "full")}


def kernels(args) -> tuple[str, ...]:
    """The integration kernels this chapter runs, compiled ahead on a fresh install."""
    return AHEAD[args.chapter]


def run(args, results) -> int:
    import importlib
    mod = importlib.import_module(f"hunting.reproduce.{args.chapter}")
    return mod.run(Path(_out(args)))
