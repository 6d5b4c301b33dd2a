"""Candidate causes of a model-data mismatch. Each module is one cause: its ``NAME`` (from the
vocabulary of ``hunting diagnose``), a one-line ``DESCRIPTION``, ``hypers(kin, model)`` (the
hyper-parameter variants to try, chosen from the fitting data: e.g. cogging pitches),
``design(kin, model, hyper)`` (regressors (n, k) of the force residual, linear in the
extension's parameters) and ``parameters(theta, hyper, model)`` turning the fitted coefficients
into named physical parameters. Adding a cause is adding a module and listing it here."""
from . import asymmetry, cogging, delay, mass, offset, stribeck, viscous

CAUSES = {m.NAME: m for m in (offset, asymmetry, cogging, stribeck, viscous, mass, delay)}

__all__ = ["CAUSES"]
