"""The dwell growth's stated uncertainties hold their coverage where the rests do not span the growth.

Rests shorter than or about the growth's time constant let the gain trade off against the time: an
uncertainty read at the fitted time alone covered the true gain within two of them in about half
of the draws (the level-and-growth fit) or a quarter (the growth from Fs). The joint uncertainty
of all fitted parameters must cover it in about 95 %."""
import numpy as np

from hunting.diagnose.causes import dwell

DRAWS = 300


def _coverage(fit_and_sigma, gain: float, tau: float, level: float, noise: float, rests: np.ndarray, seed: int):
    """Share of DRAWS noisy growths whose fitted gain lies within two stated uncertainties of
    ``gain``, and the ratio of the gains' spread to the median stated uncertainty."""
    rng = np.random.default_rng(seed)
    z, g, s = [], [], []
    for _ in range(DRAWS):
        e = level + gain * (1 - np.exp(-rests / tau)) + noise * rng.standard_normal(rests.size)
        g_k, s_k = fit_and_sigma(e)
        assert s_k is not None and np.isfinite(s_k) and s_k > 0
        z.append(abs(g_k - gain) / s_k)
        g.append(g_k)
        s.append(s_k)
    return float(np.mean(np.array(z) <= 2.0)), float(np.std(g) / np.median(s))


def test_the_level_and_growth_fit_states_the_gain_with_the_time_it_trades_against():
    rests = np.geomspace(0.05, 0.4, 7)          # [s] all about the growth's time 0.3 s

    def fit(e):
        (ss, th, tau), _ = dwell._fit(rests, e)
        return th[1], dwell._growth_sigma(rests, e, th, tau, ss, -np.inf)["gain"]
    cover, spread = _coverage(fit, gain=1.0, tau=0.3, level=0.0, noise=0.05, rests=rests, seed=1)
    assert cover >= 0.88, cover                 # read at the fitted time alone: 0.54
    assert spread < 5.0, spread                 # the stated uncertainty is of the spread's size, not a fifth of it


def test_the_growth_from_fs_states_the_gain_with_the_time_it_trades_against():
    rests = np.geomspace(0.05, 0.4, 7)

    def fit(e):
        g, _, sig, _ = dwell._saturating_fit(rests, e)
        return g, sig
    cover, _ = _coverage(fit, gain=1.0, tau=0.3, level=0.0, noise=0.05, rests=rests, seed=2)
    assert cover >= 0.85, cover                 # read at the fitted time alone: 0.26


def test_a_growth_the_rests_span_keeps_its_uncertainty():
    rests = np.geomspace(0.03, 0.6, 8)          # the growth (0.15 s) complete by the longer rests

    def fit(e):
        (ss, th, tau), _ = dwell._fit(rests, e)
        return th[1], dwell._growth_sigma(rests, e, th, tau, ss, -np.inf)["gain"]
    cover, spread = _coverage(fit, gain=1.0, tau=0.15, level=0.3, noise=0.08, rests=rests, seed=3)
    assert cover >= 0.88, cover
    assert 0.7 < spread < 1.5, spread


def test_a_time_the_rests_cannot_see_leaves_the_gain_its_own_uncertainty():
    # every rest far beyond the time: the growth is complete in each, its time undetermined
    t = np.array([1.0, 1.5, 2.0, 3.0, 4.0])
    sd = dwell._joint_sigma(t, gain=1.0, tau=0.01, ss=0.01, level=False)
    assert sd[1] is None                        # the time: its column of the Jacobian is zero
    assert np.isclose(sd[0], np.sqrt(0.01 / (t.size - 1) / t.size))


def test_the_joint_uncertainty_is_the_least_squares_covariance_of_a_finite_difference_jacobian():
    """An independent Jacobian: central differences of the growth in level, gain and time, and the
    textbook covariance (J^T J)^-1 ss / (m - p); with and without the level. It checks each
    column's scale and the covariance's form; the standard uncertainties (the diagonal) do not
    depend on a column's sign, so the time column's sign is not observable here."""
    t = np.geomspace(0.04, 0.5, 9)
    th = np.array([0.2, 1.3, 0.12])            # level [N], gain [N], time [s]
    ss = 0.02

    def growth(p):
        return p[0] + p[1] * (1 - np.exp(-t / p[2]))
    for level in (True, False):
        keep = [0, 1, 2] if level else [1, 2]
        J = np.empty((t.size, len(keep)))
        for j, k in enumerate(keep):
            h = np.zeros(3)
            h[k] = 1e-6 * abs(th[k])
            J[:, j] = (growth(th + h) - growth(th - h)) / (2 * h[k])
        expected = np.sqrt(np.diag(np.linalg.inv(J.T @ J)) * ss / (t.size - len(keep)))
        got = dwell._joint_sigma(t, gain=th[1], tau=th[2], ss=ss, level=level)
        assert np.allclose(got, expected, rtol=1e-5), (got, expected)
