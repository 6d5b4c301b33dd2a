"""Friction memory and dwell in the diagnosis, checked against independent references: the
lagging Stribeck level against scipy's solve_ivp of L' = (g(|v|) - L) / lag, the lag cause's
regressor at a lag far beyond the first-order range, the dwell cause's break-away reading on a
hand-built record whose break-away force is known, and its growth test's false-alarm rate under
the null by simulation (with the confound that made clean records look like dwell: long rests
ending in fast force ramps)."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from hunting.diagnose import Measurement, NominalModel, kinematics
from hunting.diagnose.causes import dwell, lag

STRIBECK = {"plant": {"mass": 1.0, "motor_constant": 1.0},
            "friction": {"law": "stribeck", "Fc": 1.0, "Fs": 2.0, "vs": 0.02, "beta": 2.0, "b": 0.5}}


@pytest.mark.parametrize("tau", [0.002, 0.05])
def test_lagged_level_matches_solve_ivp(tau):
    """The exact (first-order hold) lag of the Stribeck level through reversals, against
    solve_ivp on the same linearly interpolated velocity: 1e-4 of the dip at 1 kHz."""
    m = NominalModel.from_dict(STRIBECK)
    dt = 1e-3
    t = np.arange(0.0, 1.0, dt)
    v = 0.05 * np.sin(2 * np.pi * 1.3 * t) + 0.01
    L = m.lagged_level(v, np.ones(t.size, bool), dt, tau)

    def g(tt):
        vv = np.interp(tt, t, v)
        return float((m.curve.positive if vv >= 0 else m.curve.negative).level(np.array([vv]))[0])

    ref = solve_ivp(lambda tt, y: [(g(tt) - y[0]) / tau], (0.0, t[-1]), [L[0]], t_eval=t, rtol=1e-10, atol=1e-12,
                    max_step=dt / 4)
    assert np.max(np.abs(ref.y[0] - L)) < 1e-4 * (m.curve.positive.Fs - m.curve.positive.Fc)
    # a lag this long changes the friction by a good part of the dip: the first-order form
    # -lag g'(|v|) a is not what the data hold
    assert np.ptp(L - m.lagged_level(v, np.ones(t.size, bool), dt, 0.0)) > (0.05 if tau > 0.01 else 0.005)


def test_lag_regressor_recovers_a_long_lag():
    """A 50 ms frictional memory (the force change of the exact lag, through the acceleration
    filter, on a record crossing the Stribeck dip at reversals): the lag cause's regressor at the
    true trial lag explains it exactly with coefficient 0.05 s. The first-order regressor
    -lag g'(|v|) a gave 0.004 s on such data (blind benchmark tuning d0185, lag 89 ms)."""
    m = NominalModel.from_dict(STRIBECK)
    dt = 1e-3
    t = np.arange(0.0, 4.0, dt)
    q = 0.01 * np.sin(2 * np.pi * 0.7 * t) + 0.002 * np.sin(2 * np.pi * 2.3 * t)
    kin = kinematics(Measurement(t, q, np.zeros(t.size)), m.cm, resolution=0.0)
    truth = kin.sliding(m.lag_force(kin.vf, kin.slide, dt, 0.05))
    X = lag.design(kin, m, {"tau": 0.05})
    theta = np.linalg.lstsq(X, truth, rcond=None)[0]
    assert theta[0] == pytest.approx(0.05, rel=1e-9)
    # the trial lags span two samples (2 ms at 1 kHz) .. 0.3 s
    taus = [h["tau"] for h in lag.hypers(kin, m)]
    assert taus[0] == pytest.approx(2e-3) and taus[-1] == pytest.approx(0.3)


def _breakaway_record(ramp=20.0, Fs=2.0, mass=1.0, res=1e-6, dt=1e-3):
    """A move into a rest, a force ramping at ``ramp`` [N/s] through the rest until it reaches
    Fs at sample kb (the break-away), then the cubic departure m x''' = ramp (Coulomb friction
    Fs = Fc: only the ramp drives the mass), positions quantized to ``res``."""
    n, k0, kb = 700, 100, 400
    t = np.arange(n) * dt
    x = np.zeros(n)
    x[:k0] = -1e-3 * (1 - t[:k0] / t[k0]) ** 2              # arrives at rest at k0
    tb = t[kb]
    after = t > tb
    x[after] = ramp * (t[after] - tb) ** 3 / (6 * mass)
    q = res * np.round(x / res)
    F = Fs + ramp * (t - tb)
    F[:k0] = 0.5 * Fs
    # u_k is held over [t_k, t_k+1): the reader aligns it to the midpoints
    u = np.concatenate([F[1:], [F[-1]]])
    u = 0.5 * (u + F)
    model = NominalModel.from_dict({"plant": {"mass": mass, "motor_constant": 1.0},
                                    "friction": {"law": "coulomb-viscous", "Fc": Fs, "b": 0.0}})
    return Measurement(t, q, u), model, tb - t[k0]


def test_dwell_reads_the_breakaway_force_where_the_contact_broke():
    """The break-away force of a slow ramp (20 N/s, 1 µm counts, 1 kg): the mass needs ~6 ms to
    leave the rest's count, and 8 ms to show two counts, while the force ramps on. Read where
    the motion first shows (two counts) it was 0.15 N (7.7 %) too high; read where the ramp
    alone would have moved the mass that far, within one sample's ramp (0.02 N)."""
    meas, model, rest = _breakaway_record()
    t, F, s, scale = dwell.rests(meas, model, 1e-6)
    assert t.size == 1 and s[0] == 1
    assert t[0] == pytest.approx(rest, abs=0.006)        # the rest begins within two counts of the stop
    assert F[0] == pytest.approx(2.0, abs=0.03)
    assert 0.0 < scale[0] < 0.3


def _null_rests(rng, n=40):
    """Rests under the null (no dwell): durations log-uniform over 10 ms .. 1 s, the force's
    reading error scale larger after long rests (they end in setpoint moves: fast ramps; the
    short ones in a hunting cycle's slow integral ramp), e = level of the direction + a bias
    proportional to that scale + heavy-tailed noise."""
    t = np.exp(rng.uniform(np.log(0.01), np.log(1.0), n))
    s = rng.choice([-1.0, 1.0], n)
    scale = np.where(t > 0.1, 0.5, 0.02) * rng.uniform(0.2, 1.8, n)
    e = np.where(s > 0, 0.1, -0.2) + 0.8 * scale + 0.05 * rng.standard_t(3, n)
    return t, e, s, scale


def test_dwell_growth_test_holds_its_level_under_the_null():
    """300 null draws with the confound (reading bias growing with the rest) and heavy tails:
    the growth test's one-sided p falls below 0.05 in 2-9 % of them (level 5 %), below 0.01 in
    at most 3 %. Without the bias covariate nearly every draw 'grows' (checked below)."""
    rng = np.random.default_rng(7)
    p = []
    naive = 0
    for _ in range(300):
        t, e, s, scale = _null_rests(rng)
        p.append(dwell.growth_test(t, e, s, scale, draws=999, seed=1)[1])
        naive += dwell.growth_test(t, e, s, np.zeros_like(scale), draws=999, seed=1)[1] < 0.05
    p = np.array(p)
    assert 0.02 <= np.mean(p < 0.05) <= 0.09
    assert np.mean(p < 0.01) <= 0.03
    assert naive > 200


def test_dwell_growth_test_finds_a_growth():
    """A break-away excess growing by 1 N with time constant 0.1 s, besides the same confound
    and noise: p at its floor (1 / (draws + 1))."""
    rng = np.random.default_rng(3)
    t, e, s, scale = _null_rests(rng)
    e = e + 1.0 * (1 - np.exp(-t / 0.1))
    rho, p = dwell.growth_test(t, e, s, scale, draws=2000, seed=1)
    assert rho > 0.5 and p == pytest.approx(1 / 2001)


def test_dwell_growth_test_keeps_a_growth_whose_long_rests_end_in_slow_ramps():
    """Reporting6 d0478: 12 rests read within 0.02 N of the truth (gain 0.37 N, 0.55 s), the
    short ones ending in fast ramps (scale 0.01-0.04 N), the long ones in slow ones (0.001-0.004
    N). A reading bias free in sign fell with the scale and absorbed the growth (p = 0.13); the
    bias a fast ramp puts into the reading is upward, and with that sign the growth is found.
    Here: 14 rests, the same pattern, noise 5 mN."""
    rng = np.random.default_rng(4)
    t = np.exp(rng.uniform(np.log(0.02), np.log(0.9), 14))
    s = np.where(np.arange(14) % 5 == 0, -1.0, 1.0)
    scale = np.where(t < 0.1, 0.03, 0.002) * rng.uniform(0.5, 1.5, 14)
    e = 0.37 * (1 - np.exp(-t / 0.55)) + 0.005 * rng.standard_normal(14)
    rho, p = dwell.growth_test(t, e, s, scale, draws=4000, seed=1)
    assert rho > 0.8 and p < 1e-3


def _rest_then_break_away(delta: float, ramp: float = 20.0, dt: float = 1e-3, res: float = 1e-6, m: float = 1.0,
                          Fs: float = 1.0):
    """A record in closed form: the mass moves, rests 0.15 s under a drive force ramping at
    ``ramp`` [N/s], breaks away when the force reaches Fb = Fs + delta and then moves under the
    net force delta + ramp tau (sliding friction Fs): q = delta tau^2 / 2m + ramp tau^3 / 6m,
    quantized to ``res``. Returns (measurement, model, Fb)."""
    model = NominalModel.from_dict({"plant": {"mass": m, "motor_constant": 1.0},
                                    "friction": {"law": "coulomb-viscous", "Fc": Fs, "b": 0.0},
                                    "sensor": {"resolution": res}})
    t = np.arange(0.0, 0.4, dt)
    t0, tb = 0.05, 0.2
    Fb = Fs + delta
    F = np.where(t < tb, Fb - ramp * (tb - t), Fb + ramp * (t - tb))
    tau = np.clip(t - tb, 0.0, None)
    q = np.where(t < t0, -(t0 - t) * 2e-3, 0.0) + delta * tau ** 2 / (2 * m) + ramp * tau ** 3 / (6 * m)
    return Measurement(t, res * np.round(q / res), F), model, Fb


@pytest.mark.parametrize("delta", [0.0, 0.2, 0.5, 1.0])
def test_dwell_reads_the_break_away_force_of_a_closed_form_rest(delta, monkeypatch):
    """The break-away reading against the closed form: within 0.03 N of Fb (1.5 ms of the 20 N/s
    ramp: the sampling's share) whether or not the break-away force exceeds Fs, and the rest's
    duration 0.15 s within 2 ms. With the departure driven by the ramp alone (one pass, no
    excess) a break-away force above Fs was read 0.08-0.12 N low."""
    meas, model, Fb = _rest_then_break_away(delta)
    t_rest, F, s, _ = dwell.rests(meas, model, 1e-6)
    assert F.size == 1 and s[0] == 1.0
    assert abs(F[0] - Fb) < 0.03
    assert abs(t_rest[0] - 0.15) < 2e-3
    monkeypatch.setattr(dwell, "DEPARTURE_PASSES", 1)
    F_ramp_only = dwell.rests(meas, model, 1e-6)[1][0]
    if delta > 0:
        assert Fb - F_ramp_only > 0.06
    else:
        assert F_ramp_only == pytest.approx(F[0])


def test_dwell_leave_one_out_predicts_each_rest_from_the_others():
    """Rests whose excess follows level + gain (1 - exp(-t/time)) exactly: each rest predicted by
    the growth fitted on the others is exact (to the time grid's spacing), and one rest read 0.3
    N high shows up as its own residual, not spread over the others."""
    t = np.array([0.02, 0.05, 0.08, 0.15, 0.3, 0.5, 0.8, 1.2])
    e = 0.1 + 0.8 * (1 - np.exp(-t / 0.2))
    r = dwell._left_out(t, e)
    assert np.max(np.abs(r)) < 0.02 * 0.8
    e2 = e.copy()
    e2[4] += 0.3
    r2 = dwell._left_out(t, e2)
    assert r2[4] > 0.2 and np.max(np.abs(np.delete(r2, 4))) < 0.15


def _level_rests(excess=1.9, scale=0.06, n=5, Fs=10.0):
    """Rests of 0.7-2 s in both directions whose break-away force exceeds Fs by ``excess`` [N]
    after each (a growth complete before the shortest rest), with reading scales ``scale`` [N]."""
    model = NominalModel.from_dict({"plant": {"mass": 1.0, "motor_constant": 1.0},
                                    "friction": {"law": "coulomb-viscous", "Fc": Fs, "b": 0.0}})
    t = np.linspace(0.7, 2.0, n)
    s = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    rng = np.random.default_rng(3)
    F = s * (Fs + excess + 0.02 * rng.standard_normal(n))
    return t, F, s, np.full(n, scale), model


def test_dwell_level_verdict_fits_the_break_away_excess_every_rest_shows():
    """A break-away 1.9 N above Fs after every rest: the growth test's null holds a level per
    direction and cannot see it; the level verdict names it with the gain within 2 % and its
    time below the shortest rest, and each rest's leave-one-out prediction is the mean of the
    others (checked by brute force)."""
    t, F, s, scale, model = _level_rests()
    v = dwell.level_verdict(t, F, s, scale, model)
    assert v is not None and v["significant"] and v["p_value"] is None and v["rivals"] == ("stribeck",)
    assert v["parameters"]["gain"] == pytest.approx(1.9, rel=0.02)
    assert v["parameters"]["time"] <= t.min() / 5 + 1e-12
    e = dwell.excess(model, t, F, s)
    w = 1 - np.exp(-t / v["parameters"]["time"])
    loo = [e[k] - w[k] * np.delete(w * e, k).sum() / np.delete(w * w, k).sum() for k in range(t.size)]
    assert v["extended"] == pytest.approx(np.sqrt(np.mean(np.square(loo))), rel=1e-9)
    assert v["nominal"] == pytest.approx(1.9, rel=0.02) and v["extended"] < 0.05


@pytest.mark.parametrize("dip", ["both", "none", "positive"])
def test_dwell_level_verdict_reads_the_excess_as_a_static_level_too(dip):
    """The same excess read as a static level (``instead``): the stribeck cause, Fs raised by the
    mean excess in both directions (its leave-one-out prediction the mean of the other rests, by
    brute force), Fc unchanged; each direction at its own dip's velocity, a direction without
    one at half the 2nd percentile of the sliding speeds given."""
    t, F, s, scale, model = _level_rests()
    if dip != "none":                          # the same static level 10 N, above Fc = 8 N
        neg = {"Fc_neg": 10.0, "Fs_neg": 10.0} if dip == "positive" else {}
        model = NominalModel.from_dict({"plant": {"mass": 1.0, "motor_constant": 1.0}, "friction": {
            "law": "stribeck", "Fc": 8.0, "Fs": 10.0, "vs": 0.02, "beta": 2.0, "b": 0.0, **neg}})
    speeds = np.linspace(0.01, 0.2, 1000)
    v = dwell.level_verdict(t, F, s, scale, model, speeds)["instead"]
    e = dwell.excess(model, t, F, s)
    assert v["name"] == "stribeck" and v["increments"]["Fs"] == pytest.approx(e.mean(), rel=1e-12)
    ext = v["model"]
    for c, c0 in ((ext.curve.positive, model.curve.positive), (ext.curve.negative, model.curve.negative)):
        assert c.Fs == pytest.approx(c0.Fs + e.mean(), rel=1e-12) and c.Fc == c0.Fc
        assert c.vs == pytest.approx(c0.vs if c0.Fs > c0.Fc else 0.5 * np.percentile(speeds, 2), rel=1e-12)
    assert ext.law == ("stribeck" if dip == "none" else model.law)
    assert v["parameters"]["Fs"] == pytest.approx(ext.curve.positive.Fs, rel=1e-12)
    loo = [e[k] - np.delete(e, k).mean() for k in range(t.size)]
    assert v["extended"] == pytest.approx(np.sqrt(np.mean(np.square(loo))), rel=1e-9)
    assert np.abs(dwell.excess(ext, t, F, s)).max() < 0.1


def _growing_rests(n=6, gain=0.43, time=0.12, noise=0.01, Fs=1.34):
    """Rests of 0.15-0.65 s alternating in direction whose break-away force exceeds Fs by a growth
    gain (1 - exp(-t / time)) [N] (reporting21 d0380's), readings within ``noise`` [N]; a
    Coulomb nominal model (Fs = Fc). Scale 0.01 N."""
    model = NominalModel.from_dict({"plant": {"mass": 1.0, "motor_constant": 1.0},
                                    "friction": {"law": "coulomb-viscous", "Fc": Fs, "b": 0.0}})
    t = np.linspace(0.15, 0.65, n)[np.random.default_rng(5).permutation(n)]
    s = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    e = gain * (1 - np.exp(-t / time)) + noise * np.random.default_rng(7).standard_normal(n)
    return t, s * (Fs + e), s, np.full(n, 0.01), model


def _direction_ratio(t, e, s, lo):
    """The resolved-growth ratio computed independently of the library: each rest's excess
    predicted by a growth beside a level per direction fitted on the others (scipy's bounded
    least squares, the time continuous in [shortest rest, 5 x longest], several starts), against
    the mean of the other rests in its direction."""
    from scipy.optimize import least_squares
    growth, level = [], []
    for k in range(t.size):
        m = np.arange(t.size) != k
        tk, ek, sk = t[m], e[m], s[m]

        def res(x):
            return np.where(sk > 0, x[0], x[1]) + x[2] * (1 - np.exp(-tk / np.exp(x[3]))) - ek
        lo_t, hi_t = np.log(tk.min()), np.log(5 * tk.max())
        fits = [least_squares(res, [max(lo, 0.0), max(lo, 0.0), np.ptp(ek), x0],
                              bounds=([lo, lo, -np.inf, lo_t], [np.inf, np.inf, np.inf, hi_t]))
                for x0 in np.linspace(lo_t + 1e-9, hi_t - 1e-9, 7)]
        x = min(fits, key=lambda f: f.cost).x
        growth.append(e[k] - (x[0] if s[k] > 0 else x[1]) - x[2] * (1 - np.exp(-t[k] / np.exp(x[3]))))
        level.append(e[k] - ek[sk == s[k]].mean())
    return np.sqrt(np.mean(np.square(growth))) / np.sqrt(np.mean(np.square(level)))


def test_dwell_level_verdict_names_a_growth_the_rests_resolve_out_of_sample():
    """Six rests, three per direction, growing 0.43 N with time 0.12 s (reporting21 d0380): the
    growth test cannot reach alpha on them (36 orders within the directions, p >= 1/36), but a
    growth fitted on the other rests beside a level per direction predicts each one's excess to
    under half the error of a level per direction alone (checked against scipy): dwell is named
    with its fitted growth (the excess after the longest rest within 5 %), the static level its
    alternative ("also"), not the reverse; the gain's metric is the one-level growth's
    leave-one-out error (brute force)."""
    t, F, s, scale, model = _growing_rests()
    e = dwell.excess(model, t, F, s)
    assert dwell.growth_test(t, e, s, scale, draws=2000)[1] >= 1 / 36
    v = dwell.level_verdict(t, F, s, scale, model)
    assert "instead" not in v and v["also"]["name"] == "stribeck"
    ratio = _direction_ratio(t, e, s, dwell.lowest_level(model))
    assert ratio <= dwell.GROWTH_SHARE
    assert float(v["evidence"].split(" N RMS, ")[1].split(" times")[0]) == pytest.approx(ratio, rel=0.1, abs=0.02)
    p = v["parameters"]
    plateau = 0.43 * (1 - np.exp(-0.65 / 0.12))
    assert p["level"] + p["gain"] * (1 - np.exp(-0.65 / p["time"])) == pytest.approx(plateau, rel=0.05)
    assert p["gain"] > 0 and t.min() <= p["time"] <= 5 * t.max()
    lo = dwell.lowest_level(model)
    loo = []
    for k in range(t.size):
        keep = np.arange(t.size) != k
        best = min((dwell._ls(t[keep], e[keep], x, lo) + (x,) for x in np.geomspace(t[keep].min(), 5 * t[keep].max(), 41)),
                   key=lambda r: r[0])
        loo.append(e[k] - best[1][0] - best[1][1] * (1 - np.exp(-t[k] / best[2])))
    assert v["extended"] == pytest.approx(np.sqrt(np.mean(np.square(loo))), rel=1e-9)
    level_loo = [e[k] - np.delete(e, k).mean() for k in range(t.size)]
    assert v["also"]["extended"] == pytest.approx(np.sqrt(np.mean(np.square(level_loo))), rel=1e-9)


@pytest.mark.parametrize("case", ["constant", "falling", "five rests", "noisy", "direction"])
def test_dwell_level_verdict_keeps_the_static_level_where_no_growth_is_resolved(case):
    """The static level stays the named reading (``instead``) where the excess is the same after
    every rest, falls with the rest, comes from fewer than MIN_RESTS + 1 rests (five clean ones
    whose ratio would pass), is read too noisily for the growth to predict each rest to half a
    level's error (readings within 0.05 N, 8 rests), or differs between the directions, one of
    which happened to rest longer (three rests of 0.4-0.7 s 0.6 N above Fs one way, three of
    0.05-0.1 s 0.2 N above the other: a growth over both directions with one level would fit it)."""
    lo = 0.0
    if case == "constant":
        t, F, s, scale, model = _level_rests(n=8)
    elif case == "falling":
        t, F, s, scale, model = _growing_rests(gain=-0.2)
        F = s * (np.abs(F) + 0.5)
    elif case == "five rests":
        t, F, s, scale, model = _growing_rests(n=5, noise=0.002)
        assert _direction_ratio(t, dwell.excess(model, t, F, s), s, lo) <= dwell.GROWTH_SHARE
    elif case == "noisy":
        t, F, s, scale, model = _growing_rests(n=8, noise=0.05)
        F = s * (np.abs(F) + 0.5)
        e = dwell.excess(model, t, F, s)
        assert dwell._fit(t, e, dwell.lowest_level(model))[0][1][1] > 0      # it rises: the error ratio decides
    else:
        _, _, _, scale, model = _growing_rests()
        t = np.array([0.4, 0.55, 0.7, 0.05, 0.075, 0.1])
        s = np.array([1.0, 1, 1, -1, -1, -1])
        noise = 0.01 * np.random.default_rng(11).standard_normal(6)
        F = s * (1.34 + np.where(s > 0, 0.6, 0.2) + noise)
        e = dwell.excess(model, t, F, s)
        (_, th, _), _ = dwell._fit(t, e, lo)
        assert th[1] > 0 and np.sqrt(np.mean(dwell._left_out(t, e, lo) ** 2)) <= dwell.GROWTH_SHARE * np.sqrt(
            np.mean([(e[k] - np.delete(e, k).mean()) ** 2 for k in range(6)]))   # one level: it would pass
    v = dwell.level_verdict(t, F, s, scale, model)
    assert v is not None and "also" not in v and v["instead"]["name"] == "stribeck"
    assert dwell.resolved_growth(t, dwell.excess(model, t, F, s), s, model) is None


def test_dwell_level_reading_fits_the_growth_time_the_rests_show():
    """Five rests of 0.15-0.65 s after a growth of 0.43 N in 0.12 s (readings within 0.002 N):
    too few for a resolved growth, so the level verdict holds the static level and the dwell
    reading. The dwell reading's time is the one whose leave-one-out error is smallest: gain and
    time near the truth, where a growth assumed complete by the shortest rest read the gain
    low (its leave-one-out error is checked to be larger, brute force)."""
    t, F, s, scale, model = _growing_rests(n=5, noise=0.002)
    v = dwell.level_verdict(t, F, s, scale, model)
    assert v is not None and v["instead"]["name"] == "stribeck"
    assert v["parameters"]["gain"] == pytest.approx(0.43, rel=0.03)
    assert v["parameters"]["time"] == pytest.approx(0.12, rel=0.3)
    e = dwell.excess(model, t, F, s)
    w = 1 - np.exp(-t / (t.min() / 5))
    complete = [e[k] - w[k] * np.delete(w * e, k).sum() / np.delete(w * w, k).sum() for k in range(t.size)]
    assert v["extended"] < 0.5 * np.sqrt(np.mean(np.square(complete)))
    assert float(w @ e / (w @ w)) < 0.43 * 0.95          # the complete growth's gain: low


@pytest.mark.parametrize("low, negative, holds", [(2, False, True), (3, False, False), (1, True, False)])
def test_dwell_level_verdict_holds_on_a_share_of_the_rests_all_above_the_static_force(low, negative, holds):
    """Ten rests 1.9 N above Fs: the verdict holds where at least LEVEL_SHARE (80 %) of them
    reach LEVEL_RATIO times their reading's scale (two noisy readings, scale 1 N, ratio 1.6:
    holds; three: not), and never where one rest breaks away below the model's static force."""
    t, F, s, scale, model = _level_rests(n=10)
    scale = scale.copy()
    scale[:low] = 1.0
    if negative:
        F = F.copy()
        F[4] = s[4] * (10.0 - 0.5)
    v = dwell.level_verdict(t, F, s, scale, model)
    assert (v is not None) == holds
    if holds:
        ratio = np.sort(dwell.excess(model, t, F, s) / (scale + dwell.LEVEL_FLOOR * 10.0))[low]
        assert v["statistic"] == pytest.approx(ratio, rel=1e-12) and v["statistic"] >= dwell.LEVEL_RATIO


@pytest.mark.parametrize("case", ["one direction", "below the ratio", "two rests"])
def test_dwell_level_verdict_needs_the_rests_in_both_directions(case):
    """No verdict where the excess could be an asymmetry (one direction), where two of five
    rests' excesses are within three times their reading scale (ramps read late: 60 % of the
    rests reach the ratio, 80 % needed), or with fewer than three rests."""
    t, F, s, scale, model = _level_rests()
    if case == "one direction":
        F, s = np.abs(F), np.ones_like(s)
    elif case == "below the ratio":
        scale = scale.copy()
        scale[2:4] = 0.7
    else:
        t, F, s, scale = t[:2], F[:2], s[:2], scale[:2]
    assert dwell.level_verdict(t, F, s, scale, model) is None


def test_dwell_growth_fit_keeps_the_break_away_above_the_coulomb_level():
    """A growth whose free fit runs its level below -(Fs - Fc) (a contact breaking away below the
    force it slides at) is refitted with the level at that bound and the gain alone: exact data
    level -0.3 + gain 1 (1 - exp(-t / 0.2)) with a bound of -0.1 give level -0.1 and a least-squares
    gain at the same time constant (checked against numpy's); a level above the bound is kept."""
    t = np.array([0.02, 0.05, 0.1, 0.2, 0.4, 0.8, 1.2])
    e = -0.3 + 1.0 * (1 - np.exp(-t / 0.2))
    ss_free, th_free = dwell._ls(t, e, 0.2)
    assert th_free == pytest.approx([-0.3, 1.0], abs=1e-9) and ss_free < 1e-18
    ss, th = dwell._ls(t, e, 0.2, lo=-0.1)
    w = 1 - np.exp(-t / 0.2)
    g = np.linalg.lstsq(w[:, None], e + 0.1, rcond=None)[0][0]
    assert th == pytest.approx([-0.1, g], rel=1e-12) and ss == pytest.approx(np.sum((e + 0.1 - g * w) ** 2))
    assert dwell._ls(t, e, 0.2, lo=-0.5)[1] == pytest.approx([-0.3, 1.0], abs=1e-9)
    model = NominalModel.from_dict({"plant": {"mass": 1.0, "motor_constant": 1.0},
                                    "friction": {"law": "stribeck", "Fc": 1.0, "Fs": 1.4, "vs": 0.01, "b": 0.0}})
    assert dwell.lowest_level(model) == pytest.approx(-0.4)


def test_dwell_growth_test_sees_a_growth_complete_before_most_rests_end():
    """Reporting15 d0366 (a development record since its verdict): 16 rests read within 0.06 N of
    a 0.6 N growth of time constant 0.043 s; 11 of them outlast it, so their order carries no
    growth. Spearman's rank of the duration weighed their noise as much as the growth (p =
    1.1e-3, above the 1e-3 the diagnosis needs); the saturating score finds it (2.5e-4). The
    same readings with the durations shuffled inside each direction show nothing."""
    t = np.array([0.059, 0.660, 0.309, 0.822, 0.029, 0.033, 0.028, 0.030, 0.028, 0.477, 0.194, 0.113, 0.209,
                  0.183, 0.228, 0.278])
    s = np.array([1, 1, 1, -1, 1, -1, 1, -1, 1, -1, 1, 1, -1, 1, -1, 1], float)
    e = np.array([0.389, 0.560, 0.531, 0.586, 0.255, 0.284, 0.288, 0.256, 0.255, 0.582, 0.628, 0.541, 0.577,
                  0.606, 0.564, 0.548])
    scale = np.array([0.023, 0.027, 0.022, 0.009, 0.089, 0.126, 0.112, 0.118, 0.125, 0.017, 0.043, 0.024, 0.040,
                      0.029, 0.012, 0.029])
    score, p = dwell.growth_test(t, e, s, scale)
    assert score > 0.8 and p < 1e-3
    rng = np.random.default_rng(2)
    shuffled = t.copy()
    for d in (-1.0, 1.0):
        k = np.flatnonzero(s == d)
        shuffled[k] = rng.permutation(t[k])
    assert dwell.growth_test(shuffled, e, s, scale, draws=4000)[1] > 0.01


@pytest.mark.parametrize("deficit", [0.3, 0.6])
def test_dwell_reads_a_break_away_into_a_lagging_level(deficit):
    """Frictional memory: a contact breaks away at Fs = 1 N after a short rest, but its lagging
    Stribeck level has not relaxed back to Fs, so the mass slides against Fs - deficit and leaves
    its count sooner (closed form: q = deficit tau^2 / 2m + ramp tau^3 / 6m). Read as if Fs slowed
    it, the break-away came out low (0.10 N here; reporting15 d0490, an 85 ms lag, showed a
    fake dwell effect that way); with the model's level after the break-away it is read within
    0.03 N of Fs."""
    meas, model, _ = _rest_then_break_away(0.0)
    t = meas.t
    tau = np.clip(t - 0.2, 0.0, None)
    q = np.where(t < 0.05, -(0.05 - t) * 2e-3, 0.0) + deficit * tau ** 2 / 2 + 20.0 * tau ** 3 / 6
    meas = Measurement(t, 1e-6 * np.round(q / 1e-6), meas.u)
    level = np.full(t.size, 1.0 - deficit)
    F = dwell.rests(meas, model, 1e-6, level)[1]
    F_as_if_Fs = dwell.rests(meas, model, 1e-6)[1]
    assert F.size == 1 and abs(F[0] - 1.0) < 0.03
    assert 1.0 - F_as_if_Fs[0] > 0.05


def _first_slip_friction(sliding: bool, lag: float = 0.0):
    """The friction force (n,) [N] and speeds (n,) [m/s] of the first slip of a PD loop pushed out
    of a long rest on a Stribeck contact (Fc 10, Fs 15 N, vs 10 mm/s) whose break-away grows by
    5 N (Dwell sliding as given), from the re-simulation's u and v (m = cm = 1)."""
    from hunting.diagnose.model import Dwell
    from hunting.diagnose.resimulate import resimulate
    m = NominalModel.from_dict({"plant": {"mass": 1.0, "motor_constant": 1.0},
                                "friction": {"law": "stribeck", "Fc": 10.0, "Fs": 15.0, "vs": 0.01, "beta": 2.0,
                                             "lag": lag},
                                "controller": {"type": "pid", "kp": 4e4, "kd": 400.0, "ki": 0.0}})
    m = m.replace(dwell=Dwell(0.0, 5.0, 0.1, sliding))
    dt = 1e-3
    t = np.arange(0.0, 1.5, dt)
    r = np.where(t < 0.5, 0.0, 0.004 * (t - 0.5))
    sim = resimulate(Measurement(t=t, q=np.zeros_like(t), u=np.zeros_like(t), q_ref=r, name="push"), m,
                     resolution=1e-9, substeps=50)
    F = sim.u - np.gradient(sim.v, dt)
    k = np.flatnonzero(~sim.stuck & (sim.v > 0))
    k = k[(k > 0) & (k < t.size - 1)]
    first = k[:int(np.argmax(np.diff(k) > 1)) or k.size]
    return F[first], sim.v[first]


@pytest.mark.parametrize("sliding", [False, True])
def test_dwell_growth_acts_on_the_slip_only_in_the_seven_parameter_form(sliding):
    """Kato's form raises the break-away alone: the slip after the rest follows the nominal
    Stribeck curve (Fs 15 N). The seven-parameter form's slip starts from the grown break-away
    force: its Stribeck curve has Fs 15 + 5 N. The friction the loop felt (u - m a), against
    both curves evaluated independently: it follows its own within 1 N RMS (the finite
    difference of v), the other's by more than 1.5 N."""
    F, v = _first_slip_friction(sliding)
    assert v.size >= 10

    def rms(Fs):
        return np.sqrt(np.mean((F - (10.0 + (Fs - 10.0) * np.exp(-(v / 0.01) ** 2))) ** 2))
    own, other = (rms(20.0), rms(15.0)) if sliding else (rms(15.0), rms(20.0))
    assert own < 1.0 < 1.5 < other


def test_dwell_form_round_trips_through_the_model_file():
    from hunting.errors import SystemDefinitionError
    d = {"plant": {"mass": 1.0}, "friction": {"law": "stribeck", "Fc": 1.0, "Fs": 2.0, "vs": 0.01,
                                              "dwell": {"level": 0.0, "gain": 0.5, "time": 0.2, "sliding": True}}}
    m = NominalModel.from_dict(d)
    assert m.dwell.sliding and NominalModel.from_dict(m.to_dict()).dwell == m.dwell
    d["friction"]["dwell"]["sliding"] = "yes"
    with pytest.raises(SystemDefinitionError, match="sliding"):
        NominalModel.from_dict(d)
    del d["friction"]["dwell"]["sliding"]
    assert not NominalModel.from_dict(d).dwell.sliding
    assert "sliding" not in NominalModel.from_dict(d).to_dict()["friction"]["dwell"]


@pytest.mark.parametrize("sliding", [False, True])
def test_dwell_growth_fitted_on_the_loop_keeps_the_form_the_model_declares(sliding):
    """A nominal model that declares its dwell growth's form (the seven-parameter one, or Kato's)
    has the loop's growth fitted in that form (the fit and the models it builds keep it; a model
    built without a growth and no form given gets Kato's): the extension does not silently switch
    to the other."""
    from hunting.diagnose.causes import dwell_loop
    from hunting.diagnose.model import Dwell
    m = NominalModel.from_dict({"plant": {"mass": 1.0, "motor_constant": 1.0},
                                "friction": {"law": "stribeck", "Fc": 10.0, "Fs": 15.0, "vs": 0.01, "beta": 2.0},
                                "controller": {"type": "pid", "kp": 4e4, "kd": 400.0, "ki": 0.0}})
    m = m.replace(dwell=Dwell(0.0, 5.0, 0.1, sliding))
    dt = 1e-3
    t = np.arange(0.0, 1.5, dt)
    r = np.where(t < 0.5, 0.0, 0.004 * (t - 0.5))
    meas = Measurement(t=t, q=np.zeros_like(t), u=np.zeros_like(t), q_ref=r, name="push")
    ext, err = dwell_loop.fit(meas, m, np.array([0.5]), grid=False, start=(4.0, 0.1))
    assert np.isfinite(err) and ext.dwell.sliding is sliding
    assert dwell_loop._with(m, 1.0, 0.2).dwell.sliding is sliding
    assert dwell_loop._with(m.replace(dwell=None), 1.0, 0.2).dwell.sliding is False
    assert ("seven-parameter" in dwell_loop.form_words(ext.dwell)) is sliding


@pytest.mark.parametrize("sliding", [False, True])
def test_dwell_growth_fitted_on_a_model_without_one_takes_the_form_the_record_shows(sliding):
    """A model without a growth has the loop's growth fitted in both forms, and the one that
    re-simulates the fitting record better is taken: on records made in the seven-parameter form
    and in Kato's (a 5 N growth over 0.1 s on Fs 15 N, rests of 0.04-0.5 s; fits from 4.5 N over
    0.11 s, near the truth: this loop's stick-slip cycles make the error's valley too narrow for
    the grid alone), the fit names the form that made them, its gain within 11 % and its error
    below 0.4 of the other form's best (0.36 and 0.012 measured). A Coulomb-viscous model has no
    Stribeck curve for the seven-parameter slip: Kato's alone."""
    from hunting.diagnose.causes import dwell_loop
    from hunting.diagnose.model import Dwell
    from hunting.diagnose.resimulate import resimulate
    m = NominalModel.from_dict({"plant": {"mass": 1.0, "motor_constant": 1.0},
                                "friction": {"law": "stribeck", "Fc": 10.0, "Fs": 15.0, "vs": 0.01, "beta": 2.0},
                                "controller": {"type": "pid", "kp": 4e4, "kd": 400.0, "ki": 2e5},
                                "sensor": {"resolution": 1e-7}})
    dt = 1e-3
    rests = np.array([0.3, 0.04, 0.12, 0.5])          # the reference's, before moves of 0.2 s at 5 mm/s
    starts = np.cumsum(rests + np.r_[0.0, 0.2, 0.2, 0.2])
    t = np.arange(0.0, starts[-1] + 0.4, dt)
    r = sum(sign * 0.005 * np.clip(t - a, 0.0, 0.2) for sign, a in zip((1, -1, 1, -1), starts))
    push = Measurement(t=t, q=np.zeros_like(t), u=np.zeros_like(t), q_ref=r, name="push")
    sim = resimulate(push, m.replace(dwell=Dwell(0.0, 5.0, 0.1, sliding)), substeps=20)
    meas = Measurement(t=t, q=sim.q, u=sim.u, q_ref=r, name="made")
    assert dwell_loop.forms(m) == (False, True)
    ext, err = dwell_loop.fit(meas, m, rests, start=(4.5, 0.11))
    other, err_other = dwell_loop.fit(meas, m, rests, start=(4.5, 0.11), sliding=not sliding)
    assert ext.dwell.sliding is sliding
    assert ext.dwell.gain == pytest.approx(5.0, rel=0.11)
    assert err < 0.4 * err_other
    cv = NominalModel.from_dict({"plant": {"mass": 1.0, "motor_constant": 1.0},
                                 "friction": {"law": "coulomb-viscous", "Fc": 10.0, "b": 1.0},
                                 "controller": {"type": "pid", "kp": 4e4, "kd": 400.0, "ki": 2e5}})
    assert dwell_loop.forms(cv) == (False,)


@pytest.mark.parametrize("sliding", [False, True])
def test_dwell_growth_starts_the_lagging_level_of_the_slip_in_the_seven_parameter_form(sliding):
    """With frictional memory (lag 20 ms) the lagging level of the slip after a long rest starts
    at the grown break-away force in the seven-parameter form (15 + 5 N) and at the relaxed static
    level Fs (15 N) in Kato's: the first sample's friction, within 1 N."""
    F, _ = _first_slip_friction(sliding, lag=0.02)
    assert abs(F[0] - (20.0 if sliding else 15.0)) < 1.0


def test_dwell_seven_parameter_form_needs_a_stribeck_curve():
    """A Coulomb-viscous contact has no Stribeck velocity along which the grown force could decay
    (its curve's Fs is Fc with a placeholder vs): the form is refused with the reason, not
    re-simulated as a slip held at the grown force."""
    from hunting.errors import SystemDefinitionError
    d = {"plant": {"mass": 1.0}, "friction": {"law": "coulomb-viscous", "Fc": 1.0, "b": 0.1,
                                              "dwell": {"level": 0.0, "gain": 0.5, "time": 0.2, "sliding": True}}}
    with pytest.raises(SystemDefinitionError, match="needs a Stribeck curve"):
        NominalModel.from_dict(d)
    del d["friction"]["dwell"]["sliding"]
    assert NominalModel.from_dict(d).dwell.sliding is False


@pytest.mark.parametrize("gain, words", [(-4.9e-18, "the break-away force does not change with the rest: not"),
                                         (-0.745, "falls with the rest in the fitting data (gain -0.745 N)")])
def test_dwell_growth_at_the_fits_rounding_does_not_fall(gain, words, monkeypatch):
    """reporting32 d0621 (identical break-away readings): the fitted gain -4.9e-18 N was reported
    as a break-away force that 'falls with the rest'; a gain at the fit's rounding does not change
    it, a real negative gain still falls."""
    from hunting.diagnose.synthetic import TruePlant, true_model
    model = true_model(TruePlant(Fs=22.0))
    monkeypatch.setattr(dwell, "_fit", lambda t, e, lo=-np.inf: ((1.0, np.array([0.3, gain]), 0.1), 2.0))
    t = np.geomspace(0.05, 2.0, 8)
    F, s = np.full(8, 22.3), np.ones(8)
    v = dwell._growth_verdict(t, F, s, s, t[:4], F[:4], s[:4], s[:4], model)
    assert words in v["reason"]


def test_dwell_reading_gain_is_the_least_squares_growth_of_the_readings():
    """The loop fit's start from break-away readings: at a given growth time, the gain of
    e_k ~ gain (1 - exp(-t_k / time)) by least squares (the exact gain on exact readings,
    numpy's lstsq on noisy ones), 0 without readings."""
    from hunting.diagnose.causes import dwell_loop
    t = np.array([0.05, 0.2, 0.4, 1.2])
    e = 3.0 * (1 - np.exp(-t / 0.1))
    assert dwell_loop.reading_gain(t, e, 0.1) == pytest.approx(3.0, rel=1e-12)
    noisy = e + np.array([0.2, -0.1, 0.3, -0.25])
    want = np.linalg.lstsq((1 - np.exp(-t / 0.3))[:, None], noisy, rcond=None)[0][0]
    assert dwell_loop.reading_gain(t, noisy, 0.3) == pytest.approx(want, rel=1e-12)
    assert dwell_loop.reading_gain(np.array([]), np.array([]), 0.1) == 0.0


def test_dwell_is_refused_on_a_lugre_model_whose_contact_never_rests():
    """A LuGre model's re-simulation has no rest (the bristles' state carries the contact), so a
    dwell growth in it would be silently left out of every run: the model file is refused with
    the reason, the dwell verdict on a LuGre model is untestable (not a reading of break-aways
    the bristles make), and reversal (LuGre bristles) is untestable on a model with a growth."""
    from hunting.diagnose.causes import reversal
    from hunting.errors import SystemDefinitionError
    d = {"plant": {"mass": 1.0}, "friction": {"law": "lugre", "Fc": 1.0, "Fs": 2.0, "vs": 0.01, "sigma0": 1e5,
                                              "sigma1": 300.0, "dwell": {"level": 0.0, "gain": 0.5, "time": 0.2}}}
    with pytest.raises(SystemDefinitionError, match="friction dwell applies to the static laws.*'lugre'"):
        NominalModel.from_dict(d)
    meas, model, _ = _breakaway_record()
    assert "rest ending in motion" in dwell.judge(meas, meas, None, None, model, False, 1e-6)["reason"]   # read
    v = dwell.judge(meas, meas, None, None, model.replace(law="lugre", sigma0=1e5, sigma1=300.0), False, 1e-6)
    assert v["untestable"] and "LuGre" in v["reason"] and "model" not in v
    from hunting.diagnose.model import Dwell
    kin = kinematics(meas, model.cm)
    assert "dwell" not in (reversal.untestable(kin, model) or "")
    assert "dwell growth" in reversal.untestable(kin, model.replace(dwell=Dwell(0.0, 0.5, 0.2)))
