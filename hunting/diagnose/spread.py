"""The spread of the force channel's parameters between the two records.

The force channel's standard uncertainties (:func:`~hunting.diagnose.refine.refine`: the GLS or
instrumental covariance, the hyper-parameters' by the delta method) see the fitting record's
noise, not the model's error. Where the residual holds something the extended model does not
follow (a delay of a fraction of a sample read through the zero-order hold, a lag beside the
Stribeck dip whose signature it shares), the best values depend on the excitation, and the truth
lay many stated uncertainties away: on the blind set reporting29 the truth was within two of them
for 65 % of the delays, 64 % of the lags and 67 % of the bristle stiffnesses (95 % expected).

The same explanation fitted on the validation record gives a second, independent set of values:
each parameter's standard uncertainty is the larger of the within-record one and
|x_fit - x_val| / sqrt(2) (:func:`~hunting.diagnose.loop_sigma.two_records`, the loop channel's
rule: two independent estimates of one value differ by sqrt(2) sigma on average). The values
reported stay the fitting record's, those the validation gain was judged with."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .loop_sigma import two_records
from .refine import member_sigma, members_parameters, refine


def validation_values(library, names) -> dict:
    """{cause: parameters} of the explanation of the causes ``names`` fitted on the validation
    record: ``library(names)`` builds the force channel's library with the records' roles
    swapped; the explanation is each cause's best grid variant given the others, refined as the
    fitting record's was. Empty where a cause cannot be tested with the roles swapped (e.g. the
    validation record moves one way), the fit is not physical or fails: a value from another set
    of causes would measure their difference, not the spread. ``names`` in the fitting record's
    explanation's order (the extensions are applied in it)."""
    from ..errors import SystemDefinitionError
    try:
        lib = library(list(names))
        if any(n not in lib.variants for n in names):
            return {}
        ex = lib.best_variants(tuple(names))
        if not ex.physical:
            return {}
        cov, hyper_sigma = None, {}
        if ex.cols:
            ex, _, cov, hyper_sigma = refine(lib, ex)
            if not ex.physical:
                return {}
        rows = members_parameters(lib, ex, cov)
    except (SystemDefinitionError, ValueError, ArithmeticError, np.linalg.LinAlgError):
        return {}            # e.g. an extension the swapped fit makes unphysical: no second value
    # only what the validation fit estimated (a stated uncertainty there, as the fitting record's
    # causes get theirs: coefficients, refined hyper-parameters, parameters derived from them): a
    # parameter its variant holds (a Stribeck dip's Fc, a tied vs_neg) is the nominal model's
    # there, and its difference is no spread
    out = {}
    for name, _, _, pars, sig, _, _ in rows:
        sig = member_sigma(name, pars, sig, hyper_sigma)
        out[name] = {k: v for k, v in pars.items() if sig.get(k)}
    return out


def widen(causes: list, values: dict) -> list:
    """The causes with each stated standard uncertainty widened to the spread against the
    validation record's value of that parameter (:func:`validation_values`; module docstring).
    A parameter without a stated uncertainty, or without a finite validation value, keeps what
    it has."""
    out = []
    for c in causes:
        other = values.get(c.name)
        if other is None:
            out.append(c)
            continue
        sigma = {}
        for key, s in c.sigma.items():
            v = other.get(key)
            # s == 0: the fitting record's variant held the parameter (not estimated): nothing to widen
            ok = bool(s) and v is not None and np.isfinite(v) and np.isfinite(c.parameters[key])
            sigma[key] = two_records(s, c.parameters[key], v) if ok else s
        out.append(replace(c, sigma=sigma))
    return out
