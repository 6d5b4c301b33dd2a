"""A wrong viscous coefficient."""
from dataclasses import replace

from . import with_curves
from ._words import _q

NAME = "viscous"
DESCRIPTION = "viscous coefficient b"
FAMILY = "velocity"
FRICTION_FORCE = True   # a change of the friction force (a constant or a map of the velocity): sized against Fc
HYPERS = 0
NOISE_FED = True      # its regressor is made of measured derivatives, which feedback fills with noise
INSTRUMENTED = True   # its coefficient is estimated with the noise-free loop's regressor as instrument
UNITS = {"b": "N s/m"}
RATIO_WORDS = 10.0     # larger changes are given as the two values, not as a ratio


def hypers(kin, model) -> list:
    return [{}]


def design(kin, model, hyper):
    return kin.sliding(kin.vf)[:, None]


def unphysical(theta, hyper, model) -> str | None:
    b = model.curve.positive.b + float(theta[0])
    return f"b = {b:.3g} N s/m < 0 (friction that pushes along the motion)" if b < 0 else None


def parameters(theta, hyper, model) -> dict:
    return {"b": float(model.curve.positive.b + theta[0])}


def extend(model, theta, hyper):
    return with_curves(model, lambda c: replace(c, b=c.b + float(theta[0])))


def sentence(p, inc, model) -> str:
    b0 = model.curve.positive.b
    if not b0:
        return f"viscous friction that the model lacks (b = {_q(p['b'], None, 'N s/m')}; the model has none)"
    ratio = p["b"] / b0
    if not 0 < ratio <= RATIO_WORDS:       # a ratio to a next-to-nothing model value says nothing
        return (f"viscous friction of b = {_q(p['b'], None, 'N s/m')}, where the model has "
                f"{_q(b0, None, 'N s/m')}")
    return (f"viscous friction is {ratio:.3g} times the model's (b = {_q(p['b'], None, 'N s/m')} instead of "
            f"{_q(b0, None, 'N s/m')})")
