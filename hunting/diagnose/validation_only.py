"""The search of causes only the validation record can show: those the fitting record cannot test
(it moves one way only, it has no band to see a resonance in) or whose part it cannot show (a
resonance above its band, a pitch longer than its stroke), searched on alternate blocks of the
validation record and judged on the others, on top of the model the fitting record extended."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .causes import CAUSES, seen, unresolved, unseen, untestable
from .data import Measurement
from .force_channel import force_change, identified_force_channel, library_builder
from .kinematics import Kinematics
from .model import NominalModel
from .parts import INTERLEAVE_WINDOWS, interleaved
from .result import Cause


VALIDATION_ONLY_NOTE = ("the fitting data cannot show {names} ({reasons}): searched on alternate blocks of "
                        + str(INTERLEAVE_WINDOWS) + " filter windows of the validation data ({val}), on top of the "
                        "causes found, and judged on the others")
SHADOW_REASON = ("found on the fitting data, which cannot show {cross}; searched with it on alternate blocks of the "
                 "validation data ({val}), which show both, it does not hold beside it: the fitting data saw {cross}'s "
                 "effect as this cause")


def search(fc: dict, names, model: NominalModel, validate: Measurement, kf: Kinematics, kv: Kinematics,
           sensor: dict, window: float | None, rule: tuple, untested: list, notes: list,
           unresolved_here: frozenset = frozenset()) -> dict:
    """The force channel's result with the causes only the validation record can show: those
    ``untestable`` on the fitting record (it moves one way only, it has no band to see a
    resonance in) or partly ``unseen`` there (a resonance above its band, a cogging pitch longer
    than its stroke: then one found where the fitting record could show it is rejected, ``seen``)
    and testable on the validation record are searched on alternate blocks of the validation
    record (:func:`~hunting.diagnose.parts.interleaved`) and judged on the others, on top of the
    model the channel extended (reporting10 d0313 and d0327: a Coulomb level 8 % and 2 % low, the
    fitting record sliding one way, where a level is an offset, left untested), and so is a cause
    of their family that ``NESTS`` one of them when the blocks choose it. Their rows in
    ``untested`` are replaced by what that search says. fc is returned unchanged when there are
    none or the parts are not :func:`~hunting.diagnose.parts.informative`. A cross cause whose
    value the blocks do not resolve (its ``unresolved`` hook) is searched no more: the search runs
    again with it in ``unresolved_here``, where it is no cross cause but stays a candidate of its
    family (a mate), as it is without its ``unseen`` hook."""
    ext = fc["model"]
    found = [c.name for c in fc["causes"]]
    blind = {n: untestable(n, kf, ext) for n in names}
    # a cause the fitting record can test in part: only a value beyond that part is the
    # validation record's to show (``seen``)
    partly = {n: why for n in names if not blind[n] and n not in found and n not in unresolved_here
              and (why := unseen(n, kf, kv, ext))}
    reasons = {n: blind[n] or partly.get(n) for n in names}
    cross = {n: r for n, r in reasons.items() if r and n not in unresolved_here and not untestable(n, kv, ext)}
    parts = interleaved(validate, ext, sensor, window) if cross else None
    if parts is None:
        return fc
    fit2, val2, w2, kf2, kv2 = parts
    cross = {n: r for n, r in cross.items()
             if not (untestable(n, kf2, ext) or untestable(n, kv2, ext, validation=True))}
    if not cross:
        return fc
    max_causes, alpha, min_gain, alpha_reference = rule
    # judged from the nominal model among the causes found on the fitting data (refitted: fitted
    # on that record alone they carry its errors; reporting10 d0370, an offset 7 % high on a
    # one-way record, which an asymmetry took up) and the cross causes' family (reporting9
    # d0348: an "asymmetry" of 54.2 and 54.6 N s/m, a viscous change, beside a delay): only a
    # cross cause this search keeps is reported
    mates = [n for n in names if n not in cross and n not in found
             and any(CAUSES[n].FAMILY == CAUSES[c].FAMILY for c in cross)]
    # the blocks choose among the causes only the validation record can show: one they choose
    # that the fitting record could show after all (``seen``) leaves the choice, which is made
    # again without it (reporting64 d0495, a level 28 % low on a one-way fitting record: the
    # blocks chose a Stribeck dip whose velocity lies in the fitting record's speeds, and the
    # level, which alone cut the blocks' residual by 94 %, was never judged on its own)
    def seen_in(result: dict) -> dict:
        """{cause: why} of the result's causes the fitting record could show after all (``seen``)."""
        return {c.name: why for c in result["causes"]
                if c.name in partly and (why := seen(c.name, c.hyper, kf, ext, c.parameters))}

    inside: dict = {}
    candidates = list(cross) + found + mates
    # its nominal runs once; the found causes keep the hyper-parameters they were found at as variants
    blocks_library = library_builder(fit2, val2, kf2, kv2, model, w2, alpha, None,
                                     known={c.name: [c.hyper] for c in fc["causes"]})
    for _ in range(len(cross) + 1):          # each pass removes at least one candidate or ends the loop
        inner: list = []
        judged = identified_force_channel(blocks_library, candidates, model, max_causes, alpha, min_gain,
                                           alpha_reference, inner)
        seen_here = seen_in(judged)
        if not seen_here:
            break
        inside.update(seen_here)
        candidates = [n for n in candidates if n not in seen_here]
    from .force import compatible
    chosen = {c.name: c for c in judged["causes"]}
    # a mate that generalises a cross cause (its NESTS) contains the part the fitting record cannot
    # show, so that record's own test of it judged an extrapolation: the blocks, which show all of
    # it, decide it like a cross cause (reporting51 d0331: a Stribeck dip on a one-way fitting
    # record, fitted there at 1.88 N RMS on the validation data against the nominal 0.95, chosen on
    # the blocks in place of the level it nests)
    nesting = [n for n in mates if n in chosen and set(getattr(CAUSES[n], "NESTS", ())) & set(cross)]
    held = [n for n in cross if n in chosen] + nesting
    searched = list(cross) + nesting         # the causes this search may report
    # a cross cause kept in place of a found one it excludes would be refitted on top of it
    # (level_asymmetry, untestable on a one-way fitting record, over an offset found there); one
    # that generalises it (its NESTS) and that the blocks chose in its place replaces it, judged
    # with the found causes from the nominal model (:func:`_joint_values`): the one-way record
    # saw that much of it (reporting41 d0371: b+ 371 and b- 176 N s/m for a nominal 274, the
    # fitting record 91 % one way, read there as an offset, a level and a viscous change)
    nested = {n: [c for c in found if c in getattr(CAUSES[n], "NESTS", ()) and c not in chosen] for n in held}
    clash = {n: [c for c in found if not compatible([n, c]) and c not in nested[n]] for n in held}
    inside.update({n: why for n in held if nested[n] and n in partly
                   and (why := seen(n, chosen[n].hyper, kf, ext, chosen[n].parameters))})
    replacing = [n for n in held if nested[n] and not clash[n] and n not in inside]
    held = [n for n in held if not clash[n] and not nested[n]]
    fc2 = dict(causes=[], model=ext, alternatives=[], explanations=[], rejected=[])
    for _ in range(len(held)):        # each pass drops at least one held cause or ends the loop
        # judged on top of the model the fitting data extended
        fc2 = identified_force_channel(library_builder(fit2, val2, kf2, kv2, ext, w2, alpha, None), held, ext,
                                        max_causes, alpha, min_gain, alpha_reference, [])
        # a cross cause found where the fitting record can show it after all (a resonance inside
        # its band) is what that record did not show
        bad = seen_in(fc2)
        if not bad:
            break
        inside.update(bad)
        held = [n for n in held if n not in bad]
        fc2 = dict(causes=[], model=ext, alternatives=[], explanations=[], rejected=[])
    kept = {c.name for c in fc2["causes"]}
    joint = None
    if replacing:
        joint = _joint_values(found, [n for n in searched if n in kept or n in replacing], parts, model, rule)
        if joint is None:      # reported in place of its special case or not at all
            clash.update({n: nested[n] for n in replacing})
        else:
            fc2 = dict(fc2, causes=list(fc2["causes"]) + [chosen[n] for n in replacing])
            kept |= set(replacing)
    # a cross cause the blocks chose from the nominal model where they did not choose a cause the
    # fitting record found, and which does not hold on top of that cause: the found one may be
    # that record's reading of it, so both are judged together from the nominal model on the
    # blocks (:func:`_joint_values`, which drops a found cause they do not need; reporting55
    # d0349: a 14 Hz resonance the fitting record's motion does not excite, that record's mass
    # 1.2 % high, on the blocks the resonance alone)
    lost = [n for n in held if n not in kept and n in chosen]
    if joint is None and lost and any(c not in chosen for c in found):
        joint = _joint_values(found, [n for n in searched if n in kept] + lost, parts, model, rule)
        if joint is not None:
            fc2 = dict(fc2, causes=list(fc2["causes"]) + [chosen[n] for n in lost])
            kept |= set(lost)
    if joint is None and kept:
        joint = _joint_values(found, [n for n in searched if n in kept], parts, model, rule)
    # a cross cause the blocks cannot tell from their own spread (its ``unresolved`` hook on the
    # widened uncertainties) is searched for no more: the search runs again without it as a cross cause
    final = joint[0] if joint is not None else {c.name: c for c in fc2["causes"]}
    weak = {n: why for n in cross if n in final and (why := unresolved(n, final[n], ext))}
    if weak:       # cross excludes unresolved_here, which each call extends: at most len(names) + 1 calls
        out = search(fc, names, model, validate, kf, kv, sensor, window, rule, untested, notes,
                     unresolved_here | frozenset(weak))
        said = f" (fitted on alternate blocks of {validate.name}, judged on the others)"
        rows = [dict(name=n, step="identification", reason=why + said) for n, why in weak.items()]
        return dict(out, rejected=_partly_rows(out["rejected"], rows, weak, set()))
    fc2["rejected"] = [r for r in judged["rejected"] if r["name"] in cross and r["name"] not in kept] + [
        r for r in fc2["rejected"] if r["name"] in cross]
    fc2["rejected"] += [dict(name=n, step="refit", reason="it does not hold on top of the causes found on the fitting "
                                                          "data") for n in held if n not in kept]
    fc2["rejected"] += [dict(name=n, step="refit", reason=why) for n, why in inside.items()]
    fc2["rejected"] += [dict(name=n, step="refit", reason=f"it cannot be combined with {', '.join(c)}, found on the "
                                                          "fitting data") for n, c in clash.items() if c]
    for c in judged["causes"]:
        if c.name not in cross and c.name not in found:
            fc2["rejected"] = [dict(r, reason=f"{r['reason']}; {c.name} explains these data in its place")
                               if r["name"] in cross else r for r in fc2["rejected"]]
    inner = [u for u in inner if u["name"] in cross]
    untested[:] = [u for u in untested if u["name"] not in cross] + inner
    said = ", ".join(list(cross) + [f"{n} (for the {', '.join(c for c in CAUSES[n].NESTS if c in cross)} it nests)"
                                     for n in nesting])
    notes.append(VALIDATION_ONLY_NOTE.format(names=said, reasons="; ".join(f"{n}: {r}" for n, r in cross.items()),
                                             val=validate.name))
    rejected = [dict(r, reason=f"{r['reason']} (fitted on alternate blocks of {validate.name}, judged on the others)")
                for r in fc2["rejected"]]
    # the validation record's force residual with the causes found here too (the summary's
    # "force residual RMS" is the whole extended model's)
    causes, model_out, shadows = list(fc["causes"]) + list(fc2["causes"]), fc2["model"], []
    if joint is not None:
        values, model_out = joint
        shadows = [c for c in fc["causes"] if c.name not in values]
        causes = [_with_values(c, values[c.name]) for c in causes if c.name in values]
        r_val_ext = fc["r_val_nom"] - force_change(causes, kv, model)
        rejected += [dict(name=c.name, step="refit", statistic=c.statistic, p_value=c.p_value,
                          validation_gain=c.score, reason=SHADOW_REASON.format(
                              val=validate.name, cross=", ".join(n for n in values if n not in found)))
                     for c in shadows]
    else:
        r_val_ext = fc["r_val_ext"] - force_change(fc2["causes"], kv, ext)
    finite = r_val_ext[np.isfinite(r_val_ext)]
    extended = float(np.sqrt(np.mean(finite ** 2))) if fc2["causes"] and fc["extended"] is not None else fc["extended"]
    # a nesting mate's row from the fitting record stays, with what the blocks said of it
    one_row = dict(partly, **{n: "" for n in nesting})
    return dict(fc, causes=causes, rejected=_partly_rows(fc["rejected"], rejected, one_row, kept),
                model=model_out, alternatives=[a for a in list(fc["alternatives"]) + list(fc2["alternatives"])
                                               if a.get("replaces") not in {c.name for c in shadows}],
                explanations=list(fc["explanations"]) + list(fc2["explanations"]), r_val_ext=r_val_ext,
                extended=extended)


def _partly_rows(first: list, second: list, partly: dict, kept: set) -> list:
    """The rejected rows of the fitting record's search (``first``) and of the validation-only
    search (``second``), one row per cause: a cause the fitting record can show in part
    (``partly``) that the second search kept has no row; one it rejected there too has one row,
    the first's, with both reasons."""
    again = {r["name"]: r["reason"] for r in second if r["name"] in partly}
    out = []
    for r in first:
        if r["name"] in kept:
            continue
        if r["name"] in again:
            r = dict(r, reason=f"{r['reason']}; and where only the validation record can show it: {again[r['name']]}")
        out.append(r)
    said = {r["name"] for r in first}
    return out + [r for r in second if not (r["name"] in partly and r["name"] in said)]


def _joint_values(found: list, cross: list, parts: tuple, model: NominalModel, rule: tuple):
    """({cause: its force-channel Cause}, extended model): the causes ``found`` on the fitting
    record and those only the validation record can show (``cross``, kept there) searched together
    from ``model`` on the validation record's alternate blocks ``parts`` (:func:`interleaved`),
    their uncertainties widened by the other blocks' values (:mod:`~hunting.diagnose.spread`);
    None where that search does not keep every cross cause. A found cause it does not keep is
    left out of the dict: the validation record, which shows both, does not need it beside them.

    The fitting record cannot show the cross causes' effect and carries it in its own causes'
    values: a one-way record reads a viscous asymmetry's 220 N s/m times the speed as part of the
    offset (reporting33 d0413: 11.3 N for a true 8.11; fitted together on the validation record's
    blocks, 8.15 N and b+, b- within 1.2 % of the truth), or as an offset of its own (reporting34
    d0427: 0.21 N beside b+, b- of 10.8 and 10.1 N s/m for a true viscous asymmetry of 11.3 and
    9.7 and no offset; on the blocks the asymmetry alone, 11.30 and 9.65 N s/m)."""
    from .spread import validation_values, widen
    fit2, val2, w2, kf2, kv2 = parts
    max_causes, alpha, min_gain, alpha_reference = rule
    names = found + cross
    joint = identified_force_channel(library_builder(fit2, val2, kf2, kv2, model, w2, alpha, None), names, model,
                                      max(max_causes, len(names)), alpha, min_gain, alpha_reference, [])
    kept = [n for n in names if n in {c.name for c in joint["causes"]}]
    if not set(cross) <= set(kept):
        return None
    swapped = library_builder(val2, fit2, kv2, kf2, model, w2, alpha, None)
    causes = widen(joint["causes"], validation_values(swapped, kept))
    return {c.name: c for c in causes}, joint["model"]


def _with_values(cause: Cause, values: Cause) -> Cause:
    """``cause`` (its test, score and gain) with the parameters, uncertainties, coefficients and
    hyper-parameters of another fit of it (``values``)."""
    return replace(cause, parameters=values.parameters, sigma=values.sigma, hyper=values.hyper, theta=values.theta,
                   increments=values.increments)
