"""Compiling the integration kernels in a second process while this one does the rest.

On a fresh install a command's first run compiles its kernels (numba: ~9 s CPU for the lean
kernel, ~20 s for the variational one, with the functions they compile in turn). Its other
work until it first integrates (imports, the preset's or the model's own functions, parsing
data) does not depend on them. On a machine with a second core, :func:`compiling_ahead` starts
a helper process (``python -m hunting.integrate.compile_kernels KIND ...``) that compiles the
kernels the command will need into numba's disk cache, in the order given, while this process
goes on; when this process reaches a kernel the helper builds, :func:`wait_for` waits until the
helper has cached it (or has ended) and numba loads it from the cache instead of compiling it
again. This module knows kernels only as (dispatcher, signature) pairs by kind:
:func:`hunting.integrate._kernel.compiling_ahead` names them.

Nothing starts when every kernel asked for is cached already, when this process may use one
core only, or when the environment sets ``HUNTING_COMPILE_AHEAD=0``. Every wait is bounded
(:data:`WAIT_LIMIT`): past it the helper is stopped and this process compiles the kernel
itself, as it would without a helper. The helper is stopped when the command ends, so no
compilation outlives the command; numba writes each cache file whole (a temporary file, then
a rename), so a stopped helper leaves no partial entry.

Commands that run batches (:func:`hunting.integrate._batch.run_batch`) compile the batch kernel
themselves while the helper builds the integration kernel it calls.
"""
from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import time

WAIT_LIMIT = 600.0          # [s] the longest this process waits for the helper before compiling itself
POLL = 0.05                 # [s] between looks at the cache while waiting
ENV_SWITCH = "HUNTING_COMPILE_AHEAD"

_helper: _Helper | None = None      # the running helper of this process, if any


class _Helper:
    """A started helper process: the kinds it compiles, in order."""

    def __init__(self, proc: subprocess.Popen, kinds: tuple[str, ...]):
        self.proc = proc
        self.kinds = kinds

    def running(self) -> bool:
        return self.proc.poll() is None

    def stop(self) -> None:
        if self.running():
            self.proc.terminate()
            try:
                self.proc.wait(timeout=5.0)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()


def cached(disp, sig) -> bool:
    """Whether numba dispatcher ``disp`` is compiled in this process or in numba's disk cache
    for signature ``sig`` on this machine (numba's own index lookup). True where that cannot be
    told (caching off, another numba): then no helper is started for it."""
    try:
        if disp.overloads:
            return True
        cache = disp._cache
        if not getattr(cache, "_enabled", False):
            return True
        disp.targetctx.refresh()
        key = cache._index_key(sig, disp.targetctx.codegen())
        return key in cache._cache_file._load_index()
    except Exception:  # noqa: BLE001 -- numba internals: when they differ, behave as without a helper
        return True


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:          # not on Linux
        return os.cpu_count() or 1


def start(targets: dict) -> bool:
    """Start a helper compiling the uncached ones of ``targets`` ({kind: (dispatcher,
    signature)}, in order) unless one runs, this process may use one core only or
    ``HUNTING_COMPILE_AHEAD=0``. Returns whether it started."""
    global _helper
    if _helper is not None and _helper.running():
        return False
    if os.environ.get(ENV_SWITCH, "1") == "0" or _cores() < 2:
        return False
    todo = tuple(k for k, (disp, sig) in targets.items() if not cached(disp, sig))
    if not todo:
        return False
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([root, os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep))
    try:
        proc = subprocess.Popen([sys.executable, "-m", "hunting.integrate.compile_kernels", *todo], env=env,
                                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except OSError:
        return False
    _helper = _Helper(proc, todo)
    return True


def stop() -> None:
    """Stop this process's helper if it still runs."""
    global _helper
    if _helper is not None:
        _helper.stop()
        _helper = None


def wait_for(kind: str, disp, sig, limit: float = WAIT_LIMIT) -> None:
    """Before this process compiles kernel ``kind`` (dispatcher ``disp`` for signature ``sig``):
    if the helper builds it, wait until it is cached or the helper has ended; past ``limit``
    seconds stop the helper (this process then compiles it itself)."""
    h = _helper
    if h is None or kind not in h.kinds:
        return
    deadline = time.monotonic() + limit
    while h.running() and not cached(disp, sig):
        if time.monotonic() > deadline:
            stop()
            return
        time.sleep(POLL)


@contextlib.contextmanager
def compiling_ahead(targets: dict):
    """Within the block, a helper compiles the uncached ones of ``targets`` ({kind:
    (dispatcher, signature)}, see :func:`start`); it is stopped when the block ends."""
    started = start(targets)
    try:
        yield started
    finally:
        if started:
            stop()
