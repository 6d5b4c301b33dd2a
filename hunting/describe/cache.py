"""The on-disk cache of generated model modules, keyed by a description's structure hash.

``<cache>/models/m_<hash>.py`` is the generated source (numba's ``cache=True`` needs a real,
stable file: its compiled functions are stored beside it in ``__pycache__``), and
``m_<hash>.json`` the metadata (names, modes, contacts) a later process needs without sympy.
The cache directory is ``$HUNTING_CACHE_DIR`` when set, else ``$XDG_CACHE_HOME/hunting`` or
``~/.cache/hunting``. Files are written to a temporary name and renamed, so processes that
compile the same model at once never read a half-written file.

:func:`json_lookup` and :func:`json_store` keep other results derived from a description (e.g.
the nominal model diagnose reads off it, :func:`hunting.diagnose.model.nominal_from_description`)
as ``<cache>/<kind>/<digest>.json``, so a later run needs no sympy.
"""
from __future__ import annotations

import importlib.util
import json
import os
import sys
import tempfile
from pathlib import Path

from .._userdirs import CACHE_ENV, cache_root
from ..errors import SystemDefinitionError

ENV_VAR = CACHE_ENV
_loaded: dict = {}       # digest -> (module, meta): a model compiles and imports once per process


def cache_dir() -> Path:
    """The directory holding generated model modules (created on first use)."""
    d = cache_root() / "models"
    try:
        d.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise SystemDefinitionError(f"the model cache directory {d} cannot be created ({e}): set {ENV_VAR} "
                                    "to a writable directory") from None
    return d


def _write(path: Path, text: str) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def lookup(digest: str):
    """(module, meta) of a compiled model, or None when it is not cached."""
    if digest in _loaded:
        return _loaded[digest]
    d = cache_dir()
    src, meta = d / f"m_{digest}.py", d / f"m_{digest}.json"
    if not (src.is_file() and meta.is_file()):
        return None
    try:
        info = json.loads(meta.read_text())
    except (OSError, ValueError):
        return None
    return _import(digest, src, info)


def store(digest: str, source: str, meta: dict):
    """Write a generated module and its metadata, import it and return (module, meta)."""
    d = cache_dir()
    src = d / f"m_{digest}.py"
    if not (src.is_file() and src.read_text() == source):
        _write(src, source)
    _write(d / f"m_{digest}.json", json.dumps(meta, indent=1))
    return _import(digest, src, meta)


def _import(digest: str, path: Path, meta: dict):
    name = f"hunting_model_{digest}"
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    _loaded[digest] = (mod, meta)
    return mod, meta


def json_lookup(kind: str, digest: str):
    """The JSON value stored under ``kind``/``digest`` (:func:`json_store`), or None when there is
    none or it cannot be read."""
    try:
        return json.loads((cache_root() / kind / f"{digest}.json").read_text())
    except (OSError, ValueError):
        return None


def json_store(kind: str, digest: str, value) -> bool:
    """Store the JSON value ``value`` under ``kind``/``digest``; False (and nothing stored) when the
    cache directory cannot be written: a cache only saves time, so that is no error."""
    try:
        d = cache_root() / kind
        d.mkdir(parents=True, exist_ok=True)
        _write(d / f"{digest}.json", json.dumps(value, allow_nan=False))
    except (OSError, TypeError, ValueError):
        return False
    return True
