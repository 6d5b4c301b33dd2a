"""The records' parts the channels fit and judge on: the smoothing window, whether a record's used
samples suffice for the force channel, and the splits of one record into a fitting and a judging
part (the first 60 % and last 40 % in time, or alternate blocks of filter windows)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .data import Measurement
from .kinematics import kinematics, used_samples
from .model import NominalModel


# the force channel needs the used samples of each record to span this many smoothing windows:
# the residual is smoothed over one, so it has about that many independent values (tuning-clean
# d0108: a "viscous" judged on a validation record whose used samples span 0.6 windows; on tuning,
# tuning-clean, reporting5 and reporting6 the records under 3 windows held one true force cause,
# that false alarm and one wrong cause)
MIN_WINDOWS = 3
WINDOW_CYCLES = 0.5      # the smoothing window, in periods of the loop's bandwidth (at least 31 samples)
INTERLEAVE_WINDOWS = 8   # filter windows per block of :func:`interleaved`


def split_in_time(record: Measurement) -> tuple[Measurement, Measurement]:
    """(first 60 %, last 40 %) of a record by time: fitting and validation parts."""
    t_split = record.t[0] + 0.6 * (record.t[-1] - record.t[0])
    return record.part(record.t[0], t_split), record.part(t_split, record.t[-1] + record.dt)


def informative(kin) -> bool:
    """Whether a record's used samples (``kin.moving``, :func:`used_samples`) suffice for the
    force channel: at least 100, spanning at least MIN_WINDOWS filter windows."""
    n = int(kin.moving.sum())
    return n >= 100 and n * kin.dt / kin.window >= MIN_WINDOWS


# the fitting record lacks what the force channel fits on, the validation record has it: the
# validation record is split as the data are without validation data (reporting9 d0398: 56
# sliding samples in a 7 s fitting record that creeps at 0.3 mm/s, an offset of 79 % of the
# validation residual went unreported; d0308: all of its fitting record inside the Stribeck dip)
def split_validation(validate: Measurement, model: NominalModel, sensor: dict, window: float | None):
    """(fit, validate, window, kf, kv): the validation record's first 60 % and last 40 % with
    their kinematics (used samples marked), the smoothing window ``window`` [s] or the parts'
    default; None when either part is not :func:`informative`."""
    if validate.n < 250:
        return None
    fit, val = split_in_time(validate)
    w = default_window(fit, val, model) if window is None else window
    kf, kv = (kinematics(m, model.cm, window=w, **sensor) for m in (fit, val))
    kf, kv = (replace(k, moving=used_samples(k, model)) for k in (kf, kv))
    if not (informative(kf) and informative(kv)):
        return None
    return fit, val, w, kf, kv


def interleaved(record: Measurement, model: NominalModel, sensor: dict, window: float | None):
    """(fit, validate, window, kf, kv): one record split into alternate blocks of
    INTERLEAVE_WINDOWS filter windows, the even blocks' used samples to fit on and the odd
    blocks' to judge on (both parts see the motions the record has: a 60/40 split in time of a
    record that moves one way and then the other leaves each part one-way); the smoothing window
    ``window`` [s] or the record's default; None when either part is not :func:`informative`."""
    w = default_window(record, record, model) if window is None else window
    k = kinematics(record, model.cm, window=w, **sensor)
    k = replace(k, moving=used_samples(k, model))
    even = (np.arange(k.t.size) * k.dt // (INTERLEAVE_WINDOWS * k.window)).astype(int) % 2 == 0
    kf, kv = (replace(k, moving=k.moving & part, spectrum=k.moving) for part in (even, ~even))
    if not (informative(kf) and informative(kv)):
        return None
    return record, record, w, kf, kv


def sensor_settings(model: NominalModel) -> dict:
    """The keyword arguments :func:`~hunting.diagnose.kinematics.kinematics` takes from the model:
    the sensor's resolution and noise, and where a slow slide is steady for the free mass
    (:meth:`NominalModel.steady_slide`)."""
    return dict(resolution=model.resolution, noise=model.sensor_noise, steady=model.steady_slide)


def slow_slide_settings(model: NominalModel, dt: float) -> dict:
    """:func:`sensor_settings` for records sampled every ``dt`` [s] whose default reading leaves
    too few sliding samples: a slow slide is steady down to the slope the model's loop tolerates
    (:func:`~hunting.diagnose.loop.steady_slide`), and the kinematics' ``slow_slides`` rules
    apply. Asked only there: read so on every record, the blind benchmark's reporting65 changed
    its causes on 12 of the 211 records run, about as many lost as gained (an asymmetry's
    validation gain diluted below 5 % by 5000 slow samples; a saturated loop that does not hold
    the slide its linear part would)."""
    from .loop import steady_slide
    return dict(resolution=model.resolution, noise=model.sensor_noise, steady=steady_slide(model, dt),
                slow_slides=True)


def default_window(fit: Measurement, validate: Measurement, model: NominalModel) -> float:
    """The smoothing window [s]: 31 samples, or half a period of the loop's bandwidth when that is
    longer (fast sampling: the acceleration's noise falls as the fifth power of the window, and
    with it what feedback of that noise puts into the regressors), at most a quarter of the
    shorter record."""
    from .loop import loop_bandwidth
    dt = fit.dt
    f_bw = loop_bandwidth(model)
    w = 31 * dt if not f_bw else max(31 * dt, WINDOW_CYCLES / f_bw)
    return min(w, dt * (min(fit.n, validate.n) // 4))
