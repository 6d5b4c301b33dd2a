"""Actuation delay tau: the plant receives cm u(t - tau) ~ cm u(t) - tau cm u'(t), so the
residual gains tau cm u'(t) (first order in tau, valid while tau << the signal's time scales)."""
NAME = "delay"
DESCRIPTION = "actuation or measurement delay"


def hypers(kin, model) -> list:
    return [{}]


def design(kin, model, hyper):
    return (kin.cm * kin.du)[:, None]


def parameters(theta, hyper, model) -> dict:
    return {"delay": float(theta[0])}


def extend(model, theta, hyper):
    return model.replace(delay=max(model.delay + float(theta[0]), 0.0))
