"""The command line's boundary: argument types, output paths checked before any computing,
atomic result files, and the mapping of every failure to one line and an exit code.

Exit codes: 0 success, 1 a numerical failure (or an unexpected error), 2 bad input. Every
message names the argument, the value given and what is allowed.
"""
from __future__ import annotations

import argparse
import json
import math
import errno
import os
import re
import shutil
import stat
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._atomic import output_target, write_text
from ..errors import HuntingError

EXIT_OK, EXIT_FAILURE, EXIT_USAGE = 0, 1, 2
MAX_GRID_POINTS = 1_000_001


class UsageError(HuntingError, ValueError):
    """A command-line argument that is not allowed (exit code 2)."""


# What argparse takes for a value, not an option, when it starts with "-": a number in any
# spelling (-1, -.5, -1e-3, -0.1,0,0 for --x0, -0.5:0.5:11 for --grid, -inf). argparse's own
# pattern accepts only -1 and -.5 forms, so "--x0 -0.1,0,0" failed with "expected one argument".
# No option of the command line starts with "-" and a digit, so nothing is lost.
_NEGATIVE_VALUE = re.compile(r"^-(?:\.?[0-9]|inf|nan)", re.IGNORECASE)
_NO_VALUE = re.compile(r"^argument ((?:-\w|--[\w-]+)(?:/[\w-]+)*): expected one argument$")


class ArgumentParser(argparse.ArgumentParser):
    """argparse, but a bad argument raises :class:`UsageError` (one line, no usage block), and
    values may start with a minus sign (``--x0 -0.1,0,0``, ``--grid -0.5:0.5:11``)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_VALUE      # argparse's hook (3.8-3.13)

    def error(self, message):
        m = _NO_VALUE.match(message)
        if m:                       # e.g. "--json -out.json": a value that looks like an option
            flag = m.group(1).split("/")[-1]
            message += f" (to give a value that starts with '-', write {flag}=-...)"
        raise UsageError(f"{message} (see '{self.prog} --help')")


# ---------------------------------------------------------------- argument types
# argparse turns an ArgumentTypeError into "argument --flag: <message>", so the messages below
# say what the value is and what is allowed; argparse adds which argument it was.

def _number(text: str) -> float:
    return float(text.strip())          # also "inf", "nan": the callers reject what is not finite


def finite_float(text: str) -> float:
    """A finite real number."""
    try:
        v = _number(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number (allowed: a finite number)") from None
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"{text!r} is not allowed: a finite number is required")
    return v


def positive_float(text: str) -> float:
    """A finite number > 0."""
    v = finite_float(text)
    if v <= 0:
        raise argparse.ArgumentTypeError(f"{text!r} is not allowed: a finite number > 0 is required")
    return v


def _int_at_least(text: str, low: int) -> int:
    try:
        v = int(text.strip())
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer (allowed: an integer >= {low})") from None
    if v < low:
        raise argparse.ArgumentTypeError(f"{text!r} is not allowed: an integer >= {low} is required")
    return v


def positive_int(text: str) -> int:
    """An integer >= 1."""
    return _int_at_least(text, 1)


def nonnegative_int(text: str) -> int:
    """An integer >= 0."""
    return _int_at_least(text, 0)


def name_value(text: str) -> tuple[str, str]:
    """NAME=VALUE (for --set); the value is checked by whatever owns the name."""
    name, sep, value = text.partition("=")
    if not sep or not name.strip() or not value.strip():
        raise argparse.ArgumentTypeError(f"{text!r} is not NAME=VALUE (e.g. P=20)")
    if "=" in value:
        pairs = [p.strip() for p in text.replace(";", ",").split(",") if p.strip()]
        raise argparse.ArgumentTypeError(f"{text!r} holds more than one NAME=VALUE (allowed: one per option, e.g. "
                                         + " ".join(f"--set {p}" for p in pairs) + ")")
    return name.strip(), value.strip()


def collect_pairs(pairs, flag: str) -> dict:
    """A dict from repeated NAME=VALUE arguments; a name given twice is an error."""
    out: dict = {}
    for name, value in pairs or []:
        if name in out:
            raise UsageError(f"{flag} {name}={value}: {name} is already set to {out[name]!r} "
                             f"(allowed: each name once)")
        out[name] = value
    return out


@dataclass(frozen=True)
class StateSpec:
    """An initial state as typed: by position (``values``) or by name (``names`` -> values)."""

    text: str
    values: tuple = ()
    names: tuple = ()

    def vector(self, state_names, flag: str = "--x0") -> np.ndarray:
        """The state vector for a system with these state names (missing entries are 0)."""
        n = len(state_names)
        x = np.zeros(n)
        if self.names:
            for name, v in zip(self.names, self.values):
                if name not in state_names:
                    raise UsageError(f"{flag} {self.text!r}: {name!r} is not a state of this system "
                                     f"(allowed names: {', '.join(state_names)})")
                x[state_names.index(name)] = v
            return x
        if len(self.values) > n:
            raise UsageError(f"{flag} {self.text!r} has {len(self.values)} entries: this system has {n} states "
                             f"({', '.join(state_names)}); give at most {n} (missing entries are 0)")
        x[: len(self.values)] = self.values
        return x


def state_spec(text: str) -> StateSpec:
    """``0.1,0,0`` (by position, missing trailing entries 0) or ``x1=0.1,x3=2`` (by name)."""
    items = [s.strip() for s in text.split(",")]
    allowed = "comma-separated finite numbers (e.g. 0.1,0,0) or NAME=VALUE pairs (e.g. x1=0.1,x3=0)"
    named = ["=" in s for s in items]
    if any(named) and not all(named):
        raise argparse.ArgumentTypeError(f"{text!r} mixes positions and names (allowed: {allowed})")
    names, values = [], []
    for i, item in enumerate(items):
        name, _, val = item.rpartition("=") if "=" in item else ("", "", item)
        if any(named) and not name.strip():
            raise argparse.ArgumentTypeError(f"{text!r}: entry {i + 1} {item!r} has no name (allowed: {allowed})")
        if not val:
            raise argparse.ArgumentTypeError(f"{text!r}: entry {i + 1} is empty (allowed: {allowed})")
        try:
            v = _number(val)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r}: entry {i + 1} {val!r} is not a number "
                                             f"(allowed: {allowed})") from None
        if not math.isfinite(v):
            raise argparse.ArgumentTypeError(f"{text!r}: entry {i + 1} {val!r} is not finite (allowed: {allowed})")
        if name.strip() and name.strip() in names:
            raise argparse.ArgumentTypeError(f"{text!r}: {name.strip()!r} is given twice (allowed: {allowed})")
        names.append(name.strip())
        values.append(v)
    return StateSpec(text, tuple(values), tuple(names) if any(named) else ())


def grid(text: str) -> np.ndarray:
    """START:STOP:N -> N equally spaced points, START < STOP, 2 <= N <= MAX_GRID_POINTS."""
    allowed = f"START:STOP:N with finite START < STOP and 2 <= N <= {MAX_GRID_POINTS} (e.g. 0:0.5:501)"
    parts = text.split(":")
    if len(parts) != 3:
        raise argparse.ArgumentTypeError(f"{text!r} is not START:STOP:N (allowed: {allowed})")
    try:
        a, b = _number(parts[0]), _number(parts[1])
        n = int(parts[2].strip())
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not START:STOP:N (allowed: {allowed})") from None
    if not (math.isfinite(a) and math.isfinite(b)) or b <= a or not 2 <= n <= MAX_GRID_POINTS:
        raise argparse.ArgumentTypeError(f"{text!r} is not allowed: {allowed}")
    return np.linspace(a, b, n)


# ---------------------------------------------------------------- files
@dataclass(frozen=True)
class Output:
    """A path a command will write. kind: "file", "figure" (a file whose suffix names a
    matplotlib format) or "dir" (a directory, created when missing); stdout: "-" allowed."""

    flag: str
    value: str
    kind: str = "file"
    stdout: bool = False


@dataclass(frozen=True)
class Input:
    """A file a command will read."""

    flag: str
    value: str


def _figure_formats() -> dict:
    from matplotlib.backend_bases import FigureCanvasBase
    return FigureCanvasBase.get_supported_filetypes()


def _probe_writable(directory: Path) -> str | None:
    """None when a file can be created in ``directory``, else the reason it cannot."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=".hunting-probe-", dir=directory)
    except OSError as e:
        return e.strerror or str(e)
    os.close(fd)
    os.unlink(tmp)
    return None


def _check_file(o: Output) -> Path:
    """What :func:`hunting._atomic.output_target` will write, checked now: a regular file (or a
    link to one) in an existing, writable directory, or a writable FIFO or character device."""
    p = Path(o.value)
    where = f"{o.flag} {o.value!r}"
    in_dir = "allowed: a file in an existing, writable directory"
    if not p.parent.exists():
        raise UsageError(f"{where}: directory '{p.parent}' does not exist ({in_dir})")
    if not p.parent.is_dir():
        raise UsageError(f"{where}: '{p.parent}' is not a directory ({in_dir})")
    try:
        target = output_target(p)
    except OSError as e:
        if e.errno == errno.ENAMETOOLONG:
            raise UsageError(f"{where}: the name is too long (allowed: at most 255 bytes per path component)") from None
        raise UsageError(f"{where} {e.strerror}") from None
    if target.kind == "stream":
        if not os.access(p, os.W_OK):
            raise UsageError(f"{where} is not writable")
    else:
        parent = target.path.parent
        if not parent.is_dir():             # only a link can lead there: p.parent exists
            raise UsageError(f"{where} is a link to '{target.path}', whose directory does not exist ({in_dir})")
        why = _probe_writable(parent)
        if why:
            raise UsageError(f"{where}: directory '{parent}' is not writable ({why})")
    if o.kind == "figure":
        _check_figure_format(p, where)
    return p


def _check_figure_format(p: Path, where: str) -> None:
    """A suffix matplotlib writes, and for .pgf the TeX program its backend runs."""
    fmt = p.suffix[1:].lower()
    formats = _figure_formats()
    if fmt and fmt not in formats:
        raise UsageError(f"{where}: '.{fmt}' is not a figure format (allowed suffixes: "
                         f"{', '.join(sorted(formats))})")
    if fmt == "pgf":
        import matplotlib
        tex = matplotlib.rcParams["pgf.texsystem"]
        if shutil.which(tex) is None:
            raise UsageError(f"{where}: writing .pgf needs the TeX program '{tex}', which is not installed "
                             "(allowed here: " + ", ".join(f".{f}" for f in sorted(formats) if f != "pgf") + ")")


def _check_dir(o: Output) -> Path:
    p = Path(o.value)
    where = f"{o.flag} {o.value!r}"
    if p.exists() and not p.is_dir():
        raise UsageError(f"{where} exists and is not a directory (allowed: a directory, created when missing)")
    try:
        p.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise UsageError(f"{where}: the directory cannot be created ({e.strerror or e}); allowed: a directory "
                         "whose parent exists and is writable") from None
    why = _probe_writable(p)
    if why:
        raise UsageError(f"{where}: the directory is not writable ({why})")
    return p


def _check_input(i: Input) -> Path:
    p = Path(i.value)
    if not p.exists():
        raise UsageError(f"{i.flag} {i.value!r} does not exist (allowed: a readable file)")
    if not p.is_file():
        raise UsageError(f"{i.flag} {i.value!r} is not a file (allowed: a readable file)")
    if not os.access(p, os.R_OK):
        raise UsageError(f"{i.flag} {i.value!r} is not readable")
    return p


def _is_char_device(p) -> bool:
    try:
        return stat.S_ISCHR(os.stat(p).st_mode)
    except OSError:
        return False


def check_files(outputs, inputs=()) -> None:
    """Validate every output and input path before computing.

    Outputs: "-" only where standard output is allowed; standard output ("-", /dev/stdout)
    once; files in an existing, writable directory (a symbolic link: its target's), or a
    writable FIFO or character device, never a directory, block device or socket; figures with
    a known format; directories created now (so a failure shows before the computation, not
    after it); all outputs distinct from each other and from the inputs (a character device
    such as /dev/null may repeat). Inputs: readable files."""
    seen: dict = {}
    stdout_by = None
    for i in inputs:
        if i.value is not None:
            seen[os.path.realpath(_check_input(i))] = f"{i.flag} {i.value!r} (an input)"
    for o in outputs:
        if o.value is None:
            continue
        if o.value == "-" and not o.stdout:
            raise UsageError(f"{o.flag} '-': standard output is not allowed here (allowed: a path)")
        if names_stdout(o.value):
            if stdout_by is not None:
                raise UsageError(f"{o.flag} {o.value!r}: standard output is already used by {stdout_by}")
            stdout_by = f"{o.flag} {o.value!r}"
            if o.value == "-":
                continue
        p = _check_dir(o) if o.kind == "dir" else _check_file(o)
        key = os.path.realpath(p)
        if _is_char_device(p):          # /dev/null twice discards both
            continue
        if key in seen:
            raise UsageError(f"{o.flag} {o.value!r} is the same path as {seen[key]} (allowed: a different path "
                             "for every output, none of them an input)")
        seen[key] = f"{o.flag} {o.value!r}"


def add_result_arguments(p, json_help: str, plot_help: str) -> None:
    """--json FILE ('-': standard output) and --plot FILE, the results most commands write."""
    p.add_argument("--json", metavar="FILE", help=f"{json_help} as JSON ('-': standard output)")
    p.add_argument("--plot", metavar="FILE", help=f"{plot_help} (png, pdf, svg, ...)")


def result_files(args):
    """The outputs of :func:`add_result_arguments` (for a command's ``files``), and the model
    file of ``--model`` (an input) when the command has one."""
    inputs = [Input("--model", args.model)] if getattr(args, "model", None) else []
    return [Output("--json", args.json, stdout=True), Output("--plot", args.plot, "figure")], inputs


def names_stdout(value) -> bool:
    """Whether an output value means this process' standard output: "-", or a path that is the
    same pipe or file (``/dev/stdout``, ``/dev/fd/1``, a file stdout is redirected to). A
    character device is not: ``--json /dev/null`` stays a device written directly, even when
    stdout is /dev/null too (a terminal takes both alike)."""
    if value == "-":
        return True
    if value is None:
        return False
    try:
        st = os.stat(value)
        return not stat.S_ISCHR(st.st_mode) and os.path.samestat(st, os.fstat(1))
    except (OSError, ValueError):
        return False


class Results:
    """Where a command's results go: "-" (or a path that is standard output itself) to standard
    output, any other path through :func:`hunting._atomic.atomic_path` (regular files replaced
    whole, devices and FIFOs written directly)."""

    def __init__(self, stdout):
        self._stdout = stdout

    def write_text(self, target: str, text: str) -> None:
        if names_stdout(target):
            self._stdout.write(text if text.endswith("\n") else text + "\n")
            self._stdout.flush()
            return
        write_text(target, text)

    def write_json(self, target: str, data, **dumps) -> None:
        self.write_text(target, json.dumps(data, **dumps))
