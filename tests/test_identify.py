"""FRF estimation and low-order fits on linear systems with known transfer functions."""
import numpy as np
import pytest
from scipy import signal

from hunting import SystemDefinitionError
from hunting.identify import (controller_frf, estimate_frf, fit_double_integrator, fit_second_order,
                              plant_from_sensitivity)
from hunting.identify.frf import prbs
from hunting.models import PID

FS = 10_000.0


def _simulate(num, den, u):
    sysd = signal.cont2discrete((num, den), 1 / FS, method="bilinear")
    return signal.lfilter(sysd[0].ravel(), sysd[1], u)


def test_frf_of_a_second_order_system_and_sk_fit():
    """Presliding-like model cm / (J s^2 + c s + k): the FRF and the fitted parameters."""
    J, c, k, cm = 0.018, 4.47, 1.21e4, 16.0
    u = prbs(2 ** 17, bandwidth=500.0, fs=FS, seed=1)
    y = _simulate([cm], [J, c, k], u)
    frf = estimate_frf(u, y, FS)
    w = 2 * np.pi * frf.f
    true = cm / (J * (1j * w) ** 2 + c * (1j * w) + k)
    band = (frf.f > 5) & (frf.f < 300)
    # bilinear discretization warps frequencies by tan(w/2fs) (<0.3 % below 300 Hz)
    assert np.max(np.abs(frf.H[band] / true[band] - 1)) < 0.02
    assert np.all(frf.coherence[band] > 0.99)
    fit = fit_second_order(frf, 5.0, 300.0)
    assert fit["a0"] == pytest.approx(k / J, rel=0.01)           # sigma0 / J
    assert fit["a1"] == pytest.approx(c / J, rel=0.03)           # (sigma1 + sigma2) / J
    assert fit["b0"] == pytest.approx(cm / J, rel=0.01)
    assert fit.residual < 0.02 and all(v > 0 for v in fit.sigma.values())


def test_closed_loop_sensitivity_gives_the_double_integrator():
    """Weak PD loop around a mass, excitation v at the controller output (thesis Fig. 10.3):
    S = W/V and P = (1/S - 1)/C recover cm/m."""
    m, cm = 8.93, 74.4
    pd = PID(kp=50.0, kd=2.0, ki=0.0)
    # closed loop from v to w = u + v: S = 1 / (1 + P C), P = cm / (m s^2)
    num_s = [m, 0.0, 0.0]
    den_s = [m, cm * pd.kd, cm * pd.kp]
    v = prbs(2 ** 17, bandwidth=500.0, fs=FS, amplitude=0.1, seed=2)
    w = _simulate(num_s, den_s, v)
    S = estimate_frf(v, w, FS)
    P = plant_from_sensitivity(S, pd)
    fit = fit_double_integrator(P, 2.0, 100.0)
    assert fit["g"] == pytest.approx(cm / m, rel=0.01)
    assert fit.sigma["g"] < 0.01 * fit["g"]
    Cv = controller_frf(pd, np.array([10.0]))
    assert Cv[0] == pytest.approx(50.0 + 2.0 * 2j * np.pi * 10.0)


def test_errors_are_named():
    with pytest.raises(SystemDefinitionError, match="must match"):
        estimate_frf(np.zeros(10), np.zeros(11), FS)
    with pytest.raises(SystemDefinitionError, match="fewer than nperseg"):
        estimate_frf(np.zeros(100), np.zeros(100), FS)
    with pytest.raises(SystemDefinitionError, match="fs = -1 is not allowed"):
        estimate_frf(np.zeros(100), np.zeros(100), -1)


def test_stribeck_fit_recovers_table_10_2_per_direction():
    from hunting.identify import fit_stribeck
    from hunting.models import StribeckCurve
    rng = np.random.default_rng(3)
    pos = StribeckCurve(13.35, 28.3, 0.019, 2.0, 36.45)
    neg = StribeckCurve(13.45, 27.5, 0.020, 2.0, 37.95)
    vp = np.geomspace(0.002, 0.4, 40)
    v = np.concatenate([vp, -vp])
    F = np.concatenate([pos.force(vp), -neg.force(vp)]) + rng.normal(0, 0.1, 2 * vp.size)
    fits = fit_stribeck(v, F, direction_dependent=True)
    for key, true in (("positive", pos), ("negative", neg)):
        f = fits[key]
        for name, t, tol in (("Fc", true.Fc, 0.02), ("Fs", true.Fs, 0.02), ("vs", true.vs, 0.05), ("b", true.b, 0.03)):
            assert f[name] == pytest.approx(t, rel=tol), (key, name)
            assert abs(f[name] - t) < 5 * f.sigma[name] + 1e-12    # uncertainty is honest
        assert f.residual == pytest.approx(0.1, rel=0.3)
    with pytest.raises(SystemDefinitionError, match="v = 0 is not allowed"):
        fit_stribeck([0.0, 0.1, 0.2, 0.3, 0.4], [0, 1, 1, 1, 1])


def test_cogging_table_from_a_slow_two_direction_run():
    from hunting.identify import cogging_table
    rng = np.random.default_rng(4)
    q = np.linspace(-0.45, -0.05, 8001)
    cog = lambda x: 5.0 * np.sin(2 * np.pi * x / 0.015) + 2.0 * np.sin(2 * np.pi * x / 0.0075 + 0.4)  # noqa: E731
    Fp = cog(q) + 14.0 + rng.normal(0, 0.5, q.size)       # moving +: friction offset +14 N
    Fn = cog(q) - 13.5 + rng.normal(0, 0.5, q.size)       # moving -: -13.5 N
    tab = cogging_table(np.concatenate([q, q[::-1]]), np.concatenate([Fp, Fn[::-1]]),
                        np.concatenate([np.full(q.size, 0.05), np.full(q.size, -0.05)]))
    qq = np.linspace(-0.44, -0.06, 500)
    err = tab(qq) - cog(qq)
    err -= err.mean()                                      # a constant shift is the friction mean
    assert np.sqrt(np.mean(err ** 2)) < 0.05 * 5.0         # small against the amplitude


def test_fragments_average_like_one_record():
    """Fragments (a record cut where the thesis removes velocity reversals) average their
    segments: on a known system the estimate matches the truth and the averages add up."""
    J, c, k, cm = 0.018, 4.47, 1.21e4, 16.0
    u = prbs(2 ** 17, bandwidth=500.0, fs=FS, seed=2)
    y = _simulate([cm], [J, c, k], u)
    cuts = [slice(0, 40_000), slice(50_000, 90_000), slice(100_000, 131_072)]
    parts = [estimate_frf(u[s], y[s], FS) for s in cuts]
    frf = estimate_frf([u[s] for s in cuts], [y[s] for s in cuts], FS)
    assert frf.n_averages == sum(p.n_averages for p in parts)
    w = 2 * np.pi * frf.f
    true = cm / (J * (1j * w) ** 2 + c * (1j * w) + k)
    band = (frf.f > 5) & (frf.f < 300)
    assert np.max(np.abs(frf.H[band] / true[band] - 1)) < 0.03
    with pytest.raises(SystemDefinitionError, match="fewer than nperseg"):
        estimate_frf([u[:100]], [y[:100]], FS)
