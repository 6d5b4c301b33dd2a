"""Candidate causes of a model-data mismatch. Each module is one cause: its ``NAME`` (from the
vocabulary of ``hunting diagnose``), a one-line ``DESCRIPTION``, ``hypers(kin, model)`` (the
hyper-parameter variants to try, chosen from the fitting data: e.g. cogging pitches),
``design(kin, model, hyper)`` (regressors (n, k) of the force residual, linear in the
extension's parameters) and ``parameters(theta, hyper, model)`` turning the fitted coefficients
into named physical parameters, and ``extend(model, theta, hyper)`` returning the extended
NominalModel (what the behaviour view re-simulates); optionally ``unphysical(theta, hyper, model)``
returning why a fitted theta is not the physical effect (the cause is then rejected), else None;
optionally ``shift(kin, model, hyper)``: the known, unfitted part (n,) [N] of the extension's
force change (e.g. the nominal Stribeck dip moved to a new vs). Also: ``FAMILY`` (causes that share
a signature share it), ``HYPERS`` (continuous hyper-parameters searched, counted in BIC; optionally ``hyper_count(hyper)``
where a variant searched fewer: :func:`hyper_count`),
``HYPER_KEYS`` (those refined by Gauss-Newton; optionally ``hyper_keys(hyper)`` giving those a
variant has, when some do not apply to it: :func:`hyper_keys`; ``derived_sigma(parameters, sigma)``
giving the standard uncertainty of parameters computed from them, and ``refine_starts(hyper)``:
other starting values of hyper-parameters the search holds fixed), ``UNITS`` (of the parameters), ``sentence(p,
increments, model)`` (the finding in words), ``untestable(kin, model)`` (why a record cannot test
it; with ``ONE_WAY_VALIDATION`` it takes ``validation=True`` for a record that only judges a fit made
on another: :func:`untestable`), ``EXCLUDES`` (causes it cannot be combined with), ``NOISE_FED`` (its regressor is made of
measured derivatives: judged also along a noise-free instrument trajectory), ``JUDGED_FIRST``
(an own-evidence cause whose evidence reads only the measured records, judged before the other
channels so that their re-simulations run on its extension), ``FRICTION_FORCE`` (a change of the
friction force's level or curve, a constant or a map of the velocity: its size is judged against
the Coulomb level, :func:`hunting.diagnose.force.relevance_floor`). Adding a cause is
adding a module and listing it here."""
from ..model import NominalModel
from ...models.friction import DirectionalCurve


def with_curves(model: NominalModel, pos, neg=None) -> NominalModel:
    """The model with its friction curves mapped: positive direction by ``pos``, negative by
    ``neg`` (default: the same map)."""
    neg = pos if neg is None else neg
    return model.replace(curve=DirectionalCurve(pos(model.curve.positive), neg(model.curve.negative)))


def two_way_share(kin) -> float:
    """The smaller share of a record's sliding samples in one direction (0 for a record that does
    not slide): causes whose fit needs both directions (asymmetry, level, level_asymmetry) want 10 %."""
    import numpy as np
    v = kin.v[kin.moving]
    return float(min(np.mean(v > 0), np.mean(v < 0))) if v.size else 0.0


from . import (asymmetry, cogging, delay, dwell, dwell_peak, flexibility, lag, level, level_asymmetry, mass, offset,  # noqa: E402
               presliding, quantization, reversal, saturation, stribeck, viscous)

CAUSES = {m.NAME: m for m in (offset, asymmetry, cogging, level, level_asymmetry, stribeck, viscous, mass, delay, flexibility, lag, reversal,
                                presliding, dwell, dwell_peak, saturation, quantization)}


def hyper_keys(name: str, hyper: dict) -> tuple:
    """The hyper-parameters refined for a variant of cause ``name``: its ``hyper_keys(hyper)``
    where it has one (a Stribeck dip taken symmetric on a one-way record has no vs_neg of its
    own), else its ``HYPER_KEYS``."""
    mod = CAUSES[name]
    fn = getattr(mod, "hyper_keys", None)
    return tuple(fn(hyper)) if fn is not None else tuple(getattr(mod, "HYPER_KEYS", ()))


def hyper_count(name: str, hyper: dict) -> int:
    """The hyper-parameters a variant of cause ``name`` searched, counted in BIC: its
    ``hyper_count(hyper)`` where it has one (a variant at fixed hyper-parameters searched none),
    else its ``HYPERS``."""
    mod = CAUSES[name]
    fn = getattr(mod, "hyper_count", None)
    return int(fn(hyper)) if fn is not None else int(mod.HYPERS)


def untestable(name: str, kin, model, validation: bool = False) -> str | None:
    """Why a record (its Kinematics) cannot test cause ``name`` against ``model`` (its
    ``untestable`` hook), or None when it can or the cause has no such hook. ``validation``: the
    record only judges a fit made on another, which a cause with ``ONE_WAY_VALIDATION`` (its fit
    needs both directions of motion, its prediction either) tells its hook."""
    if validation and getattr(CAUSES[name], "ONE_WAY_VALIDATION", False):
        return _hook(name, "untestable", kin, model, validation=True)
    return _hook(name, "untestable", kin, model)


def _hook(name: str, hook: str, *args, **kwargs) -> str | None:
    """Cause ``name``'s optional reason hook called with the arguments, or None where it has none."""
    fn = getattr(CAUSES[name], hook, None)
    return None if fn is None else fn(*args, **kwargs)


def unseen(name: str, kf, kv, model) -> str | None:
    """Why the fitting record (its Kinematics ``kf``) cannot show a part of cause ``name`` that
    the validation record (``kv``) can (its ``unseen`` hook: e.g. a resonance above the fitting
    record's band), or None when it can show all of it or the cause has no such hook."""
    return _hook(name, "unseen", kf, kv, model)


def seen(name: str, hyper: dict, kf, model, parameters: dict | None = None) -> str | None:
    """Why cause ``name`` at hyper-parameters ``hyper`` (its fitted ``parameters``), found where
    the fitting record (``kf``) cannot show it all (:func:`unseen`), lies where that record can
    show it after all (its ``seen`` hook, called with hyper, kf, model and parameters), or None."""
    return _hook(name, "seen", hyper, kf, model, parameters or {})


def unresolved(name: str, cause, model) -> str | None:
    """Why cause ``name``, found where only the validation record can show it (:func:`unseen`),
    is not resolved there: its ``unresolved`` hook, called with the found Cause (final parameters,
    their standard uncertainties widened by the spread between the validation record's blocks)
    and the model it extends, or None where it is resolved or the cause has no such hook."""
    return _hook(name, "unresolved", cause, model)


__all__ = ["CAUSES", "hyper_count", "hyper_keys", "seen", "unresolved", "unseen", "untestable"]
