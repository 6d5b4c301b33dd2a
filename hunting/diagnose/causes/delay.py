"""Actuation delay tau: the plant receives cm u(t - tau) instead of cm u(t), so the residual gains
cm u(t) - cm u(t - tau). The regressor at a trial delay tau is that difference divided by tau
(the drive force's rate for small tau, linear interpolation between samples): its coefficient is
tau itself when the trial is right, and the Gauss-Newton refinement of tau (``HYPER_KEYS``)
makes the two agree for delays of many samples, where the first-order term tau cm u' is not
enough."""

from ._words import _q

NAME = "delay"
DESCRIPTION = "actuation or measurement delay"
FAMILY = "velocity"
HYPERS = 0
HYPER_KEYS = ("tau",)
NOISE_FED = True      # its regressor is made of measured derivatives, which feedback fills with noise
INSTRUMENTED = True   # its coefficient is estimated with the noise-free loop's regressor as instrument
UNITS = {"delay": "s"}


def hypers(kin, model) -> list:
    return [{"tau": kin.dt}]


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
