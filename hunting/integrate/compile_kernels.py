"""The helper process of :mod:`hunting.integrate.ahead`: ``python -m
hunting.integrate.compile_kernels KIND ...`` compiles each integration kernel named (one of
:data:`hunting.integrate._kernel.KINDS`), in order, into numba's disk cache, as a command
would (:func:`hunting.integrate._kernel.compiled`, under the kernels' cache lock). When its
standard input closes (the command that started it has ended or stopped it) it finishes the
kernel it is compiling and ends (it prints "compiling KIND" to its standard output as it begins
each one): numba writes a kernel's index entry before its data file, so a
helper killed in between could leave an entry naming another kernel's file."""
from __future__ import annotations

import contextlib
import sys
import threading
import time

from .ahead import POLL


_stop = threading.Event()


def _watch_stdin() -> None:
    with contextlib.suppress(OSError, ValueError):
        sys.stdin.read()
    _stop.set()


def main(argv: list[str]) -> int:
    """Compile the kernels ``argv`` names; 2 for a name that is not a kind."""
    from . import _kernel as K
    bad = [k for k in argv if k not in K.KINDS]
    if bad:
        print(f"kernel kinds {bad} are not allowed: use {tuple(K.KINDS)}", file=sys.stderr)
        return 2
    threading.Thread(target=_watch_stdin, daemon=True).start()
    for i, kind in enumerate(argv):
        if _stop.is_set():
            break
        if i:
            # a pause with the lock free: a command waiting to load the kernel just compiled
            # (it polls every POLL) takes the lock before this compiles the next one
            time.sleep(3 * POLL)
        print(f"compiling {kind}", flush=True)     # progress: the caller may read which kernel is begun
        K.compiled(kind)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
