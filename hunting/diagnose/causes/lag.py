"""Frictional memory (lag): the friction force accelerating through a speed differs from the
force decelerating through it (Hess and Soom). Modelled on the velocity-weakening level: it
follows the Stribeck level g(|v|) through a first-order lag of time constant ``lag`` [s]
(L' = (g(|v|) - L) / lag, F = sign(v) L + b v), so to first order the friction changes by
-lag g'(|v|) a: lower than the static curve while accelerating out of the Stribeck dip, higher
while decelerating into it. A curve without a dip (Fs = Fc) has no level to lag, and the cause
does not apply. The re-simulation integrates the lag exactly."""
from ._words import _q


NAME = "lag"
DESCRIPTION = "frictional memory: the Stribeck level lags the velocity (time constant)"
FAMILY = "velocity"
HYPERS = 0
NOISE_FED = True      # its regressor is made of measured derivatives, which feedback fills with noise
EXCLUDES = ("reversal",)     # LuGre bristles have their own memory
UNITS = {"lag": "s"}


def hypers(kin, model) -> list:
    pos, neg = model.curve.positive, model.curve.negative
    return [{}] if (model.law != "lugre" and (pos.Fs > pos.Fc or neg.Fs > neg.Fc)) else []


def untestable(kin, model) -> str | None:
    if model.law == "lugre":
        return "the nominal model is LuGre (its bristles are its memory)"
    pos, neg = model.curve.positive, model.curve.negative
    if not (pos.Fs > pos.Fc or neg.Fs > neg.Fc):
        return "the nominal friction curve has no Stribeck dip: no level to lag"
    return None


def design(kin, model, hyper):
    return kin.sliding(model.replace(lag=1.0).lag_force(kin.vf, kin.a_inst))[:, None]


def unphysical(theta, hyper, model) -> str | None:
    total = model.lag + float(theta[0])
    return f"lag = {total:.3g} s < 0 (the friction would lead the velocity)" if total < 0 else None


def parameters(theta, hyper, model) -> dict:
    return {"lag": float(model.lag + theta[0])}


def extend(model, theta, hyper):
    return model.replace(lag=max(model.lag + float(theta[0]), 0.0))


def sentence(p, inc, model) -> str:
    return (f"friction at low speed lags the velocity by {_q(p['lag'], None, 's')} (frictional memory: lower while "
            "accelerating, higher while decelerating)")
