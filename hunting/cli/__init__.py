"""The ``hunting`` command.

    hunting models                      presets and their parameters with units
    hunting simulate PRESET [--set NAME=VALUE ...] [--x0 X1,X2,X3] [--t T] [--json F] [--plot F]
    hunting eventmap PRESET [--set NAME=VALUE ...] --grid START:STOP:N [--iterate K]
                     [--json FILE] [--plot FILE]
    hunting continue PRESET [--set NAME=VALUE ...] --param NAME --from A --to B [--back-to C]
                     [--json FILE] [--plot FILE]
    hunting reproduce ch8|ch9|ch10 [--out DIR]   a thesis chapter: tables and figures, checked
    hunting demo [--out DIR]            short simulations of chapters 4, 8 and 9, checked
    hunting diagnose DATA --model MODEL.json [--validate DATA2] [--json FILE] [--report DIR]
                     [--names KEY=COLUMN,...] [--drop COLUMN]   measured data against the model

Every command checks its arguments and output paths before computing, writes result files
whole (a temporary file, then a rename; ``--json -`` writes to standard output) and reports a
failure in one line: exit code 2 for bad input, 1 for a numerical failure. ``--debug`` shows
the traceback.

A command is a module in this package with ``NAME``, ``HELP``, ``add_arguments(parser)``,
``run(args, results) -> exit code`` and optionally ``files(args) -> (outputs, inputs)``; it is
registered by its module name in ``COMMANDS``.
"""
from __future__ import annotations

import argparse
import contextlib
import importlib
import logging
import os
import sys
import traceback

from ..errors import ConvergenceError, HuntingError
from .boundary import EXIT_FAILURE, EXIT_OK, EXIT_USAGE, ArgumentParser, Results, check_files

COMMANDS = ("models", "simulate", "eventmap", "continue_", "reproduce", "demo", "diagnose")
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
    for name, mod in _commands().items():
        p = sub.add_parser(name, help=mod.HELP, description=mod.HELP)
        p.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                       help="show the traceback of a failure")
        mod.add_arguments(p)
    return ap


class _OneLine(logging.Formatter):
    def format(self, record):
        return f"hunting: {record.levelname.lower()}: {record.getMessage()}"


@contextlib.contextmanager
def _warnings_to_stderr():
    """Library warnings (logging) printed as 'hunting: warning: ...' on stderr while a command runs."""
    h = logging.StreamHandler(sys.stderr)
    h.setFormatter(_OneLine())
    h.setLevel(logging.WARNING)
    logger = logging.getLogger("hunting")
    logger.addHandler(h)
    try:
        yield
    finally:
        logger.removeHandler(h)


def _say_error(message: str) -> None:
    one_line = " ".join(str(message).split())
    print(f"hunting: error: {one_line}", file=sys.stderr)


def _quiet_stdout() -> None:
    """After a broken pipe: point stdout at devnull so the interpreter's final flush is silent."""
    with contextlib.suppress(OSError, ValueError, AttributeError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())


def main(argv=None) -> int:
    """Run the command line; returns the exit code (0 ok, 1 numerical failure, 2 bad input)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    debug = "--debug" in argv
    try:
        try:
            args = build_parser().parse_args(argv)
        except SystemExit as e:             # --help and --version
            return int(e.code or 0)
        cmd = _commands()[args.cmd]
        outputs, inputs = cmd.files(args) if hasattr(cmd, "files") else ((), ())
        check_files(outputs, inputs)
        to_stdout = any(o.value == "-" for o in outputs)
        results = Results(sys.stdout)
        # with results on stdout, everything a command says goes to stderr
        redirect = contextlib.redirect_stdout(sys.stderr) if to_stdout else contextlib.nullcontext()
        with _warnings_to_stderr(), redirect:
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
        _say_error(str(e))
        return EXIT_FAILURE
    except (HuntingError, ValueError) as e:
        if debug:
            traceback.print_exc()
        _say_error(str(e))
        return EXIT_USAGE
    except OSError as e:                    # a file system failure while writing results
        if debug:
            traceback.print_exc()
        _say_error(f"{e.strerror or e}" + (f": '{e.filename}'" if e.filename else ""))
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
