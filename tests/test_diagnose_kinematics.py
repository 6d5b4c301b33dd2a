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


def _pid_loop_edge(mass, cm, kp, kd, ki, tau_f, T):
    """The spectral radius, as a function of the friction curve's slope c [N s/m], of the loop
    python-control closes: plant cm / (m s^2 + c s) held over T, the digital PID of the
    diagnosis's controller (integral kp + ki T z / (z - 1), derivative kd (z - 1) / ((tau_f + T)
    z - tau_f)), unit negative feedback."""
    import control as ct
    z = ct.tf([1, 0], [1], T)
    C = kp + ki * T * z / (z - 1) + kd * (z - 1) / ((tau_f + T) * z - tau_f)
    return lambda c: float(np.max(np.abs(ct.poles(ct.feedback(ct.c2d(ct.tf([cm], [mass, c, 0]), T, "zoh") * C, 1)))))


@pytest.mark.parametrize("kp, kd, ki, tau_f, T", [(317319.9, 3279.3, 15771479.8, 0.0, 1 / 4026.6),
                                                  (2605.0, 105.4, 9632.0, 0.0, 1e-3),
                                                  (4599.0, 171.9, 25411.8, 0.00124, 5e-4)])
def test_the_steady_slope_is_the_sampled_loops_stability_edge(kp, kd, ki, tau_f, T):
    """The slope a steady slide tolerates is STEADY_SHARE of the edge where the sampled loop
    about the slide loses stability: python-control's closed loop (a second construction of the
    same digital PID and zero-order-held plant) has its largest pole inside the unit circle 1 %
    on the safe side of the edge and outside 1 % beyond it, and the edge approaches the
    continuous loop's Routh-Hurwitz bound c = m ki / kp - kd cm at fast sampling."""
    from hunting.diagnose import NominalModel
    from hunting.diagnose.loop import STEADY_SHARE, steady_slope
    mass, cm = 15.0, 1.33
    model = NominalModel.from_dict({"plant": {"mass": mass, "motor_constant": cm},
                                    "friction": {"law": "stribeck", "Fc": 1.0, "Fs": 1.5, "vs": 0.003, "b": 0.0},
                                    "controller": {"type": "pid", "kp": kp, "kd": kd, "ki": ki, "tau_f": tau_f}})
    edge = steady_slope(model, T) / STEADY_SHARE
    rho = _pid_loop_edge(mass, cm, kp, kd, ki, tau_f, T)
    assert edge < 0
    assert rho(0.99 * edge) < 1.0 < rho(1.01 * edge)
    if tau_f == 0.0:
        assert edge == pytest.approx(mass * ki / kp - kd * cm, rel=0.02)
    free = NominalModel.from_dict({"plant": {"mass": mass}, "friction": {"law": "stribeck", "Fc": 1.0, "Fs": 1.5,
                                                                         "vs": 0.003, "b": 0.0}})
    assert steady_slope(free, T) == 0.0


def test_the_steady_slope_of_the_pd_velocity_loop_is_its_stability_edge():
    """The PD + velocity loop (u = kv (kp (r - y) - (qf_k - qf_k-1) / T), qf the mean of the last
    two measurements): python-control's closed loop with that controller, kv (kp + (z^2 - 1) /
    (2 T z^2)), has its largest pole inside the unit circle 1 % on the safe side of the edge and
    outside 1 % beyond it."""
    import control as ct
    from hunting.diagnose import NominalModel
    from hunting.diagnose.loop import STEADY_SHARE, steady_slope
    mass, cm, kp, kv, T = 15.0, 1.33, 160.18, 243.45, 1e-3
    model = NominalModel.from_dict({"plant": {"mass": mass, "motor_constant": cm},
                                    "friction": {"law": "stribeck", "Fc": 1.0, "Fs": 1.5, "vs": 0.003, "b": 0.0},
                                    "controller": {"type": "pd-velocity-loop", "kp": kp, "kv": kv}})
    edge = steady_slope(model, T) / STEADY_SHARE
    z = ct.tf([1, 0], [1], T)
    C = kv * (kp + (z * z - 1) / (2 * T * z * z))

    def rho(c):
        return float(np.max(np.abs(ct.poles(ct.feedback(ct.c2d(ct.tf([cm], [mass, c, 0]), T, "zoh") * C, 1)))))
    assert edge < 0
    assert rho(0.99 * edge) < 1.0 < rho(1.01 * edge)


def test_a_stiff_loop_holds_a_slow_slide_on_the_falling_branch():
    """Independent seed 11 d0050's case: a ramp at 0.09 counts per sample (a count every 11
    samples) inside a Stribeck dip, under a PID whose damping outweighs the curve's negative
    slope many times. The free mass's rule calls the whole slide a stick; the slow-slide reading
    (the loop's rule, the long span that sees counts this sparse), a slide; a 20-sample pause
    amid the ramp stays a stick under both."""
    from hunting.diagnose import NominalModel
    from hunting.diagnose.parts import slow_slide_settings
    res, dt, n = 1e-6, 2.5e-4, 4000
    t = np.arange(n) * dt
    rate = 0.09 * res / dt                                            # 0.36 mm/s
    x = np.clip(t - 0.1, 0.0, None) * rate
    x = np.where(t > 0.6, x - np.clip(t - 0.6, 0.0, 20 * dt) * rate, x)    # a pause of 20 samples at 0.6 s
    q = _quantized(x + 0.3 * res, res)
    friction = {"law": "stribeck", "Fc": 1.0, "Fs": 1.5, "vs": 0.0005, "beta": 2.0, "b": 0.0}
    stiff = NominalModel.from_dict({"plant": {"mass": 15.0, "motor_constant": 1.33}, "friction": friction,
                                    "controller": {"type": "pid", "kp": 3.2e5, "kd": 3.3e3, "ki": 1.6e7}})
    meas = Measurement(t, q, np.zeros(n))
    free = kinematics(meas, 1.0, window=0.0108, resolution=res, steady=stiff.steady_slide)
    held = kinematics(meas, 1.0, window=0.0108, **dict(slow_slide_settings(stiff, dt), resolution=res))
    v = np.abs(held.v)
    inside = (t > 0.15) & (t < 0.9) & (np.abs(t - 0.6025) > 0.01)
    assert (stiff.curve.positive.level_slope(v[inside]) < -100).all()          # the falling branch
    assert free.slide[inside].mean() < 0.05
    assert held.slide[inside].mean() > 0.99
    pause = (t > 0.6 + 3 * dt) & (t < 0.6 + 17 * dt)
    assert not held.slide[pause].any() and not free.slide[pause].any()
    # the map's velocity has the slide's direction: the short window's cubic derivative of a
    # staircase this sparse has the other sign on a fifth of the samples, the long window's not
    from scipy.signal import savgol_filter
    short = savgol_filter(q, max(5, (int(round(0.0108 / dt)) | 1) // 3 | 1), 3, deriv=1, delta=dt)
    assert (short[inside] <= 0).mean() > 0.1
    assert (held.vf[inside & held.slide] > 0).all()
    assert held.slow_slides and not free.slow_slides
