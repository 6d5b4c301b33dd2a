"""Frictional memory (lag): the friction force accelerating through a speed differs from the
force decelerating through it (Hess and Soom). Modelled on the velocity-weakening level: it
follows the Stribeck level g(|v|) through a first-order lag of time constant ``lag`` [s]
(L' = (g(|v|) - L) / lag, F = sign(v) L + b v; at rest L relaxes to Fs), so the friction is lower
than the static curve while accelerating out of the Stribeck dip, higher while decelerating into
it, and stays near Fs for about ``lag`` after a break-away. A curve without a dip (Fs = Fc) has
no level to lag, and the cause does not apply.

The regressor at a trial lag tau is the exact change of the friction force from the model's lag
to lag + tau, divided by tau (:meth:`NominalModel.lag_force`, the lag integrated exactly between
samples): its coefficient is tau itself when the trial is right, and the Gauss-Newton refinement
of tau (``HYPER_KEYS``) makes the two agree. The first-order form -lag g'(|v|) a holds only while
the lag is short against the passage through the dip (a few ms); a 50 ms lag, common in the
literature, is far outside it (the first-order term then exceeds Fs - Fc itself), and it was
made of second differences of the measured position, which feedback fills with noise. The
trial lags span 1 ms (or two samples) to 0.3 s. The re-simulation integrates the lag exactly."""
import numpy as np

from ._words import _q


NAME = "lag"
DESCRIPTION = "frictional memory: the Stribeck level lags the velocity (time constant)"
FAMILY = "velocity"
HYPERS = 1
HYPER_KEYS = ("tau",)
NOISE_FED = True      # its regressor is a map of the measured velocity, which feedback fills with noise
INSTRUMENTED = True   # its coefficient is estimated with the noise-free loop's regressor as instrument
LAGS = (1e-3, 0.3)    # [s] the trial lags' range (at least two samples)
N_LAGS = 12
EXCLUDES = ("reversal",)     # LuGre bristles have their own memory
UNITS = {"lag": "s"}


def hypers(kin, model) -> list:
    pos, neg = model.curve.positive, model.curve.negative
    if model.law == "lugre" or not (pos.Fs > pos.Fc or neg.Fs > neg.Fc):
        return []
    lo, hi = hyper_bounds(kin, model)["tau"]
    return [{"tau": float(x)} for x in np.geomspace(lo, hi, N_LAGS)]


def hyper_bounds(kin, model) -> dict:
    lo = max(LAGS[0], 2 * kin.dt)
    return {"tau": (lo, max(LAGS[1], 4 * lo))}


def untestable(kin, model) -> str | None:
    if model.law == "lugre":
        return "the nominal model is LuGre (its bristles are its memory)"
    pos, neg = model.curve.positive, model.curve.negative
    if not (pos.Fs > pos.Fc or neg.Fs > neg.Fc):
        return "the nominal friction curve has no Stribeck dip: no level to lag"
    return None


def design(kin, model, hyper):
    # on top of the model's own lag (the residual already holds it)
    tau, l0 = hyper["tau"], model.lag
    now = model.lag_force(kin.vf, kin.slide, kin.dt, l0)
    more = model.lag_force(kin.vf, kin.slide, kin.dt, l0 + tau)
    return kin.sliding((more - now) / tau)[:, None]


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
