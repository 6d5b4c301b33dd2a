"""Direction-dependent viscous friction: b+ for positive and b- for negative velocity, each free
(a Coulomb-level difference is a constant force while moving: the ``offset`` cause, or each
direction's whole Stribeck level scaled by its own factor: ``level_asymmetry``; equal changes are
the ``viscous`` cause, the special case b+ - b- unchanged)."""
from dataclasses import replace

import numpy as np

from . import two_way_share, with_curves
from ._words import _pct, _q

NAME = "asymmetry"
DESCRIPTION = "direction-dependent viscous friction (b+ != b-)"
FAMILY = "velocity"
FRICTION_FORCE = True   # a change of the friction force (a constant or a map of the velocity): sized against Fc
HYPERS = 0
NOISE_FED = True      # its regressor is made of measured derivatives, which feedback fills with noise
EXCLUDES = ("viscous",)      # v = max(v, 0) + min(v, 0): viscous is the special case b+ = b-
ONE_WAY_VALIDATION = True   # its fit needs both directions of motion, its prediction either
NESTS = ("viscous",)        # force.select names viscous unless b+ != b- explains the validation data better
UNITS = {"b_pos": "N s/m", "b_neg": "N s/m"}


def hypers(kin, model) -> list:
    return [{}]


def untestable(kin, model, validation: bool = False) -> str | None:
    """Both directions must be driven: at least 10 % of the sliding samples each way; a
    validation record (``validation``) that moves one way still judges the fitted coefficient of
    that way (reporting28 d0483: b+ 16.6 and b- 7.3 N s/m against a nominal 11.9, the fitting
    record's sines both ways, the validation record one move: untested, the viscous change fitted
    on both ways no change)."""
    if validation:
        return None
    share = two_way_share(kin)
    return None if share >= 0.1 else f"the record moves one way only ({share:.0%} of the sliding samples the other way)"


def design(kin, model, hyper):
    return kin.sliding(np.column_stack([np.maximum(kin.vf, 0.0), np.minimum(kin.vf, 0.0)]))


def unphysical(theta, hyper, model) -> str | None:
    bp, bn = model.curve.positive.b + float(theta[0]), model.curve.negative.b + float(theta[1])
    return f"b+ = {bp:.3g}, b- = {bn:.3g} N s/m: a negative viscous coefficient" if min(bp, bn) < 0 else None


def parameters(theta, hyper, model) -> dict:
    return {"b_pos": float(model.curve.positive.b + theta[0]), "b_neg": float(model.curve.negative.b + theta[1])}


def extend(model, theta, hyper):
    return with_curves(model, lambda c: replace(c, b=c.b + float(theta[0])),
                       lambda c: replace(c, b=c.b + float(theta[1])))


def sentence(p, inc, model) -> str:
    parts = []
    for key, side, c in (("b_pos", "positive", model.curve.positive), ("b_neg", "negative", model.curve.negative)):
        if not c.b:
            parts.append(f"lacks the viscous friction for {side} velocities ({key} = {_q(p[key], None, 'N s/m')}; "
                         "the model has none)")
            continue
        rel = p[key] / c.b - 1
        if abs(rel) >= 0.005:
            word = "underestimates" if rel > 0 else "overestimates"
            parts.append(f"{word} viscous friction for {side} velocities by {_pct(abs(rel))} "
                         f"({key} = {_q(p[key], None, 'N s/m')} instead of {_q(c.b, None, 'N s/m')})")
    return "the model " + (" and ".join(parts) if parts else "has the viscous friction of both directions nearly right")
