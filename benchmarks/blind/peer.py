"""The peer a user might pick instead of ``hunting diagnose``: sparse regression (pysindy's STLSQ,
sequentially thresholded least squares) of the nominal model's force residual on a library of
candidate terms, one group per cause, each term the cause's signature.

Residual and kinematics: :mod:`benchmarks.blind.measures` (not hunting's), on the fitting
record's moving samples. Library (H the kinematics' low pass, q v a the filtered kinematics):

    offset        1
    asymmetry     H[|v|]
    viscous       H[v]
    stribeck      H[sign v], H[sign(v) exp(-(v / vs)^2)] for vs at the 10, 30, 60 % speed quantiles
    mass          a
    delay         cm du/dt (of H[u])
    cogging       H[cos(2 pi k q / p)], H[sin(...)], k = 1..3, p the Lomb-Scargle peak of r(q)
    flexibility   the second-order high pass s^2 / (s^2 + 0.2 w s + w^2) of a, w at the
                  residual's spectral peak between 2 Hz and a tenth of the sampling rate
    lag           H[-g'(|v|) a] (a nominal curve with a Stribeck dip only)
    reversal      H[F_LuGre - F_static] along v for slip lengths 2, 10, 50 um

Columns and residual are scaled to unit RMS, so the STLSQ threshold lambda is the coefficient a
term must reach to stay (a share of the residual's RMS; a small ridge penalty steadies nearly
collinear terms). A cause is reported when the variance share its surviving terms explain
uniquely (the refit without them leaves that much more) is at least lambda^2, which is what a
single orthogonal term of coefficient lambda explains; causes are ranked by that share. Dwell, saturation and quantization
leave no signature in the force residual: the peer cannot report them. The threshold is chosen
on the tuning seeds (:func:`choose_threshold`) and only then applied to the reporting seeds."""
from __future__ import annotations

import json
import math
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

from . import measures
from .system import Curve, Plant

THRESHOLDS = tuple(float(x) for x in np.geomspace(0.01, 1.0, 31))
MIN_MOVING = 50       # samples away from rest a regression needs (fewer: the peer reports nothing)
RIDGE = 1e-2          # ridge penalty per sample (columns have unit RMS): steadies collinear terms
SLIPS = (2e-6, 1e-5, 5e-5)


def plant_from_json(d: dict) -> Plant:
    """The nominal plant of a model JSON (the subset of the schema the generator writes)."""
    pl, fr = d["plant"], d["friction"]

    def curve(sfx):
        get = lambda k, dflt=None: fr.get(k + sfx, fr.get(k, dflt))  # noqa: E731
        Fc = float(get("Fc"))
        if fr["law"] == "coulomb-viscous":
            return Curve(Fc, Fc, 1.0, 2.0, float(get("b", 0.0)))
        return Curve(Fc, float(get("Fs")), float(get("vs")), float(get("beta", 2.0)), float(get("b", 0.0)))
    pos = curve("")
    neg = curve("_neg") if any(k.endswith("_neg") for k in fr) else pos
    cog = None
    if pl.get("cogging"):
        c = pl["cogging"][0]
        cog = (c["pitch"], tuple(c["cos"]), tuple(c["sin"]))
    law = "lugre" if fr["law"] == "lugre" else "static"
    return Plant(pl["mass"], pl.get("motor_constant", 1.0), pos, neg, offset=pl.get("offset", 0.0), law=law,
                 sigma0=fr.get("sigma0", 0.0), sigma1=fr.get("sigma1", 0.0), lag=fr.get("lag", 0.0),
                 cogging=cog, delay=pl.get("delay", 0.0))


def _pitch(q, r, step, stroke) -> float | None:
    """The spatial period [m] of the strongest periodic component of r against q: r averaged on
    a uniform position grid (bins of 5 typical steps, empty bins interpolated), its FFT
    periodogram between 20 steps and a quarter of the stroke."""
    width = 5 * step
    if not (width > 0 and stroke > 80 * width):
        return None
    idx = np.floor((q - q.min()) / width).astype(np.int64)
    cnt = np.bincount(idx)
    mean = np.bincount(idx, r) / np.maximum(cnt, 1)
    grid = np.arange(cnt.size)
    full = cnt > 0
    rb = np.interp(grid, grid[full], mean[full])
    P = np.abs(np.fft.rfft(rb - rb.mean())) ** 2
    wl = np.full(P.size, np.inf)
    wl[1:] = cnt.size * width / np.arange(1, P.size)
    band = (wl >= 20 * step) & (wl <= stroke / 4)
    if band.sum() < 3:
        return None
    return float(wl[band][np.argmax(P[band])])


def _peak_frequency(r, moving, dt) -> float | None:
    from scipy.signal import welch
    if moving.sum() < 256:
        return None
    f, P = welch(np.where(moving, r - r[moving].mean(), 0.0), fs=1 / dt, nperseg=min(2048, r.size // 4))
    band = (f >= 2.0) & (f <= 0.1 / dt)
    return float(f[band][np.argmax(P[band])]) if band.sum() >= 3 else None


def library(kin: measures.Kin, nominal: Plant, r: np.ndarray) -> tuple[np.ndarray, list, dict]:
    """(Theta (n, k), the cause of each column, physical scale info {cause: column indices})."""
    from scipy.signal import lsim
    H, v, a, q = kin.H, kin.v, kin.a, kin.q
    mv = kin.moving
    cols, names = [], []

    def add(name, x):
        cols.append(np.asarray(x, float))
        names.append(name)
    add("offset", np.ones_like(v))
    add("asymmetry", H(np.abs(v)))
    add("viscous", H(v))
    add("stribeck", H(np.sign(v)))
    speed = np.abs(v[mv])
    for pct in (10, 30, 60):
        vs = max(float(np.percentile(speed, pct)), 1e-9)
        add("stribeck", H(np.sign(v) * np.exp(-(v / vs) ** 2)))
    add("mass", a)
    add("delay", kin.cm * np.gradient(H(kin.u), kin.dt))
    step = float(np.median(np.abs(np.diff(q)[mv[1:]])))
    p = _pitch(q[mv], r[mv], step, float(np.ptp(q[mv])))
    if p is not None:
        for k in (1, 2, 3):
            add("cogging", H(np.cos(2 * np.pi * k * q / p)))
            add("cogging", H(np.sin(2 * np.pi * k * q / p)))
    f = _peak_frequency(r, mv, kin.dt)
    if f is not None:
        w = 2 * np.pi * f
        _, y, _ = lsim(([1.0, 0.0, 0.0], [1.0, 0.2 * w, w * w]), a, kin.t - kin.t[0])
        add("flexibility", y)
    c = nominal.pos
    if c.Fs > c.Fc and nominal.law != "lugre":
        x = np.abs(v) / c.vs
        slope = -(c.Fs - c.Fc) * c.beta * x ** (c.beta - 1) / c.vs * np.exp(-x ** c.beta)
        add("lag", H(-slope * a))
    if nominal.law != "lugre":
        stat = measures.static_friction(nominal, v)
        for slip in SLIPS:
            s0 = max(nominal.pos.Fs, nominal.neg.Fs) / slip
            lug = replace(nominal, law="lugre", sigma0=s0, sigma1=2 * 0.5 * math.sqrt(s0 * nominal.mass))
            add("reversal", H(measures.memory_friction(lug, v, kin.dt) - stat))
    return np.column_stack(cols), names, {"pitch": p, "frequency": f}


def _away_from_rest(kin: measures.Kin) -> np.ndarray:
    """The moving samples at least half a filter period (1 / (2 f_c)) from any sample that does
    not move: the low pass spreads the stick phases' friction error (the model's F(v) of a noisy
    v near 0 against the force that holds the mass) that far into the motion around them."""
    from scipy.ndimage import binary_erosion
    fc = min(measures.FC_HZ, 0.05 / kin.dt)
    half = int(math.ceil(0.5 / fc / kin.dt))
    return binary_erosion(kin.moving, structure=np.ones(2 * half + 1, bool), border_value=0)


def fit(kin: measures.Kin, nominal: Plant) -> dict:
    """STLSQ on the fitting record for every threshold in THRESHOLDS: {threshold: [(cause,
    |coefficient|), ...] ranked}, plus physical estimates of the simplest causes at each."""
    import pysindy as ps
    r = measures.residual(kin, nominal)
    mv = _away_from_rest(kin)
    if min(np.count_nonzero(kin.moving), np.count_nonzero(mv)) < MIN_MOVING:
        # a record that hardly moves has no sliding samples to regress on (it raised an
        # IndexError on reporting4's d0427): nothing to report, as sparse regression would say
        return dict(thresholds={f"{th:.6g}": dict(causes=[]) for th in THRESHOLDS}, pitch=None, frequency=None)
    Theta, names, hyper = library(kin, nominal, r)
    X = Theta[mv]
    y = r[mv]
    scale = np.sqrt(np.mean(X ** 2, axis=0))
    scale[scale == 0] = 1.0
    ys = max(float(np.sqrt(np.mean(y ** 2))), 1e-300)
    # the least-squares problems STLSQ solves on column subsets are the same on (R, Q^T y) of
    # the thin QR decomposition as on (X, y), and k x k instead of n x k
    Q, R = np.linalg.qr(X / scale)
    Xs, yn = R, Q.T @ (y / ys)
    out = {}
    for th in THRESHOLDS:
        opt = ps.STLSQ(threshold=th, alpha=RIDGE * X.shape[0], max_iter=20)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)      # "eliminated all coefficients"
            opt.fit(Xs, yn)
        coef = np.asarray(opt.coef_).reshape(-1)
        best: dict = {}
        support = coef != 0
        ss_full = _ss(Xs, yn, support)
        for name in dict.fromkeys(names):
            own = np.array([n == name for n in names]) & support
            if own.any():
                # the variance share only this cause's surviving terms explain: the refit
                # without them leaves that much more (nearly collinear terms of other causes
                # take over what they can; for one orthogonal term it is its coefficient^2)
                share = (_ss(Xs, yn, support & ~own) - ss_full) / X.shape[0]
                if share >= th * th:
                    best[name] = float(share)
        ranked = sorted(best.items(), key=lambda kv: -kv[1])
        phys = coef * ys / scale
        out[f"{th:.6g}"] = dict(causes=[{"name": n, "weight": w, "parameters": _parameters(n, names, phys, nominal)}
                                        for n, w in ranked])
    return dict(thresholds=out, pitch=hyper["pitch"], frequency=hyper["frequency"])


def _ss(R: np.ndarray, z: np.ndarray, cols: np.ndarray) -> float:
    """Residual sum of squares of z on the columns ``cols`` of R, least squares (the part of
    ||y||^2 outside R's span is left out: it cancels in differences)."""
    if not cols.any():
        return float(z @ z)
    w, *_ = np.linalg.lstsq(R[:, cols], z, rcond=None)
    e = z - R[:, cols] @ w
    return float(e @ e)


def _parameters(cause, names, phys, nominal: Plant) -> dict:
    """Final values of the simplest causes from the physical coefficients (others: none)."""
    def c(name):
        idx = [i for i, n in enumerate(names) if n == name]
        return float(phys[idx[0]]) if idx else 0.0
    if cause == "offset":
        return {"offset": nominal.offset + c("offset")}
    if cause == "viscous":
        return {"b": nominal.pos.b + c("viscous")}
    if cause == "mass":
        return {"mass": nominal.mass + c("mass")}
    if cause == "delay":
        return {"delay": nominal.delay + c("delay")}
    if cause == "asymmetry":
        return {"b_pos": nominal.pos.b + c("viscous") + c("asymmetry"),
                "b_neg": nominal.neg.b + c("viscous") - c("asymmetry")}
    return {}


def judge(dd: Path) -> dict:
    """The peer on one dataset directory (fitting record only; the validation record is not
    used: sparse regression has no validation step of its own)."""
    z = np.load(dd / "fit.npz")
    nominal = plant_from_json(json.loads((dd / "model.json").read_text()))
    kin = measures.Kin(z["t"], z["q"], z["u"], nominal.cm)
    return fit(kin, nominal)


def at_threshold(result: dict, threshold: float) -> list:
    """The ranked causes [{name, weight, parameters}] of a peer result at a threshold of
    THRESHOLDS."""
    return result["thresholds"][f"{threshold:.6g}"]["causes"]


def choose_threshold(clean_results: list, target: float = 0.05) -> float:
    """The smallest threshold (most sensitive) at which at most ``target`` of the clean tuning
    datasets report anything; the largest threshold when none does."""
    for th in THRESHOLDS:
        alarms = sum(bool(at_threshold(r, th)) for r in clean_results)
        if alarms <= target * len(clean_results):
            return th
    return THRESHOLDS[-1]
