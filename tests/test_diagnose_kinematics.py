"""The force balance's drive: the delayed zero-order-held drive as the position's second
difference sees it, against quadrature of the delayed staircase under the triangular kernel."""
import numpy as np
import pytest

from hunting.diagnose import Measurement, kinematics


@pytest.mark.parametrize("delay", [0.0004, 0.0017, 0.003])
def test_delayed_drive_is_the_second_difference_of_the_delayed_staircase(delay):
    """u held over [t_k, t_k+1) and delayed by a fraction of samples: the second difference of
    the position at t_k sees the staircase weighted by (dt - |s|) / dt^2 over [t_k - dt, t_k +
    dt]. Linear interpolation of the aligned drive is off by 0.4 (of a unit random walk) there."""
    rng = np.random.default_rng(0)
    n, dt, cm = 400, 1e-3, 2.0
    t = np.arange(n) * dt
    u = np.cumsum(rng.normal(size=n))
    kin = kinematics(Measurement(t, np.zeros(n), u), cm, resolution=0.0)
    got = kin.delayed_drive(delay)
    s = np.linspace(-dt, dt, 40001)
    w = (dt - np.abs(s)) / dt ** 2
    for k in range(50, 70):
        j = np.clip(np.floor((t[k] + s - delay) / dt + 1e-12).astype(int), 0, n - 1)
        exact = cm * np.trapezoid(w * u[j], s)
        assert got[k] == pytest.approx(exact, abs=1e-3)
    # whole samples: the aligned drive shifted
    assert np.allclose(kin.delayed_drive(2 * dt)[10:], kin.drive[8:-2])


def _quantized(x, res):
    return res * np.round(x / res)


def test_a_slow_slide_is_not_stuck_and_a_rest_keeps_its_edges():
    """An exactly known motion: rest, a slide at 0.4 counts per sample (the short span sees one
    count, as reporting7 d0385's 1.5 mm/s at 4.1 um and 800 Hz did), rest again. Every sample of
    the slide a count away from its ends slides; the rests stick up to the count that ends or
    starts the motion."""
    from hunting.diagnose.kinematics import stuck_samples
    res, dt, n = 1e-6, 1e-3, 600
    t = np.arange(n) * dt
    x = np.clip(t - 0.2, 0.0, 0.2) * 0.4 * res / dt          # slides on [0.2, 0.4] s
    q = _quantized(x + 0.3 * res, res)
    old = stuck_samples(q, dt, res)
    new = stuck_samples(q, dt, res, progress_samples=20)
    inside = (t > 0.2 + 2.5 * dt) & (t < 0.4 - 2.5 * dt)
    assert old[inside].mean() > 0.9                          # the short span alone calls it a rest
    assert not new[inside].any()
    first = np.flatnonzero(np.diff(q) != 0)
    assert new[1:first[0] - 1].all() and new[first[-1] + 2:n - 1].all()


def test_a_rest_dithering_between_two_counts_stays_stuck():
    """A mass at rest on a count boundary with sensor noise toggles between two counts: it never
    progresses one way on both sides, so it stays stuck however long the progress span is."""
    from hunting.diagnose.kinematics import stuck_samples
    rng = np.random.default_rng(3)
    res, dt, n = 1e-6, 1e-3, 2000
    q = _quantized(0.5 * res + 0.2 * res * rng.normal(size=n), res)
    assert np.unique(q).size >= 2
    assert stuck_samples(q, dt, res, progress_samples=25)[1:-1].all()


def test_a_slow_slide_counts_only_where_friction_rises_with_speed():
    """On the falling branch of a Stribeck dip the same count progress is a stick-slip below the
    count: the progress test is held back where the model's curve falls with speed."""
    from hunting.diagnose import NominalModel
    from hunting.diagnose.kinematics import stuck_samples
    res, dt, n = 1e-6, 1e-3, 600
    t = np.arange(n) * dt
    q = _quantized(np.clip(t - 0.2, 0.0, 0.2) * 0.4 * res / dt + 0.3 * res, res)
    v = np.gradient(q, dt)
    inside = (t > 0.2 + 2.5 * dt) & (t < 0.4 - 2.5 * dt)
    dip = NominalModel.from_dict({"plant": {"mass": 1.0}, "friction": {"law": "stribeck", "Fc": 1.0, "Fs": 1.5,
                                                                       "vs": 0.002, "beta": 1.0, "b": 0.0}})
    flat = NominalModel.from_dict({"plant": {"mass": 1.0}, "friction": {"Fc": 1.0, "b": 1.0}})
    assert flat.steady_slide(v[inside]).all()
    assert not dip.steady_slide(v[inside]).any()
    assert stuck_samples(q, dt, res, progress_samples=20, progress_where=dip.steady_slide(v))[inside].mean() > 0.9
    assert not stuck_samples(q, dt, res, progress_samples=20, progress_where=flat.steady_slide(v))[inside].any()


def test_a_pause_between_counts_is_a_stick():
    """A slide that pauses for 5 samples on one count (a brief stick between two motions) has
    counts behind and ahead within the progress span, but its short-window velocity near zero
    says stick (reporting7 d0109: the map's sign at that velocity put 3 N into a clean residual)."""
    from scipy.signal import savgol_filter
    from hunting.diagnose.kinematics import stuck_samples
    res, dt, n = 1e-6, 1e-3, 400
    t = np.arange(n) * dt
    x = np.where(t < 0.2, t, 0.2 + np.clip(t - 0.205, 0.0, None)) * 0.4 * res / dt
    q = _quantized(x + 0.3 * res, res)
    vf = savgol_filter(q, 11, 3, deriv=1, delta=dt)
    pause = (t > 0.2005) & (t < 0.2025)                  # counts within 5 samples both ways
    assert pause.sum() >= 2
    assert stuck_samples(q, dt, res, progress_samples=5, progress_velocity=vf)[pause].all()
    assert not stuck_samples(q, dt, res, progress_samples=5)[pause].any()
    moving = (t > 0.1) & (t < 0.18)
    assert not stuck_samples(q, dt, res, progress_samples=5, progress_velocity=vf)[moving].any()


def test_creep_below_the_moving_bound_stays_a_stick():
    """The same count progress (0.4 counts per sample) is a slide in a record whose fastest
    motion is 10 times faster, and a stick (presliding's creep, left to the stick channel) where
    the record also moves 100 times faster: only speeds above 2 % of the largest are slides."""
    res, dt, n = 1e-6, 1e-3, 1200
    t = np.arange(n) * dt
    slow = 0.4 * res / dt

    def record(fast):
        v = np.where(t < 0.3, fast * np.sin(np.pi * t / 0.3) ** 2, np.where((t > 0.6) & (t < 0.9), slow, 0.0))
        q = _quantized(np.cumsum(v) * dt + 0.3 * res, res)
        return kinematics(Measurement(t, q, np.zeros(n)), 1.0, window=0.031, resolution=res)

    creep = (t > 0.65) & (t < 0.85)
    assert record(10 * slow).slide[creep].all()
    assert not record(100 * slow).slide[creep].any()


@pytest.mark.parametrize("shape, w", [((2000,), 21), ((2000, 3), 41), ((30,), 21), ((15, 2), 21)])
def test_the_acceleration_filter_is_scipys_savitzky_golay_second_derivative(shape, w):
    """H_a applies scipy's savgol_filter (cubic, second derivative, mode 'interp') to the double
    sum, as a linear operator read once from that filter: the same output as the filter itself,
    interior and edges, on single and multi-column inputs, and the filter's own on inputs shorter
    than the window (its error: 15 samples under 21)."""
    from scipy.signal import savgol_filter

    from hunting.diagnose.kinematics import acceleration_filter
    rng = np.random.default_rng(3)
    dt = 1e-3
    x = rng.normal(size=shape) + np.linspace(0.0, 5.0, shape[0]).reshape((-1,) + (1,) * (len(shape) - 1))
    m = np.mean(x, axis=0)
    y = np.cumsum(x - m, axis=0) * dt
    X = np.concatenate([np.zeros((1,) + x.shape[1:]), np.cumsum(y, axis=0)[:-1]], axis=0) * dt
    if shape[0] < w:
        with pytest.raises(ValueError):
            acceleration_filter(x, dt, w)
        return
    want = savgol_filter(X, w, 3, deriv=2, delta=dt, mode="interp", axis=0) + m
    got = acceleration_filter(x, dt, w)
    assert got.shape == x.shape
    assert np.allclose(got, want, rtol=0.0, atol=1e-9 * np.max(np.abs(want)))
    # and it is the second derivative's low pass: a parabola's second derivative exactly
    t = np.arange(shape[0]) * dt
    assert np.allclose(acceleration_filter(np.full(shape[0], 2.0), dt, w), 2.0)
    assert np.allclose(savgol_filter(t ** 2, w, 3, deriv=2, delta=dt, mode="interp"), 2.0)
