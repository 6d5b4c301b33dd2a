"""The loop fit's standard uncertainty (hunting.diagnose.loop_sigma) against analytic values and
a Monte Carlo spread."""
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.signal import lfilter

from hunting.diagnose import loop_sigma, resimulate


@pytest.mark.parametrize("phi", [0.0, 0.5, 0.9, 0.99])
def test_integrated_time_of_ar1(phi):
    """tau = (1 + phi) / (1 - phi) for an AR(1) series, within 10 % on 2e5 samples."""
    x = lfilter([1.0], [1.0, -phi], np.random.default_rng(1).standard_normal(200_000))
    assert loop_sigma.integrated_time(x) == pytest.approx((1 + phi) / (1 - phi), rel=0.1)


def test_coefficient_sigma_matches_the_spread_of_the_estimate(monkeypatch):
    """A linear 'loop' q_sim(x) = x g(t) under AR(1) noise (phi 0.95): the stated sigma at the
    least-squares x matches the spread of x over 300 noise draws within 15 %, and is about
    sqrt(tau) times the white-noise formula's."""
    t = np.linspace(0.0, 10.0, 5000)
    g = np.sin(2 * np.pi * 0.3 * t) + 0.5 * np.sign(np.sin(2 * np.pi * 0.11 * t))
    monkeypatch.setattr(resimulate, "resimulate", lambda meas, m: SimpleNamespace(q=m * g, ok=True))
    rng = np.random.default_rng(7)
    xs, sigmas = [], []
    for _ in range(300):
        e = lfilter([1.0], [1.0, -0.95], 1e-3 * rng.standard_normal(t.size))
        q = 2.0 * g + e
        x = float(g @ q / (g @ g))
        xs.append(x)
        sigmas.append(loop_sigma.coefficient_sigma(SimpleNamespace(q=q), lambda v: v, x, 0.01))
    assert np.median(sigmas) == pytest.approx(np.std(xs), rel=0.15)
    white = np.sqrt(np.mean(np.square(lfilter([1.0], [1.0, -0.95], 1e-3 * rng.standard_normal(t.size))))) \
        / np.sqrt(g @ g)
    assert np.median(sigmas) > 3 * white


def test_coefficients_sigma_matches_the_spread_of_two_correlated_estimates(monkeypatch):
    """Two coefficients fitted together on a linear 'loop' q_sim(x) = x0 g0(t) + x1 g1(t) whose
    shapes are strongly correlated (0.9), under AR(1) noise (phi 0.9): each stated sigma matches
    its estimate's spread over 300 draws within 15 %, and is larger than the one-coefficient
    estimate (which holds the other coefficient fixed and misses the correlation)."""
    t = np.linspace(0.0, 10.0, 4000)
    g0 = np.sin(2 * np.pi * 0.3 * t) + 0.5 * np.sign(np.sin(2 * np.pi * 0.11 * t))
    g1 = 0.9 * g0 + np.sqrt(1 - 0.81) * np.cos(2 * np.pi * 0.23 * t) * np.std(g0) / np.std(np.cos(2 * np.pi * 0.23 * t))
    G = np.column_stack([g0, g1])
    monkeypatch.setattr(resimulate, "resimulate", lambda meas, m: SimpleNamespace(q=G @ m, ok=True))
    rng = np.random.default_rng(11)
    xs, sigmas, single = [], [], []
    for _ in range(300):
        q = G @ np.array([2.0, -1.0]) + lfilter([1.0], [1.0, -0.9], 1e-3 * rng.standard_normal(t.size))
        x, *_ = np.linalg.lstsq(G, q, rcond=None)
        xs.append(x)
        sigmas.append(loop_sigma.coefficients_sigma(SimpleNamespace(q=q), lambda v: v, x, np.full(2, 0.01)))
        single.append(loop_sigma.coefficient_sigma(SimpleNamespace(q=q), lambda v: np.array([v, x[1]]), x[0], 0.01))
    xs, sigmas = np.array(xs), np.array(sigmas, float)
    for j in range(2):
        assert np.median(sigmas[:, j]) == pytest.approx(np.std(xs[:, j]), rel=0.15)
    assert np.median(sigmas[:, 0]) > 1.5 * np.median(single)


def test_coefficients_sigma_is_none_for_a_coefficient_the_record_does_not_resolve(monkeypatch):
    """A second coefficient that moves the 'loop' 1e-8 as much as the first (a dwell time every
    rest outlasts): no finite uncertainty for it (a pseudo-inverse reported ~1e-14), while the
    first keeps its one-coefficient value."""
    t = np.linspace(0.0, 10.0, 2000)
    g0, g1 = np.sin(2 * np.pi * 0.3 * t), np.cos(2 * np.pi * 0.7 * t)
    G = np.column_stack([g0, 1e-8 * g1])
    monkeypatch.setattr(resimulate, "resimulate", lambda meas, m: SimpleNamespace(q=G @ m, ok=True))
    q = G @ np.array([2.0, 1.0]) + 1e-3 * np.random.default_rng(3).standard_normal(t.size)
    x = np.array([float(g0 @ q / (g0 @ g0)), 1.0])
    sig = loop_sigma.coefficients_sigma(SimpleNamespace(q=q), lambda v: v, x, np.full(2, 0.01))
    one = loop_sigma.coefficient_sigma(SimpleNamespace(q=q), lambda v: np.array([v, 1.0]), x[0], 0.01)
    assert sig[1] is None and sig[0] == pytest.approx(one, rel=1e-6)


def test_coefficient_sigma_is_none_where_the_loop_fails_or_ignores_x(monkeypatch):
    monkeypatch.setattr(resimulate, "resimulate", lambda meas, m: SimpleNamespace(q=np.ones(10), ok=m is not None))
    meas = SimpleNamespace(q=np.zeros(10))
    assert loop_sigma.coefficient_sigma(meas, lambda v: v, 1.0, 0.1) is None          # q independent of x
    assert loop_sigma.coefficient_sigma(meas, lambda v: None if v > 1 else v, 1.0, 0.1) is None


def test_parameter_sigma_by_the_delta_method():
    """p = exp(x): sigma_p = exp(x) sigma_x; a parameter x does not move gets None."""
    s = loop_sigma.parameter_sigma(lambda x: {"p": np.exp(x), "fixed": 3.0}, 0.5, 0.1, 1e-4)
    assert s["p"] == pytest.approx(np.exp(0.5) * 0.1, rel=1e-6) and s["fixed"] is None
    assert loop_sigma.parameter_sigma(lambda x: {"p": x}, 0.5, None, 1e-4) == {"p": None}


def test_two_records_takes_the_larger_spread():
    """Within-record sigma 0.1: fits 1.0 and 1.05 keep it; 1.0 and 2.0 (the model's error) give
    1 / sqrt(2); no validation fit keeps the within-record value."""
    assert loop_sigma.two_records(0.1, 1.0, 1.05) == 0.1
    assert loop_sigma.two_records(0.1, 1.0, 2.0) == pytest.approx(1 / np.sqrt(2))
    assert loop_sigma.two_records(0.1, 1.0, None) == 0.1 and loop_sigma.two_records(None, 1.0, 2.0) is None
