"""A resonance the rigid model lacks, searched on the re-simulated loop where the force channel
is skipped (too few sliding samples) and no one-parameter loop candidate was named.

The force channel finds a resonance from the measured acceleration's ringing on the sliding
samples (:mod:`~hunting.diagnose.causes.flexibility`): a record that barely slides gives it
nothing to fit. Its loop still rings after every move and every slip. Here the load on its
spring is fitted on the fitting record's re-simulated position: a grid of frequencies
(FREQUENCIES_PER_OCTAVE per octave from F_MIN to the lower of F_MAX and NYQUIST_SHARE of the
Nyquist frequency) times load shares of the whole mass (SHARES) at damping ratio DAMPING, then
Nelder-Mead on log frequency, the share's logit and log damping (at most REFINE evaluations). It
is named when it cuts both records' position RMS error by at least
:data:`~hunting.diagnose.causes.presliding.LOOP_GAIN`, the loop channel's bar, and the validation
record's own fit (the same search on that record) finds the same load (its frequency and load
mass: AGREE_FREQUENCY, AGREE_FACTOR); both records' fits give its uncertainties
(:func:`~hunting.diagnose.loop_sigma.two_records`).

Three coefficients fitted on one record's loop fit much of any stick-slip error there, and the
nominal loop of a clean record can be far from the measured one (a contact resting on a steep
cogging flank, a saturated loop): on the 58 clean records of reporting62-64 whose force channel
was skipped (development) the fit cut the fitting record's error by up to 89 % (reporting62
d0105), and on two the validation record's too: reporting63 d0277 (128.6 Hz, 11 % of the mass:
73 and 64 %) and d0216 (7.3 Hz: 86 and 46 %); of the 53 effect records of those sets whose force
channel was skipped, reporting63 d0423 (a saturation, 5.6 Hz: 77 and 73 %). No bar on the gains
separates them from a true load (seed-10 d0086: 97 and 83 %) with any room. The validation
record's own fit does: it finds d0086's load again within 0.4 % in frequency and 0.9 % in load
mass, and puts the others' 8-13 % away in frequency, d0277's and d0216's with 2.7 times the load
mass. It runs apart from the one-parameter candidates
(:func:`hunting.diagnose.loop_channel.judge`), after them, so a fit this flexible never stands
before one of theirs on the fitting record. The independent generator's seed-10 d0086 (a 19.5 Hz
load, 26 % of the mass, damping 0.029, fewer than 100 sliding samples): 19.6 Hz, 26 %, 0.030."""
from __future__ import annotations

import numpy as np

from .causes import flexibility
from .causes.presliding import LOOP_GAIN
from .data import Measurement
from .model import NominalModel

F_MIN = 3.0                     # [Hz] the lowest frequency tried
F_MAX = 300.0                   # [Hz] the highest, unless the sampling bounds it lower
NYQUIST_SHARE = 0.4             # the highest frequency tried at most this share of the Nyquist frequency
FREQUENCIES_PER_OCTAVE = 3
SHARES = (0.1, 0.3, 0.6)        # the load's share of the whole mass on the grid
SHARE_MAX = 0.95                # the largest share the refinement may reach
DAMPING = 0.05                  # the damping ratio on the grid
DAMPING_RANGE = (0.002, 1.0)    # the damping ratios the refinement may reach
REFINE = 40                     # Nelder-Mead evaluations after the grid
SIGMA_STEP = 0.01               # half step of the coefficients' central differences
# the validation record's own fit (its own grid) must find the same load: its frequency within
# AGREE_FREQUENCY (relative) and its load mass within a factor AGREE_FACTOR of the fitting
# record's. Set on the development records (module docstring): the true d0086 0.4 % and 0.9 %; the
# clean reporting63 d0277 and d0216 11 and 13 % in frequency, 2.7 times in load mass; reporting63
# d0423's extra (a saturated loop) 8.4 % in frequency. Not the damping ratio, which the ringing's
# decay on one record fixes least: the independent seed-11 d0081 (an 18.4 Hz load, damping 0.029,
# held out until then) was fitted at 18.4 Hz and 0.030 on the fitting record, cut both errors by
# 79 %, and its validation record's own fit found the same frequency and load mass at damping 0.083
AGREE_FREQUENCY = 0.05
AGREE_FACTOR = 1.5


def frequencies(meas: Measurement) -> np.ndarray:
    """The grid's frequencies [Hz] on record ``meas``: geometric, FREQUENCIES_PER_OCTAVE per
    octave from F_MIN to min(F_MAX, NYQUIST_SHARE / (2 dt)); empty where that is below F_MIN."""
    top = min(F_MAX, NYQUIST_SHARE * 0.5 / meas.dt)
    if top <= F_MIN:
        return np.array([])
    n = 1 + int(np.ceil(FREQUENCIES_PER_OCTAVE * np.log2(top / F_MIN)))
    return np.geomspace(F_MIN, top, n)


def _model(model: NominalModel, x) -> NominalModel:
    """``model`` with a load at coefficients x = (log frequency [Hz], logit of its share of the
    whole mass, log damping ratio), the share and damping clipped to their ranges."""
    share = min(1.0 / (1.0 + np.exp(-float(x[1]))), SHARE_MAX)
    zeta = float(np.clip(np.exp(float(x[2])), *DAMPING_RANGE))
    return flexibility.extend(model, np.array([share * model.mass]),
                              {"frequency": float(np.exp(float(x[0]))), "damping": zeta})


def _coefficients(frequency: float, share: float, damping: float) -> np.ndarray:
    return np.array([np.log(frequency), np.log(share / (1.0 - share)), np.log(damping)])


def fit(meas: Measurement, model: NominalModel) -> tuple[np.ndarray | None, float]:
    """(x, error): the load's coefficients (:func:`_model`) that minimize the re-simulated position
    RMS error [m] on ``meas``, and that error: the grid (module docstring), then Nelder-Mead (at
    most REFINE evaluations); (None, inf) where nothing re-simulates."""
    from scipy.optimize import minimize

    from .loop_grid import cached_errors
    cache = {}

    def costs(xs):
        return cached_errors(meas, cache, xs, lambda x: tuple(np.round(np.asarray(x, float), 9)),
                             lambda x: _model(model, x))
    points = [_coefficients(f, s, DAMPING) for f in frequencies(meas) for s in SHARES]
    if not points:
        return None, np.inf
    errs = costs(points)
    k = int(np.argmin(errs))
    if not np.isfinite(errs[k]):
        return None, np.inf
    x0 = points[k]
    # steps of a fifth of an octave in frequency, about a factor 2 in the share and the damping
    simplex = x0 + np.array([[0.0, 0.0, 0.0], [0.14, 0.0, 0.0], [0.0, 0.7, 0.0], [0.0, 0.0, 0.7]])
    minimize(lambda x: min(costs([x])[0], 1e300), x0, method="Nelder-Mead",
             options=dict(maxfev=REFINE, xatol=0.01, fatol=0.0, initial_simplex=simplex))
    best = min(cache, key=cache.get)
    return np.array(best), cache[best]


def parameters(model: NominalModel, x) -> dict:
    """The resonance's final parameters (:func:`hunting.diagnose.causes.flexibility.parameters`)
    at coefficients x."""
    ext = _model(model, x).flexibility
    return flexibility.parameters(np.array([ext.load_mass]), {"frequency": ext.frequency, "damping": ext.damping},
                                  model)


def judge(fit_meas: Measurement, val_meas: Measurement, model: NominalModel) -> dict:
    """The loop's verdict on a resonance (module docstring): ``x`` (coefficients, or None),
    ``fit`` and ``val`` (nominal, extended) position RMS errors [m], ``gain_fit``, ``gain_val``,
    ``significant``, ``reason`` where not, and where it is ``model`` (the extended model),
    ``parameters`` and ``sigma`` (standard uncertainties of load_mass, frequency, damping and
    stiffness; None where the records do not resolve one)."""
    from .resimulate import position_rms_error
    f0, v0 = position_rms_error(fit_meas, model), position_rms_error(val_meas, model)
    out = dict(x=None, fit=(f0, np.inf), val=(v0, np.inf), gain_fit=-np.inf, gain_val=None, significant=False)
    if model.flexibility is not None:
        return dict(out, reason="the model has a flexible load already")
    if not (np.isfinite(f0) and f0 > 0 and np.isfinite(v0) and v0 > 0):
        return dict(out, reason="the nominal loop does not re-simulate these records")
    x, f1 = fit(fit_meas, model)
    if x is None:
        why = ("no load re-simulates the fitting record" if frequencies(fit_meas).size else
               f"the fitting record's sampling leaves no frequency above {F_MIN:g} Hz to try")
        return dict(out, reason=why)
    gain_fit = 1.0 - f1 / f0
    out.update(x=x, fit=(f0, f1), gain_fit=gain_fit)
    p = parameters(model, x)
    at = f"{p['frequency']:.3g} Hz, {p['load_mass']:.3g} kg, damping ratio {p['damping']:.2g}"
    if gain_fit < LOOP_GAIN:
        return dict(out, reason=(f"a load on a spring fitted on the fitting record's loop ({at}) cuts its re-simulated "
                                 f"position error by {gain_fit:.1%} ({LOOP_GAIN:.0%} needed on both records)"))
    ext = _model(model, x)
    v1 = position_rms_error(val_meas, ext)
    gain_val = 1.0 - v1 / v0 if np.isfinite(v1) else None
    out.update(val=(v0, v1), gain_val=gain_val)
    if gain_val is None or gain_val < LOOP_GAIN:
        g = "nothing" if gain_val is None else f"{gain_val:.1%}"
        return dict(out, reason=(f"a load on a spring fitted on the fitting record's loop ({at}; {gain_fit:.1%} there) "
                                 f"cuts the validation record's position error by {g} ({LOOP_GAIN:.0%} needed)"))
    x_val, _ = fit(val_meas, model)
    disagree = _disagreement(model, x, x_val)
    if disagree:
        return dict(out, reason=(f"a load on a spring fitted on the fitting record's loop ({at}) cuts the position error "
                                 f"by {gain_fit:.1%} there and {gain_val:.1%} on the validation record, but {disagree}: "
                                 "not one resonance of the machine"))
    return dict(out, significant=True, model=ext, parameters=p, sigma=_sigma(fit_meas, model, x, x_val, p))


def _disagreement(model: NominalModel, x: np.ndarray, x_val: np.ndarray | None) -> str | None:
    """Where the validation record's own fit x_val puts the load elsewhere than the fitting
    record's x (AGREE_FREQUENCY, AGREE_FACTOR), in words; None where they agree."""
    if x_val is None:
        return "the validation record's own fit does not re-simulate"
    a, b = parameters(model, x), parameters(model, x_val)
    words = []
    if abs(b["frequency"] / a["frequency"] - 1.0) > AGREE_FREQUENCY:
        words.append(f"{b['frequency']:.3g} Hz against {a['frequency']:.3g} Hz ({AGREE_FREQUENCY:.0%} allowed)")
    if max(a["load_mass"], b["load_mass"]) > AGREE_FACTOR * min(a["load_mass"], b["load_mass"]):
        words.append(f"load mass {b['load_mass']:.3g} kg against {a['load_mass']:.3g} kg "
                     f"(a factor {AGREE_FACTOR:g} allowed)")
    return None if not words else "the validation record's own fit finds " + ", ".join(words)


def _sigma(fit_meas: Measurement, model: NominalModel, x: np.ndarray, x_val: np.ndarray, p: dict) -> dict:
    """Standard uncertainties of the parameters ``p`` fitted at coefficients x on the fitting
    record's loop: the sandwich estimate of the three coefficients together
    (:func:`~hunting.diagnose.loop_sigma.coefficients_sigma`), or the spread against the validation
    record's own fit x_val where larger (:func:`~hunting.diagnose.loop_sigma.two_records`),
    carried to the parameters by the delta method (the stiffness's from the load mass's and the
    frequency's in quadrature)."""
    from .loop_sigma import coefficients_sigma, two_records
    within = coefficients_sigma(fit_meas, lambda c: _model(model, c), x, np.full(3, SIGMA_STEP)) or [None] * 3
    s = [two_records(w, xf, xv) for w, xf, xv in zip(within, x, x_val)]
    share = p["load_mass"] / model.mass
    sig = {"frequency": None if s[0] is None else float(p["frequency"] * s[0]),
           # d share / d logit = share (1 - share)
           "load_mass": None if s[1] is None else float(model.mass * share * (1.0 - share) * s[1]),
           "damping": None if s[2] is None else float(p["damping"] * s[2])}
    if sig["load_mass"] is not None and sig["frequency"] is not None:
        sig["stiffness"] = float(p["stiffness"] * np.hypot(sig["load_mass"] / p["load_mass"],
                                                           2.0 * sig["frequency"] / p["frequency"]))
    else:
        sig["stiffness"] = None
    return sig


def evidence_text(r: dict, why: str) -> str:
    """The rule a loop resonance ``r`` (:func:`judge`) met, in words, after ``why`` the loop judged it."""
    return (f"{why}; the loop re-simulated with a load on a spring (its frequency, mass and damping fitted on the "
            f"fitting record's position) follows both records better: position RMS error -{r['gain_fit']:.0%} "
            f"fitting, -{r['gain_val']:.0%} validation (at least {LOOP_GAIN:.0%} on both needed)")
