"""Frictional memory (lag): the friction force accelerating through a speed differs from the
force decelerating through it (Hess and Soom). Modelled on the velocity-weakening level: it
follows the Stribeck level g(|v|) through a first-order lag of time constant ``lag`` [s]
(L' = (g(|v|) - L) / lag, F = sign(v) L + b v), so to first order the friction changes by
-lag g'(|v|) a: lower than the static curve while accelerating out of the Stribeck dip, higher
while decelerating into it. A curve without a dip (Fs = Fc) has no level to lag, and the cause
does not apply. The re-simulation integrates the lag exactly."""

NAME = "lag"
DESCRIPTION = "frictional memory: the Stribeck level lags the velocity (time constant)"


def hypers(kin, model) -> list:
    pos, neg = model.curve.positive, model.curve.negative
    return [{}] if (model.law != "lugre" and (pos.Fs > pos.Fc or neg.Fs > neg.Fc)) else []


def design(kin, model, hyper):
    return kin.filtered(model.replace(lag=1.0).lag_force(kin.v, kin.a))[:, None]


def unphysical(theta, hyper, model) -> str | None:
    total = model.lag + float(theta[0])
    return f"lag = {total:.3g} s < 0 (the friction would lead the velocity)" if total < 0 else None


def parameters(theta, hyper, model) -> dict:
    return {"lag": float(model.lag + theta[0])}


def extend(model, theta, hyper):
    return model.replace(lag=max(model.lag + float(theta[0]), 0.0))
