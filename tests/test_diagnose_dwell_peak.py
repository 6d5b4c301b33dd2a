"""The dwell growth in the seven-parameter form as a force-channel cause (``dwell_peak``): the rest
that began each slip, read from positions alone, and its regressor against the friction the
re-simulated loop felt (the numba kernel's Dwell.sliding, an independent implementation)."""
import numpy as np
import pytest

from hunting.diagnose import Measurement, NominalModel, kinematics
from hunting.diagnose.causes import dwell, dwell_peak
from hunting.diagnose.model import Dwell

DT = 1e-3
# a PD loop on a Stribeck contact
CONTACT = {"plant": {"mass": 1.0, "motor_constant": 1.0},
           "friction": {"law": "stribeck", "Fc": 10.0, "Fs": 15.0, "vs": 0.01, "beta": 2.0, "b": 50.0},
           "controller": {"type": "pid", "kp": 4e4, "kd": 400.0, "ki": 0.0}}

def _programme(speed: float):
    """A reference [m] (n,) of moves at ``speed`` [m/s]: out of a rest at the start, rests of 0.05, 0.4
    and 0.15 s ending in slips either way (the loop makes them longer: it stops short of the
    reference and waits for the error to break away), and a fast move that the reference reverses
    abruptly: the mass turns around under a drive far beyond the static level, without a rest.
    Each rest lies elsewhere than the one before: rests are read as the dwell cause reads them
    (:func:`hunting.diagnose.behaviour.stick_phases`), where a still run at the very position the
    last rest ended at continues that rest (noise can interrupt one)."""
    pieces = []

    def rest(d):
        pieces.append(np.full(int(round(d / DT)), pieces[-1][-1] if pieces else 0.0))

    def move(d, speed):
        start = pieces[-1][-1] if pieces else 0.0
        pieces.append(start + speed * DT * np.arange(1, int(round(d / DT)) + 1))
    rest(0.3)
    move(0.01 / speed, speed)
    rest(0.05)
    move(0.01 / speed, -speed)
    move(0.06, -0.1)
    move(0.06, 0.1)
    move(0.015 / speed, speed)     # (a rest where the last one ended would be read as that one's)
    rest(0.4)
    move(0.01 / speed, -speed)
    rest(0.15)
    move(0.01 / speed, speed)
    rest(0.2)
    return np.concatenate(pieces)


def _record(gain: float, system: dict = CONTACT, speed: float = 0.04):
    """(nominal model, kinematics of its loop re-simulated with a seven-parameter growth of
    ``gain`` [N] over 0.1 s along :func:`_programme`, the kernel's stuck flags (n,))."""
    from hunting.diagnose.resimulate import resimulate
    m = NominalModel.from_dict(system)
    truth = m.replace(dwell=Dwell(0.0, gain, 0.1, sliding=True)) if gain else m
    r = _programme(speed)
    t = np.arange(r.size) * DT
    sim = resimulate(Measurement(t=t, q=np.zeros_like(t), u=np.zeros_like(t), q_ref=r, name="steps"), truth,
                     resolution=1e-8, substeps=50)
    meas = Measurement(t=t, q=sim.q, u=sim.u, q_ref=r, name="steps")
    return m, kinematics(meas, 1.0, resolution=1e-8, noise=0.0), np.asarray(sim.stuck, bool)


def test_slip_rests_reads_each_slip_from_the_rest_before_it():
    """Against the kernel's own stick flags: 30 ms into the slip after each stick of at least two
    rest windows, the duration of that stick (within 2 ms, read from the measured positions at the
    default filter window: the smoothed ones round a rest's corners off, by 29 ms on the 53 ms
    rest here), inf after the rest at the record's start, NaN inside the rests;
    and 0 after the fast move's turnaround, where the kernel's mass did not stick at all. (Sticks
    of a sample or a few inside a slip, where the grown static level holds the mass for a moment
    after it breaks away, leave no trace in the positions: they are read as part of the slip.)"""
    m, kin, stuck = _record(5.0)
    r = dwell_peak.slip_rests(kin)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], stuck.astype(np.int8), [0]])))
    rests = [(a, b) for a, b in zip(edges[::2], edges[1::2]) if (b - a) * DT >= 2 * dwell.REST_WINDOW]
    assert len(rests) == 5 and rests[0][0] == 0
    assert np.isinf(r[rests[0][1] + 30])
    for a, b in rests[1:-1]:
        assert r[b + 30] == pytest.approx((b - a) * DT, abs=0.002)
        assert np.isnan(r[(a + b) // 2])
    # the turnaround between the second and third rest: the velocity changes sign, nothing sticks
    v = np.gradient(kin.q, DT)
    between = np.arange(rests[1][1] + 30, rests[2][0])
    turn = between[np.flatnonzero(np.diff(np.sign(kin.vf[between])) != 0)]
    assert turn.size and not stuck[turn[0] - 5:turn[0] + 5].any() and np.max(np.abs(v[turn[0] - 40:turn[0] + 40])) > 0.05
    assert r[turn[0] + 30] == 0.0


def test_regressor_is_the_friction_of_the_seven_parameter_loop():
    """The friction the re-simulated loop felt (u - m dv/dt from the kernel's own velocity) with a
    5 N seven-parameter growth over 0.1 s, against the nominal curve plus 5 N times the
    regressor's shape sign(v) exp(-(|v| / vs)^beta) (1 - exp(-t_r / time)) with t_r read from the
    positions by :func:`slip_rests`: the growth's force is matched within 10 % RMS on the sliding
    samples (three samples from every stick left out, and those whose speed changes by more than
    a fifth of vs in a sample, where the interval mean of the curve is not the trapezoid's), on
    a loop whose slips start out of its rests and the fast move's turnaround."""
    from hunting.diagnose.resimulate import resimulate
    m = NominalModel.from_dict(CONTACT)
    r = _programme(0.02)
    t = np.arange(r.size) * DT
    sim = resimulate(Measurement(t=t, q=np.zeros_like(t), u=np.zeros_like(t), q_ref=r, name="steps"),
                     m.replace(dwell=Dwell(0.0, 5.0, 0.1, sliding=True)), resolution=1e-8, substeps=50)
    kin = kinematics(Measurement(t=t, q=sim.q, u=sim.u, q_ref=r, name="steps"), 1.0, window=0.01, resolution=1e-8,
                     noise=0.0)
    v = np.asarray(sim.v)
    stuck = np.asarray(sim.stuck, bool)
    ok = ~np.convolve(stuck, np.ones(7), mode="same").astype(bool)
    ok[[0, -1]] = False
    c = m.curve
    nominal = np.where(v > 0, c.positive.level(np.abs(v)) + c.positive.b * np.abs(v),
                       -(c.negative.level(np.abs(v)) + c.negative.b * np.abs(v)))
    rest = dwell_peak.slip_rests(kin)
    shape = np.where(v > 0, np.exp(-(np.abs(v) / c.positive.vs) ** c.positive.beta),
                     -np.exp(-(np.abs(v) / c.negative.vs) ** c.negative.beta))
    model = 5.0 * shape * (1.0 - np.exp(-np.nan_to_num(rest, nan=0.0, posinf=np.inf) / 0.1))
    # the mean friction over each sample interval (u held there): u_k - m (v_k+1 - v_k) / dt, against
    # the interval means (trapezoidal) of the nominal curve and the growth
    mean = lambda x: 0.5 * (x[1:] + x[:-1])                      # noqa: E731
    growth = sim.u[:-1] - np.diff(v) / DT - mean(nominal)
    model, shape, ok = mean(model), mean(shape), ok[:-1] & ok[1:]
    ok &= np.abs(np.diff(v)) < 0.2 * c.positive.vs          # where a trapezoid is a mean of the curve
    k = ok & (np.abs(model) > 0.05)
    assert k.sum() > 15, k.sum()
    size = float(np.sqrt(np.mean(growth[k] ** 2)))
    assert np.sqrt(np.mean((growth[k] - model[k]) ** 2)) < 0.1 * size


def test_untestable_where_the_model_cannot_hold_the_growth_or_the_record_has_too_few_rests():
    """Testable on the stepping record; not without a Stribeck dip, on a discontinuous curve (no
    shape to decay along), on a LuGre model (its re-simulation holds no dwell growth), beside a
    dwell the model has, or with fewer than MIN_RESTS rests ending in slips (the record cut after
    its second rest)."""
    from dataclasses import replace
    m, kin, stuck = _record(0.0)
    assert dwell_peak.untestable(kin, m) is None
    flat = m.replace(law="coulomb-viscous", curve=m.curve.__class__(
        *(c.__class__(Fc=c.Fc, Fs=c.Fc, vs=c.vs, beta=c.beta, b=c.b) for c in (m.curve.positive, m.curve.negative))))
    assert "Stribeck dip" in dwell_peak.untestable(kin, flat)
    step = m.replace(curve=m.curve.__class__(
        *(replace(c, beta=np.inf) for c in (m.curve.positive, m.curve.negative))))
    assert "discontinuous" in dwell_peak.untestable(kin, step)
    assert "LuGre" in dwell_peak.untestable(kin, m.replace(law="lugre", sigma0=1e6, sigma1=1e3))
    assert "dwell effect already" in dwell_peak.untestable(kin, m.replace(dwell=Dwell(0.0, 1.0, 0.1)))
    ends = np.flatnonzero(np.diff(stuck.astype(np.int8)) == -1)
    n = int(ends[1]) + 100                  # the rest at the start and one more end in slips
    short = kinematics(Measurement(t=kin.t[:n], q=kin.q_measured[:n], u=np.zeros(n), name="cut"), 1.0,
                       resolution=1e-8, noise=0.0)
    assert dwell_peak.untestable(short, m) == "2 rests end in a slip (at least 3 needed)"
    k = int(ends[2]) + 100                  # ... and the third
    assert dwell_peak.untestable(kinematics(Measurement(t=kin.t[:k], q=kin.q_measured[:k], u=np.zeros(k), name="cut"),
                                            1.0, resolution=1e-8, noise=0.0), m) is None


def test_time_grid_spans_the_rests_the_record_has():
    """``time`` is searched from a third of the shortest rest that ends in a slip to three times
    the longest, and refined within ten times that span."""
    m, kin, _ = _record(0.0)
    r = dwell_peak.slip_rests(kin)
    d = r[np.isfinite(r) & (r > 0)]
    grid = [h["time"] for h in dwell_peak.hypers(kin, m)]
    assert len(grid) == dwell_peak.TIMES
    assert grid[0] == pytest.approx(d.min() / 3) and grid[-1] == pytest.approx(3 * d.max())
    lo, hi = dwell_peak.hyper_bounds(kin, m)["time"]
    assert lo == pytest.approx(d.min() / 10) and hi == pytest.approx(10 * d.max())


def test_extension_is_the_seven_parameter_dwell():
    m = NominalModel.from_dict(CONTACT)
    ext = dwell_peak.extend(m, np.array([2.0]), {"time": 0.3})
    assert ext.dwell == Dwell(0.0, 2.0, 0.3, sliding=True)
    assert "fall with the rest" in dwell_peak.unphysical(np.array([-1.0]), {"time": 0.3}, m)


def test_the_reversal_reads_the_same_rests_from_the_measured_positions():
    """reversal.rest_force holds a force exactly on the rests dwell.kinematics_rests reads from the
    measured positions (those dwell_peak's slips start from); the smoothed positions' rests are
    shorter (rounded corners), so reading them would have moved every rest's ends."""
    from hunting.diagnose.behaviour import stick_phases
    from hunting.diagnose.causes import reversal
    m, kin, _ = _record(2.0)
    rests = dwell.kinematics_rests(kin)
    held = np.isfinite(reversal.rest_force(kin, m))
    mask = np.zeros(kin.t.size, bool)
    for a, b in rests:
        mask[a:b + 1] = True
    assert len(rests) >= 4 and np.array_equal(held, mask)
    smoothed = stick_phases(kin.q, kin.dt, dwell.rest_band(kin.resolution, kin.noise), window=dwell.REST_WINDOW)
    assert sum(b - a for a, b in smoothed) < sum(b - a for a, b in rests)
