"""Actuation delay tau: the plant receives cm u(t - tau) ~ cm u(t) - tau cm u'(t), so the
residual gains tau cm u'(t) (first order in tau, valid while tau << the signal's time scales)."""
from ._words import _q

NAME = "delay"
DESCRIPTION = "actuation or measurement delay"
FAMILY = "velocity"
HYPERS = 0
NOISE_FED = True      # its regressor is made of measured derivatives, which feedback fills with noise
UNITS = {"delay": "s"}


def hypers(kin, model) -> list:
    return [{}]


def design(kin, model, hyper):
    return kin.du[:, None]


def unphysical(theta, hyper, model) -> str | None:
    d = model.delay + float(theta[0])
    return f"delay = {d:.3g} s < 0 (the plant would act before the command)" if d < 0 else None


def parameters(theta, hyper, model) -> dict:
    return {"delay": float(theta[0])}


def extend(model, theta, hyper):
    return model.replace(delay=max(model.delay + float(theta[0]), 0.0))


def sentence(p, inc, model) -> str:
    d = inc.get("delay", p["delay"])
    return (f"the drive force acts {_q(abs(d), None, 's')} {'later' if d >= 0 else 'earlier'} than the model assumes "
            f"(delay {_q(p['delay'], None, 's')})")
