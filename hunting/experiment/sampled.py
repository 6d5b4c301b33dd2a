"""Sampled-data experiments on a :class:`VirtualMotor`: a digital controller at fs (zero-order
hold, computed from the quantized, noisy encoder position) around the continuous plant, which is
integrated with fixed RK4 substeps between samples.

The plant: m q'' = cm u - F_cog(q) - F, F = sigma0 z + sigma1 z' + b v, z' = v - sigma0 |v| z / g(v)
(LuGre, the curve of the direction of v). The controller (``DiscretePID``):
e_k = y_k - r_k, I_k = I_{k-1} + T e_k, D_k = (tau_f D_{k-1} + e_k - e_{k-1}) / (tau_f + T),
u_k = sat(-(kp e_k + kd D_k + ki I_k) + v_k + ff_k), held over [t_k, t_k + T)."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numba
import numpy as np

from ..errors import SystemDefinitionError, check_finite, check_finite_positive
from ..models.controller import PID
from ..models.friction import lugre_rates
from .motor import VirtualMotor, cogging_and_slope

_CURVE = 4          # params: m, cm, sigma0, sigma1, curve+ (5), curve- (5), cogging
_COG = 14


@numba.njit(cache=True, error_model="numpy", inline="always")
def _plant_rates(q, v, z, u, p):
    """(q', v', z') of the true plant at drive voltage u."""
    base = _CURVE if v >= 0.0 else _CURVE + 5
    s = 1.0 if v >= 0.0 else -1.0
    zdot, F = lugre_rates(v, z, s, p[base], p[base + 1], p[base + 2], p[base + 3], p[base + 4],
                          p[2], p[3], 0.0)
    fcog, _ = cogging_and_slope(q, p[_COG:])
    return v, (p[1] * u - fcog - F) / p[0], zdot


@numba.njit(cache=True, error_model="numpy", nogil=True)
def _run(p, x, ctrl, cstate, r, vinj, uff, noise, resolution, dt, substeps, u_max,
         y_out, u_out, uc_out, x_out):
    """Advance n = r.size samples. x (3,) plant state [q, v, z] and cstate (3,) controller state
    [I, D, e_prev] are updated in place. ctrl = [closed (0/1), kp, kd, ki, tau_f]."""
    h = dt / substeps
    for k in range(r.size):
        qm = x[0] + noise[k]
        y = resolution * math.floor(qm / resolution + 0.5) if resolution > 0.0 else qm
        uc = 0.0
        if ctrl[0] > 0.5:
            e = y - r[k]
            if math.isnan(cstate[2]):
                cstate[2] = e
            cstate[0] += dt * e
            cstate[1] = (ctrl[4] * cstate[1] + (e - cstate[2])) / (ctrl[4] + dt)
            cstate[2] = e
            uc = -(ctrl[1] * e + ctrl[2] * cstate[1] + ctrl[3] * cstate[0])
        u = uc + vinj[k] + uff[k]
        if u > u_max:
            u = u_max
        elif u < -u_max:
            u = -u_max
        y_out[k] = y
        u_out[k] = u
        uc_out[k] = uc
        x_out[k, 0] = x[0]
        x_out[k, 1] = x[1]
        x_out[k, 2] = x[2]
        q, v, z = x[0], x[1], x[2]
        for _ in range(substeps):
            a1, b1, c1 = _plant_rates(q, v, z, u, p)
            a2, b2, c2 = _plant_rates(q + 0.5 * h * a1, v + 0.5 * h * b1, z + 0.5 * h * c1, u, p)
            a3, b3, c3 = _plant_rates(q + 0.5 * h * a2, v + 0.5 * h * b2, z + 0.5 * h * c2, u, p)
            a4, b4, c4 = _plant_rates(q + h * a3, v + h * b3, z + h * c3, u, p)
            q += h / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4)
            v += h / 6.0 * (b1 + 2 * b2 + 2 * b3 + b4)
            z += h / 6.0 * (c1 + 2 * c2 + 2 * c3 + c4)
        if not (math.isfinite(q) and math.isfinite(v) and math.isfinite(z)):
            return k
        x[0], x[1], x[2] = q, v, z
    return r.size


@dataclass(frozen=True)
class DiscretePID:
    """u = -(kp e + kd D + ki I) on the sampled error e = y - r (see the module docstring).
    kp [V/m], kd [V s/m], ki [V/(m s)], tau_f [s] : first-order filter of the derivative."""

    kp: float
    kd: float
    ki: float
    tau_f: float = 0.0

    def __post_init__(self):
        for k in ("kp", "kd", "ki"):
            check_finite(k, getattr(self, k))
        if not (math.isfinite(self.tau_f) and self.tau_f >= 0):
            raise SystemDefinitionError(f"tau_f = {self.tau_f!r} must be a finite number >= 0 [s]")

    @staticmethod
    def from_pid(pid: PID, tau_f: float = 0.0) -> "DiscretePID":
        return DiscretePID(pid.kp, pid.kd, pid.ki, tau_f)

    def frf(self, f, fs: float) -> np.ndarray:
        """C(e^{j w T}) at frequencies f [Hz]: the gain from the error to -u of this sampled law."""
        zinv = np.exp(-2j * np.pi * np.asarray(f, float) / fs)
        T = 1.0 / fs
        D = (1 - zinv) / (self.tau_f + T - self.tau_f * zinv)
        I = T / (1 - zinv)
        return self.kp + self.kd * D + self.ki * I


@dataclass
class Record:
    """Signals of one run, one row per sample. t [s]; y : measured position [m]; u : applied
    voltage [V]; uc : feedback part [V]; r : reference [m]; v : injected signal [V]; q, qd, z :
    true position [m], velocity [m/s], bristle deflection [m] at the sample instants.
    state / ctrl_state : final plant and controller states (to continue with another controller);
    ok : False when the plant state stopped being finite (``message`` says where)."""

    t: np.ndarray
    y: np.ndarray
    u: np.ndarray
    uc: np.ndarray
    r: np.ndarray
    v: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    z: np.ndarray
    state: np.ndarray
    ctrl_state: np.ndarray
    ok: bool = True
    message: str = ""

    def since(self, k: int) -> "Record":
        """The samples from index k on (final states unchanged)."""
        cut = {name: getattr(self, name)[k:] for name in ("t", "y", "u", "uc", "r", "v", "q", "qd", "z")}
        return replace(self, **cut)


def _as_samples(name, val, n):
    if val is None:
        return np.zeros(n)
    a = np.asarray(val, float)
    if a.ndim == 0:
        return np.full(n, float(a))
    if a.shape != (n,):
        raise SystemDefinitionError(f"{name} has shape {a.shape}: it must be a scalar or have {n} samples")
    if not np.all(np.isfinite(a)):
        raise SystemDefinitionError(f"{name} must be finite")
    return a


def run(motor: VirtualMotor, controller: DiscretePID | None, n: int, *, reference=0.0, injection=None,
        feedforward=None, x0=(0.0, 0.0, 0.0), ctrl_state=None, t0: float = 0.0, seed: int = 0,
        u_max: float = 10.0) -> Record:
    """Run n samples. controller None: open loop (u = injection + feedforward). reference,
    injection [V], feedforward [V] : scalars or (n,) arrays. x0 = (q [m], v [m/s], z [m]);
    ctrl_state = (I, D, e_prev) to continue a controller (default: a fresh one). seed : the
    measurement noise; u_max [V] : the amplifier's saturation."""
    if not isinstance(motor, VirtualMotor):
        raise SystemDefinitionError(f"motor = {motor!r} must be a VirtualMotor")
    if not (isinstance(n, (int, np.integer)) and 1 <= n <= 50_000_000):
        raise SystemDefinitionError(f"n = {n!r} must be an integer number of samples in [1, 5e7]")
    check_finite_positive("u_max", u_max)
    r = _as_samples("reference", reference, n)
    vinj = _as_samples("injection", injection, n)
    uff = _as_samples("feedforward", feedforward, n)
    noise = np.random.default_rng(seed).normal(0.0, motor.noise, n) if motor.noise > 0 else np.zeros(n)
    ctrl = np.zeros(5) if controller is None else np.array([1.0, controller.kp, controller.kd, controller.ki,
                                                            controller.tau_f])
    cs = np.array([0.0, 0.0, np.nan]) if ctrl_state is None else np.array(ctrl_state, float)
    x = np.array(x0, float)
    if x.shape != (3,) or not np.all(np.isfinite(x)):
        raise SystemDefinitionError(f"x0 = {x0!r} must be three finite numbers (q, v, z)")
    y, u, uc, xs = np.empty(n), np.empty(n), np.empty(n), np.empty((n, 3))
    dt = 1.0 / motor.fs
    done = _run(motor.params(), x, ctrl, cs, r, vinj, uff, noise, motor.resolution, dt, motor.substeps, u_max,
                y, u, uc, xs)
    t = t0 + dt * np.arange(n)
    ok = done == n
    msg = "" if ok else (f"the plant state stopped being finite at t = {t[done]:.6g} s: reduce the time step "
                         f"(substeps = {motor.substeps}) or the gains")
    m = done if not ok else n
    return Record(t[:m], y[:m], u[:m], uc[:m], r[:m], vinj[:m], xs[:m, 0], xs[:m, 1], xs[:m, 2], x, cs, ok, msg)
