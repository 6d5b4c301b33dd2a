"""Dwell-time effect: the break-away force grows with the time the contact has rested (Kato; the
thesis' time-varying friction of Fig. 8.1). A break-away channel cause, judged on rests and the
force at which each one ends.

Rests are read from the measured positions (runs within two encoder counts for at least 30 ms,
:func:`hunting.diagnose.behaviour.stick_phases`) that end in motion before the record does; the
record's first rest is skipped (how long the contact rested before it is unknown). At rest a = 0,
so the force friction carries at the end of a rest is F = cm u + f_ext - offset - F_cog(q)
(u aligned for the zero-order hold; a straight line through the 10 ms before the position is two
counts from its rest value, at its end: the break-away lies in that span, and the force ramps
into it); its excess over the model's break-away force in
the direction of the motion that follows is e_k. The extension fits

    e_k = level + gain (1 - exp(-t_k / time))     (t_k the rest's duration)

(level and gain linear, time on a logarithmic grid over the measured rests). Evidence, out of
sample like the force channel's: on the validation data's rests, the growth predicted by the fit
against a constant level (a wrong Fs is a constant, not dwell) must explain the measured excess,
one-sided t test over independent rests. Gain: the RMS of e on the validation data's rests,
nominal (the model's break-away force) against extended."""
import numpy as np
from scipy import stats
from ._words import _count, _q

NAME = "dwell"
DESCRIPTION = "break-away force growing with the time at rest"
CHANNEL = "own"
FAMILY = "break-away"
UNITS = {"level": "N", "gain": "N", "time": "s"}
MIN_RESTS = 6


def rests(meas, model, resolution: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t_rest [s], F [N], s) per rest that ends in motion: duration, the force friction carries
    at its last sample, and the direction of the motion that follows (+1 / -1)."""
    from ..behaviour import stick_phases
    dt = meas.dt
    # a count, or the sensor's noise band where that is wider (noise would fake moves and rests)
    resolution = max(resolution, 1e-15) + 4.0 * model.sensor_noise
    phases = stick_phases(meas.q, dt, resolution)
    u_at = np.concatenate([[meas.u[0]], 0.5 * (meas.u[1:] + meas.u[:-1])])
    F = model.cm * u_at + meas.force_ext() - model.offset - model.cogging_force(meas.q)
    tr, Fb, sd = [], [], []
    ahead = max(int(round(0.05 / dt)), 2)
    span = max(int(round(0.01 / dt)), 3)
    for a, b in phases:
        if a == 0 or b + ahead >= meas.n:
            continue
        q_rest = np.median(meas.q[a:b + 1])
        moved = np.flatnonzero(np.abs(meas.q[a:b + ahead] - q_rest) > 1.5 * resolution)
        moved = moved[moved > (b - a) // 2]
        if moved.size == 0 or moved[0] - span < 0:
            continue
        m = a + int(moved[0])         # the first sample two counts away: motion has begun
        tr.append((m - a) * dt)
        # a digital loop's u is noisy (the velocity estimate of a quantized position) and ramps
        # up to the break-away (an integral action at a rate set by the error at rest: faster for
        # shorter rests, so a mean would fake a dwell effect); the break-away lies within the
        # ~10 ms before the motion shows: a straight line through that span, at its end
        k = np.arange(span, dtype=float)
        slope, icpt = np.polyfit(k, F[m - span:m], 1)
        Fb.append(float(icpt + slope * (span - 1)))
        # the motion follows the force that broke the contact away (the position's first step
        # decides only when that force is small)
        Fs = min(model.curve.positive.Fs, model.curve.negative.Fs)
        sd.append(np.sign(Fb[-1]) if abs(Fb[-1]) > 0.5 * Fs else np.sign(meas.q[m] - q_rest))
    return np.array(tr), np.array(Fb), np.array(sd)


def excess(model, t, F, s) -> np.ndarray:
    """e_k [N]: s F - the model's break-away force after rest t in direction s."""
    Fs = np.where(s > 0, model.curve.positive.Fs, model.curve.negative.Fs)
    pred = model.dwell.breakaway(Fs, t) if model.dwell is not None else Fs
    return s * F - pred


def _design(t, tau):
    return np.column_stack([np.ones_like(t), 1 - np.exp(-t / tau)])


def _ls(t, e, tau) -> tuple[float, np.ndarray]:
    """(residual sum of squares, [level, gain]) at time constant tau."""
    A = _design(t, tau)
    th, *_ = np.linalg.lstsq(A, e, rcond=None)
    return float(np.sum((e - A @ th) ** 2)), th


def _fit(t, e):
    """Best (ss, [level, gain], time) over the time grid, and the constant-only ss."""
    grid = np.geomspace(0.2 * t.min(), 5 * t.max(), 41)
    ss, th, tau = min(((*_ls(t, e, x), float(x)) for x in grid), key=lambda r: r[0])
    return (ss, th, tau), float(np.sum((e - e.mean()) ** 2))


def judge(fit, validate, kf, kv, model, can_sim, resolution):
    """The verdict on dwell (module docstring): a dict with statistic, p_value, parameters,
    sigma, metric, nominal, extended, model (the extended model) or reason (why not)."""
    from ..model import Dwell
    t, F, s = rests(fit, model, resolution)
    if t.size < MIN_RESTS:
        return dict(reason=f"{_count(t.size, 'rest')} ending in motion in the fitting data (need {MIN_RESTS})", untestable=True)
    if np.ptp(t) < 0.5 * np.mean(t):
        return dict(reason=f"the rests all last about {np.mean(t):.3g} s: a dwell effect cannot be told from Fs", untestable=True)
    e = excess(model, t, F, s)
    (ss, th, tau), ss0 = _fit(t, e)
    dof = t.size - 4
    if dof < 1:
        return dict(reason="too few rests to fit the growth", untestable=True)
    if th[1] <= 0:
        return dict(statistic=None, p_value=None,
                    reason=f"the break-away force falls with the rest (gain {th[1]:.3g} N): not a dwell effect")
    tv, Fv, sv = rests(validate, model, resolution)
    if tv.size < 3:
        return dict(reason=f"{_count(tv.size, 'rest')} ending in motion in the validation data (need 3)", untestable=True)
    # out of sample: does the growth fitted on the fitting rests explain the validation rests'
    # break-away excess beyond a constant level (a wrong Fs)? One-sided t test of gamma in
    # e_v - level0 = gamma (prediction - level0) + eps over independent rests
    ev = excess(model, tv, Fv, sv)
    level0 = float(np.mean(e))
    yhat = _design(tv, tau) @ th - level0
    e0 = ev - level0
    syy = float(yhat @ yhat)
    if not syy > 0:
        return dict(reason="the validation rests do not vary the predicted growth", untestable=True)
    gamma = float(yhat @ e0) / syy
    s2 = float(np.sum((e0 - gamma * yhat) ** 2)) / (tv.size - 1)
    tstat = gamma / np.sqrt(max(s2, 1e-300) / syy)
    out = dict(statistic=float(tstat), p_value=float(stats.t.sf(tstat, tv.size - 1)))
    base = model.dwell or Dwell(0.0, 0.0, tau)
    ext = model.replace(dwell=Dwell(base.level + float(th[0]), base.gain + float(th[1]), tau))
    ev0, ev1 = ev, excess(ext, tv, Fv, sv)
    A = _design(t, tau)
    cov = np.linalg.pinv(A.T @ A) * ss / dof
    # the time's standard uncertainty from the curvature of the residual sum of squares in tau
    h = 0.05 * tau
    ssp = [_ls(t, e, x)[0] for x in (tau - h, tau + h)]
    curv = (ssp[0] - 2 * ss + ssp[1]) / h ** 2
    sig_tau = float(np.sqrt(2 * ss / dof / curv)) if curv > 0 else None
    d = ext.dwell
    return dict(out, parameters={"level": d.level, "gain": d.gain, "time": d.time},
                sigma={"level": float(np.sqrt(cov[0, 0])), "gain": float(np.sqrt(cov[1, 1])), "time": sig_tau},
                metric="break-away force RMS error [N], validation rests",
                nominal=float(np.sqrt(np.mean(ev0 ** 2))), extended=float(np.sqrt(np.mean(ev1 ** 2))), model=ext)


def sentence(p, inc, model) -> str:
    return (f"the break-away force grows with the time at rest by up to {_q(p['gain'], None, 'N')} "
            f"(time constant {_q(p['time'], None, 's')}), which the model's constant static level lacks")
