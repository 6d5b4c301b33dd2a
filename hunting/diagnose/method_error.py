"""The force residual the nominal model leaves on its own noise-free closed loop.

The force balance (:mod:`hunting.diagnose.kinematics`) is an estimate: smoothed derivatives of
quantized positions, a held drive seen through a second difference, friction evaluated at a
short-window velocity. On a record of the nominal model itself it leaves a small systematic
residual where the motion is fast-changing (a filter's bias at a velocity reversal, the friction
map's curvature under the smoothing). A cause fitted on that residual explains the method, not
the machine: on the blind benchmark's clean records such biases passed as Stribeck, viscous and
lag effects (4 of 300 clean datasets).

The remedy is a control experiment on the same instants: the nominal loop re-simulated from the
record's reference without sensor noise (quantized like the data), put through the same force
balance with the same window. What it leaves is the method's error along (nearly) the measured
trajectory, and it is subtracted from the data's residual where the re-simulation tracks the
measured motion (speed within ``TRACK`` of the measured one, both used by the force channel).
It is applied only when it is small (RMS at most ``MAX_SHARE`` of the drive force's): a larger
one means the nominal loop runs another motion (the data's effect changes the loop's behaviour),
and its residual then says nothing about the data's."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .data import Measurement
from .kinematics import Kinematics, kinematics, residual, used_samples

TRACK = 0.1        # the re-simulated speed within this fraction of the measured one
MAX_SHARE = 0.01   # applied only when its RMS is at most this fraction of the drive force's RMS


@dataclass(frozen=True)
class MethodError:
    """The nominal model's force residual on its own noise-free closed loop: force [N] (n,),
    zero where ``valid`` is false; valid : bool (n,), samples where the re-simulation tracks the
    measured motion and both are used by the force channel; rms [N] : its RMS over ``valid``."""

    force: np.ndarray
    valid: np.ndarray
    rms: float


def method_error(meas: Measurement, kin: Kinematics, model) -> MethodError | None:
    """The method's error on the record ``meas`` whose kinematics are ``kin`` (module docstring),
    or None when it cannot be formed (no controller or reference, the re-simulation fails) or is
    not applied (too few tracking samples, or RMS above ``MAX_SHARE`` of the drive force's).

    Parameters
    ----------
    meas : Measurement
        The measured record (its reference q_ref, f_ext and u_inj drive the re-simulation).
    kin : Kinematics
        Its kinematics, with ``moving`` already the force channel's used samples.
    model : NominalModel
        The nominal model (its controller closes the loop).

    Returns
    -------
    MethodError or None
    """
    if model.controller is None or meas.q_ref is None:
        return None
    from .parts import sensor_settings, slow_slide_settings
    from .resimulate import resimulate
    sim = resimulate(meas, model, sensor_noise=0.0)
    if not sim.ok:
        return None
    own = Measurement(meas.t, sim.q, sim.u, meas.q_ref, meas.f_ext, name=meas.name + " (nominal loop, noise-free)")
    settings = slow_slide_settings(model, meas.dt) if kin.slow_slides else sensor_settings(model)
    ks = kinematics(own, model.cm, window=kin.window, **dict(settings, resolution=kin.resolution, noise=kin.noise))
    valid = kin.moving & used_samples(ks, model) & (np.abs(ks.v - kin.v) <= TRACK * np.abs(kin.v))
    if valid.sum() < 100:
        return None
    r = np.where(valid, residual(ks, model), 0.0)
    rms = float(np.sqrt(np.mean(r[valid] ** 2)))
    if not np.isfinite(rms) or rms > MAX_SHARE * float(np.sqrt(np.mean(kin.force[kin.moving] ** 2))):
        return None
    return MethodError(r, valid, rms)
