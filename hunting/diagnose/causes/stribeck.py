"""A wrong velocity-weakening shape: Coulomb level change c1 sign(v) plus a Stribeck term
c2 sign(v) exp(-(|v|/vs)^2) with vs searched on a logarithmic grid over the measured speeds."""
import numpy as np

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
    return np.column_stack([s, s * np.exp(-(np.abs(kin.v) / hyper["vs"]) ** 2)])


def parameters(theta, hyper, model) -> dict:
    c = model.curve.positive
    return {"Fc": float(c.Fc + theta[0]), "Fs": float(c.Fc + theta[0] + theta[1]), "vs": hyper["vs"]}
