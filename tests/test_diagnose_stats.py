"""The diagnosis' tests hold their false-alarm rate on correlated residuals: noise with no effect
in it (AR(1) near a unit root, a lightly damped AR(2), noise whose level follows the
acceleration), passed through the acceleration's filter like a real force residual, against the
regressors of real causes on a stroke programme. The out-of-sample test must reject at most at
its nominal level; the plain least-squares t test must not (else this test could not tell a
calibrated rule from a broken one)."""
import numpy as np
import pytest
from scipy import stats as st
from scipy.signal import lfilter

from hunting.diagnose import Measurement, NominalModel, kinematics
from hunting.diagnose.causes import CAUSES
from hunting.diagnose.stats import NoiseModel, Samples, autocovariance, out_of_sample
from hunting.diagnose.synthetic import bang_bang

MODEL = NominalModel.from_dict({"plant": {"mass": 2.0, "motor_constant": 1.0},
                                "friction": {"law": "coulomb-viscous", "Fc": 5.0, "b": 20.0}})
ALPHA = 0.05
DRAWS = 150


def _kin(seed):
    fs = 1000.0
    q = bang_bang(fs, 10.0, stroke=0.1, seed=seed, rest=(0.05, 0.3), speed=(0.05, 0.2))
    t = np.arange(q.size) / fs
    v = np.gradient(q, 1 / fs)
    u = MODEL.mass * np.gradient(v, 1 / fs) + MODEL.friction(v)
    return kinematics(Measurement(t, q, u), 1.0, resolution=0.0)


KF, KV = _kin(1), _kin(2)
SF, SV = Samples.thin(KF.moving, 10), Samples.thin(KV.moving, 10)


def _noise(kind, kin, rng):
    n = kin.t.size
    w = rng.normal(size=n)
    if kind == "ar1":
        x = lfilter([1.0], [1.0, -0.99], w)
    elif kind == "ar2":                               # a 30 Hz resonance, damping 0.02
        r, th = 0.98, 2 * np.pi * 30e-3
        x = lfilter([1.0], [1.0, -2 * r * np.cos(th), r * r], w)
    else:                                            # level following |a|, coloured
        x = lfilter([1.0], [1.0, -0.95], w) * (0.3 + np.abs(kin.a) / np.abs(kin.a).max())
    x = kin.filtered(x)
    return x / x.std()


def _naive(e0, yhat):
    """Plain least-squares one-sided t test of gamma (independent samples assumed)."""
    g = float(yhat @ e0) / float(yhat @ yhat)
    s2 = float(np.sum((e0 - g * yhat) ** 2)) / (e0.size - 1)
    return float(st.norm.sf(g / np.sqrt(s2 / float(yhat @ yhat))))


@pytest.mark.parametrize("kind", ["ar1", "ar2", "hetero"])
def test_out_of_sample_test_holds_its_level_on_correlated_noise(kind):
    rng = np.random.default_rng({"ar1": 1, "ar2": 2, "hetero": 3}[kind])
    names = ("offset", "viscous", "mass", "delay")
    Xf = {n: CAUSES[n].design(KF, MODEL, CAUSES[n].hypers(KF, MODEL)[0])[SF.idx] for n in names}
    Xv = {n: CAUSES[n].design(KV, MODEL, CAUSES[n].hypers(KF, MODEL)[0])[SV.idx] for n in names}
    ours = {n: [] for n in names}
    naive = []
    for _ in range(DRAWS):
        ef, ev = _noise(kind, KF, rng)[SF.idx], _noise(kind, KV, rng)[SV.idx]
        for n in names:
            th, *_ = np.linalg.lstsq(Xf[n], ef, rcond=None)          # a "cause" fitted on pure noise
            yhat = Xv[n] @ th
            noise = NoiseModel.fit(ev - yhat, SV.run)
            ours[n].append(out_of_sample(ev, yhat, SV.run, noise)[2])
            naive.append(_naive(ev, yhat))
    # three standard errors above the nominal level at this number of draws
    bound = ALPHA + 3 * np.sqrt(ALPHA * (1 - ALPHA) / DRAWS)
    rates = {n: float(np.mean(np.array(p) < ALPHA)) for n, p in ours.items()}
    assert max(rates.values()) <= bound, rates
    # independent samples assumed: false alarms several times the level (the test can tell)
    if kind != "ar2":
        assert np.mean(np.array(naive) < ALPHA) > 2 * bound


def test_noise_model_recovers_an_ar2_process_and_skips_gaps():
    """Yule-Walker inside runs: an AR(2) process cut into runs gives its coefficients back, and a
    jump between runs (a level change across a gap) does not enter the autocovariance."""
    rng = np.random.default_rng(5)
    phi = np.array([1.2, -0.5])
    e = lfilter([1.0], [1.0, -phi[0], -phi[1]], rng.normal(size=40_000))
    run = np.repeat(np.arange(40), 1000)
    e = e + 50.0 * (run % 2)                     # every other run offset by far more than its spread
    e = e - np.repeat([e[run == r].mean() for r in range(40)], 1000)
    nm = NoiseModel.fit(e, run)
    assert nm.order == 2 and np.allclose(nm.phi, phi, atol=0.02)
    c = autocovariance(e, run, 3)
    assert c[1] / c[0] == pytest.approx(phi[0] / (1 - phi[1]), abs=0.02)


def test_out_of_sample_with_no_residual_left_is_no_test():
    """A prediction that reproduces the validation residual exactly leaves no variance to judge
    it by: p = 1, not a ZeroDivisionError (blind reporting3 d0004: a diverging prediction of
    1.9e24 N fitted 105 samples exactly and crashed the diagnosis)."""
    from hunting.diagnose.stats import NoiseModel, out_of_sample
    y = np.sin(np.linspace(0.0, 20.0, 105)) * 1e24
    run = np.repeat([0, 1, 2], 35)
    gamma, t, p = out_of_sample(y.copy(), y, run, NoiseModel(np.zeros(0), 1.0))
    assert gamma == pytest.approx(1.0) and p == 1.0




def test_out_of_sample_with_an_alternating_residual_keeps_a_variance():
    """An over-differenced residual (lag-1 autocorrelation -1/2) beside a smooth prediction makes
    the truncated sum of autocovariances non-positive; it read as no variance and p = 1 for a
    prediction that explains all of the residual (blind reporting8 d0530: a level change of 98 %
    of the validation residual, rejected). The lag-0 term stands in: a finite variance, p ~ 0."""
    from hunting.diagnose.stats import long_run_meat
    rng = np.random.default_rng(3)
    w = rng.normal(0.0, 0.01, 401)
    noise = w[1:] - w[:-1]
    yhat = np.full(400, 0.2)
    run = np.zeros(400, np.int64)
    S = long_run_meat(yhat[:, None], noise, run)
    assert S[0, 0] > 0
    gamma, t, p = out_of_sample(yhat + noise, yhat, run, NoiseModel(np.zeros(0), float(noise.var())))
    assert gamma == pytest.approx(1.0, abs=0.01) and np.isfinite(t) and p < 1e-6
def _feedback_draw(rng, theta=2.0):
    """A regressor measured with the noise that also drives the residual (feedback puts the
    sensor's noise into the drive and into the force balance alike): x_meas = x + n, y = theta x
    - 0.8 n + e, with coloured n and e; the instrument is x itself, plus its own small error."""
    m = SF.idx.size
    x = KF.filtered(np.sin(np.linspace(0, 40 * np.pi, KF.t.size)) * (1 + KF.v / np.abs(KF.v).max()))[SF.idx]
    x = x / x.std()
    n = lfilter([1.0], [1.0, -0.7], rng.normal(size=m)) * 0.5
    e = lfilter([1.0], [1.0, -0.9], rng.normal(size=m)) * 0.3
    y = theta * x - 0.8 * n + e
    z = x + 0.1 * lfilter([1.0], [1.0, -0.5], rng.normal(size=m))
    return (x + n)[:, None], z[:, None], y


def test_instrumented_estimate_removes_the_feedback_bias_and_covers_its_truth():
    """Errors in variables: least squares (prewhitened or not) of a residual on a regressor that
    carries the residual's own noise is biased; the instrumented estimate is not, and its
    standard error covers the truth near its nominal rate: 1.96 sigma held 90.5 % of 200 draws
    (nominal 95 %; without the autocorrelation terms 63 %)."""
    from hunting.diagnose.stats import gls, instrumented
    rng = np.random.default_rng(11)
    iv, ls, cover = [], [], []
    for _ in range(200):
        X, Z, y = _feedback_draw(rng)
        noise = NoiseModel.fit(y - X[:, 0] * np.linalg.lstsq(X, y, rcond=None)[0], SF.run)
        th, cov, _, _ = instrumented(X, Z, y, SF.run, noise)
        iv.append(th[0])
        ls.append(gls(X, y, SF.run, noise)[0][0])
        cover.append(abs(th[0] - 2.0) <= 1.96 * np.sqrt(cov[0, 0]))
    assert abs(np.median(iv) - 2.0) < 0.05, np.median(iv)
    assert abs(np.median(ls) - 2.0) > 0.1, np.median(ls)        # the bias the instrument removes
    assert 0.85 <= np.mean(cover) <= 0.99, np.mean(cover)


def test_out_of_sample_with_few_windows_reads_student_t():
    """With dof degrees of freedom the tail is Student's t: reporting8 d0096 (clean, 4.6 filter
    windows of validation data) had an 'offset' at t = 4.3, p = 8.5e-6 from the normal; with 3.6
    degrees of freedom it is 0.01. Without dof the normal is kept."""
    rng = np.random.default_rng(5)
    yhat = np.sin(np.linspace(0.0, 6.0, 60))
    e0 = 0.3 * yhat + rng.normal(0.0, 0.5, 60)
    run = np.zeros(60, np.int64)
    nm = NoiseModel(np.zeros(0), 0.25)
    g, t, p_norm = out_of_sample(e0, yhat, run, nm)
    _, t2, p_t = out_of_sample(e0, yhat, run, nm, dof=3.6)
    assert t2 == t and p_norm == pytest.approx(st.norm.sf(t)) and p_t == pytest.approx(st.t.sf(t, 3.6))
    assert p_t > p_norm


def test_relative_changes_of_nothing_are_zero_and_of_a_failed_run_minus_inf():
    """A noise-free record of the nominal model leaves residuals and position errors of exactly 0:
    their relative changes were 0 / 1e-300 (reasons quoted -100.0 %, -999.0 % and -5.3e+293 %)."""
    from hunting.diagnose import force
    from hunting.diagnose.stats import relative_fall, relative_gain
    assert relative_gain(0.0, 0.0) == 0.0 and relative_gain(1.0, 0.0) == np.inf
    assert relative_gain(3.0, 2.0) == pytest.approx(0.5)
    assert relative_fall(0.0, 0.0) == 0.0
    assert relative_fall(0.0, 1e-7) == -np.inf
    assert relative_fall(2.0, np.inf) == -np.inf
    assert relative_fall(np.inf, 1.0) == 1.0 and relative_fall(np.inf, np.inf) == -np.inf
    assert relative_fall(np.nan, 1.0) == -np.inf and relative_fall(1.0, np.nan) == -np.inf
    assert relative_gain(np.inf, 1.0) == np.inf and relative_gain(1.0, np.inf) == -1.0
    assert relative_fall(2.0, 0.5) == pytest.approx(0.75)
    assert force._shape_gain(np.zeros(8), np.ones(8)) == 0.0
    e = np.linspace(-1.0, 1.0, 8)
    assert force._shape_gain(e, e) > 1e6        # the shape explains it all


def test_a_share_just_below_its_bar_does_not_read_as_the_bar():
    """'explain 5.0% ... (at least 5% needed)' for a share of 0.04996 (reporting31 reasons)."""
    from hunting.diagnose.causes._words import pct_against
    assert pct_against(0.04996, 0.05) == "4.996%"
    assert pct_against(0.048, 0.05) == "4.8%" and pct_against(-0.3, 0.05) == "-30.0%"
    assert pct_against(0.05, 0.05) == "5.0%"
