"""Velocity and acceleration from quantized positions, and the force residual.

Positions are differentiated with a Savitzky-Golay filter (local cubic least squares over
``window`` seconds, zero phase); the drive force cm u + f_ext goes through the same smoothing
(parallel filtering, as in inverse-dynamics identification) so both sides of the force balance
have the same bandwidth: :meth:`Kinematics.filtered` is that filter, and the model's static maps
(friction F(v), cogging F(q)) and the causes' regressors that are functions of v or q go through it
too (unfiltered, the friction's jump at a velocity reversal stays sharp while the measured force's
is smoothed over the window, and the residual shows a false low-speed friction dip); u is aligned
for the zero-order hold of a digital controller. The residual of a model is
r = force - m a - H_a[F(v) + F_cog(q)] - offset
(and the first-order delay term)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import cumulative_trapezoid
from scipy.signal import savgol_filter

from ..errors import SystemDefinitionError
from .data import Measurement


@dataclass(frozen=True)
class Kinematics:
    """(n,) arrays: t [s], q [m] (smoothed), v [m/s], a [m/s^2], force [N] (cm u + f_ext,
    smoothed), du [V/s] (du/dt, smoothed); cm : motor constant; window [s]; moving : samples with
    |v| above v_min (where the static friction map is single-valued)."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    force: np.ndarray
    du: np.ndarray
    cm: float
    window: float
    moving: np.ndarray

    def filtered(self, x: np.ndarray) -> np.ndarray:
        """x (n,) or (n, k) through the acceleration's filter (the one the force went through)."""
        dt = float(self.t[1] - self.t[0])
        return _acceleration_filter(np.asarray(x, dtype=float), dt, int(round(self.window / dt)))


def _acceleration_filter(x: np.ndarray, dt: float, w: int) -> np.ndarray:
    """The low pass H_a of the SG second derivative (w samples, cubic) applied to x (n,) or to
    each column of x (n, k): the derivative filter on x's double (trapezoidal) integral (it
    annihilates the integration constants, so the result is exactly H_a x)."""
    m = np.mean(x, axis=0)
    x2 = cumulative_trapezoid(cumulative_trapezoid(x - m, dx=dt, axis=0, initial=0.0), dx=dt, axis=0, initial=0.0)
    return savgol_filter(x2, w, 3, deriv=2, delta=dt, mode="interp", axis=0) + m


def kinematics(meas: Measurement, cm: float, *, window: float | None = None, v_min_frac: float = 0.02) -> Kinematics:
    """Smoothed derivatives of a measurement (see the module docstring). window [s] defaults to
    31 samples (31 ms at 1 kHz)."""
    dt = meas.dt
    w = 31 if window is None else int(round(window / dt)) | 1
    if w < 5 or w > meas.n // 2:
        raise SystemDefinitionError(f"window = {window!r} s gives {w} samples: need 5 <= samples <= n/2 = {meas.n // 2}")
    sg = dict(window_length=w, polyorder=3, mode="interp")
    q = savgol_filter(meas.q, deriv=0, **sg)
    v = savgol_filter(meas.q, deriv=1, delta=dt, **sg)
    a = savgol_filter(meas.q, deriv=2, delta=dt, **sg)
    # u_k is held over [t_k, t_k+1) (zero-order hold): the force acting around t_k is the mean of
    # u_k-1 and u_k; without this half-sample alignment every sampled loop shows a 0.5 T "delay"
    u_at = np.concatenate([[meas.u[0]], 0.5 * (meas.u[1:] + meas.u[:-1])])
    # the force goes through the acceleration's own filter: the SG second derivative is
    # d^2/dt^2 times a low-pass H_a(w) that attenuates more than SG smoothing does (0.80 against
    # 0.97 at 18 Hz for 31 samples at 1 kHz), so smoothing the force would leave m (1 - H_a) a in
    # the residual
    force = _acceleration_filter(cm * u_at + meas.force_ext(), dt, w)
    du = savgol_filter(meas.u, deriv=1, delta=dt, **sg)
    moving = np.abs(v) > v_min_frac * np.max(np.abs(v))
    edge = np.zeros(meas.n, bool)
    edge[w:-w] = True                    # drop the filter's edge samples
    return Kinematics(meas.t, q, v, a, force, du, float(cm), w * dt, moving & edge)


def residual(kin: Kinematics, model) -> np.ndarray:
    """Force residual r = force - delay cm u' - m a - offset - H_a[F(v) + F_cog(q)] - F_flex [N] of
    a NominalModel (H_a : :meth:`Kinematics.filtered`) (the delay to first order: cm u(t - delay) ~ cm u(t) - delay cm u'(t))."""
    r = (kin.force - model.delay * kin.cm * kin.du - model.mass * kin.a - model.offset
         - kin.filtered(model.friction(kin.v) + model.lag_force(kin.v, kin.a) + model.cogging_force(kin.q)))
    if model.flexibility is not None:
        r = r - model.flexibility.force(kin.a, float(kin.t[1] - kin.t[0]))
    return r
