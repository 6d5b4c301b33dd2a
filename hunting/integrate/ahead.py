"""Compiling the integration kernels in a second process while this one does the rest.

On a fresh install a command's first run compiles its kernels (numba: ~9 s CPU for the lean
kernel, ~15-20 s for the variational one, with the functions they compile in turn). Its other
work until it first integrates (imports, the preset's or the model's own functions, parsing
data) does not depend on them. On a machine with a second core, :func:`compiling_ahead` starts
a helper process (``python -m hunting.integrate.compile_kernels KIND ...``) that compiles the
kernels the command will run into numba's disk cache, in the order it runs them, while this
process goes on. This module knows kernels only as (dispatcher, signature) pairs by kind:
:func:`hunting.integrate._kernel.compiling_ahead` names them.

Every kernel compile, in any process, holds :func:`kernel_lock`, an exclusive lock on a file in
the kernels' numba cache directory. The kernels share their compiled helpers (steppers, guards,
right-hand sides) and numba's on-disk index files, which numba rewrites without a lock and
writes before the data file they name: two processes compiling different specializations of one
function at once can give two entries the same data file, and a process reading an index entry
before its data is written loads nothing or an older file. Under the lock a command that reaches
a kernel the helper is compiling waits for it, then numba loads it from the cache; a kernel whose
cache entry is whole loads without the lock (:func:`load`), so a command does not wait for a
helper compiling another kernel. (The other
functions a command compiles meanwhile, the models' and the batch kernel, share nothing with the
kernels.)

Nothing starts when every kernel asked for is cached already, when this process may use one
core only, or when the environment sets ``HUNTING_COMPILE_AHEAD=0``. Every wait for the lock is
bounded (:data:`WAIT_LIMIT`; past it the process compiles without it). When the command ends
the helper is told to stop (its standard input closes, also when this process dies): it
finishes the kernel it is compiling, so numba's cache stays whole, and starts no other.
"""
from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import time

WAIT_LIMIT = 600.0          # [s] the longest a process waits for the kernel lock
POLL = 0.05                 # [s] between attempts to take it
ENV_SWITCH = "HUNTING_COMPILE_AHEAD"
LOCK_NAME = "hunting-kernels.lock"

_helper: subprocess.Popen | None = None     # the running helper of this process, if any
_stopped: list = []                          # helpers told to stop that may still finish a kernel
_queue: tuple = ()                           # the kinds the running helper was given, in order


def _disk_cache(disp):
    """Dispatcher ``disp``'s numba disk cache, its target refreshed for a lookup; None where
    caching is off. May raise where numba's internals differ (callers catch it)."""
    cache = disp._cache
    if not getattr(cache, "_enabled", False):
        return None
    disp.targetctx.refresh()
    return cache


def load(disp, sig) -> bool:
    """Load dispatcher ``disp``'s compiled ``sig`` from numba's disk cache into this process, as
    numba's own compile does on a cache hit (without taking the kernel lock: a cache entry is
    whole once numba has written it, index and data each by an atomic rename, and loading writes
    nothing; a helper compiling another kernel meanwhile holds the lock for seconds). Returns
    whether it did: False where the entry is missing, not yet written or unreadable, and the
    caller then compiles under :func:`kernel_lock` (numba loads it there if it appeared)."""
    if disp.overloads:
        return True
    from numba.core.compiler_lock import global_compiler_lock
    try:
        with global_compiler_lock:
            cache = _disk_cache(disp)
            cres = None if cache is None else cache.load_overload(sig, disp.targetctx)
            if cres is None or cres.objectmode:
                return False
            disp.targetctx.insert_user_function(cres.entry_point, cres.fndesc, [cres.library])
            disp.add_overload(cres)
        return True
    except Exception:  # noqa: BLE001 -- numba internals: when they differ, compile under the lock instead
        return False


def cached(disp, sig) -> bool:
    """Whether numba dispatcher ``disp`` is compiled in this process or in numba's disk cache
    for signature ``sig`` on this machine (numba's own index lookup). True where that cannot be
    told (caching off, another numba): then no helper is started for it."""
    if disp.overloads:
        return True
    try:
        cache = _disk_cache(disp)
        return cache is None or cache._index_key(sig, disp.targetctx.codegen()) in cache._cache_file._load_index()
    except Exception:  # noqa: BLE001 -- numba internals: when they differ, behave as without a helper
        return True


@contextlib.contextmanager
def kernel_lock(disp, limit: float = WAIT_LIMIT):
    """Hold the exclusive lock on the kernels' numba cache directory (that of dispatcher
    ``disp``) while compiling a kernel. Taken by polling, at most ``limit`` seconds; where it
    cannot be taken (no cache directory, no ``fcntl``, the limit passed) the block runs
    without it, as numba does."""
    fd = None
    try:
        import fcntl
        path = os.path.join(disp._cache._cache_path, LOCK_NAME)
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
        deadline = time.monotonic() + limit
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() > deadline:
                    raise TimeoutError from None
                time.sleep(POLL)
    except Exception:  # noqa: BLE001 -- no lock to be had: compile as numba does without one
        if fd is not None:
            os.close(fd)
        fd = None
    try:
        yield
    finally:
        if fd is not None:
            os.close(fd)            # closing the descriptor releases the lock


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:          # not on Linux
        return os.cpu_count() or 1


def _running(proc) -> bool:
    return proc is not None and proc.poll() is None


def start(targets: dict) -> bool:
    """Start a helper compiling the uncached ones of ``targets`` ({kind: (dispatcher,
    signature)}, in order) unless a helper of this process still runs, this process may use one
    core only or ``HUNTING_COMPILE_AHEAD=0``. Returns whether it started."""
    global _helper, _queue
    _stopped[:] = [p for p in _stopped if _running(p)]        # reaped once they end
    if _running(_helper) or _stopped:
        return False
    if os.environ.get(ENV_SWITCH, "1") == "0" or _cores() < 2:
        return False
    todo = tuple(k for k, (disp, sig) in targets.items() if not cached(disp, sig))
    if not todo:
        return False
    # -P: the working directory is not searched first (a ./hunting there would shadow this
    # one); the package's root goes on the path unless it is a site directory, there already
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    env = dict(os.environ)
    if os.path.basename(root) not in ("site-packages", "dist-packages"):
        env["PYTHONPATH"] = os.pathsep.join(p for p in (root, os.environ.get("PYTHONPATH", "")) if p)
    import numba
    if numba.config.CACHE_DIR:          # the cache this process uses, even if set after numba's import
        env["NUMBA_CACHE_DIR"] = numba.config.CACHE_DIR
    try:
        _helper = subprocess.Popen([sys.executable, "-P", "-m", "hunting.integrate.compile_kernels", *todo],
                                   env=env, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
    except OSError:
        return False
    _queue = todo
    return True


def queued() -> tuple:
    """The kinds this process's running helper compiles, in order (empty without one)."""
    return _queue if _running(_helper) else ()


def stop() -> None:
    """Tell this process's helper to end after the kernel it is compiling."""
    global _helper, _queue
    if _helper is not None:
        with contextlib.suppress(OSError):
            _helper.stdin.close()
        _stopped.append(_helper)
        _helper, _queue = None, ()


@contextlib.contextmanager
def compiling_ahead(targets: dict):
    """Within the block, a helper compiles the uncached ones of ``targets`` ({kind:
    (dispatcher, signature)}, see :func:`start`); it is told to stop when the block ends."""
    started = start(targets)
    try:
        yield started
    finally:
        if started:
            stop()
