"""Frequency response functions from time series and low-order fits (thesis sections 4.4, 5.2.1,
10.3.1).

* ``estimate_frf``: H1 estimate P_uy / P_uu from averaged periodograms (Welch: Hann window, 50 %
  overlap, as in the thesis' 8192-sample records), with the coherence.
* ``plant_from_sensitivity``: closed loop with a known controller C excited at the controller
  output: S = W / V, then P = (1/S - 1) / C.
* ``fit_double_integrator``: P(jw) ~ g / (jw)^2, g = cm / m.
* ``fit_second_order``: H(jw) ~ b0 / ((jw)^2 + a1 jw + a0) by Sanathanan-Koerner iteration
  (linearized least squares reweighted by the previous denominator), e.g. the presliding model
  cm / (J s^2 + (sigma1 + sigma2) s + sigma0).
Every fit returns values with standard uncertainties and the residual, never bare numbers.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal

from ..errors import SystemDefinitionError


@dataclass(frozen=True)
class FRF:
    """f : (k,) frequencies [Hz]; H : (k,) complex response; coherence : (k,) in [0, 1];
    n_averages : records averaged."""

    f: np.ndarray
    H: np.ndarray
    coherence: np.ndarray
    n_averages: int

    def band(self, fmin: float, fmax: float) -> "FRF":
        sel = (self.f >= fmin) & (self.f <= fmax)
        return FRF(self.f[sel], self.H[sel], self.coherence[sel], self.n_averages)


@dataclass(frozen=True)
class ParameterFit:
    """values / sigma : dicts of estimates and standard uncertainties; residual : rms of the
    relative complex misfit over the fitted band; n : points used."""

    values: dict
    sigma: dict
    residual: float
    n: int

    def __getitem__(self, k):
        return self.values[k]


def _check_signals(u, y, fs):
    u = np.asarray(u, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    if u.shape != y.shape:
        raise SystemDefinitionError(f"input and output have {u.size} and {y.size} samples: they must match")
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(y))):
        raise SystemDefinitionError("signals contain NaN or inf")
    if not (np.isfinite(fs) and fs > 0):
        raise SystemDefinitionError(f"fs = {fs!r} is not allowed: the sampling frequency must be > 0 [Hz]")
    return u, y


def estimate_frf(u, y, fs: float, *, nperseg: int = 8192, overlap: float = 0.5) -> FRF:
    """H1 estimate of the FRF from input u to output y sampled at fs [Hz]: averaged periodograms
    with a Hann window and ``overlap`` (sections 4.4, 10.3.1).

    u, y : (n,) arrays, or lists of arrays (fragments, e.g. the parts of a record between
    velocity reversals): the cross and auto spectra are averaged over all segments of all
    fragments, weighted by their number of segments; fragments shorter than nperseg are skipped."""
    frags = list(zip(u, y)) if isinstance(u, (list, tuple)) else [(u, y)]
    if not 0 <= overlap < 1:
        raise SystemDefinitionError(f"overlap = {overlap!r} must be in [0, 1)")
    nov = int(round(overlap * nperseg))
    acc, n_avg = None, 0
    for uf, yf in frags:
        uf, yf = _check_signals(uf, yf, fs)
        if uf.size < nperseg:
            continue
        kw = dict(fs=fs, window="hann", nperseg=nperseg, noverlap=nov, detrend="constant")
        f, Puu = signal.welch(uf, **kw)
        _, Puy = signal.csd(uf, yf, **kw)
        _, Pyy = signal.welch(yf, **kw)
        k = 1 + (uf.size - nperseg) // (nperseg - nov)
        part = np.array([Puu * k, Puy * k, Pyy * k])
        acc = part if acc is None else acc + part
        n_avg += k
    if acc is None:
        raise SystemDefinitionError(f"every signal (fragment) has fewer than nperseg = {nperseg} samples")
    Puu, Puy, Pyy = acc / n_avg
    with np.errstate(divide="ignore", invalid="ignore"):
        H = Puy / Puu
        coh = np.abs(Puy) ** 2 / (Puu.real * Pyy.real)
    keep = f > 0
    return FRF(f[keep], H[keep], np.clip(np.nan_to_num(coh[keep].real), 0, 1), int(n_avg))


def controller_frf(controller, f) -> np.ndarray:
    """C(jw) of a PID u = -(kp e + kd e' + ki int e) as the gain from error to -u."""
    s = 2j * np.pi * np.asarray(f, dtype=float)
    return controller.kp + controller.kd * s + controller.ki / s


def plant_from_sensitivity(S: FRF, C) -> FRF:
    """P = (1/S - 1)/C from a measured sensitivity S and the known controller response C (array
    on S.f, or a PID)."""
    Cv = controller_frf(C, S.f) if not isinstance(C, np.ndarray) else C
    return FRF(S.f, (1.0 / S.H - 1.0) / Cv, S.coherence, S.n_averages)


def fit_double_integrator(P: FRF, fmin: float, fmax: float) -> ParameterFit:
    """Least-squares g in P(jw) ~ g / (jw)^2 on [fmin, fmax] (relative error weighting): for a
    mass m driven through cm, g = cm / m."""
    B = P.band(fmin, fmax)
    if B.f.size < 3:
        raise SystemDefinitionError(f"band [{fmin}, {fmax}] Hz holds {B.f.size} points: need at least 3")
    s = 2j * np.pi * B.f
    b = 1.0 / s ** 2
    w = 1.0 / np.abs(B.H) ** 2          # relative error
    g = float(np.real(np.sum(w * B.H * np.conj(b))) / np.sum(w * np.abs(b) ** 2))
    rel = (B.H - g * b) / B.H
    res = float(np.sqrt(np.mean(np.abs(rel) ** 2)))
    # each frequency gives 2 real equations of the relative misfit; sigma(g) from the scatter
    sig = abs(g) * res / np.sqrt(2 * B.f.size - 1)
    return ParameterFit({"g": g}, {"g": float(sig)}, res, int(B.f.size))


def fit_second_order(H: FRF, fmin: float, fmax: float, *, iterations: int = 20, tol: float = 1e-10) -> ParameterFit:
    """b0 / (s^2 + a1 s + a0) fitted on [fmin, fmax] by Sanathanan-Koerner iteration: solve
    min sum |(H (s^2 + a1 s + a0) - b0) / (|A_prev| |H|)|^2 for (a1, a0, b0), repeat with the new
    denominator until the parameters settle. Returns a0, a1, b0 with uncertainties, plus the
    derived natural frequency f0 [Hz] and damping ratio zeta."""
    B = H.band(fmin, fmax)
    if B.f.size < 4:
        raise SystemDefinitionError(f"band [{fmin}, {fmax}] Hz holds {B.f.size} points: need at least 4")
    s = 2j * np.pi * B.f
    Hv = B.H
    theta = np.zeros(3)
    wprev = np.ones(s.size)
    cov = np.full((3, 3), np.nan)
    res = np.nan
    for _ in range(int(iterations)):
        # H a1 s + H a0 - b0 = -H s^2, weighted
        A = np.column_stack([Hv * s, Hv, -np.ones_like(Hv)]) * wprev[:, None]
        rhs = -Hv * s ** 2 * wprev
        Ar = np.vstack([A.real, A.imag])
        br = np.concatenate([rhs.real, rhs.imag])
        new, *_ = np.linalg.lstsq(Ar, br, rcond=None)
        r = br - Ar @ new
        dof = max(br.size - 3, 1)
        cov = np.linalg.pinv(Ar.T @ Ar) * (r @ r) / dof
        done = np.all(np.abs(new - theta) <= tol * np.maximum(np.abs(new), 1e-300))
        theta = new
        den = s ** 2 + theta[0] * s + theta[1]
        wprev = 1.0 / (np.abs(den) * np.abs(Hv))
        if done:
            break
    a1, a0, b0 = theta
    model = b0 / (s ** 2 + a1 * s + a0)
    res = float(np.sqrt(np.mean(np.abs((Hv - model) / Hv) ** 2)))
    sd = np.sqrt(np.abs(np.diag(cov)))
    f0 = float(np.sqrt(abs(a0)) / (2 * np.pi))
    zeta = float(a1 / (2 * np.sqrt(abs(a0))))
    return ParameterFit({"a1": float(a1), "a0": float(a0), "b0": float(b0), "f0": f0, "zeta": zeta},
                        {"a1": float(sd[0]), "a0": float(sd[1]), "b0": float(sd[2])}, res, int(B.f.size))


def prbs(n: int, *, bandwidth: float, fs: float, amplitude: float = 1.0, seed: int = 0) -> np.ndarray:
    """A pseudo-random binary signal of n samples holding each level for ~fs / (2 bandwidth)
    samples (flat spectrum up to about ``bandwidth`` Hz), levels +-amplitude."""
    rng = np.random.default_rng(seed)
    hold = max(1, int(round(fs / (2.0 * bandwidth))))
    levels = rng.choice([-1.0, 1.0], size=n // hold + 1)
    return amplitude * np.repeat(levels, hold)[:n]
