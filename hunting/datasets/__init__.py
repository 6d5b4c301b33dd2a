"""Measured data sets the examples use: found on this machine or fetched, always verified.

:func:`emps` gives the two files of the EMPS benchmark (an electro-mechanical positioning
system with Coulomb and viscous friction under a PD/velocity loop; A. Janot, M. Gautier and
M. Brunot, "Data Set and Reference Models of EMPS", Workshop on Nonlinear System
Identification Benchmarks, 2019). They are looked for, in this order:

1. ``$HUNTING_DATA/emps/`` or ``$HUNTING_DATA/`` when the environment variable is set;
2. ``../shared/data/emps/`` relative to the working directory, then relative to the project
   checkout (the directory holding ``pyproject.toml`` above this package), the layout of the
   project's shared data;
3. the user cache, ``$HUNTING_CACHE_DIR/data/emps/`` or ``~/.cache/hunting/data/emps/``
   (``$XDG_CACHE_HOME`` honoured), where a missing pair is downloaded with ``pooch`` from the
   publisher (:data:`EMPS_URL`, a zip archive) and unpacked.

A directory counts when it holds both files. Every file is checked against its SHA-256
(:data:`EMPS_SHA256`) before it is returned: a file that differs raises
:class:`ChecksumError` naming the file, the hash expected and the hash found (a corrupt
download is removed from the cache, a local copy is left as it is). Files are never modified.

:func:`emps_model_json` is the example nominal model for the EMPS data (the benchmark's
published symmetric model, in the format of ``hunting diagnose --model``), shipped with the
package.
"""
from __future__ import annotations

import hashlib
import logging
import os
import re
import shutil
import tempfile
from importlib import resources
from pathlib import Path
from typing import NamedTuple

from .._userdirs import CACHE_ENV, cache_root
from ..errors import HuntingError

log = logging.getLogger(__name__)

ENV_DATA = "HUNTING_DATA"
ENV_CACHE = CACHE_ENV          # shared with the model cache (hunting.describe.cache)

# The publisher's archive: nonlinearbenchmark.org's file host, as used by the benchmark's own
# data loader (github.com/GerbenBeintema/nonlinear_benchmarks, nonlinear_benchmarks/benchmarks.py,
# EMPS(): url 'http://www.nonlinearbenchmark.org/FILES/BENCHMARKS/EMPS/EMPS.zip', 1 949 929
# bytes; later versions of that loader keep it as a comment and use a Google Drive mirror,
# https://drive.google.com/file/d/1zwoXYa9-3f8NQ0ohzmjpF7UxbNgRTHkS/view). The archive's own
# hash is not published; the two .mat files inside are verified instead.
EMPS_URL = "https://www.nonlinearbenchmark.org/FILES/BENCHMARKS/EMPS/EMPS.zip"
EMPS_PAGE = "https://www.nonlinearbenchmark.org/benchmarks/emps"
EMPS_SHA256 = {
    "DATA_EMPS.mat": "6cf6814ae14618795da0101aae2bb97ff0c6351b0501b5492751b02b07facf7e",
    "DATA_EMPS_PULSES.mat": "0eab75bb1f6b16228ee78791343a88bf9bfd9a51036ac9807d7b5fc11c0e1704",
}
EMPS_MODEL = "emps_model.json"
DOWNLOAD_TIMEOUT = 60.0                  # [s] per connection attempt and between received bytes


class DataError(HuntingError):
    """A data set that cannot be found, fetched or verified."""


class ChecksumError(DataError):
    """A data file whose SHA-256 is not the published one."""


class EmpsFiles(NamedTuple):
    """Local paths of the EMPS benchmark's two files.

    fit : DATA_EMPS.mat, the identification run (fit only on this).
    validate : DATA_EMPS_PULSES.mat, the validation run with test pulses.
    """

    fit: Path
    validate: Path


def sha256(path) -> str:
    """The SHA-256 of a file's bytes, as 64 hex digits."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


_LOCAL_ADVICE = f"remove or replace it, or point {ENV_DATA} at a verified copy"


def verify(path, expected: str, label: str | None = None, advice: str = _LOCAL_ADVICE) -> Path:
    """``path`` when its SHA-256 is ``expected``, else :class:`ChecksumError` naming the file
    (``label``, default the path), the hash expected and the hash found."""
    path = Path(path)
    got = sha256(path)
    if got != expected:
        raise ChecksumError(f"{label or path} has sha256 {got}, expected {expected}: it is not the published "
                            f"file (corrupt or changed); {advice}")
    return path


def cache_dir() -> Path:
    """The user data cache: ``data`` under the cache root the compiled models share
    (``$HUNTING_CACHE_DIR``, ``$XDG_CACHE_HOME/hunting`` or ``~/.cache/hunting``). Not created here."""
    return cache_root() / "data"


def _project_root() -> Path | None:
    """The checkout this package runs from (an editable install), or None."""
    root = Path(__file__).resolve().parents[2]
    return root if (root / "pyproject.toml").is_file() else None


def search_dirs(name: str = "emps") -> list[tuple[str, Path]]:
    """(label, directory) of every local place a data set ``name`` is looked for, in order
    (the cache last)."""
    out = []
    env = os.environ.get(ENV_DATA)
    if env:
        base = Path(env).expanduser()
        out += [(f"${ENV_DATA}/{name}", base / name), (f"${ENV_DATA}", base)]
    out.append((f"the working directory's ../shared/data/{name}", Path.cwd().parent / "shared" / "data" / name))
    root = _project_root()
    if root is not None:
        out.append((f"the checkout's ../shared/data/{name}", root.parent / "shared" / "data" / name))
    out.append(("the user cache", cache_dir() / name))
    return out


def _local(files: dict) -> Path | None:
    """The first search directory that holds every file, each verified; None if none does."""
    seen = set()
    for label, d in search_dirs("emps"):
        key = os.path.realpath(d)
        if key in seen:
            continue
        seen.add(key)
        if all((d / f).is_file() for f in files):
            for f, digest in files.items():
                verify(d / f, digest)
            log.info("EMPS data found in %s: %s", label, d)
            return d
    return None


def _reason(exc: Exception) -> str:
    """A short, one-line reason for a failed download."""
    response = getattr(exc, "response", None)
    if response is not None and getattr(response, "status_code", None):
        return f"HTTP {response.status_code} {response.reason or ''}".strip()
    text = " ".join(str(exc).split())
    m = re.search(r"\[Errno -?\d+\][^'\")\]]*", text)
    if m:
        return m.group(0).strip()
    return f"{type(exc).__name__}: {text[:160]}"


def _fetch(url: str, dest: Path, files: dict) -> Path:
    """Download the archive at ``url``, unpack it, verify ``files`` inside it and move them to
    ``dest``. Nothing is left in ``dest`` but verified files."""
    import pooch
    import requests

    try:
        dest.mkdir(parents=True, exist_ok=True)
        work = Path(tempfile.mkdtemp(prefix=".fetch-", dir=dest))
    except OSError as e:
        raise DataError(f"the data cache {dest} cannot be created ({e.strerror or e}): set {ENV_CACHE} to a "
                        f"writable directory, or {ENV_DATA} to a directory holding {' and '.join(files)}") from None
    try:
        log.info("downloading %s to %s", url, dest)
        downloader = pooch.HTTPDownloader(timeout=DOWNLOAD_TIMEOUT, progressbar=False)
        pooch_log = pooch.get_logger()
        level = pooch_log.level
        pooch_log.setLevel(logging.WARNING)         # its INFO lines suggest a known_hash to users
        try:
            members = pooch.retrieve(url, known_hash=None, fname="archive.zip", path=work,
                                     processor=pooch.Unzip(extract_dir="unpacked"), downloader=downloader)
        finally:
            pooch_log.setLevel(level)
        found = {Path(m).name: Path(m) for m in members if Path(m).name in files}
        missing = [f for f in files if f not in found]
        if missing:
            raise DataError(f"the archive {url} holds no {', '.join(missing)}")
        for f, digest in files.items():
            verify(found[f], digest, label=f"{f} downloaded from {url}",
                   advice=f"the download was discarded; set {ENV_DATA} to a directory holding a verified copy")
        for f in files:
            os.replace(found[f], dest / f)
    except (requests.RequestException, OSError) as e:
        raise DataError(f"downloading {url} failed ({_reason(e)})") from None
    except ValueError as e:                         # pooch: a url it cannot handle
        raise DataError(f"downloading {url} failed ({e})") from None
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return dest


def emps(url: str | None = None, download: bool = True) -> EmpsFiles:
    """The local paths of the EMPS benchmark's DATA_EMPS.mat and DATA_EMPS_PULSES.mat.

    Parameters
    ----------
    url : str, optional
        Where to download the archive from when no local copy exists (default
        :data:`EMPS_URL`, the publisher's).
    download : bool
        False: only look on this machine.

    Returns
    -------
    EmpsFiles
        ``(fit, validate)``, both verified against :data:`EMPS_SHA256`.

    Raises
    ------
    ChecksumError
        A file found or downloaded is not the published one.
    DataError
        No local copy, and the download is off or failed; the message says what to do.
    """
    files = EMPS_SHA256
    d = _local(files)
    if d is None and os.environ.get(ENV_DATA):
        log.warning("%s=%s holds no %s (nor its emps/ folder)", ENV_DATA, os.environ[ENV_DATA], " and ".join(files))
    if d is None:
        url = url or EMPS_URL
        looked = "; ".join(f"{label} ({p})" for label, p in search_dirs("emps"))
        todo = (f"set {ENV_DATA} to a directory holding {' and '.join(files)} (download {url}, from {EMPS_PAGE}, "
                "and unzip it there)")
        if not download:
            raise DataError(f"the EMPS data is not on this machine (looked in: {looked}): {todo}")
        try:
            d = _fetch(url, cache_dir() / "emps", files)
        except ChecksumError:
            raise
        except DataError as e:
            raise DataError(f"the EMPS data is not on this machine and {e}: {todo}") from None
    return EmpsFiles(d / "DATA_EMPS.mat", d / "DATA_EMPS_PULSES.mat")


def emps_model_json() -> str:
    """The example nominal model for the EMPS data, as JSON text (``hunting diagnose --model``):
    the benchmark's published symmetric model (M = 95.1089 kg, Fc = 20.3935 N,
    Fv = 203.5034 N s/m, no offset) with its PD/velocity loop (kp = 160.18 1/s,
    kv = 243.45 V/(m/s), 1 ms sampling, +-10 V)."""
    return resources.files(__name__).joinpath(EMPS_MODEL).read_text()


__all__ = ["emps", "emps_model_json", "EmpsFiles", "DataError", "ChecksumError", "verify", "sha256",
           "search_dirs", "cache_dir", "EMPS_URL", "EMPS_SHA256", "ENV_DATA"]
