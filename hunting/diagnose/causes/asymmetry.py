"""Direction-dependent friction: different viscous coefficients for positive and negative
velocity (a Coulomb-level difference is a constant force while moving: the ``offset`` cause)."""
from dataclasses import replace

import numpy as np

from . import with_curves

NAME = "asymmetry"
DESCRIPTION = "direction-dependent viscous friction (b+ != b-)"


def hypers(kin, model) -> list:
    return [{}]


def design(kin, model, hyper):
    return kin.filtered(np.abs(kin.v))[:, None]


def parameters(theta, hyper, model) -> dict:
    bp, bn = model.curve.positive.b, model.curve.negative.b
    return {"b_pos": float(bp + theta[0]), "b_neg": float(bn - theta[0]), "delta_b": float(theta[0])}


def extend(model, theta, hyper):
    d = float(theta[0])
    return with_curves(model, lambda c: replace(c, b=c.b + d), lambda c: replace(c, b=c.b - d))
