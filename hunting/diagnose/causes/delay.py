"""Actuation delay tau: the plant receives cm u(t - tau) instead of cm u(t), so the residual gains
cm u(t) - cm u(t - tau). The regressor at a trial delay tau is that difference divided by tau
(the drive force's rate for small tau, linear interpolation between samples): its coefficient is
tau itself when the trial is right, and the Gauss-Newton refinement of tau (``HYPER_KEYS``)
makes the two agree for delays of many samples, where the first-order term tau cm u' is not
enough."""

import numpy as np

from ._fitting_share import shown_on_fitting_record
from ._words import _q

NAME = "delay"
DESCRIPTION = "actuation or measurement delay"
FAMILY = "velocity"
HYPERS = 0
HYPER_KEYS = ("tau",)
NOISE_FED = True      # its regressor is made of measured derivatives, which feedback fills with noise
INSTRUMENTED = True   # its coefficient is estimated with the noise-free loop's regressor as instrument
UNITS = {"delay": "s"}


# the validation record's drive-force rate over the fitting record's beyond which a delay is the
# validation record's to show (:func:`unseen`; stribeck's, cogging's and flexibility's factor)
UNSEEN_FACTOR = 3.0


def hypers(kin, model) -> list:
    return [{"tau": kin.dt}]


def drive_rate(kin, model) -> float:
    """RMS [N/s] of the drive force's rate over one sample on a record's used samples: what a delay
    of tau changes the force by, per second of tau (the regressor at tau = one sample)."""
    used = kin.moving
    if not used.any():
        return 0.0
    x = design(kin, model, {"tau": kin.dt})[used, 0]
    return float(np.sqrt(np.mean(x ** 2)))


def seen(hyper, kf, model, parameters) -> str | None:
    """Why a delay found on the validation record alone (:func:`unseen`) is one the fitting record
    (``kf``, its used samples marked) would show, where it showed none: its force there, the delay
    (``parameters["delay"]`` less the model's own) times that record's drive rate, reaches
    SEEN_SHARE (:mod:`._fitting_share`) of that record's force residual against ``model`` (RMS on
    its used samples; reporting62 d0046, clean: a 0.16 ms "delay" on the validation record's
    blocks whose force on the fitting record, 29 mN,
    is 1.6 times that record's residual; the true delays found there, reporting63 d0432 and
    reporting62 d0569, 0.23 and 0.64 times)."""
    force = abs(float(parameters["delay"]) - model.delay) * drive_rate(kf, model)
    return shown_on_fitting_record(kf, model, force, "the delay times that record's drive force rate")


def unseen(kf, kv, model) -> str | None:
    """Why the fitting record (``kf``) cannot show a delay the validation record (``kv``) can: the
    validation record's drive force changes more than UNSEEN_FACTOR times faster (:func:`drive_rate`):
    a delay's force is its length times that rate (reporting63 d0432: a 2.1 ms delay, the fitting
    record creeping one way at up to 10 mm/s with a drive rate of 0.63 N/s, the validation record
    moving at up to 0.18 m/s with 58 N/s; the delay fitted on the fitting record predicted the
    validation record 3 % worse than none, where the true one explains 95 % of its residual)."""
    rf, rv = drive_rate(kf, model), drive_rate(kv, model)
    if rf <= 0 or rv <= UNSEEN_FACTOR * rf:
        return None
    return (f"its force, the delay times the drive force's rate ({_q(rf, None, 'N/s')} RMS on the fitting record, "
            f"{_q(rv, None, 'N/s')} on the validation record)")


def hyper_bounds(kin, model) -> dict:
    return {"tau": (0.25 * kin.dt, 0.25 * kin.window + 20 * kin.dt)}


def design(kin, model, hyper):
    # on top of the model's own delay (the residual's drive is already delayed by it)
    tau, d0 = hyper["tau"], model.delay
    now, late = kin.delayed_drive(d0), kin.delayed_drive(d0 + tau)
    return kin.sliding((now - late) / tau)[:, None]


def unphysical(theta, hyper, model) -> str | None:
    d = model.delay + float(theta[0])
    if d < 0:
        return f"delay = {d:.3g} s < 0 (the plant would act before the command)"
    from ..loop import delay_margin
    top = delay_margin(model)
    if top is not None and d > top:
        # a data record of a loop that tracks its reference is not one that a delay beyond its
        # margin would make oscillate (reporting6 d0425: a 71 ms "delay" on a one-way record,
        # margin 29 ms; the true delays of the blind sets reach at most 0.58 of their margin)
        return (f"delay = {d:.3g} s is beyond the nominal loop's delay margin {top:.3g} s: with it the model's loop "
                "would be unstable, and the measured one tracks its reference")
    return None


def parameters(theta, hyper, model) -> dict:
    return {"delay": float(model.delay + theta[0])}


def extend(model, theta, hyper):
    return model.replace(delay=max(model.delay + float(theta[0]), 0.0))


def sentence(p, inc, model) -> str:
    d = inc.get("delay", p["delay"])
    return (f"the drive force acts {_q(abs(d), None, 's')} {'later' if d >= 0 else 'earlier'} than the model assumes "
            f"(delay {_q(p['delay'], None, 's')})")
