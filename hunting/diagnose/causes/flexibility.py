"""An unmodelled resonance: a load of mass m2 on a spring-damper behind the measured side. The
rigid model's mass is the total, so the residual gains m2 (a2 - a1) = -m2 H(s) a1 with
H(s) = s^2 / (s^2 + 2 zeta w s + w^2): linear in m2 for a given resonance (w, zeta), which the
hyper-parameter grid scans around the peaks of the residual's spectrum."""
import numpy as np

from ..model import Flexibility, highpass_response

NAME = "flexibility"
DESCRIPTION = "an unmodelled resonance (load on a spring behind the measured side)"
DAMPING = (0.02, 0.05, 0.1, 0.2, 0.4)
DAMPING_MAX = (0.002, 1.0)            # the damping ratios the refinement may reach


def hypers(kin, model) -> list:
    """(frequency, damping) candidates: for each of the two strongest peaks of the nominal
    residual's spectrum (Welch) between 2 Hz and a tenth of the sampling rate, the best of a
    +-20 % frequency grid times the damping ratios in DAMPING, refined by least squares in
    (log frequency, log damping) with the load mass eliminated (variable projection)."""
    from scipy.optimize import minimize
    from scipy.signal import find_peaks, welch
    from ..kinematics import residual
    dt = float(kin.t[1] - kin.t[0])
    r = residual(kin, model)
    m = kin.moving & np.isfinite(r)
    if m.sum() < 512:
        return []
    f, P = welch(np.where(m, r - r[m].mean(), 0.0), fs=1.0 / dt, nperseg=min(4096, r.size // 4))
    band = (f >= 2.0) & (f <= 0.1 / dt)
    if band.sum() < 5:
        return []
    fb, Pb = f[band], P[band]
    idx, _ = find_peaks(Pb)
    idx = sorted(idx, key=lambda i: -Pb[i])[:2]

    def fit(z):
        x = design(kin, model, {"frequency": float(np.exp(z[0])), "damping": float(np.exp(z[1]))})[m, 0]
        th = float(x @ r[m]) / max(float(x @ x), 1e-300)
        e = r[m] - th * x
        return float(e @ e), th

    def ss(z):
        # a resonance is lightly damped (zeta <= 1), inside the band, with a positive load mass
        if not (np.log(DAMPING_MAX[0]) <= z[1] <= np.log(DAMPING_MAX[1]) and np.log(2.0) <= z[0] <= np.log(0.1 / dt)):
            return np.inf
        val, th = fit(z)
        return val if th > 0 else np.inf
    out = []
    for i in idx:
        grid = [(np.log(fb[i] * s), np.log(zeta)) for s in np.linspace(0.8, 1.2, 11) for zeta in DAMPING]
        z0 = min(grid, key=ss)
        if not np.isfinite(ss(z0)):
            continue                                  # no positive load mass fits near this peak
        # outside the admissible set: a finite penalty (inf - inf would be NaN in the simplex test)
        cap = 1e6 * ss(z0)
        res = minimize(lambda z: min(ss(z), cap), z0, method="Nelder-Mead",
                       options=dict(xatol=1e-4, fatol=1e-10, maxiter=200))
        z = res.x if res.fun <= ss(z0) else z0
        out.append({"frequency": float(np.exp(z[0])), "damping": float(np.exp(z[1]))})
    return out


def design(kin, model, hyper):
    dt = float(kin.t[1] - kin.t[0])
    return -highpass_response(kin.a, dt, hyper["frequency"], hyper["damping"])[:, None]


def unphysical(theta, hyper, model) -> str | None:
    return f"load mass {theta[0]:.3g} kg <= 0" if theta[0] <= 0 else None


def parameters(theta, hyper, model) -> dict:
    m2 = float(theta[0])
    w = 2 * np.pi * hyper["frequency"]
    return {"load_mass": m2, "frequency": hyper["frequency"], "damping": hyper["damping"],
            "stiffness": m2 * w ** 2}


def extend(model, theta, hyper):
    # the force residual carries the load; the re-simulation engine models the rigid body only
    return model.replace(flexibility=Flexibility(max(float(theta[0]), 0.0), hyper["frequency"], hyper["damping"]))
