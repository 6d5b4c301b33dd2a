"""The force channel run on two records: its library (with the saturation the records show, the
instrument trajectories and the estimation's error), the selection's causes refined and
identified, their alternatives and the runner-up explanations (:mod:`hunting.diagnose.force`
searches and tests; this module turns its result into reported causes)."""
from __future__ import annotations

import numpy as np

from .causes import CAUSES
from .data import Measurement
from .kinematics import Kinematics, reference_kinematics
from .model import NominalModel
from .result import Cause


METHOD_NOTE = ("force residuals are the data's less the nominal model's own on its noise-free closed loop (the "
               "estimation's error, where that loop tracks the measured motion: {} on the fitting data, {} on the "
               "validation data)")


def library_builder(fit: Measurement, validate: Measurement, kf: Kinematics, kv: Kinematics, model: NominalModel,
                     window: float, alpha: float, notes: list | None, known: dict | None = None):
    """names -> Library: the force channel's library on two records with their kinematics (used
    samples marked), the saturation the records show, the instrument trajectories and the
    estimation's error (said in ``notes`` unless None); known : {cause: [hyper-parameters]} found
    on another record, variants beside the record's own candidates (:class:`~hunting.diagnose.force.Library`)."""
    from .force import Library
    from .method_error import method_error
    from .resimulate import side_by_side
    step = max(1, int(round(kf.window / fit.dt)) // 3)
    sat = measured_saturation(fit, validate, model, alpha)
    # four independent re-simulations of the nominal loop, side by side: the instrument
    # trajectories of both records and the estimation's error on each
    kr, kfr, *errors = side_by_side(lambda job: job(), [
        lambda: reference_kinematics(validate, sat(model), window=window),
        lambda: reference_kinematics(fit, sat(model), window=window),
        lambda: method_error(fit, kf, model), lambda: method_error(validate, kv, model)])
    kfr, errors = (kfr if kr is not None else None), tuple(errors)
    inst = ((lambda m: reference_kinematics(validate, sat(m), window=window)) if kr is not None and model.controller is not None
            else None)
    if notes is not None and any(e is not None for e in errors):
        notes.append(METHOD_NOTE.format(*(("not formed" if e is None else f"{e.rms:.3g} N RMS") for e in errors)))
    return lambda names: Library(names, kf, kv, model, kf.moving, kv.moving, step, kr, inst, errors, kfr, known)


def measured_saturation(fit: Measurement, validate: Measurement, model: NominalModel, alpha: float):
    """model -> model: the controller with the saturation the measured output piles up at (the
    saturation cause's evidence, p < alpha), where the model's controller has none at that level;
    the identity otherwise. The instrument trajectories re-simulate the loop from the reference:
    a loop that saturates follows it otherwise only where it does not, and a force-channel cause
    beside the saturation failed its instrument check (reporting9 d0554 mass and d0568 lag, found
    since; reporting8 d0560's viscous still fails it), beside a saturation the own channel found."""
    from .causes import saturation as sat
    if model.controller is None:
        return lambda m: m
    U, top, _, p = sat.evidence(sat.records_output(fit, validate))
    if not (p < alpha and top >= sat.MIN_AT_BOUND and U > 0 and sat.model_level(model) > 1.01 * U):
        return lambda m: m
    return lambda m: m.replace(controller=dict(m.controller, saturation=U)) if m.controller is not None else m


def force_change(causes: list, kin: Kinematics, model: NominalModel) -> np.ndarray:
    """The force-channel causes' summed force change (n,) [N] on a record, each at its fitted
    coefficients and hyper-parameters on top of ``model`` (0 without causes)."""
    from .force import member_force
    out = np.zeros(kin.t.size)
    for c in causes:
        out += member_force(c.name, c.hyper, c.theta, kin, model)
    return out


def _rms(r) -> float:
    return float(np.sqrt(np.mean(r ** 2)))


def identified_force_channel(library, names, model, max_causes, alpha, min_gain, alpha_reference, untested) -> dict:
    """The force channel's result (:func:`force_channel_result`) with every selected cause identified:
    a cause whose ``unidentified(parameters, sigma, model=, theta=)`` hook gives a reason (its fitted
    parameters do not single it out, e.g. a reversal scale within two standard uncertainties of
    zero, or a new cogging ripple below the friction force's relevance floor) is taken
    out of the library and the channel judged again without it; each such cause gets a rejected
    row (step "identification") ahead of the others. library(names) builds the Library; the
    untested causes of the first one are appended to ``untested``. At most len(names) + 1 passes:
    each pass but the last removes at least one cause."""
    from .force import select
    excluded: list = []
    identification: list = []
    for _ in range(len(names) + 1):
        lib = library([n for n in names if n not in excluded])
        if not excluded:
            untested += [dict(name=k, reason=v) for k, v in lib.untested.items()]
        fc = force_channel_result(lib, model, select(lib, max_causes, alpha, min_gain, alpha_reference), min_gain)
        fails = [(c, getattr(CAUSES[c.name], "unidentified", lambda *a, **k: None)(c.parameters, c.sigma, model=lib.model,
                                                                                    theta=c.theta))
                 for c in fc["causes"]]
        fails = [(c, why) for c, why in fails if why]
        if not fails:
            break
        excluded += [c.name for c, _ in fails]
        identification += [dict(name=c.name, step="identification", statistic=c.statistic, p_value=c.p_value,
                                validation_gain=c.gain["nominal"] / max(c.gain["extended"], 1e-300) - 1, reason=why)
                           for c, why in fails]
    if identification:
        fc["rejected"] = identification + [r for r in fc["rejected"] if r["name"] not in excluded]
    return fc


def force_channel_result(lib, model, sel, min_gain: float) -> dict:
    """Causes, extended model, residuals and alternatives from the force channel's selection."""
    from .force import compatible
    from .refine import member_sigma, members_parameters, refine
    ex = sel["explanation"]
    mf, mv = lib.used_f, lib.used_v
    cov, hyper_sigma, idle = None, {}, []
    if ex.cols:
        ex, _, cov, hyper_sigma = refine(lib, ex)
        ex, cov, hyper_sigma, idle = _idle_after_refinement(lib, ex, cov, hyper_sigma, min_gain)
    rows = members_parameters(lib, ex, cov)
    pred_v = lib.prediction(ex, "v")
    rv_ext = np.where(mv, lib.rv - pred_v, np.nan)
    causes = []
    for name, hyper, th, pars, sig, inc, _ in rows:
        sig = member_sigma(name, pars, sig, hyper_sigma)
        t = sel["tests"][name]
        causes.append(Cause(name, t["gain"], t["t"], t["p_value"], pars, sig,
                            dict(metric="force residual RMS [N], validation", nominal=t["rms_without"],
                                 extended=t["rms"]), hyper, th, inc, CAUSES[name].FAMILY))
    causes.sort(key=lambda c: -c.score)
    ext = rows[-1][6] if rows else model
    nominal_rms = _rms(lib.rv[mv])
    # alternatives: (1) a cause of a selected one's family in its place; (2) a cause that explains
    # the data alone (better BIC than the nominal model, validation gain >= min_gain) but not once the
    # selected ones are in
    alternatives, seen = [], {c.name for c in causes}
    fits = sel["fits"]
    chosen = set(ex.names)
    for c in causes:
        for mate in lib.variants:
            if mate in seen or CAUSES[mate].FAMILY != c.family:
                continue
            alt_set = tuple(sorted((chosen - {c.name}) | {mate}, key=list(lib.variants).index))
            if not compatible(alt_set):
                continue
            alt = fits.get(alt_set) or lib.best_variants(alt_set)
            if not alt.physical:
                continue
            row = [r for r in members_parameters(lib, alt) if r[0] == mate][0]
            alternatives.append(dict(name=mate, kind="same family", replaces=c.name, parameters=row[3],
                                     bic_difference=float(alt.bic - ex.bic),
                                     gain=dict(metric="force residual RMS [N], validation, in place of " + c.name,
                                               nominal=nominal_rms, extended=lib.validation_rms(alt))))
            seen.add(mate)
    empty = fits[()]
    for name in lib.variants:
        if name in seen:
            continue
        alone = fits[(name,)]
        if not alone.physical:
            continue
        rms1 = lib.validation_rms(alone)
        if alone.bic < empty.bic and rms1 < (1 - min_gain) * nominal_rms:
            row = members_parameters(lib, alone)[0]
            alternatives.append(dict(name=name, kind="alone", absorbed_by=sorted(chosen), parameters=row[3],
                                     bic_difference=float(alone.bic - ex.bic),
                                     gain=dict(metric="force residual RMS [N], validation, alone", nominal=nominal_rms,
                                               extended=rms1)))
            seen.add(name)
    # the search's best sets: BIC on the fitting data relative to the selected explanation
    # (negative: a set that fits the fitting data better but whose extra causes did not hold on
    # the validation data)
    explanations = []
    for alt in sel["ranking"][:6]:
        if alt.names == ex.names:
            continue
        explanations.append(dict(causes=list(alt.names), bic_difference=float(alt.bic - ex.bic),
                                 validation_rms=lib.validation_rms(alt),
                                 pruned=sorted(set(alt.names) - set(ex.names))))
        if len(explanations) == 4:
            break
    return dict(causes=causes, nominal=nominal_rms, extended=_rms(rv_ext[mv]), rejected=sel["rejected"] + idle,
                alternatives=alternatives, explanations=explanations, model=ext,
                r_fit=np.where(mf, lib.rf, np.nan), r_val_nom=np.where(mv, lib.rv, np.nan), r_val_ext=rv_ext)


def _idle_after_refinement(lib, ex, cov, hyper_sigma, min_gain: float):
    """(explanation, cov, hyper sigmas, rejected rows): the refined explanation without the
    members its refinement left idle. The selection judged each member with the others at their
    grid values; refined (a Stribeck velocity per direction moved between grid points), the
    others can explain what a member took up there: reporting8 d0401's refined Stribeck dip left
    the offset selected beside it at -7e-5 N. A member whose refined part, the others held, grows
    the validation RMS by less than min_gain when dropped is removed and the rest refitted and
    refined (one at a time, the smallest first; a single member stays: its tests judged it
    against nothing). A member stays too where the others without it fit only unphysically:
    reporting57 d0586's viscous change, idle beside a refined Stribeck dip, left the dip alone at
    Fs - Fc = -0.35 N on a curve without one, and the report failed on that curve."""
    from .refine import refine
    idle = []
    for _ in range(len(ex.members)):
        if len(ex.members) < 2:
            break
        mv = lib.used_v
        pred = lib.prediction(ex, "v")
        rms = _rms((lib.rv - pred)[mv])
        gains = {name: _rms((lib.rv - pred + lib.part(ex, name, "v"))[mv]) / max(rms, 1e-300) - 1.0 for name in ex.names}
        name = min(gains, key=gains.get)
        if gains[name] >= min_gain:
            break
        rest = lib.best_variants(tuple(n for n in ex.names if n != name))
        if not rest.physical:
            break
        idle.append(dict(name=name, step="validation", statistic=None, p_value=None, validation_gain=gains[name],
                         reason=f"once the hyper-parameters of the others are refined it explains less than {min_gain:.0%} "
                                f"of the validation residual (validation gain {gains[name]:.1%})"))
        ex, _, cov, hyper_sigma = refine(lib, rest)
    return ex, cov, hyper_sigma, idle
