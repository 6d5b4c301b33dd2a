"""Direction-dependent friction: different viscous coefficients for positive and negative
velocity (a Coulomb-level difference is a constant force while moving: the ``offset`` cause)."""
import numpy as np

NAME = "asymmetry"
DESCRIPTION = "direction-dependent viscous friction (b+ != b-)"


def hypers(kin, model) -> list:
    return [{}]


def design(kin, model, hyper):
    return np.abs(kin.v)[:, None]


def parameters(theta, hyper, model) -> dict:
    bp, bn = model.curve.positive.b, model.curve.negative.b
    return {"b_pos": float(bp + theta[0]), "b_neg": float(bn - theta[0]), "delta_b": float(theta[0])}
