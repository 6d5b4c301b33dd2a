"""Measured signals for diagnosis: loaders for CSV, NumPy and MATLAB files with explicit units.

Columns (any file type): ``t`` [s], ``q`` [m or rad], ``u`` (controller output, in the unit the
motor constant multiplies), optional ``q_ref`` (reference), ``f_ext`` (known external force on the
load) and ``u_inj`` (a known signal added to the controller output, e.g. test pulses: already part
of u, used by the re-simulation). Other variable names map through ``names`` (e.g.
``{"q": "qm", "u": "vir"}``); the EMPS benchmark's names are tried by default (``qm``, ``vir``,
``qg``, and ``pulses_N`` as ``u_inj``: its README shows the pulses are inside ``vir``, a 5 V
injection, not a force on the load); ``names={"u_inj": None}`` leaves a column out."""
from __future__ import annotations

import csv
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..errors import SystemDefinitionError

REQUIRED = ("t", "q", "u")
OPTIONAL = ("q_ref", "f_ext", "u_inj")
ALIASES = {"t": ("t", "time"), "q": ("q", "qm", "position"), "u": ("u", "vir", "input"),
           "q_ref": ("q_ref", "qg", "reference"), "f_ext": ("f_ext",), "u_inj": ("u_inj", "pulses_N")}


@dataclass(frozen=True)
class Measurement:
    """Sampled signals, one row per sample (uniform sampling required). t [s]; q [m or rad];
    u [V or N] (what drove the plant, injections included); q_ref, f_ext : optional arrays;
    u_inj : optional known signal added to the controller output (an injected test signal, in
    u's unit; part of u, so only re-simulation uses it); name : where they came from; source,
    start : for a part cut out of a longer record (:meth:`part`), that record and the index of
    the part's first sample in it (None, 0 otherwise)."""

    t: np.ndarray
    q: np.ndarray
    u: np.ndarray
    q_ref: np.ndarray | None = None
    f_ext: np.ndarray | None = None
    name: str = "data"
    u_inj: np.ndarray | None = None
    source: "Measurement | None" = field(default=None, repr=False, compare=False)
    start: int = 0

    def __post_init__(self):
        n = np.asarray(self.t).size
        for k in REQUIRED + OPTIONAL:
            v = getattr(self, k)
            if v is None:
                continue
            try:
                a = np.asarray(v, dtype=float).ravel()
            except (TypeError, ValueError):
                raise SystemDefinitionError(f"{self.name}: column {k} = {str(v)[:40]!r} is not numeric") from None
            if a.size != n:
                raise SystemDefinitionError(f"{self.name}: column {k} has {a.size} samples, t has {n}")
            if not np.all(np.isfinite(a)):
                bad = np.flatnonzero(~np.isfinite(a))
                raise SystemDefinitionError(f"{self.name}: column {k} has {bad.size} NaN or inf values (first at "
                                            f"sample {int(bad[0])}): remove or interpolate them")
            object.__setattr__(self, k, a)
        if n < 50:
            raise SystemDefinitionError(f"{self.name}: {n} samples are too few (need >= 50)")
        dt = np.diff(self.t)
        if np.any(dt <= 0):
            k = int(np.flatnonzero(dt <= 0)[0])
            raise SystemDefinitionError(f"{self.name}: t must increase: sample {k + 1} has t = {float(self.t[k + 1]):.6g} s "
                                        f"after t = {float(self.t[k]):.6g} s (sort the rows or remove repeated times)")
        if np.ptp(dt) > 1e-3 * np.mean(dt):
            k = int(np.argmax(np.abs(dt - np.median(dt))))
            raise SystemDefinitionError(f"{self.name}: t must be uniformly sampled: steps range from {dt.min():.6g} "
                                        f"to {dt.max():.6g} s (e.g. at sample {k + 1}, t = {self.t[k + 1]:.6g} s); "
                                        "resample the data to a fixed interval")

    @property
    def dt(self) -> float:
        return float(self.t[1] - self.t[0])

    @property
    def n(self) -> int:
        return int(self.t.size)

    def force_ext(self) -> np.ndarray:
        return np.zeros(self.n) if self.f_ext is None else self.f_ext

    def part(self, start: float, stop: float) -> "Measurement":
        """The samples with start <= t < stop [s]. A part that starts after the record's first
        sample keeps the record as its ``source`` (:meth:`from_record_start`)."""
        sel = (self.t >= start) & (self.t < stop)
        kw = {k: (None if getattr(self, k) is None else getattr(self, k)[sel]) for k in REQUIRED + OPTIONAL}
        first = int(np.argmax(sel)) if sel.any() else 0
        root, at = (self.source, self.start + first) if self.source is not None else (self, first)
        return replace(self, **kw, name=f"{self.name}[{start:g}:{stop:g}]", source=root if at > 0 else None, start=at)

    def from_record_start(self) -> "Measurement":
        """The record this part was cut from, from its first sample through the part's last
        (itself when it is not a part): what a re-simulation of the part runs through, so that the
        part starts from the state the loop had there (a part that starts in motion, re-simulated
        from its own first sample, starts from guessed controller and friction states:
        reporting58 d0405, d0625)."""
        if self.source is None:
            return self
        kw = {}
        for k in REQUIRED + OPTIONAL:           # the record's samples before the part, then the part's own
            before, own = getattr(self.source, k), getattr(self, k)
            kw[k] = None if before is None and own is None else np.concatenate(
                [np.zeros(self.start) if before is None else before[:self.start],
                 np.zeros(self.n) if own is None else own])
        return replace(self.source, **kw, source=None, start=0)


def _pick(found: dict, names: dict | None, path: Path) -> dict:
    unknown = sorted(set(names or {}) - set(REQUIRED + OPTIONAL))
    if unknown:
        raise SystemDefinitionError(f"{path}: column keys {unknown} are not known: use {list(REQUIRED + OPTIONAL)}")
    cols = {}
    for k in REQUIRED + OPTIONAL:
        if names and k in names and names[k] is None:
            if k in REQUIRED:
                raise SystemDefinitionError(f"{path}: column {k!r} cannot be left out (required: {list(REQUIRED)}; "
                                            f"optional, may be dropped: {list(OPTIONAL)})")
            continue                         # the caller excludes this column
        cands = (names[k],) if names and k in names else ALIASES[k]
        hit = next((c for c in cands if c in found), None)
        if hit is None:
            if k in REQUIRED:
                raise SystemDefinitionError(f"{path}: no column for {k!r} (tried {list(cands)}; "
                                            f"the file has {sorted(found)})")
            continue
        try:
            cols[k] = np.asarray(found[hit], dtype=float).ravel()
        except (TypeError, ValueError):
            raise SystemDefinitionError(f"{path}: column {hit!r} (for {k!r}) is not numeric") from None
    return cols


def load(path, names: dict | None = None) -> Measurement:
    """Load a measurement from .csv (header row), .npz or .mat by its suffix."""
    path = Path(path)
    if not path.is_file():
        raise SystemDefinitionError(f"data file {path} does not exist")
    suffix = path.suffix.lower()
    if suffix == ".csv":
        try:
            with path.open(newline="", encoding="utf-8-sig") as fh:
                rows = list(csv.reader(fh))
        except UnicodeDecodeError as exc:
            raise SystemDefinitionError(f"{path}: not UTF-8 text (byte {exc.start}: {exc.reason}); save it as UTF-8 "
                                        "CSV, or as .npz/.mat") from None
        except csv.Error as exc:          # e.g. a NUL byte; the reader names the line
            raise SystemDefinitionError(f"{path}: not a CSV file ({exc}; in csv's count of lines)") from None
        if len(rows) < 2:
            raise SystemDefinitionError(f"{path}: needs a header row and data rows")
        header = [h.strip() for h in rows[0]]
        body = []
        for line, r in enumerate(rows[1:], start=2):
            if not r:
                continue
            if len(r) != len(header):
                raise SystemDefinitionError(f"{path}: line {line} has {len(r)} fields, the header has {len(header)} "
                                            f"({', '.join(header)}): every row needs one value per column")
            try:
                body.append([float(x) for x in r])
            except ValueError:
                bad = next(x for x in r if not _is_float(x))
                raise SystemDefinitionError(f"{path}: line {line}: {bad!r} is not a number") from None
        if not body:
            raise SystemDefinitionError(f"{path}: needs a header row and data rows")
        data = np.array(body, dtype=float)
        found = {h: data[:, i] for i, h in enumerate(header)}
    elif suffix == ".npz":
        try:
            with np.load(path) as z:
                found = {k: z[k] for k in z.files}
        except (OSError, ValueError, EOFError) as exc:
            raise SystemDefinitionError(f"{path}: not a readable .npz file ({exc})") from None
    elif suffix == ".mat":
        from scipy.io import loadmat
        try:
            found = {k: v for k, v in loadmat(path).items() if not k.startswith("__")}
        except (OSError, ValueError, TypeError, NotImplementedError) as exc:
            raise SystemDefinitionError(f"{path}: not a readable MATLAB file ({exc})") from None
    else:
        raise SystemDefinitionError(f"{path}: suffix {suffix!r} is not supported (use .csv, .npz or .mat)")
    return Measurement(**_pick(found, names, path), name=path.name)


def _is_float(x: str) -> bool:
    try:
        float(x)
        return True
    except ValueError:
        return False


def save_csv(meas: Measurement, path) -> None:
    """Write a measurement in the CSV format ``load`` reads."""
    cols = [k for k in REQUIRED + OPTIONAL if getattr(meas, k) is not None]
    data = np.column_stack([getattr(meas, k) for k in cols])
    np.savetxt(path, data, delimiter=",", header=",".join(cols), comments="", fmt="%.10g")


def same_record(a: Measurement, b: Measurement) -> bool:
    """Whether two measurements hold the same samples (q and u equal, whatever their names or
    time origins): validation on them would not be out of sample."""
    return a.n == b.n and np.array_equal(a.q, b.q) and np.array_equal(a.u, b.u)
