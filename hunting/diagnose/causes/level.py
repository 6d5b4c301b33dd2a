"""A wrong friction level, the same in both directions: the whole Stribeck level of each
direction scaled by one factor k, Fc -> k Fc and Fs -> k Fs (the dip Fs - Fc scaled with them, its
shape vs, beta and the viscous coefficient b kept).

Why a common factor and not a common shift (Fs - Fc kept): what changes a friction level on a
machine scales the whole boundary-lubrication curve. The friction force of a dry or boundary-
lubricated contact is a friction coefficient times the normal load, mu(v) N, with the static and
the Coulomb coefficient both properties of the same surfaces: a changed preload, belt tension or
normal load (N), worn or run-in surfaces, another grease or temperature (mu) move Fs and Fc in
proportion, so the velocity-weakening dip scales with them. The viscous part comes from shearing
the lubricant film, not from the normal load, and stays (a wrong b is the ``viscous`` cause).
For a Coulomb + viscous model (Fs = Fc) the two parametrisations are the same change.

The change against the nominal force while sliding is (k - 1) g(|v|) sign(v), g the nominal
Stribeck level of each direction: one coefficient, no hyper-parameter. It is the special case of
the ``stribeck`` cause's change at the nominal vs (for beta = 2), of one family with it, and
excludes it: the specific one wins by BIC when the data show no change of shape, the other is then
listed as an alternative. A level that differs between the directions is ``level_asymmetry``
(each direction's level scaled by its own factor, of which this cause is the special case) or a
constant force, ``offset``."""
from dataclasses import replace

import numpy as np

from . import two_way_share, with_curves
from ._words import _pct, _q

NAME = "level"
DESCRIPTION = "friction level (Coulomb and static) scaled in both directions"
FAMILY = "friction curve"
FRICTION_FORCE = True   # a change of the friction force (a constant or a map of the velocity): sized against Fc
HYPERS = 0
ONE_WAY_VALIDATION = True     # its fit needs both directions of motion (against an offset), its prediction either
EXCLUDES = ("stribeck",)      # both change the levels Fc and Fs; the shape change includes this one
UNITS = {"Fc": "N", "Fs": "N", "scale": "", "Fc_neg": "N", "Fs_neg": "N"}


def hypers(kin, model) -> list:
    return [{}]


def untestable(kin, model, validation: bool = False) -> str | None:
    """No level to scale, or a record that moves one way only (less than 10 % of the sliding
    samples the other way) against a curve without a Stribeck dip: there sign(v) g(|v|) = Fc is a
    constant force while sliding, the ``offset`` cause, and a change common to both directions
    cannot be told from it (with a dip the regressor's shape in speed tells them apart). A
    validation record (``validation``) that moves one way still judges a level fitted on both."""
    pos, neg = model.curve.positive, model.curve.negative
    if pos.Fc <= 0 and neg.Fc <= 0 and pos.Fs <= 0 and neg.Fs <= 0:
        return "the nominal model has no Coulomb or static friction to scale (offset, stribeck or asymmetry add it)"
    share = two_way_share(kin)
    if share < 0.1 and pos.Fs == pos.Fc and neg.Fs == neg.Fc and not validation:
        return (f"the record moves one way only ({share:.0%} of the sliding samples the other way): a level common "
                "to both directions of a curve without a Stribeck dip is a constant force (offset) there")
    return None


def signed_levels(v, model) -> np.ndarray:
    """sign(v) g(|v|) [N] (n,): the nominal Stribeck level of the direction of each velocity."""
    pos, neg = model.curve.positive, model.curve.negative
    out = np.zeros_like(v)
    p, n = v > 0, v < 0
    out[p] = pos.level(v[p])
    out[n] = -neg.level(-v[n])
    return out


def design(kin, model, hyper):
    return kin.sliding(signed_levels(kin.vf, model))[:, None]


def unphysical(theta, hyper, model) -> str | None:
    k = 1.0 + float(theta[0])
    return f"the friction level scaled by {k:.3g} <= 0 (friction pushing along the motion)" if k <= 0 else None


def parameters(theta, hyper, model) -> dict:
    k = 1.0 + float(theta[0])
    pos, neg = model.curve.positive, model.curve.negative
    out = {"Fc": k * pos.Fc, "Fs": k * pos.Fs, "scale": k}
    if (neg.Fc, neg.Fs) != (pos.Fc, pos.Fs):
        out.update(Fc_neg=k * neg.Fc, Fs_neg=k * neg.Fs)
    return out


def extend(model, theta, hyper):
    k = 1.0 + float(theta[0])
    return with_curves(model, lambda c: replace(c, Fc=k * c.Fc, Fs=k * c.Fs))


def sentence(p, inc, model) -> str:
    c = model.curve.positive
    k = p["scale"]
    what = "Coulomb friction level" if c.Fs == c.Fc else "friction level (Coulomb and static)"
    if abs(k - 1) < 0.005:
        return f"the {what} is the model's (Fc = {_q(p['Fc'], None, 'N')})"
    how = f"{k:.3g} times the model's" if k >= 1.5 or k <= 0.5 else \
        f"{_pct(abs(k - 1))} {'higher' if k > 1 else 'lower'} than the model's"
    levels = f"Fc = {_q(p['Fc'], None, 'N')} instead of {_q(c.Fc, None, 'N')}"
    if c.Fs != c.Fc:
        levels += f", Fs = {_q(p['Fs'], None, 'N')} instead of {_q(c.Fs, None, 'N')}"
    return f"the {what} is {how} in both directions ({levels})"
