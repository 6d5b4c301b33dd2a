"""A wrong viscous coefficient."""
from dataclasses import replace

from . import with_curves

NAME = "viscous"
DESCRIPTION = "viscous coefficient b"


def hypers(kin, model) -> list:
    return [{}]


def design(kin, model, hyper):
    return kin.filtered(kin.v)[:, None]


def parameters(theta, hyper, model) -> dict:
    return {"b": float(model.curve.positive.b + theta[0])}


def extend(model, theta, hyper):
    return with_curves(model, lambda c: replace(c, b=c.b + float(theta[0])))
