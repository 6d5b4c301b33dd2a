"""A constant force (gravity on an incline, a cable, an electrical offset in the amplifier)."""
import numpy as np

NAME = "offset"
DESCRIPTION = "constant force on the load"


def hypers(kin, model) -> list:
    return [{}]


def design(kin, model, hyper):
    return np.ones((kin.t.size, 1))


def parameters(theta, hyper, model) -> dict:
    return {"offset": float(model.offset + theta[0])}


def extend(model, theta, hyper):
    return model.replace(offset=model.offset + float(theta[0]))
