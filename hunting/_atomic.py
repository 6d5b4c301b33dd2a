"""Result files written whole or not at all, without harming whatever the path names.

What the path names decides how it is written (:func:`output_target` says which):

- nothing yet, or a regular file: a temporary file in the same directory, then ``os.replace``.
  A reader (or a crash) never sees half a figure or half a JSON file, and a failure while
  writing leaves the older file untouched. A replaced file keeps its permission bits (and its
  owner, where the process may set it); a new file gets what ``open()`` gives (0o666 & ~umask).
- a symbolic link, or a chain of them: the link stays; its final target is written as above (a
  dangling link creates its target).
- a character device (``/dev/null``, a terminal), a FIFO, or a file reached through
  ``/proc/PID/fd`` (``/dev/stdout``, ``/dev/fd/N``): opened and written directly, like a shell's
  ``>``. Renaming over these would replace the device node or the pipe itself (as root:
  ``/dev/null`` for every user), so that never happens. A FIFO must have a reader: without one
  the write waits at most ``FIFO_WAIT`` seconds, then fails.
- a directory, a block device, a socket, a loop of links, a missing directory on the way:
  :class:`OutputPathError` (an ``OSError``) naming the path and what is allowed.
"""
from __future__ import annotations

import contextlib
import errno
import os
import secrets
import stat
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

FIFO_WAIT = 10.0                # [s] how long a write to a FIFO waits for a reader
_MAX_LINKS = 40                 # Linux's own bound on a chain of symbolic links
ALLOWED = "a regular file (replaced whole), a symbolic link to one, a FIFO or a character device"


class OutputPathError(OSError):
    """A path a result cannot be written to, with the reason (``strerror``) and the path."""


@dataclass(frozen=True)
class Target:
    """How a result path is written.

    kind : "file" (a temporary file beside ``path``, then a rename onto it) or "stream"
        (``path`` opened and written directly); path : the path to replace (symbolic links
        resolved) or to open (as given); mode : the permission bits to keep (None: a new file);
    owner : (uid, gid) of the file replaced (None: a new file); fifo : a FIFO (needs a reader).
    """

    kind: str
    path: Path
    mode: int | None = None
    owner: tuple | None = None
    fifo: bool = False


def _resolve(path: str) -> tuple[str, bool]:
    """The absolute path with every symbolic link resolved (directories and the last part),
    and whether the resolution passes through /proc (``/dev/stdout``, ``/dev/fd/N``: the
    "links" there name open files, which may be pipes or terminals with no path)."""
    p = os.path.abspath(path)
    via_proc = False
    for _ in range(_MAX_LINKS):
        parent = os.path.realpath(os.path.dirname(p))
        p = os.path.join(parent, os.path.basename(p))
        via_proc = via_proc or parent == "/proc" or parent.startswith("/proc/")
        if not os.path.islink(p):
            return p, via_proc
        p = os.path.join(parent, os.readlink(p))
    raise OutputPathError(errno.ELOOP, "is a loop of symbolic links", path)


def _kind_name(mode: int) -> str:
    for test, name in ((stat.S_ISDIR, "a directory"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "not a regular file"


def output_target(path) -> Target:
    """How a result is written to ``path`` (see the module docstring).

    Raises
    ------
    OutputPathError
        ``path`` is a directory, a block device, a socket or a loop of links, or its name
        cannot be looked up (too long, a component that is not a directory, ...).
    """
    given = os.fspath(path)
    resolved, via_proc = _resolve(given)
    try:
        st = os.stat(given)                 # follows links: what a writer's open() reaches
    except FileNotFoundError:
        st = None
    except OSError as e:
        raise OutputPathError(e.errno, e.strerror or str(e), given) from None
    if st is None:
        if via_proc:
            raise OutputPathError(errno.ENOENT, "names no open file", given)
        return Target("file", Path(resolved))
    mode = st.st_mode
    if stat.S_ISCHR(mode) or stat.S_ISFIFO(mode) or (stat.S_ISREG(mode) and via_proc):
        return Target("stream", Path(given), fifo=stat.S_ISFIFO(mode))
    if stat.S_ISREG(mode):
        return Target("file", Path(resolved), stat.S_IMODE(mode), (st.st_uid, st.st_gid))
    raise OutputPathError(errno.EISDIR if stat.S_ISDIR(mode) else errno.EINVAL,
                          f"is {_kind_name(mode)} (allowed: {ALLOWED})", given)


def _temp_name(name: str) -> str:
    """A hidden name beside ``name`` with the same suffix (writers may choose the format from
    it), no longer than the file system allows for ``name`` itself (255 bytes)."""
    suffix = Path(name).suffix if len(os.fsencode(Path(name).suffix)) <= 32 else ""
    tag = f".{secrets.token_hex(4)}{suffix}"
    room = max(0, 255 - 1 - len(os.fsencode(tag)))
    stem = os.fsencode(name)[:room].decode(errors="ignore")
    return f".{stem}{tag}"


def _create_temp(path: Path) -> Path:
    """A new, empty temporary file beside ``path`` (see :func:`_temp_name`)."""
    for _ in range(100):
        tmp = path.parent / _temp_name(path.name)
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)   # the umask applies
        except FileExistsError:
            continue
        os.close(fd)
        return tmp
    raise OutputPathError(errno.EEXIST, "has no free temporary name beside it", str(path))


def _wait_for_reader(path: Path, wait: float) -> int:
    """An open write descriptor on the FIFO ``path`` once a process reads it (polled without
    blocking, for at most ``wait`` seconds). The caller keeps it open until its own writer has
    opened the FIFO: closing it earlier would give the reader an end of file."""
    deadline = time.monotonic() + wait
    while True:
        try:
            return os.open(path, os.O_WRONLY | os.O_NONBLOCK)
        except OSError as e:
            if e.errno != errno.ENXIO:
                raise
        if time.monotonic() >= deadline:
            raise OutputPathError(errno.ENXIO, f"is a FIFO that no process read within {wait:g} s "
                                  "(start its reader first)", str(path))
        time.sleep(0.05)


@contextlib.contextmanager
def atomic_path(path, *, fifo_wait: float = FIFO_WAIT) -> Iterator[Path]:
    """Yield the path a writer should write ``path``'s new content to.

    For a regular (or new) file that is a temporary file beside it (same suffix): on a normal
    exit it replaces the file, keeping its permission bits; on an exception it is removed and
    the old file stays. For a device, a FIFO or an open file under /proc it is ``path`` itself
    (written directly, never renamed over). Symbolic links are kept and their target written.
    """
    target = output_target(path)
    if target.kind == "stream":
        keep = _wait_for_reader(target.path, fifo_wait) if target.fifo else None
        try:
            with _named(path):
                yield target.path
        finally:
            if keep is not None:
                os.close(keep)
        return
    tmp = _create_temp(target.path)
    try:
        with _named(path):
            yield tmp
        if target.mode is not None:
            os.chmod(tmp, target.mode)
            if target.owner is not None and target.owner != (os.geteuid(), os.getegid()):
                with contextlib.suppress(OSError):      # only a privileged process may
                    os.chown(tmp, *target.owner)
        _replace(tmp, target.path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def _named(path) -> Iterator[None]:
    """A write that fails without naming a file (ENOSPC on /dev/full or a full disk) names
    ``path``, the output the user gave."""
    try:
        yield
    except OSError as e:
        if e.filename is not None:
            raise
        raise OSError(e.errno, f"the result could not be written ({e.strerror or e})", str(path)) from e


def _replace(tmp: Path, path: Path) -> None:
    """``os.replace``, after checking once more that ``path`` is still a regular file or absent
    (it may have changed since :func:`output_target` looked)."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        mode = None
    if mode is not None and not stat.S_ISREG(mode):
        raise OutputPathError(errno.EEXIST, f"changed while the result was written: it is now "
                              f"{_kind_name(mode) if not stat.S_ISLNK(mode) else 'a symbolic link'}; "
                              "nothing was replaced", str(path))
    os.replace(tmp, path)


def write_text(path, text: str) -> None:
    """``Path(path).write_text(text)``, atomically where the path allows (see :func:`atomic_path`)."""
    with atomic_path(path) as tmp:
        Path(tmp).write_text(text)
