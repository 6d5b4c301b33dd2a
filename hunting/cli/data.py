"""``hunting data``: a published data set and its example model, ready to diagnose."""
from __future__ import annotations

import shlex
from pathlib import Path

from .._atomic import atomic_path
from .boundary import Output, UsageError

NAME = "data"
HELP = "put a published data set and its example model into a directory"
DATASETS = ("emps",)
DATA_HELP = """\
emps: the EMPS benchmark (Janot, Gautier, Brunot 2019), DATA_EMPS.mat (identification) and
  DATA_EMPS_PULSES.mat (validation), and emps_model.json, the benchmark's published symmetric
  model in the format of 'hunting diagnose --model'. The files come from $HUNTING_DATA (or
  $HUNTING_DATA/emps), ../shared/data/emps, or the user cache, where they are downloaded from
  nonlinearbenchmark.org on first use; each is checked against its published SHA-256.
Files already in DIR with the same content are kept; different ones are replaced only with
--force. Exit code 2 when the data cannot be found, fetched or verified, or DIR holds other files.
"""


def add_arguments(p) -> None:
    import argparse
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.epilog = DATA_HELP
    p.add_argument("dataset", choices=DATASETS, help="the data set: " + ", ".join(DATASETS))
    p.add_argument("--dir", default=".", metavar="DIR",
                   help="where to put the files (default: the current directory; created when missing)")
    p.add_argument("--force", action="store_true", help="replace files in DIR whose content differs")


def _names() -> tuple[str, ...]:
    from ..datasets import EMPS_MODEL, EMPS_SHA256
    return (*EMPS_SHA256, EMPS_MODEL)


def files(args):
    d = Path(args.dir)
    return [Output("--dir", args.dir, "dir"), *(Output("--dir", str(d / n)) for n in _names())], []


def _same_content(a: Path, data: bytes) -> bool:
    try:
        return a.stat().st_size == len(data) and a.read_bytes() == data
    except OSError:
        return False


def run(args, results) -> int:
    from ..datasets import EMPS_MODEL, emps, emps_model_json
    found = emps()
    wanted = {found.fit.name: found.fit, found.validate.name: found.validate}
    contents = {name: src.read_bytes() for name, src in wanted.items()}
    contents[EMPS_MODEL] = emps_model_json().encode()
    d = Path(args.dir)
    todo, differ = [], []
    for name, data in contents.items():
        target = d / name
        if _same_content(target, data):
            continue
        if target.exists() and not args.force:
            differ.append(name)
        todo.append(name)
    if differ:
        raise UsageError(f"--dir {args.dir!r} already holds {', '.join(differ)} with other content "
                         "(allowed: --force to replace it, or another --dir)")
    for name in todo:
        with atomic_path(d / name) as tmp:
            Path(tmp).write_bytes(contents[name])
    for name in contents:
        src = wanted.get(name)
        how = "kept (same content)" if name not in todo else (f"copied from {src.parent}" if src else "written")
        print(f"{d / name}: {how}")
    q = lambda name: shlex.quote(str(d / name))        # noqa: E731
    print("next:")
    print(f"  hunting diagnose {q(found.fit.name)} --validate {q(found.validate.name)} --model {q(EMPS_MODEL)}")
    return 0
