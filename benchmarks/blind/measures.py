"""Effect sizes as validation gains, computed without hunting: how much the validation record's
force residual (or re-simulated position error) shrinks when a true effect is modelled exactly.

Kinematics (inverse dynamics with parallel filtering): the measured position through a
zero-phase low pass H (Butterworth, order 2, run forwards and backwards; cut-off FC_HZ or a
twentieth of the sampling rate), differenced centrally for v and a; the drive force cm u,
averaged over each sample's neighbourhood [t - dt/2, t + dt/2] of the zero-order hold (and the
model's delay), and the model's force terms go through the same H. The residual of a model on
the samples that move (|v| above 2 % of its maximum, filter edges dropped):

    r = H[cm u_bar(t - delay)] - m1 a - H[F(v) + offset + F_cog(q) + F_load],

F a memoryless law at v, or LuGre / the lagging level integrated along the measured v; F_load
the flexible load's force with the load driven by the measured motion; m1 the motor-side mass.
"Modelled exactly" is this residual with the nominal model changed by the true effect (its true
parameters): the force gain is 1 - RMS(r_effect) / RMS(r_nominal). The behaviour gain is
1 - RMS(q - q_e) / RMS(q - q_nom), q_e and q_nom the noise-free re-simulations of the validation
reference with the nominal plant with and without the effect."""
from __future__ import annotations

import math

import numpy as np
from scipy.signal import butter, filtfilt

from .system import Plant

FC_HZ = 30.0
MOVING = 0.02


class Kin:
    """Kinematics of a record: t, q (filtered), v, a, u (n,); H (callable: the low pass); moving
    (n,) bool; dt [s]; cm."""

    def __init__(self, t, q, u, cm: float):
        self.dt = dt = float(t[1] - t[0])
        fs = 1.0 / dt
        fc = min(FC_HZ, fs / 20)
        self._ba = butter(2, fc / (fs / 2))
        self.t = np.asarray(t, float)
        self.q = self.H(np.asarray(q, float))
        self.v = np.gradient(self.q, dt)
        self.a = np.gradient(self.v, dt)
        self.u = np.asarray(u, float)
        self.cm = float(cm)
        edge = int(math.ceil(3.0 / fc / dt))
        keep = np.zeros(t.size, bool)
        keep[edge:-edge] = True
        self.moving = keep & (np.abs(self.v) > MOVING * np.max(np.abs(self.v)))

    def H(self, x):
        b, a = self._ba
        return filtfilt(b, a, x, axis=0)


def zoh_mean(u: np.ndarray, dt: float, delay: float) -> np.ndarray:
    """The mean over [t_k - dt/2, t_k + dt/2] of the held signal u_j on [t_j + delay,
    t_j+1 + delay) (0 before the first sample) (n,)."""
    n = u.size
    grid = np.arange(n + 1) * dt
    cum = np.concatenate([[0.0], np.cumsum(u) * dt])
    t = np.arange(n) * dt - delay
    return (np.interp(t + dt / 2, grid, cum, left=0.0) - np.interp(t - dt / 2, grid, cum, left=0.0)) / dt


def levels(plant: Plant, v: np.ndarray) -> np.ndarray:
    """The Stribeck level g_s(|v|) [N] of the direction of v (positive curve at v = 0)."""
    out = np.empty_like(v)
    for c, sel in ((plant.pos, v >= 0), (plant.neg, v < 0)):
        r = np.abs(v[sel])
        out[sel] = c.Fc + (c.Fs - c.Fc) * np.exp(-(r / c.vs) ** c.beta) if c.Fs > c.Fc else c.Fc
    return out


def static_friction(plant: Plant, v: np.ndarray) -> np.ndarray:
    """g_s(|v|) sign(v) + b_s v of the plant's curves (0 at v = 0)."""
    return np.sign(v) * levels(plant, v) + np.where(v >= 0, plant.pos.b, plant.neg.b) * v


def cog_force(plant: Plant, q: np.ndarray) -> np.ndarray:
    if not plant.cogging:
        return np.zeros_like(q)
    pitch, cos, sin = plant.cogging
    w = 2 * np.pi / pitch
    return sum(a * np.cos(w * (k + 1) * q) + s * np.sin(w * (k + 1) * q) for k, (a, s) in enumerate(zip(cos, sin)))


def memory_friction(plant: Plant, v: np.ndarray, dt: float) -> np.ndarray:
    """Friction [N] (n,) of a law with memory (LuGre, or the lagging Stribeck level) along the
    velocity samples v, each held over its sample interval and integrated exactly for held v
    from the model's own state; interval means centred on the samples (for stiff LuGre bristles
    z' is large at an instant but its mean over a sample small, like the force the data carry).

    LuGre: z(t) = z_ss + (z_k - z_ss) exp(-lambda t), z_ss = sign(v) g / sigma0, lambda = sigma0
    |v| / g; mean force sigma0 mean(z) + sigma1 (z_k+1 - z_k) / dt + b v. Lag: L relaxes to
    g(|v|) with its time constant; mean force sign(v) mean(L) + b v."""
    g = levels(plant, v)
    b_s = np.where(v >= 0, plant.pos.b, plant.neg.b)
    n = v.size
    mean = np.zeros(n)
    if plant.law == "lugre":
        z = 0.0
        for k in range(n):
            zss = math.copysign(g[k], v[k]) / plant.sigma0
            lam = plant.sigma0 * abs(v[k]) * dt / g[k]
            e = math.exp(-lam)
            frac = (1 - e) / lam if lam > 1e-12 else 1.0
            z_new = zss + (z - zss) * e
            mean[k] = plant.sigma0 * (zss + (z - zss) * frac) + plant.sigma1 * (z_new - z) / dt + b_s[k] * v[k]
            z = z_new
    else:
        L, e = g[0], math.exp(-dt / plant.lag)
        frac = (1 - e) * plant.lag / dt
        for k in range(n):
            mean[k] = math.copysign(g[k] + (L - g[k]) * frac, v[k]) + b_s[k] * v[k]
            L = g[k] + (L - g[k]) * e
    return np.concatenate([[mean[0]], 0.5 * (mean[1:] + mean[:-1])])


def load_force(plant: Plant, kin: Kin) -> np.ndarray:
    """The flexible load's force on the motor side [N] (n,), the load driven by the measured
    motion: m2 q2'' = k (q - q2) + c (v - v2), from rest relative to the motor."""
    from scipy.signal import lsim
    m2, f, zeta = plant.flex
    wn = 2 * math.pi * f
    k, c = m2 * wn * wn, 2 * zeta * m2 * wn
    # x = [q2 - q0, v2]; input [q - q0, v]
    A = np.array([[0.0, 1.0], [-k / m2, -c / m2]])
    B = np.array([[0.0, 0.0], [k / m2, c / m2]])
    Cm = np.array([[-k, -c]])
    D = np.array([[k, c]])
    inp = np.column_stack([kin.q - kin.q[0], kin.v])
    _, y, _ = lsim((A, B, Cm, D), inp, kin.t - kin.t[0])
    return np.asarray(y).reshape(-1)


def model_forces(plant: Plant, kin: Kin) -> np.ndarray:
    """G: friction + offset + cogging + the flexible load's force [N] (n,) of ``plant`` on the
    measured kinematics (memory laws integrated along the measured velocity)."""
    if plant.law == "lugre" or plant.lag:
        fr = memory_friction(plant, kin.v, kin.dt)
    else:
        fr = static_friction(plant, kin.v)
    out = fr + plant.offset + cog_force(plant, kin.q)
    if plant.flex:
        out = out + load_force(plant, kin)
    return out


def residual(kin: Kin, plant: Plant) -> np.ndarray:
    """r = H[cm u_bar] - m1 a - H[G] (n,) of a model (``plant``: its delay, motor-side mass and
    force terms) on the record's kinematics."""
    m1 = plant.mass - (plant.flex[0] if plant.flex else 0.0)
    return kin.H(kin.cm * zoh_mean(kin.u, kin.dt, plant.delay)) - m1 * kin.a - kin.H(model_forces(plant, kin))


def force_gain(kin: Kin, nominal: Plant, modelled: Plant, r_nom: np.ndarray | None = None) -> float:
    """1 - RMS(r_modelled) / RMS(r_nominal) on the moving samples."""
    r_nom = residual(kin, nominal) if r_nom is None else r_nom
    mv = kin.moving
    return 1.0 - _rms(residual(kin, modelled)[mv]) / max(_rms(r_nom[mv]), 1e-300)


def behaviour_gain(q_meas: np.ndarray, q_nom: np.ndarray, q_eff: np.ndarray) -> float:
    return 1.0 - _rms(q_meas - q_eff) / max(_rms(q_meas - q_nom), 1e-300)


def _rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if np.size(x) else 0.0
