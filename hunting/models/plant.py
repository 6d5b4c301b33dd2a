"""Plants: a mass (or inertia) driven through a motor constant, with an optional
position-dependent force (cogging, thesis chapter 10) and a known external force."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from ..errors import SystemDefinitionError, check_finite, check_finite_positive

COG_NONE, COG_HARMONIC, COG_TABLE = 0, 1, 2
FEXT_NONE, FEXT_CONSTANT, FEXT_TRIANGLE = 0, 1, 2


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _segment(q, p, d, n):
    """Index lo of the table segment [q_lo, q_lo+1] holding q (bisection; q inside the table)."""
    lo = 0
    hi = n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if p[d + mid] <= q:
            lo = mid
        else:
            hi = mid
    return lo


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def cogging_force(q, p, base):
    """Cogging force F_cog(q) [N] from the flat parameter array, block starting at ``base``:
    [kind, n, L, data...]; harmonic: F = sum_k a_k cos(2 pi k q / L) + b_k sin(2 pi k q / L),
    data = a_1, b_1, ..., a_n, b_n; table: linear interpolation of (q_i, F_i), i < n, data =
    q_1..q_n, F_1..F_n, held constant outside [q_1, q_n]."""
    kind = p[base]
    if kind == COG_NONE:
        return 0.0
    n = int(p[base + 1])
    d = base + 3
    if kind == COG_HARMONIC:
        w = 2.0 * math.pi / p[base + 2]
        acc = 0.0
        for k in range(n):
            acc += p[d + 2 * k] * math.cos(w * (k + 1) * q) + p[d + 2 * k + 1] * math.sin(w * (k + 1) * q)
        return acc
    # table
    if q <= p[d]:
        return p[d + n]
    if q >= p[d + n - 1]:
        return p[d + 2 * n - 1]
    lo = _segment(q, p, d, n)
    q0 = p[d + lo]
    q1 = p[d + lo + 1]
    w1 = (q - q0) / (q1 - q0)
    return (1.0 - w1) * p[d + n + lo] + w1 * p[d + n + lo + 1]


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def cogging_slope(q, p, base):
    """dF_cog/dq [N/m] of :func:`cogging_force` (table: the slope of the segment; 0 outside)."""
    kind = p[base]
    if kind == COG_NONE:
        return 0.0
    n = int(p[base + 1])
    d = base + 3
    if kind == COG_HARMONIC:
        w = 2.0 * math.pi / p[base + 2]
        acc = 0.0
        for k in range(n):
            wk = w * (k + 1)
            acc += -p[d + 2 * k] * wk * math.sin(wk * q) + p[d + 2 * k + 1] * wk * math.cos(wk * q)
        return acc
    if q <= p[d] or q >= p[d + n - 1]:
        return 0.0
    lo = _segment(q, p, d, n)
    return (p[d + n + lo + 1] - p[d + n + lo]) / (p[d + lo + 1] - p[d + lo])


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def external_force(t, kind, amplitude, period):
    """Known external force [N]: none, constant, or a triangle wave that starts at 0, rises to
    +amplitude at period/4, falls to -amplitude at 3 period/4 and returns to 0 at period."""
    if kind == FEXT_NONE:
        return 0.0
    if kind == FEXT_CONSTANT:
        return amplitude
    ph = t / period - math.floor(t / period)
    if ph < 0.25:
        return amplitude * 4.0 * ph
    if ph < 0.75:
        return amplitude * (2.0 - 4.0 * ph)
    return amplitude * (4.0 * ph - 4.0)


@dataclass(frozen=True)
class Cogging:
    """Position-dependent force F_cog(q) [N], subtracted from the drive force.

    Build with :meth:`harmonic` or :meth:`table`."""

    kind: int
    data: tuple = ()
    period: float = 1.0

    @staticmethod
    def harmonic(period: float, cos: list | tuple = (), sin: list | tuple = ()) -> "Cogging":
        """F(q) = sum_k cos[k-1] cos(2 pi k q / period) + sin[k-1] sin(2 pi k q / period)."""
        period = check_finite_positive("cogging period", period)
        n = max(len(cos), len(sin))
        if n == 0:
            raise SystemDefinitionError("cogging harmonic needs at least one coefficient in cos or sin")
        a = list(cos) + [0.0] * (n - len(cos))
        b = list(sin) + [0.0] * (n - len(sin))
        data = []
        for k in range(n):
            data += [check_finite(f"cos[{k}]", a[k]), check_finite(f"sin[{k}]", b[k])]
        return Cogging(COG_HARMONIC, tuple(data), period)

    @staticmethod
    def sine(amplitude: float, pitch: float, phase: float = 0.0) -> "Cogging":
        """F(q) = amplitude sin(2 pi q / pitch + phase)."""
        amplitude = check_finite("cogging amplitude", amplitude)
        phase = check_finite("cogging phase", phase)
        return Cogging.harmonic(pitch, cos=[amplitude * math.sin(phase)], sin=[amplitude * math.cos(phase)])

    @staticmethod
    def table(q, force) -> "Cogging":
        """Linear interpolation of the table (q_i [m], F_i [N]); constant outside its range."""
        q = np.asarray(q, dtype=float).reshape(-1)
        f = np.asarray(force, dtype=float).reshape(-1)
        if q.size < 2 or q.shape != f.shape:
            raise SystemDefinitionError(f"cogging table needs q and force of equal length >= 2, got {q.size} and {f.size}")
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(f))):
            raise SystemDefinitionError("cogging table entries must be finite")
        if np.any(np.diff(q) <= 0):
            raise SystemDefinitionError("cogging table q must be strictly increasing")
        return Cogging(COG_TABLE, tuple(q) + tuple(f), 1.0)

    @property
    def n(self) -> int:
        return len(self.data) // 2

    def encoded(self) -> np.ndarray:
        return np.array([self.kind, self.n, self.period, *self.data], dtype=float)

    def __call__(self, q) -> np.ndarray:
        """F_cog at positions q (array) [N]: the formula of :func:`cogging_force`, vectorized."""
        qa = np.atleast_1d(np.asarray(q, dtype=float))
        d = np.asarray(self.data, dtype=float)
        if self.kind == COG_TABLE:
            return np.interp(qa, d[:self.n], d[self.n:])          # held constant outside, as in the kernel
        out = np.zeros_like(qa)
        if self.kind == COG_HARMONIC:
            w = 2.0 * np.pi / self.period
            for k in range(self.n):
                out += d[2 * k] * np.cos(w * (k + 1) * qa) + d[2 * k + 1] * np.sin(w * (k + 1) * qa)
        return out

    def slope(self, q, dq: float = 1e-7) -> np.ndarray:
        """dF_cog/dq [N/m] by central differences (exact for tables away from nodes)."""
        q = np.asarray(q, dtype=float)
        return (self(q + dq) - self(q - dq)) / (2 * dq)


@dataclass(frozen=True)
class Plant:
    """m q'' = cm u - F_cog(q) + f_ext(t) - F_friction.

    mass : mass [kg] or inertia [kg m^2] (> 0); motor_constant : cm [N/V] or [N m/V] (> 0;
    1 when u is already a force); setpoint : q_d [m or rad], the state x1 = q - q_d;
    cogging : Cogging or None; external_force : None, a constant [N], or
    ("triangle", amplitude [N], period [s])."""

    mass: float
    motor_constant: float = 1.0
    setpoint: float = 0.0
    cogging: Cogging | None = None
    external_force: object = None

    def __post_init__(self):
        object.__setattr__(self, "mass", check_finite_positive("mass", self.mass))
        object.__setattr__(self, "motor_constant", check_finite_positive("motor_constant", self.motor_constant))
        object.__setattr__(self, "setpoint", check_finite("setpoint", self.setpoint))
        if self.cogging is not None and not isinstance(self.cogging, Cogging):
            raise SystemDefinitionError(f"cogging = {self.cogging!r} must be a Cogging or None")
        self.external_force_encoded()

    def external_force_encoded(self) -> tuple[float, float, float]:
        fe = self.external_force
        if fe is None:
            return (FEXT_NONE, 0.0, 1.0)
        if isinstance(fe, (int, float)):
            return (FEXT_CONSTANT, check_finite("external_force", fe), 1.0)
        if isinstance(fe, tuple) and len(fe) == 3 and fe[0] == "triangle":
            return (FEXT_TRIANGLE, check_finite("external force amplitude", fe[1]),
                    check_finite_positive("external force period", fe[2]))
        raise SystemDefinitionError(
            f"external_force = {fe!r} is not allowed: use None, a number, or ('triangle', amplitude, period)")

    def cogging_encoded(self) -> np.ndarray:
        return np.array([COG_NONE, 0, 1.0]) if self.cogging is None else self.cogging.encoded()
