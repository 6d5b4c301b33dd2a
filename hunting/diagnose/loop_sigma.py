"""Standard uncertainty of coefficients fitted on the re-simulated loop.

The loop channel and presliding's loop evidence fit one coefficient x (dwell's loop growth two,
log gain and log time: :func:`coefficients_sigma`, J a matrix) by the whole record's
re-simulated position RMS error (presliding's creep fit by the error inside the stick segments,
each segment's mean removed: a residual linear in the re-simulated position too). Near the optimum x* the residual
r(x) = q_sim(x) - q is linear in x, r(x) = r* + J (x - x*), and the least-squares estimate's
error is (J^T J)^-1 J^T e for a residual noise e. Its variance is the long-run variance of the
score s_t = J_t r_t over (J^T J)^2 (the sandwich estimate; it holds for the pseudo-true value of a
model that is misspecified elsewhere, too). A loop's position residual is strongly correlated
(a stick phase's error lasts hundreds of samples), so the long-run variance is sum(s^2) times the
score's integrated autocorrelation time, its window chosen by Sokal's rule (the smallest lag M
with M >= SOKAL_C times the time summed up to M). J is a central difference over ``h``, wide
enough to step across the encoder's quantization of q_sim.

That estimate sees the record's noise, not the model's error: where the residual is the model's
(a loop that cannot follow the record whatever x is), the best x depends on the excitation. The
same fit on the validation record gives a second, independent value; where the two differ by
more than the within-record estimate says, their spread is the uncertainty
(:func:`two_records`)."""
from __future__ import annotations

import numpy as np

from .data import Measurement

SOKAL_C = 5.0        # Sokal's window: the smallest lag M with M >= SOKAL_C * tau(M)
RESOLVED = 1e-6      # a Jacobian's singular value below this share of the largest: a direction the record does not resolve


def integrated_time(s: np.ndarray) -> float:
    """The integrated autocorrelation time tau = 1 + 2 sum_k rho_k of the series s (n,), summed
    up to Sokal's window; at least 1, at most n (where no window up to n / 2 satisfies the rule,
    the sum up to n / 2)."""
    s = np.asarray(s, float) - np.mean(s)
    n = s.size
    if n < 4 or not np.any(s):
        return 1.0
    f = np.fft.rfft(s, 2 * n)
    acov = np.fft.irfft(f * np.conj(f))[:n // 2 + 1]
    rho = acov / acov[0]
    tau = 1.0 + 2.0 * np.cumsum(rho[1:])
    lags = np.arange(1, rho.size)
    ok = np.nonzero(lags >= SOKAL_C * tau)[0]
    t = tau[ok[0]] if ok.size else tau[-1]
    return float(np.clip(t, 1.0, n))


def coefficient_sigma(meas: Measurement, model_at, x: float, h: float, residual=None) -> float | None:
    """Standard uncertainty of a coefficient x fitted on the re-simulated loop of ``meas``
    (module docstring). model_at(x) : the NominalModel at coefficient x (None where x is not a
    physical model); h : the half step of the central difference, in x's units; residual(q_sim)
    : the fit's residual vector of a re-simulated position (default q_sim - meas.q; a fit on
    parts of the record, e.g. presliding's creep in the stick segments, passes its own, linear
    in q_sim). None where a re-simulation fails or the residual does not depend on x."""
    sig = coefficients_sigma(meas, lambda v: model_at(float(v[0])), np.array([x], float), np.array([h], float),
                             residual)
    return None if sig is None or sig[0] is None else float(sig[0])


def coefficients_sigma(meas: Measurement, model_at, x: np.ndarray, h: np.ndarray, residual=None) -> list | None:
    """Standard uncertainties (k,) of coefficients x (k,) fitted together on the re-simulated
    loop of ``meas`` (:func:`coefficient_sigma`'s estimate with a (n, k) Jacobian: bread (J^T J)^-1,
    meat sum(s s^T) times the largest of the scores' integrated autocorrelation times; 1 + 2k
    re-simulations). model_at(x) : the NominalModel at coefficients x (k,); h (k,) : half steps.
    An entry is None where the residual does not depend on that coefficient, or the coefficient
    loads on a direction the record does not resolve (a singular value of J below RESOLVED of
    the largest); None where a re-simulation fails or no coefficient moves the residual."""
    from .resimulate import resimulate_many
    x, h = np.asarray(x, float), np.asarray(h, float)
    steps = np.diag(h)
    points = [x] + [x + sign * steps[j] for j in range(x.size) for sign in (1.0, -1.0)]
    models = [model_at(xx) for xx in points]
    if any(m is None for m in models):
        return None
    sims = resimulate_many(meas, models)          # the centre and the central differences' pairs, side by side
    if not all(sim.ok for sim in sims):
        return None
    res = [sim.q if residual is None else np.asarray(residual(sim.q), float) for sim in sims]
    centre, cols = res[0], [res[1 + 2 * j:3 + 2 * j] for j in range(x.size)]
    n = min([centre.size] + [v.size for pair in cols for v in pair])
    if residual is None:
        r = centre[:n] - meas.q[:n]
    elif any(v.size != centre.size for pair in cols for v in pair):
        return None
    else:
        r = centre
    J = np.column_stack([(a[:n] - b[:n]) / (2.0 * hj) for (a, b), hj in zip(cols, h)])
    moves = np.any(J != 0, axis=0)
    if not moves.any():
        return None
    Jm = J[:, moves]
    S = Jm * r[:n, None]
    tau = max(integrated_time(S[:, j]) for j in range(S.shape[1]))
    # the bread from the SVD of J: a direction whose singular value is below RESOLVED of the
    # largest is not resolved by the record, and a coefficient that loads on it has no finite
    # uncertainty (a pseudo-inverse would drop the direction and report it as known exactly)
    _, sv, Vt = np.linalg.svd(Jm, full_matrices=False)
    kept = sv > RESOLVED * sv[0]
    V = Vt[kept].T / sv[kept]
    bread = V @ V.T
    cov = bread @ (S.T @ S * tau) @ bread
    unresolved = np.any(np.abs(Vt[~kept]) > 1e-3, axis=0) if not kept.all() else np.zeros(Jm.shape[1], bool)
    out, it = [], iter(zip(np.sqrt(np.clip(np.diag(cov), 0.0, None)), unresolved))
    for m in moves:
        if not m:
            out.append(None)
            continue
        sig, lost = next(it)
        out.append(None if lost else float(sig))
    return out


def parameter_sigma(parameters_at, x: float, sigma_x: float | None, h: float) -> dict:
    """{parameter: standard uncertainty} of the parameters parameters_at(x) (a dict) of a
    coefficient x with standard uncertainty sigma_x, by the delta method (a central difference
    over h); None for a parameter x does not change, or for all where sigma_x is None."""
    pars = parameters_at(x)
    if sigma_x is None:
        return {k: None for k in pars}
    lo, hi = parameters_at(x - h), parameters_at(x + h)
    out = {}
    for k in pars:
        d = (hi[k] - lo[k]) / (2.0 * h)
        out[k] = float(abs(d) * sigma_x) if d != 0 else None
    return out


def two_records(sigma: float | None, x_fit: float, x_val: float | None) -> float | None:
    """The standard uncertainty of a loop-fitted coefficient with the validation record's own
    fit x_val beside the fitting record's x_fit: the larger of the within-record estimate
    ``sigma`` and |x_fit - x_val| / sqrt(2) (two independent estimates of one value differ by
    sqrt(2) sigma on average; where they differ by more, the residual is the model's error, which
    no within-record statistic sees, and the value depends on the excitation)."""
    if sigma is None or x_val is None or not np.isfinite(x_val):
        return sigma
    return float(max(sigma, abs(x_fit - x_val) / np.sqrt(2.0)))
