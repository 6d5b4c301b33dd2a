"""Friction-velocity maps and cogging tables from motion experiments (thesis sections 5.3.2,
10.3.2, 10.3.3).

* ``fit_stribeck``: least squares of F(v) = sgn(v) (Fc + (Fs - Fc) exp(-|v/vs|^beta)) + b v to
  averaged forces at constant velocities, optionally per direction, with standard uncertainties
  from the Jacobian at the optimum.
* ``cogging_table``: the force needed at low constant velocity minus each direction's mean
  (the frictional offset), filtered zero-phase with a fifth-order Butterworth filter in
  position, averaged over the directions into a linear-interpolation table.
"""
from __future__ import annotations

import numpy as np
from scipy import signal
from scipy.optimize import least_squares

from ..errors import SystemDefinitionError
from ..models.friction import StribeckCurve
from ..models.plant import Cogging
from .frf import ParameterFit

_NAMES = ("Fc", "Fs", "vs", "beta", "b")


def _stribeck(theta, v, fit_beta, beta):
    Fc, Fs, vs = theta[0], theta[1], theta[2]
    bet = theta[3] if fit_beta else beta
    b = theta[-1]
    return np.sign(v) * (Fc + (Fs - Fc) * np.exp(-np.abs(v / vs) ** bet)) + b * v


def _fit_one(v, F, fit_beta, beta):
    v = np.asarray(v, float)
    F = np.asarray(F, float)
    a = np.abs(F)
    Fc0 = float(np.percentile(a, 25))
    Fs0 = float(max(np.max(a[np.argsort(np.abs(v))[: max(3, v.size // 5)]]), Fc0 * 1.05))
    vs0 = float(np.median(np.abs(v)) / 3)
    theta0 = [Fc0, Fs0, vs0] + ([2.0] if fit_beta else []) + [0.0]
    lo = [0.0, 0.0, 1e-9] + ([0.2] if fit_beta else []) + [-np.inf]
    hi = [np.inf, np.inf, np.inf] + ([10.0] if fit_beta else []) + [np.inf]
    r = least_squares(lambda th: _stribeck(th, v, fit_beta, beta) - F, theta0, bounds=(lo, hi), x_scale="jac")
    dof = max(v.size - r.x.size, 1)
    s2 = float(r.fun @ r.fun) / dof
    cov = np.linalg.pinv(r.jac.T @ r.jac) * s2
    names = ["Fc", "Fs", "vs"] + (["beta"] if fit_beta else []) + ["b"]
    vals = dict(zip(names, map(float, r.x)))
    sig = dict(zip(names, map(float, np.sqrt(np.abs(np.diag(cov))))))
    if not fit_beta:
        vals["beta"], sig["beta"] = float(beta), 0.0
    return ParameterFit(vals, sig, float(np.sqrt(s2)), int(v.size))


def fit_stribeck(v, F, *, direction_dependent: bool = False, fit_beta: bool = False,
                 beta: float = 2.0) -> dict:
    """Fit the Stribeck curve plus viscous friction to (velocity [m/s], force [N]) pairs.

    Returns {"both": fit} or {"positive": fit, "negative": fit} (magnitudes for v < 0), each a
    ParameterFit with Fc, Fs, vs, beta, b and their standard uncertainties; residual in N."""
    v = np.asarray(v, float).ravel()
    F = np.asarray(F, float).ravel()
    if v.shape != F.shape or v.size < 5:
        raise SystemDefinitionError(f"need matching v and F with at least 5 points, got {v.size} and {F.size}")
    if np.any(v == 0):
        raise SystemDefinitionError("v = 0 is not allowed in a friction-velocity map (the force is set-valued there)")
    if not direction_dependent:
        return {"both": _fit_one(v, F, fit_beta, beta)}
    pos, neg = v > 0, v < 0
    if pos.sum() < 5 or neg.sum() < 5:
        raise SystemDefinitionError("direction-dependent fits need at least 5 points per direction")
    fp = _fit_one(v[pos], F[pos], fit_beta, beta)
    fn = _fit_one(-v[neg], -F[neg], fit_beta, beta)
    return {"positive": fp, "negative": fn}


def curve_from_fit(fit: ParameterFit) -> StribeckCurve:
    """The StribeckCurve of a fit."""
    v = fit.values
    return StribeckCurve(Fc=v["Fc"], Fs=max(v["Fs"], v["Fc"]), vs=v["vs"], beta=v["beta"], b=v["b"])


def cogging_table(q, force, velocity, *, spacing: float = 1e-4, cutoff: float = 1.0 / 3e-3,
                  order: int = 5) -> Cogging:
    """Cogging table from a slow tracking run in both directions.

    q : positions [m]; force : the feedback force needed [N] (cm u); velocity : reference
    velocity [m/s] (its sign tells the direction). Per direction the mean force (the friction
    offset) is removed, the force is resampled on a uniform position grid with ``spacing`` [m],
    filtered forwards and backwards (zero phase) with a Butterworth filter of ``order`` and
    ``cutoff`` [1/m] in position, and the two directions are averaged on their common range."""
    q = np.asarray(q, float).ravel()
    F = np.asarray(force, float).ravel()
    vel = np.asarray(velocity, float).ravel()
    if not (q.shape == F.shape == vel.shape):
        raise SystemDefinitionError("q, force and velocity must have the same length")
    tables = []
    for sgn in (1.0, -1.0):
        sel = np.sign(vel) == sgn
        if sel.sum() < 10:
            raise SystemDefinitionError("cogging_table needs motion in both directions")
        qs, Fs = q[sel], F[sel]
        order_idx = np.argsort(qs)
        qs, Fs = qs[order_idx], Fs[order_idx] - np.mean(Fs)
        grid = np.arange(qs[0], qs[-1], spacing)
        Fg = np.interp(grid, qs, Fs)
        wn = cutoff * 2 * spacing             # normalized to the Nyquist wavenumber 1 / (2 spacing)
        if not 0 < wn < 1:
            raise SystemDefinitionError(f"cutoff = {cutoff!r} 1/m must lie below the Nyquist wavenumber {0.5 / spacing}")
        sos = signal.butter(order, wn, output="sos")
        tables.append((grid, signal.sosfiltfilt(sos, Fg)))
    lo = max(tables[0][0][0], tables[1][0][0])
    hi = min(tables[0][0][-1], tables[1][0][-1])
    grid = np.arange(lo, hi, spacing)
    avg = 0.5 * (np.interp(grid, *tables[0]) + np.interp(grid, *tables[1]))
    return Cogging.table(grid, avg)
