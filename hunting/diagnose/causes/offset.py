"""A constant force (gravity on an incline, a cable, an electrical offset in the amplifier)."""
import numpy as np
from ._words import _q

NAME = "offset"
DESCRIPTION = "constant force on the load"
FAMILY = "constant force"
FRICTION_FORCE = True   # a change of the friction force (a constant or a map of the velocity): sized against Fc
HYPERS = 0
UNITS = {"offset": "N"}


def hypers(kin, model) -> list:
    return [{}]


def design(kin, model, hyper):
    return kin.sliding(np.ones(kin.t.size))[:, None]


def parameters(theta, hyper, model) -> dict:
    return {"offset": float(model.offset + theta[0])}


def extend(model, theta, hyper):
    return model.replace(offset=model.offset + float(theta[0]))


def sentence(p, inc, model) -> str:
    if model.offset and abs(p["offset"]) < 0.05 * abs(model.offset):
        # the finding is that the model's constant force is not there, not the tiny rest
        return (f"the model's constant force of {_q(abs(model.offset), None, 'N')} is not in the data (what remains "
                f"of it is {_q(p['offset'], None, 'N')}, less than 5 % of it)")
    side = "negative" if p["offset"] > 0 else "positive"
    return (f"a constant force of {_q(abs(p['offset']), None, 'N')} pushes the load towards {side} positions "
            f"(the model has {_q(model.offset, None, 'N') if model.offset else 'none'}; a Coulomb level differing by twice that between the "
            "directions looks the same while the load moves)")
