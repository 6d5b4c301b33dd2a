"""The ``hunting`` command.

    hunting models                      presets and their parameters with units
    hunting simulate PRESET [--set NAME=VALUE ...] [--x0 X1,X2,X3] [--t T] [--method M] [--rtol R]
                     [--atol A] [--max-steps N] [--max-events N] [--max-samples N] [--json F] [--plot F]
    hunting eventmap PRESET [--set NAME=VALUE ...] --grid START:STOP:N [--iterate K]
                     [--json FILE] [--plot FILE]
    hunting continue PRESET [--set NAME=VALUE ...] --param NAME --from A --to B [--back-to C]
                     [--max-points N] [--ds-max S] [--ds-min S] [--x0 NAME=V,...] [--period-guess T]
                     [--json FILE] [--plot FILE]
                                        exit 1 when the branch stops short of B
    hunting cycle PRESET [--set NAME=VALUE ...] [--x0 NAME=V,...] [--period-guess T]
                     [--which stable|unstable] [--t-max T] [--d-max D] [--json FILE] [--plot FILE]
                                        a periodic orbit: period, multipliers, stick phases
    (simulate, eventmap, continue and cycle take --model FILE, a model description, instead
    of PRESET)
    hunting reproduce ch8|ch9|ch10 [--out DIR]   a thesis chapter: tables and figures, checked
    hunting demo [--out DIR]            short simulations of chapters 4, 8 and 9, checked
    hunting diagnose DATA --model MODEL.json [--validate DATA2] [--json FILE] [--report DIR]
                     [--names KEY=COLUMN,...] [--drop COLUMN]   measured data against the model
    hunting data emps [--dir DIR] [--force]   the EMPS benchmark's files (found or downloaded,
                                        verified) and its example model, ready to diagnose

Every command checks its arguments and output paths before computing, writes result files
whole (a temporary file, then a rename; devices, FIFOs and ``/dev/stdout`` directly, see
:mod:`hunting._atomic`; ``--json -`` writes to standard output) and reports a failure in one
line, in the command line's words (:mod:`hunting.cli.advice`): exit code 2 for bad input, 1 for
a numerical failure. ``--debug`` shows the traceback.

A command is a module in this package with ``NAME``, ``HELP``, ``add_arguments(parser)``,
``run(args, results) -> exit code`` and optionally ``files(args) -> (outputs, inputs)`` and
``kernels(args)`` (the integration kernels it runs, compiled ahead in a second process on a
fresh install: :mod:`hunting.integrate.ahead`); it is registered by its module name in
``COMMANDS``.
"""
from __future__ import annotations

import argparse
import contextlib
import importlib
import logging
import os
import sys
import traceback
import warnings

from .._atomic import OutputPathError
from ..errors import ConvergenceError, HuntingError
from .advice import Command, command_of, for_cli
from .boundary import EXIT_FAILURE, EXIT_OK, EXIT_USAGE, ArgumentParser, Results, check_files, names_stdout

COMMANDS = ("models", "simulate", "eventmap", "continue_", "cycle", "reproduce", "demo", "diagnose", "data")
EXIT_BROKEN_PIPE = 141          # what a shell reports for a command ended by SIGPIPE


def _commands() -> dict:
    mods = [importlib.import_module(f"{__name__}.{m}") for m in COMMANDS]
    return {m.NAME: m for m in mods}


def build_parser() -> ArgumentParser:
    """The argument parser of every command."""
    from .. import __version__
    ap = ArgumentParser(prog="hunting", description="What friction does to controlled machines: "
                        "equilibrium sets, hunting limit cycles, their stability and bifurcations.")
    ap.add_argument("--version", action="version", version=f"hunting {__version__}")
    ap.add_argument("--debug", action="store_true", help="show the traceback of a failure")
    sub = ap.add_subparsers(dest="cmd", required=True, metavar="COMMAND")
    ap.commands = {}
    for name, mod in _commands().items():
        p = ap.commands[name] = sub.add_parser(name, help=mod.HELP, description=mod.HELP)
        p.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                       help="show the traceback of a failure")
        mod.add_arguments(p)
    return ap


class _OneLine(logging.Formatter):
    def __init__(self, words=None):
        super().__init__()
        self._words = words or (lambda text: text)

    def format(self, record):
        return f"hunting: {record.levelname.lower()}: {self._words(record.getMessage())}"


@contextlib.contextmanager
def _warnings_to_stderr(words=None):
    """Library warnings (logging) printed as 'hunting: warning: ...' on stderr while a command
    runs, in the command line's words (``words``: text -> text)."""
    h = logging.StreamHandler(sys.stderr)
    h.setFormatter(_OneLine(words))
    h.setLevel(logging.WARNING)
    logger = logging.getLogger("hunting")
    logger.addHandler(h)
    try:
        yield
    finally:
        logger.removeHandler(h)


@contextlib.contextmanager
def _python_warnings_one_line():
    """Python warnings (numpy's RuntimeWarning from inside a computation) as one line each on
    stderr, not the two-line source listing."""
    def show(message, category, filename, lineno, file=None, line=None):
        where = os.path.splitext(os.path.basename(filename))[0]
        print(f"hunting: warning: {message} ({category.__name__} in {where})", file=sys.stderr)
    with warnings.catch_warnings():
        warnings.showwarning = show
        yield


def _say_error(message: str, command: Command | None = None) -> None:
    message = for_cli(str(message), command) if command is not None else str(message)
    one_line = " ".join(message.split())
    print(f"hunting: error: {one_line}", file=sys.stderr)


def _kernels_ahead(cmd, args):
    """On a fresh install, the integration kernels command ``cmd`` declares (``kernels(args)``)
    compile in a helper process while the command does its other work
    (:mod:`hunting.integrate.ahead`)."""
    kinds = cmd.kernels(args) if hasattr(cmd, "kernels") else ()
    if not kinds:
        return contextlib.nullcontext()
    from ..integrate._kernel import compiling_ahead
    return compiling_ahead(kinds)


def _quiet_stdout() -> None:
    """After a broken pipe: point stdout at devnull so the interpreter's final flush is silent."""
    with contextlib.suppress(OSError, ValueError, AttributeError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())


def main(argv=None) -> int:
    """Run the command line; returns the exit code (0 ok, 1 numerical failure, 2 bad input)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    debug = "--debug" in argv
    command = None                          # the command, once known: its messages in its words
    try:
        parser = build_parser()
        try:
            args = parser.parse_args(argv)
        except SystemExit as e:             # --help and --version
            return int(e.code or 0)
        command = args.cli_command = command_of(args, parser)
        cmd = _commands()[args.cmd]
        outputs, inputs = cmd.files(args) if hasattr(cmd, "files") else ((), ())
        check_files(outputs, inputs)
        to_stdout = any(names_stdout(o.value) for o in outputs)
        results = Results(sys.stdout)
        # with results on stdout, everything a command says goes to stderr
        redirect = contextlib.redirect_stdout(sys.stderr) if to_stdout else contextlib.nullcontext()
        with _kernels_ahead(cmd, args), _warnings_to_stderr(lambda text: for_cli(text, command)), \
                _python_warnings_one_line(), redirect:
            code = cmd.run(args, results)
        sys.stdout.flush()
        return code
    except BrokenPipeError:
        _quiet_stdout()
        return EXIT_BROKEN_PIPE
    except KeyboardInterrupt:
        _say_error("interrupted")
        return 130
    except ConvergenceError as e:
        if debug:
            traceback.print_exc()
        _say_error(str(e), command)
        return EXIT_FAILURE
    except (HuntingError, ValueError) as e:
        if debug:
            traceback.print_exc()
        _say_error(str(e), command)
        return EXIT_USAGE
    except OSError as e:                    # a file system failure while writing results
        if debug:
            traceback.print_exc()
        if isinstance(e, OutputPathError):
            _say_error(f"'{e.filename}' {e.strerror}", command)
        else:
            _say_error(f"{e.strerror or e}" + (f": '{e.filename}'" if e.filename else ""), command)
        return EXIT_FAILURE
    except Exception as e:  # noqa: BLE001 -- the last line of defence: one line, never a traceback
        if debug:
            traceback.print_exc()
            _say_error(f"unexpected {type(e).__name__}: {e}")
        else:
            _say_error(f"unexpected {type(e).__name__}: {e} (run again with --debug for the traceback, "
                       "and please report it)")
        return EXIT_FAILURE


__all__ = ["main", "build_parser", "COMMANDS", "EXIT_OK", "EXIT_FAILURE", "EXIT_USAGE"]
