"""Actuator saturation the model does not have: the measured controller output sits flat at a
bound the model's controller never reaches (or reaches at a different level).

Evidence: the longest run of consecutive samples with u within a tolerance (1e-6 of the bound,
or half the output's quantization step) of its extreme, at either sign. Were those samples
scattered independently, a run of L would have probability (fraction of samples at the bound)^(L-1);
that is the p-value stated. The extension is the controller's ``saturation`` at the measured bound;
its gain is the fall of the re-simulated position RMS error on the validation data (needs the
controller and the reference)."""
import numpy as np

NAME = "saturation"
DESCRIPTION = "controller output saturation missing from the model"
CHANNEL = "own"
FAMILY = "actuator"
UNITS = {"saturation": ""}
MIN_RUN = 5


def bound_runs(u: np.ndarray) -> tuple[float, int, float]:
    """(bound |u| [u units], the longest run at it [samples], the fraction of samples at it)."""
    from ..resimulate import resolution_of
    peak = float(np.max(np.abs(u)))
    best = (peak, 0, 0.0)
    for sgn in (1.0, -1.0):
        ext = float(np.max(sgn * u))
        if not ext > 0.5 * peak:
            continue                  # a bound is an extreme of |u| (u resting at 0 is not one)
        tol = max(1e-6 * abs(ext), 0.5 * resolution_of(u))
        at = sgn * u >= ext - tol
        edges = np.flatnonzero(np.diff(np.concatenate([[0], at.astype(np.int8), [0]])))
        run = int(np.max(edges[1::2] - edges[::2])) if edges.size else 0
        if run > best[1]:
            best = (abs(ext), run, float(np.mean(at)))
    return best


def judge(fit, validate, kf, kv, model, can_sim, resolution):
    from ..resimulate import position_rms_error
    U, run, frac = bound_runs(fit.u)
    p = float(frac ** (run - 1)) if run > 1 else 1.0
    out = dict(statistic=float(run), p_value=p)
    if run < MIN_RUN:
        return dict(out, reason=f"the controller output does not dwell at a bound (longest run {run} samples)")
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
