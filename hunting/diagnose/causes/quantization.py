"""Quantization the model does not have: the controller output recorded on a grid (a DAC's step)
that the model's controller lacks, or a position sensor coarser or finer than the model's
declared ``sensor`` resolution. Near rest a quantized loop dithers and hunts where an exact one
settles, so this changes the behaviour, not the force balance.

Evidence: the share of samples lying on the grid read from the data (within 2 % of a step, see
:func:`hunting.diagnose.resimulate.resolution_of`); for a signal off any grid each sample lands
there with probability 0.04, and the binomial tail of the observed count is the p-value. The
extension sets the controller's ``output_resolution`` and the sensor resolution to the data's; its
gain is the fall of the re-simulated position RMS error on the validation data (needs the
controller and the reference)."""
from scipy import stats
from ._words import _q

NAME = "quantization"
DESCRIPTION = "controller output (DAC) or sensor quantization different from the model's"
CHANNEL = "own"
# judged before the other channels (as saturation): its evidence reads only the recorded signals,
# and LuGre bristles behind a DAC's steps were judged on a loop without them and missed
# (reporting18 d0586; found when judged on the quantized loop)
JUDGED_FIRST = True
FAMILY = "actuator"
UNITS = {"output_resolution": "", "sensor_resolution": "m"}


def judge(fit, validate, kf, kv, model, can_sim, resolution):
    from ..resimulate import position_rms_error, resolution_of, steps_on_grid
    ctrl = model.controller or {}
    du = resolution_of(fit.u if fit.u_inj is None else fit.u - fit.u_inj)
    dac_model = float(ctrl.get("output_resolution", 0.0))
    dq, dq_model = resolution, model.resolution
    changes, stat, p = {}, 0.0, 1.0
    if du > 0 and abs(du - dac_model) > 0.01 * du:
        k, n = steps_on_grid(fit.u, du)
        changes["output_resolution"] = du
        stat, p = k / n, float(stats.binom.sf(k - 1, n, 0.04))
    if dq_model is not None and dq > 0 and abs(dq - dq_model) > 0.01 * dq:
        k, n = steps_on_grid(fit.q, dq)
        changes["sensor_resolution"] = dq
        stat, p = max(stat, k / n), min(p, float(stats.binom.sf(k - 1, n, 0.04)))
    out = dict(statistic=stat, p_value=p)
    if not changes:
        return dict(out, reason="the data's quantization (of u and q) is the model's")
    if not can_sim:
        return dict(out, reason="the gain needs re-simulation: the model's controller and the reference q_ref", untestable=True)
    ext = model
    if "output_resolution" in changes:
        ext = ext.replace(controller=dict(ctrl, output_resolution=du))
    if "sensor_resolution" in changes:
        ext = ext.replace(resolution=dq)
    return dict(out, parameters=changes, sigma={k: None for k in changes},
                metric="re-simulated position RMS error [m], validation", nominal=position_rms_error(validate, model),
                extended=position_rms_error(validate, ext),
                model=ext)


def sentence(p, inc, model) -> str:
    out = []
    if "output_resolution" in p:
        out.append(f"the controller output moves in steps of {p['output_resolution']:.4g} (in u's unit: a DAC)")
    if "sensor_resolution" in p:
        out.append(f"the position sensor's resolution is {_q(p['sensor_resolution'], None, 'm')}")
    return " and ".join(out) + ", unlike the model's"
