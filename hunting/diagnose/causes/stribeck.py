"""A wrong velocity-weakening shape: Coulomb level change c1 sign(v) plus a Stribeck term
c2 sign(v) exp(-(|v|/vs)^2) with vs searched on a logarithmic grid over the measured speeds."""
from dataclasses import replace

import numpy as np

from . import with_curves

NAME = "stribeck"
DESCRIPTION = "velocity-weakening (Stribeck) shape: levels and vs"


def hypers(kin, model) -> list:
    speed = np.abs(kin.v[kin.moving])
    if speed.size < 10:
        return []
    lo, hi = np.percentile(speed, 2), np.percentile(speed, 90)
    return [{"vs": float(vs)} for vs in np.geomspace(max(lo, 1e-9), max(hi, 2e-9), 16)]


def design(kin, model, hyper):
    s = np.sign(kin.v)
    return kin.filtered(np.column_stack([s, s * np.exp(-(np.abs(kin.v) / hyper["vs"]) ** 2)]))


def unphysical(theta, hyper, model) -> str | None:
    if theta[1] < 0:
        return (f"Fs - Fc = {theta[1]:.3g} N < 0 (friction rising with speed at low speed); a force dip at low "
                "speed through reversals is frictional memory (lag) or presliding, not a Stribeck curve")
    return None


def parameters(theta, hyper, model) -> dict:
    c = model.curve.positive
    return {"Fc": float(c.Fc + theta[0]), "Fs": float(c.Fc + theta[0] + theta[1]), "vs": hyper["vs"]}


def extend(model, theta, hyper):
    """Levels Fc + theta0 and Fs = Fc + theta0 + theta1 at the fitted vs (replacing the curve's
    own Stribeck term when it had one)."""
    def new(c):
        Fc = max(c.Fc + float(theta[0]), 0.0)
        return replace(c, Fc=Fc, Fs=Fc + float(theta[1]), vs=hyper["vs"], beta=2.0)
    out = with_curves(model, new)
    return out.replace(law="stribeck") if model.law == "coulomb-viscous" else out
