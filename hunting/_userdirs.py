"""Where hunting keeps per-user files: one cache root for compiled models and fetched data."""
from __future__ import annotations

import os
from pathlib import Path

CACHE_ENV = "HUNTING_CACHE_DIR"


def cache_root() -> Path:
    """``$HUNTING_CACHE_DIR`` when set, else ``$XDG_CACHE_HOME/hunting`` or ``~/.cache/hunting``
    (on every platform, as the README says). Not created here."""
    root = os.environ.get(CACHE_ENV)
    if root:
        return Path(root).expanduser()
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "hunting"
