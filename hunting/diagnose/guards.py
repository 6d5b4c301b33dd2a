"""Checks of measured data against the model before a diagnosis: the sample rate against the
model's time constants, the units of the force balance. A record that cannot support a diagnosis
is an error naming what to change; one that supports it only in part gives notes (the causes a
record is too short for are listed by the causes themselves as untested)."""
from __future__ import annotations

import math

import numpy as np

from ..errors import SystemDefinitionError
from .causes.saturation import REPLAY_MISMATCH, replay
from .data import Measurement
from .loop import loop_bandwidth
from .model import NominalModel

MIN_RATE_RATIO = 10.0      # the sample rate must exceed the loop bandwidth this many times
MAX_FORCE_RATIO = 30.0     # the model's inertia or friction force against the measured drive force


def check_inputs(fit: Measurement, validate: Measurement, model: NominalModel) -> list:
    """Errors for data the model cannot be judged on; notes (list of str) for what is doubtful."""
    notes = []
    for meas in (fit, validate):
        dt = meas.dt
        ts = (model.controller or {}).get("sample_time")
        if ts is not None and dt > 1.0001 * float(ts):
            raise SystemDefinitionError(
                f"{meas.name}: sampled every {dt:.3g} s, slower than the model's controller (sample_time {ts:g} s): "
                "the data cannot show what the controller does between samples; give data at the controller's rate")
    f_bw = loop_bandwidth(model)
    if f_bw:
        fs = 1.0 / fit.dt
        if fs < MIN_RATE_RATIO * f_bw:
            raise SystemDefinitionError(
                f"{fit.name}: sampled at {fs:.4g} Hz, less than {MIN_RATE_RATIO:g} times the model's loop bandwidth "
                f"{f_bw:.3g} Hz: the smoothed acceleration cannot follow the loop; record faster (or check that t is "
                "in seconds)")
        if fs > 1e5 * f_bw:
            notes.append(f"the data are sampled at {fs:.4g} Hz, {fs / f_bw:.3g} times the model's loop bandwidth "
                         f"{f_bw:.3g} Hz: is t in seconds?")
    return notes


# the controller's u against the measured u, relative RMS, before a note (the saturation cause's rule)
CONTROLLER_MISMATCH = REPLAY_MISMATCH


def check_controller(meas: Measurement, model: NominalModel) -> str | None:
    """A note when the model's controller, fed the measured q and q_ref, does not give the
    measured u: RMS mismatch above CONTROLLER_MISMATCH of u's RMS (None when it does, or
    without a controller, a reference or a u that moves). Re-simulations with a controller that
    is not the machine's judge the model on a loop that was never run."""
    if model.controller is None or meas.q_ref is None:
        return None
    from .resimulate import controller_output
    u_model = controller_output(meas, model.controller)
    size = float(np.sqrt(np.mean(meas.u ** 2)))
    if size <= 0 or not np.all(np.isfinite(u_model)):
        return None
    mismatch = float(np.sqrt(np.mean((u_model - meas.u) ** 2))) / size
    if mismatch <= CONTROLLER_MISMATCH:
        return None
    keys = "kp/kv/sample_time" if model.controller.get("type") == "pd-velocity-loop" else \
        "kp/kd/ki/derivative_on/tau_f/sample_time"
    text = (f"{meas.name}: the model's controller fed the measured q and q_ref gives u with {mismatch:.0%} RMS "
            f"mismatch to the measured u (more than {CONTROLLER_MISMATCH:.0%})")
    if math.isfinite(model.controller.get("saturation", math.inf)):
        free = controller_output(meas, {k: v for k, v in model.controller.items() if k != "saturation"})
        rest = float(np.sqrt(np.mean((free - meas.u) ** 2))) / size
        if rest <= CONTROLLER_MISMATCH:
            return (f"{text}; without its saturation at {model.controller['saturation']:.4g} it is {rest:.1%}: the "
                    "saturation is what differs, and re-simulations clip u where the machine did not")
    # the machine's output may be limited where the model's is not: clipped at the measured
    # extreme, does the model's controller give the measured u?
    replayed = replay(meas, model)
    if replayed is not None and replayed.clipped <= CONTROLLER_MISMATCH:
        return (f"{text}; saturated at the measured extreme ±{replayed.extreme:.4g} it is {replayed.clipped:.1%}: the "
                "machine's output is limited there and the model's is not (the saturation cause judges it)")
    return f"{text}: check the controller's {keys} and the sign and unit of u; re-simulations run a loop the machine did not"


def check_saturation(records, model: NominalModel) -> str | None:
    """A note when a record's measured controller output goes beyond the model's saturation level
    (:func:`hunting.diagnose.causes.saturation.beyond`, at least MIN_AT_BOUND samples), with both
    numbers: the model's controller cannot give those outputs, so its level is wrong or the
    machine's controller has none (None otherwise, or without a saturation in the model)."""
    from .causes.saturation import MIN_AT_BOUND, beyond, model_level
    level = model_level(model)
    if not (math.isfinite(level) and level > 0):
        return None
    found = [(beyond(m.u, level), m.name) for m in records]
    (U, above), name = max(found, key=lambda f: f[0][0])
    if above < MIN_AT_BOUND:
        return None
    return (f"{name}: the measured controller output reaches |u| = {U:.4g}, {U / level:.3g} times the model's saturation "
            f"level {level:.4g} (in u's unit; {above} samples beyond it): the model's controller cannot give that, so its "
            "saturation is wrong or the machine's controller has none; re-simulations clip u where the machine did not")


def check_breakaway(records, model: NominalModel) -> list:
    """Notes for the records whose drive force stays below the model's Coulomb friction: the
    largest |cm u + f_ext - offset - F_cog(q)| [N] over the record below the smaller of the
    model's Fc+ and Fc- (empty for a model without Coulomb friction). By the model such a record's
    mass can neither break away nor keep sliding (a saturation below the friction holds it,
    reporting22 d0561: +-1.02 N against Fc = 1.66 N, Fs = 2.79 N). Said where the force channel is
    skipped for too few sliding samples, as the reason there are so few: elsewhere a record that
    slides with such a drive has less friction than the model (a level change), which the causes
    judge. (Below Fs alone a mass keeps sliding once moving: of the 3000 clean development
    datasets of reporting13-22, 25 records moved more than a millimetre on a drive between Fc and
    Fs, none on a drive below Fc.)"""
    Fc = min(model.curve.positive.Fc, model.curve.negative.Fc)
    if not Fc > 0:
        return []
    out = []
    for m in records:
        drive = float(np.max(np.abs(model.cm * np.asarray(m.u, float) + m.force_ext() - model.offset
                                    - model.cogging_force(np.asarray(m.q, float)))))
        if drive < Fc:
            out.append(f"{m.name}: the drive force never exceeds {drive:.4g} N (|cm u + f_ext - offset - cogging|), "
                       f"below the model's Coulomb friction {Fc:.4g} N: by the model the mass can neither break away "
                       f"nor keep sliding (its position spans {float(np.ptp(m.q)):.3g} m)")
    return out


SAME_DATA_NOTE = ("the validation data are the fitting data ({}): the out-of-sample test then runs on the fitting data "
                  "and is not out of sample; give a separate record with --validate (or none: the last 40 % of DATA)")


MIN_MOTION_STEPS = 2.0     # a record whose position spans no more sensor steps than this does not move


def check_motion(meas: Measurement, model: NominalModel) -> None:
    """An error when the record's position never leaves a band of MIN_MOTION_STEPS sensor steps
    (the model's resolution, or the step read from the data) plus the sensor's noise band: the
    mass does not move, and the force balance has nothing to show (the sliding-sample guards would
    read the quantization's flicker as motion: a record at rest was reported as disagreeing in its
    units)."""
    from .resimulate import resolution_of
    step = model.resolution if model.resolution is not None else resolution_of(meas.q)
    band = MIN_MOTION_STEPS * max(float(step or 0.0), 0.0) + 4.0 * float(model.sensor_noise or 0.0)
    span = float(np.ptp(meas.q))
    if not span > band:
        raise SystemDefinitionError(
            f"{meas.name}: the mass does not move: its position spans {span:.3g} m over {meas.t[-1] - meas.t[0]:.3g} s, "
            f"within {MIN_MOTION_STEPS:g} sensor steps ({float(step or 0.0):.3g} m each) and the noise band; friction "
            "shows only in motion: give a record in which the machine moves")


MIN_UNIT_SAMPLES = 100    # sliding samples the units check needs


def check_units(kin, model: NominalModel, name: str) -> None:
    """An error when the model's inertia force m a or friction force F(v) on the sliding samples
    is more than MAX_FORCE_RATIO times the measured drive force: the data and the model then
    disagree in their units (most often the time column: a in m/s^2 scales with its square).
    Judged on at least MIN_UNIT_SAMPLES sliding samples (the force channel's own minimum): a
    record that only creeps has a few samples just over the stick speed, where the drive is near
    zero and the model's friction is a full sign(v) Fc (independent seed-5 d0078, a LuGre contact
    in presliding: 20 samples at 30-90 um/s, 'friction 115 times the drive')."""
    m = kin.moving
    if m.sum() < MIN_UNIT_SAMPLES:
        return
    drive = float(np.sqrt(np.mean(kin.force[m] ** 2)))
    inertia = float(np.sqrt(np.mean((model.mass * kin.a[m]) ** 2)))
    friction = float(np.sqrt(np.mean(model.friction(kin.v[m]) ** 2)))
    worst, label = max((inertia, "inertia force m a"), (friction, "friction force F(v)"))
    if worst > MAX_FORCE_RATIO * max(drive, 1e-300):
        raise SystemDefinitionError(
            f"{name}: the model's {label} (RMS {worst:.3g} N) is {worst / max(drive, 1e-300):.3g} times the measured "
            f"drive force cm u (RMS {drive:.3g} N): the data and the model disagree in their units. Check the time "
            f"column (t in seconds: these data are sampled at {1 / float(kin.t[1] - kin.t[0]):.4g} Hz), the position "
            "unit (m or rad) and the motor constant")
