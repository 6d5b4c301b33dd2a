"""Which causes explain a model-data mismatch: forward selection on the force residual that does
not fool itself.

Criterion (stated in every report): a cause is added when (1) its extension, fitted by least
squares on the fitting data, reduces the residual sum of squares there significantly (F test,
p < alpha, with the degrees of freedom reduced to the effective number of independent samples
n (1 - rho1) / (1 + rho1), rho1 the lag-1 autocorrelation of the extended model's residual,
because smoothed residuals are far from white), and (2) it lowers the RMS residual on the validation data by at
least ``min_gain`` (relative). Hyper-parameters (a cogging pitch, a Stribeck velocity) are chosen
on the fitting data only. Causes are ranked by their score: how much the validation metric grows
when each is dropped from the final extended model (force channel), or nominal / extended - 1 of
the cause's own validation metric (other channels).

Causes with their own evidence (``CHANNEL = "own"``: dwell, saturation, quantization) bring a
statistic with its p-value and a validation metric of their own (module docstrings); the same
alpha and min_gain decide.

Stick-channel causes (``CHANNEL = "stick"``, e.g. presliding) are judged on the samples where the
(force-extended) model says the mass sticks: a chi-square test of the motion there against the
sensor's quantization and noise (p < alpha), then a validation gain of at least ``min_gain`` in
the re-simulated position error (controller known) or in the stick-segment displacement.

The behaviour view (when the model has a controller and the data a reference): the validation run
re-simulated with the nominal and the extended model, compared with the measurement
(:mod:`hunting.diagnose.behaviour`)."""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy import stats

from ..errors import SystemDefinitionError
from .causes import CAUSES
from .data import Measurement
from .kinematics import Kinematics, kinematics, residual
from .model import NominalModel

CRITERION = ("F test on the fitting data (p < {alpha:g}, effective sample size from the residual's lag-1 "
             "autocorrelation) and a validation RMS reduction of at least {min_gain:.0%}")


@dataclass(frozen=True)
class Cause:
    """One reported cause: name; score (relative growth of the validation RMS when it is dropped
    from the extended model); statistic (F) and p_value on the fitting data when it was added;
    parameters and their standard uncertainties; gain: validation force-residual RMS [N] of the
    model before and after adding it."""

    name: str
    score: float
    statistic: float
    p_value: float
    parameters: dict
    sigma: dict
    gain: dict
    hyper: dict = field(default_factory=dict)
    theta: np.ndarray | None = None

    def as_dict(self) -> dict:
        return dict(name=self.name, score=self.score, statistic=self.statistic, p_value=self.p_value,
                    parameters=self.parameters, sigma=self.sigma, gain=self.gain, role="selected")


@dataclass
class Diagnosis:
    """causes : list of Cause ranked by score over all channels; nominal /
    extended : validation force-residual RMS [N] (None when the force channel was skipped);
    criterion : the selection rule; kin_fit, kin_val : kinematics; r_* : residuals (n,) of the
    nominal and extended model on both sets (NaN where not used: |v| small or filter edges);
    rejected : candidates that failed the criterion at the step where selection stopped;
    alternatives : causes that pass the criterion on their own but add nothing once the selected
    ones are in (their stand-alone parameters and gain: e.g. a constant offset that a
    direction-dependent viscous term explains as well); extended_model : the nominal model with
    every selected extension; behaviour : the behaviour view on the validation data (None without
    a controller or a reference); notes : what was skipped and why; validation : the validation
    Measurement used; simulations : the behaviour view's re-simulations {"nominal", "extended"}."""

    causes: list
    nominal: float | None
    extended: float | None
    criterion: str
    model: NominalModel
    kin_fit: Kinematics
    kin_val: Kinematics
    r_fit_nominal: np.ndarray
    r_val_nominal: np.ndarray
    r_val_extended: np.ndarray
    rejected: list = field(default_factory=list)
    alternatives: list = field(default_factory=list)
    extended_model: NominalModel | None = None
    behaviour: dict | None = None
    notes: list = field(default_factory=list)
    validation: Measurement | None = None
    simulations: dict | None = None

    def gains(self) -> list:
        """Validation metrics of the nominal against the extended model: force residual RMS [N],
        and from the behaviour view position and drive-force RMS errors of the re-simulation,
        stick-error, cycle-amplitude, cycle-period and event-map-contraction errors against the
        measurement."""
        out = []
        if self.nominal is not None:
            out.append(dict(metric="force residual RMS [N]", nominal=self.nominal, extended=self.extended))
        b = self.behaviour
        if b:
            for key, label in (("position_rms", "re-simulated position RMS error [m]"),
                               ("force_rms", "re-simulated drive force RMS error [N]")):
                out.append(dict(metric=label, nominal=b["nominal"][key], extended=b["extended"][key]))
            for key, label in (("stick_error", "stick error RMS [m]"), ("cycle_amplitude", "cycle amplitude [m]"),
                               ("cycle_period", "cycle period [s]"), ("final_error", "final error [m]"),
                               ("map_contraction", "event map contraction |d_n+1| / |d_n|")):
                m = b["measured"][key]
                if m is None:
                    continue
                err = [None if b[k][key] is None else abs(b[k][key] - m) for k in ("nominal", "extended")]
                out.append(dict(metric=f"|{label} - measured {m:.4g}|", nominal=err[0], extended=err[1]))
            out.append(dict(metric="ends at rest (measured: {})".format(b["measured"]["at_rest"]),
                            nominal=b["nominal"]["at_rest"], extended=b["extended"]["at_rest"]))
        return out

    def as_dict(self) -> dict:
        alts = [dict(name=a["name"], score=0.0, parameters=a["parameters"], gain=a["gain"], role="alternative",
                     absorbed_by=a["absorbed_by"]) for a in self.alternatives]
        return dict(causes=[c.as_dict() for c in self.causes] + alts,
                    gain=dict(metric="force residual RMS [N] on the validation data", nominal=self.nominal,
                              extended=self.extended),
                    gains=self.gains(), behaviour=self.behaviour, notes=self.notes,
                    criterion=self.criterion, rejected=self.rejected, alternatives=self.alternatives,
                    nominal_model=self.model.to_dict(),
                    extended_model=None if self.extended_model is None else self.extended_model.to_dict())


def _rms(r) -> float:
    return float(np.sqrt(np.mean(r ** 2)))


def _n_eff(r: np.ndarray) -> float:
    r = r - r.mean()
    rho = float(np.dot(r[1:], r[:-1]) / max(np.dot(r, r), 1e-300))
    rho = min(max(rho, 0.0), 0.999)
    return r.size * (1 - rho) / (1 + rho)


def _designs(name, kin_f, kin_v, model, mf, mv):
    """(Phi_fit, Phi_val, hyper, shift_fit, shift_val) per hyper-parameter variant of a cause, on
    the used samples; shift is the known, unfitted part of the extension's force change (the
    cause's optional ``shift``; zeros without one)."""
    mod = CAUSES[name]
    shift = getattr(mod, "shift", None)
    for hyper in mod.hypers(kin_f, model):
        sf = shift(kin_f, model, hyper)[mf] if shift else np.zeros(int(mf.sum()))
        sv = shift(kin_v, model, hyper)[mv] if shift else np.zeros(int(mv.sum()))
        yield mod.design(kin_f, model, hyper)[mf], mod.design(kin_v, model, hyper)[mv], hyper, sf, sv


def diagnose(fit: Measurement, model: NominalModel, validate: Measurement | None = None, *, causes=None,
             max_causes: int = 4, min_gain: float = 0.02, alpha: float = 1e-3, window: float | None = None,
             behaviour: bool = True) -> Diagnosis:
    """Rank the causes of the mismatch between the model and the measured data.

    fit : data to fit extensions on; validate : data to judge them on (default: the last 40 % of
    ``fit``, the first 60 % being used for fitting); causes : names to consider (default all);
    max_causes : bound on the force-channel selection; min_gain, alpha : the criterion (module
    docstring); behaviour : re-simulate the validation run (needs a controller and q_ref)."""
    names = list(CAUSES) if causes is None else list(causes)
    bad = [c for c in names if c not in CAUSES]
    if bad:
        raise SystemDefinitionError(f"causes {bad} are not known: use {sorted(CAUSES)}")
    if validate is None:
        t_split = fit.t[0] + 0.6 * (fit.t[-1] - fit.t[0])
        fit, validate = fit.part(fit.t[0], t_split), fit.part(t_split, fit.t[-1] + fit.dt)
    kf = kinematics(fit, model.cm, window=window)
    kv = kinematics(validate, model.cm, window=window)
    crit = CRITERION.format(alpha=alpha, min_gain=min_gain)
    force_names = [n for n in names if getattr(CAUSES[n], "CHANNEL", "force") == "force"]
    stick_names = [n for n in names if getattr(CAUSES[n], "CHANNEL", "force") == "stick"]
    own_names = [n for n in names if getattr(CAUSES[n], "CHANNEL", "force") == "own"]
    notes: list = []
    nan_f, nan_v = np.full(kf.t.size, np.nan), np.full(kv.t.size, np.nan)
    # sliding samples: |v| above 2 % of the maximum and above the model's stick speed (creep in
    # presliding is not sliding)
    kf = replace(kf, moving=kf.moving & (np.abs(kf.v) > model.v_stick()))
    kv = replace(kv, moving=kv.moving & (np.abs(kv.v) > model.v_stick()))
    if kf.moving.sum() >= 50 and kv.moving.sum() >= 50:
        fc = _force_channel(force_names, kf, kv, model, max_causes, min_gain, alpha)
    else:
        notes.append("force channel skipped: fewer than 50 sliding samples (|v| > 2 % of the maximum and > the "
                     f"model's stick speed {model.v_stick():.3g} m/s) in the fitting or validation data")
        fc = dict(causes=[], nominal=None, extended=None, rejected=[], alternatives=[], model=model,
                  r_fit=nan_f, r_val_nom=nan_v, r_val_ext=nan_v)
    ext = fc["model"]
    result, rejected = list(fc["causes"]), list(fc["rejected"])
    can_sim = model.controller is not None and validate.q_ref is not None and fit.q_ref is not None
    for name in stick_names:
        if ext.law == "lugre" and model.law != "lugre":
            rejected.append(dict(name=name, step="stick", statistic=None, p_value=None, validation_gain=None,
                                 reason="the force channel's extension already has LuGre presliding (reversal)"))
            continue
        cause, row, ext = _stick_channel(CAUSES[name], fit, validate, kf, kv, ext, alpha, min_gain, can_sim)
        if cause is not None:
            result.append(cause)
        elif row is not None:
            rejected.append(row)
    if own_names:
        from .resimulate import resolution_of
        res = model.resolution if model.resolution is not None else resolution_of(fit.q)
        for name in own_names:
            cause, row, ext = _own_channel(CAUSES[name], fit, validate, kf, kv, ext, alpha, min_gain, can_sim, res)
            if cause is not None:
                result.append(cause)
            else:
                rejected.append(row)
    # one ranking over the channels: the relative worsening of each cause's own validation metric
    # without it
    result.sort(key=lambda c: -c.score)
    view, sims = None, None
    if behaviour and model.controller is not None and validate.q_ref is not None:
        from .behaviour import compare
        from .resimulate import resimulate, resolution_of
        res = model.resolution if model.resolution is not None else resolution_of(validate.q)
        sims = {"nominal": resimulate(validate, model), "extended": resimulate(validate, ext)}
        view = compare(validate, sims, model.cm, res)
    elif behaviour:
        notes.append("behaviour view skipped: it needs the model's 'controller' and the reference q_ref in the data")
    return Diagnosis(result, fc["nominal"], fc["extended"], crit, model, kf, kv, fc["r_fit"], fc["r_val_nom"],
                     fc["r_val_ext"], rejected, fc["alternatives"], ext, view, notes, validate, sims)


def _force_channel(names, kf, kv, model, max_causes, min_gain, alpha) -> dict:
    """Forward selection on the force residual (module docstring); returns the selected causes,
    the extended model and the residuals."""
    mf, mv = kf.moving, kv.moving
    rf0 = residual(kf, model)[mf]
    rv0 = residual(kv, model)[mv]
    # chosen: (name, Phi_f, Phi_v, hyper, F, p, rms_before, rms_after, gain, shift_f, shift_v);
    # the extended model's force change is Pf theta + Sf (Sf: the chosen causes' known shifts)
    chosen: list = []
    Pf = np.zeros((rf0.size, 0))
    Pv = np.zeros((rv0.size, 0))
    Sf, Sv = np.zeros(rf0.size), np.zeros(rv0.size)
    rejected = []
    alone: dict = {}                       # step-1 fits that pass the criterion on their own
    for _ in range(max_causes):
        th, *_ = np.linalg.lstsq(Pf, rf0 - Sf, rcond=None) if Pf.shape[1] else (np.zeros(0),)
        rf_cur = rf0 - Sf - Pf @ th
        rv_cur = rv0 - Sv - Pv @ th
        ss0 = float(rf_cur @ rf_cur)
        best = None
        for name in names:
            if any(c[0] == name for c in chosen):
                continue
            fits = []
            for df, dv, hyper, sf, sv in _designs(name, kf, kv, model, mf, mv):
                A = np.column_stack([Pf, df])
                t2, *_ = np.linalg.lstsq(A, rf0 - Sf - sf, rcond=None)
                fits.append((float(np.sum((rf0 - Sf - sf - A @ t2) ** 2)), df, dv, hyper, t2, sf, sv))
            if not fits:
                continue
            # the simplest variant (first in the cause's list: e.g. the shortest cogging pitch, not
            # a multiple of it) among those within 0.1 % of the best fit
            ss_min = min(f[0] for f in fits)
            ss1, df, dv, hyper, t2, sf, sv = next(f for f in fits if f[0] <= ss_min * (1 + 1e-3))
            k = df.shape[1]
            # effective sample size from the residual of the extended fit (the residual before it
            # is dominated by the very effect being tested, e.g. a smooth cogging force)
            r1 = rf0 - Sf - sf - np.column_stack([Pf, df]) @ t2
            dof = max(_n_eff(r1) - Pf.shape[1] - k, 1.0)
            F = ((ss0 - ss1) / k) / max(ss1 / dof, 1e-300)
            p = float(stats.f.sf(F, k, dof))
            rms_v = _rms(rv0 - Sv - sv - np.column_stack([Pv, dv]) @ t2)
            gain = 1 - rms_v / _rms(rv_cur)
            row = (name, df, dv, hyper, float(F), p, _rms(rv_cur), rms_v, gain, sf, sv)
            why = getattr(CAUSES[name], "unphysical", lambda *a: None)(t2[Pf.shape[1]:], hyper, model)
            if p < alpha and gain >= min_gain and why:
                rejected.append(dict(name=name, step=len(chosen) + 1, F=float(F), p_value=p, validation_gain=gain,
                                     reason=f"the fitted extension is not physical: {why}"))
            elif p < alpha and gain >= min_gain:
                if not chosen:
                    alone[name] = (CAUSES[name].parameters(t2, hyper, model),
                                   dict(metric="force residual RMS [N], validation, alone", nominal=_rms(rv_cur),
                                        extended=rms_v))
                if best is None or gain > best[8]:
                    best = row
            else:
                rejected.append(dict(name=name, step=len(chosen) + 1, F=float(F), p_value=p, validation_gain=gain))
        if best is None:
            break
        chosen.append(best)
        Pf = np.column_stack([Pf, best[1]])
        Pv = np.column_stack([Pv, best[2]])
        Sf, Sv = Sf + best[9], Sv + best[10]
        rejected = [r for r in rejected if r["step"] != len(chosen)]
    # final joint fit: parameters, uncertainties, drop-one scores
    result = []
    rv_ext = rv0.copy()
    if chosen:
        th, *_ = np.linalg.lstsq(Pf, rf0 - Sf, rcond=None)
        r = rf0 - Sf - Pf @ th
        # residual variance inflated by n / n_eff for the correlation of smoothed residuals
        s2 = float(r @ r) / max(r.size - Pf.shape[1], 1.0) * (r.size / max(_n_eff(r), 1.0))
        cov = np.linalg.pinv(Pf.T @ Pf) * s2
        rv_ext = rv0 - Sv - Pv @ th
        full = _rms(rv_ext)
        col = 0
        for (name, df, dv, hyper, F, p, before, after, gain, sf, sv) in chosen:
            k = df.shape[1]
            sl = slice(col, col + k)
            col += k
            keep = np.ones(Pf.shape[1], bool)
            keep[sl] = False
            if keep.any():
                t_d, *_ = np.linalg.lstsq(Pf[:, keep], rf0 - Sf + sf, rcond=None)
                dropped = _rms(rv0 - Sv + sv - Pv[:, keep] @ t_d)
            else:
                dropped = _rms(rv0)
            mod = CAUSES[name]
            pars = mod.parameters(th[sl], hyper, model)
            # uncertainties: propagate by finite differences through the parameter map
            sig = {}
            for key in pars:
                grad = np.zeros(k)
                for j in range(k):
                    h = 1e-6 * max(1.0, abs(th[sl][j]))
                    tp = th[sl].copy()
                    tp[j] += h
                    grad[j] = (mod.parameters(tp, hyper, model)[key] - pars[key]) / h
                sig[key] = float(np.sqrt(max(grad @ cov[sl, sl] @ grad, 0.0)))
            result.append(Cause(name, dropped / full - 1, F, p, pars, sig,
                                dict(metric="force residual RMS [N], validation", nominal=before, extended=after), hyper,
                                th[sl].copy()))
        result.sort(key=lambda c: -c.score)
    ext = model
    for c in result:
        ext = CAUSES[c.name].extend(ext, c.theta, c.hyper)
    rf_full = np.full(kf.t.size, np.nan)
    rf_full[mf] = rf0
    rvn = np.full(kv.t.size, np.nan)
    rvn[mv] = rv0
    rve = np.full(kv.t.size, np.nan)
    rve[mv] = rv_ext
    picked = {c.name for c in result}
    alternatives = [dict(name=k, parameters=v[0], gain=v[1], absorbed_by=sorted(picked))
                    for k, v in alone.items() if k not in picked]
    return dict(causes=result, nominal=_rms(rv0), extended=_rms(rv_ext), rejected=rejected, alternatives=alternatives,
                model=ext, r_fit=rf_full, r_val_nom=rvn, r_val_ext=rve)


def _own_channel(mod, fit, val, kf, kv, model, alpha, min_gain, can_sim, resolution):
    """Judge a cause with its own evidence and gain (``CHANNEL = "own"``: dwell, saturation,
    quantization): its ``judge`` returns the statistic, p-value, fitted parameters and the
    validation metric nominal / extended, or a reason; accepted when p < alpha and the metric
    falls by at least min_gain. Returns (Cause or None, rejected row or None, model)."""
    v = mod.judge(fit, val, kf, kv, model, can_sim, resolution)
    row = dict(name=mod.NAME, step="own", statistic=v.get("statistic"), p_value=v.get("p_value"))
    if "reason" in v:
        return None, dict(row, validation_gain=None, reason=v["reason"]), model
    gain = 1 - v["extended"] / max(v["nominal"], 1e-300)
    if v["p_value"] >= alpha or gain < min_gain:
        return None, dict(row, validation_gain=gain), model
    return (Cause(mod.NAME, v["nominal"] / max(v["extended"], 1e-300) - 1, v["statistic"], v["p_value"],
                  v["parameters"], v["sigma"], dict(metric=v["metric"], nominal=v["nominal"], extended=v["extended"])),
            None, v["model"])


def _stick_channel(mod, fit, val, kf, kv, model, alpha, min_gain, can_sim):
    """Judge one stick-channel cause (module docstring). Returns (Cause or None, rejected row or
    None, the model extended by it when accepted)."""
    from .resimulate import position_rms_error, resolution_of
    segs = mod.segments(kf, model)
    if sum(b - a + 1 for a, b in segs) < 200:
        return None, None, model
    res = model.resolution if model.resolution is not None else resolution_of(fit.q)
    chi2, p = mod.evidence(kf, model, segs, res)

    def reject(gain=None, reason=None):
        row = dict(name=mod.NAME, step="stick", statistic=chi2, p_value=p, validation_gain=gain)
        return None, (row if reason is None else dict(row, reason=reason)), model
    if p >= alpha:
        return reject(reason="no motion beyond quantization and sensor noise where the model sticks")
    theta = mod.fit_behaviour(fit, model)[0] if can_sim else mod.fit_quasistatic(kf, model, segs)
    try:
        ext = mod.extend(model, theta, {})
    except SystemDefinitionError as exc:           # e.g. a negative fitted compliance
        return reject(reason=f"the fitted extension is not physical: {exc}")
    if can_sim:
        before, after = position_rms_error(val, model), position_rms_error(val, ext)
        metric = "re-simulated position RMS error [m], validation"
    else:
        sv = mod.segments(kv, model)
        if sum(b - a + 1 for a, b in sv) < 50:
            return reject(reason="no stick segments in the validation data")
        before, after = mod.displacement_rms(kv, model, sv, theta)
        metric = "stick-segment displacement RMS [m], validation"
    gain = 1 - after / max(before, 1e-300)
    if gain < min_gain:
        return reject(gain)
    pars = mod.parameters(theta, {}, model)
    return (Cause(mod.NAME, before / max(after, 1e-300) - 1, chi2, p, pars, {k: None for k in pars},
                  dict(metric=metric, nominal=before, extended=after), {}, np.asarray(theta)), None, ext)
