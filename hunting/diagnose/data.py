"""Measured signals for diagnosis: loaders for CSV, NumPy and MATLAB files with explicit units.

Columns (any file type): ``t`` [s], ``q`` [m or rad], ``u`` (controller output, in the unit the
motor constant multiplies), optional ``q_ref`` (reference), ``f_ext`` (known external force on the
load) and ``u_inj`` (a known signal added to the controller output, e.g. test pulses).
MATLAB and NumPy files may use other variable names through ``names`` (e.g. the EMPS files:
``{"q": "qm", "u": "vir", "q_ref": "qg", "f_ext": "pulses_N"}``; those are tried by default);
``names={"f_ext": None}`` leaves a column out."""
from __future__ import annotations

import csv
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..errors import SystemDefinitionError

REQUIRED = ("t", "q", "u")
OPTIONAL = ("q_ref", "f_ext", "u_inj")
ALIASES = {"t": ("t", "time"), "q": ("q", "qm", "position"), "u": ("u", "vir", "input"),
           "q_ref": ("q_ref", "qg", "reference"), "f_ext": ("f_ext", "pulses_N"), "u_inj": ("u_inj",)}


@dataclass(frozen=True)
class Measurement:
    """Sampled signals, one row per sample (uniform sampling required). t [s]; q [m or rad];
    u [V or N] (what drove the plant, injections included); q_ref, f_ext : optional arrays;
    u_inj : optional known signal added to the controller output (an injected test signal, in
    u's unit; part of u, so only re-simulation uses it); name : where they came from."""

    t: np.ndarray
    q: np.ndarray
    u: np.ndarray
    q_ref: np.ndarray | None = None
    f_ext: np.ndarray | None = None
    name: str = "data"
    u_inj: np.ndarray | None = None

    def __post_init__(self):
        n = np.asarray(self.t).size
        for k in REQUIRED + OPTIONAL:
            v = getattr(self, k)
            if v is None:
                continue
            a = np.asarray(v, dtype=float).ravel()
            if a.size != n:
                raise SystemDefinitionError(f"{self.name}: column {k} has {a.size} samples, t has {n}")
            if not np.all(np.isfinite(a)):
                raise SystemDefinitionError(f"{self.name}: column {k} has NaN or inf values")
            object.__setattr__(self, k, a)
        if n < 50:
            raise SystemDefinitionError(f"{self.name}: {n} samples are too few (need >= 50)")
        dt = np.diff(self.t)
        if np.any(dt <= 0) or np.ptp(dt) > 1e-3 * np.mean(dt):
            raise SystemDefinitionError(f"{self.name}: t must be uniformly sampled and increasing "
                                        f"(steps from {dt.min():.3g} to {dt.max():.3g} s)")

    @property
    def dt(self) -> float:
        return float(self.t[1] - self.t[0])

    @property
    def n(self) -> int:
        return int(self.t.size)

    def force_ext(self) -> np.ndarray:
        return np.zeros(self.n) if self.f_ext is None else self.f_ext

    def part(self, start: float, stop: float) -> "Measurement":
        """The samples with start <= t < stop [s]."""
        sel = (self.t >= start) & (self.t < stop)
        kw = {k: (None if getattr(self, k) is None else getattr(self, k)[sel]) for k in REQUIRED + OPTIONAL}
        return replace(self, **kw, name=f"{self.name}[{start:g}:{stop:g}]")


def _pick(found: dict, names: dict | None, path: Path) -> dict:
    cols = {}
    for k in REQUIRED + OPTIONAL:
        if names and k in names and names[k] is None:
            continue                         # the caller excludes this column
        cands = (names[k],) if names and k in names else ALIASES[k]
        hit = next((c for c in cands if c in found), None)
        if hit is None:
            if k in REQUIRED:
                raise SystemDefinitionError(f"{path}: no column for {k!r} (tried {list(cands)}; "
                                            f"the file has {sorted(found)})")
            continue
        cols[k] = np.asarray(found[hit], dtype=float).ravel()
    return cols


def load(path, names: dict | None = None) -> Measurement:
    """Load a measurement from .csv (header row), .npz or .mat by its suffix."""
    path = Path(path)
    if not path.is_file():
        raise SystemDefinitionError(f"data file {path} does not exist")
    suffix = path.suffix.lower()
    if suffix == ".csv":
        with path.open(newline="") as fh:
            rows = list(csv.reader(fh))
        if len(rows) < 2:
            raise SystemDefinitionError(f"{path}: needs a header row and data rows")
        header = [h.strip() for h in rows[0]]
        try:
            data = np.array([[float(x) for x in r] for r in rows[1:] if r], dtype=float)
        except ValueError as exc:
            raise SystemDefinitionError(f"{path}: non-numeric value ({exc})") from None
        if data.shape[1] != len(header):
            raise SystemDefinitionError(f"{path}: {data.shape[1]} columns of data, {len(header)} names in the header")
        found = {h: data[:, i] for i, h in enumerate(header)}
    elif suffix == ".npz":
        with np.load(path) as z:
            found = {k: z[k] for k in z.files}
    elif suffix == ".mat":
        from scipy.io import loadmat
        found = {k: v for k, v in loadmat(path).items() if not k.startswith("__")}
    else:
        raise SystemDefinitionError(f"{path}: suffix {suffix!r} is not supported (use .csv, .npz or .mat)")
    return Measurement(**_pick(found, names, path), name=path.name)


def save_csv(meas: Measurement, path) -> None:
    """Write a measurement in the CSV format ``load`` reads."""
    cols = [k for k in REQUIRED + OPTIONAL if getattr(meas, k) is not None]
    data = np.column_stack([getattr(meas, k) for k in cols])
    np.savetxt(path, data, delimiter=",", header=",".join(cols), comments="", fmt="%.10g")
