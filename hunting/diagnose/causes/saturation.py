"""Actuator saturation the model does not have: the measured controller output piles up at a
bound the model's controller never reaches (or reaches at a different level).

Evidence: samples whose |u| lies at its extreme (within 1e-6 of it, or half the output's
quantization step) against those in the band just below it (the next step down, or the next
0.1 % of the bound). An output that is not limited thins out towards its extreme, so each of the
samples in the two bands lies at the top with probability at most one half; a saturated one piles
up there, as single samples too when the loop chatters against the bound. The binomial tail of
the count at the top is the p-value stated. The extension is the controller's ``saturation`` at the
measured bound; its gain is the fall of the re-simulated position RMS error on the validation
data (needs the controller and the reference)."""
import numpy as np
from scipy import stats

from ._words import _count

NAME = "saturation"
DESCRIPTION = "controller output saturation missing from the model"
CHANNEL = "own"
FAMILY = "actuator"
UNITS = {"saturation": ""}
MIN_AT_BOUND = 5


def pile_up(u: np.ndarray) -> tuple[float, int, int]:
    """(bound |u| [u units], samples at it, samples in the band just below it)."""
    from ..resimulate import resolution_of
    U = float(np.max(np.abs(u)))
    du = resolution_of(u)
    tol = max(1e-6 * U, 0.5 * du)
    width = max(1e-3 * U, du)
    a = np.abs(u)
    top = int(np.sum(a >= U - tol))
    below = int(np.sum((a < U - tol) & (a >= U - tol - width)))
    return U, top, below


def judge(fit, validate, kf, kv, model, can_sim, resolution):
    from ..resimulate import position_rms_error
    U, top, below = pile_up(fit.u)
    p = float(stats.binom.sf(top - 1, top + below, 0.5)) if top > 0 else 1.0
    out = dict(statistic=float(top), p_value=p)
    if top < MIN_AT_BOUND or U <= 0:
        return dict(out, reason=f"the controller output does not pile up at a bound ({_count(top, 'sample')} at its extreme)")
    sat = model.controller.get("saturation", np.inf) if model.controller else np.inf
    if abs(sat - U) <= 0.01 * U:
        return dict(out, reason=f"the model already saturates at {sat:.4g}")
    if not can_sim:
        return dict(out, reason="the gain needs re-simulation: the model's controller and the reference q_ref", untestable=True)
    ext = model.replace(controller=dict(model.controller, saturation=U))
    return dict(out, parameters={"saturation": U}, sigma={"saturation": None},
                metric="re-simulated position RMS error [m], validation", nominal=position_rms_error(validate, model),
                extended=position_rms_error(validate, ext),
                model=ext)


def sentence(p, inc, model) -> str:
    return (f"the controller output saturates at ±{p['saturation']:.4g} (in u's unit), which the model's controller "
            "does not")
