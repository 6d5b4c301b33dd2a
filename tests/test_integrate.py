"""Integrator checks against closed forms, scipy, convergence order and symmetry."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import hunting
from hunting.models import servo as S
from reference import affine_flow, coulomb_first_stop, scipy_switch_sequence, slip_affine

COULOMB = dict(Fc=4.0, Fs=4.0)  # Table 9.1 with Fs = Fc: slip phases are linear


def coulomb_loop(**kw):
    return hunting.preset("table9.1", **{**COULOMB, **kw})


@pytest.mark.parametrize("method", ["dop853", "dp5", "radau"])
def test_coulomb_slip_phase_matches_matrix_exponential(method):
    loop = coulomb_loop()
    x0 = np.array([0.5, 0.0, 0.0])          # |F_nf| = 5 > Fs: slips negative at once
    te, xe = coulomb_first_stop(1.0, 10.0, 10.0, 100.0, 4.0, 1.0, x0, -1.0)
    t_eval = np.linspace(0.0, 0.95 * te, 40)
    tr = hunting.simulate(loop.system, x0, (0.0, 0.95 * te), t_eval=t_eval, method=method,
                          rtol=1e-11, atol=1e-13)
    A, c = slip_affine(1.0, 10.0, 10.0, 100.0, 4.0, 1.0, -1.0)
    exact = np.array([affine_flow(A, c, x0, t) for t in t_eval])
    tol = 1e-9 if method != "radau" else 1e-8
    np.testing.assert_allclose(tr.x, exact, atol=tol, rtol=0)


@pytest.mark.parametrize("method", ["dop853", "dp5", "radau"])
def test_stick_entry_and_breakaway_match_closed_forms(method):
    loop = coulomb_loop()
    x0 = np.array([0.5, 0.0, 0.0])
    te, xe = coulomb_first_stop(1.0, 10.0, 10.0, 100.0, 4.0, 1.0, x0, -1.0)
    tr = hunting.simulate(loop.system, x0, (0.0, 3.0), method=method, rtol=1e-12, atol=1e-14)
    ev = tr.events
    # first event: slip- reaches x2 = 0 (stick or reversal decided by |F_nf| <= Fs)
    assert ev.mode_from[0] == S.SLIP_NEG
    assert abs(ev.t[0] - te) < 1e-9
    np.testing.assert_allclose(ev.x_after[0], [xe[0], 0.0, xe[2]], atol=1e-9)
    k = np.flatnonzero(ev.mode_to == S.STICK)[0]
    d, x3 = ev.x_after[k, 0], ev.x_after[k, 2]
    # stick: x3(t) = x3 + d t; break-away when -(kp d + ki x3(t)) = -sign(d) Fs
    dt = (-(10 * d + 100 * x3) + np.sign(d) * 4.0) / (100 * d)
    assert ev.mode_from[k + 1] == S.STICK
    assert abs((ev.t[k + 1] - ev.t[k]) - dt) < 1e-11
    np.testing.assert_allclose(ev.x_after[k + 1], [d, 0.0, x3 + d * dt], atol=1e-12)
    # during stick x1, x2 are constant exactly
    sel = (tr.mode == S.STICK) & (tr.t >= ev.t[k]) & (tr.t <= ev.t[k + 1])
    assert sel.sum() >= 2 and np.all(tr.x[sel, 1] == 0.0) and np.all(tr.x[sel, 0] == d)


def _convergence_orders(method, hs, t_end=2.2):
    loop = hunting.preset("table9.1")
    x0 = [0.1, 0.0, 0.0]
    ref = hunting.simulate(loop.system, x0, (0.0, t_end), rtol=1e-13, atol=1e-15)
    errs = []
    for h in hs:
        tr = hunting.simulate(loop.system, x0, (0.0, t_end), method=method, fixed_step=h, rtol=1e-13,
                              atol=1e-15)
        assert len(tr.events) == len(ref.events) >= 3   # across stick entries and break-aways
        errs.append(np.max(np.abs(tr.x_final - ref.x_final)))
    return np.polyfit(np.log(hs), np.log(errs), 1)[0], errs


@pytest.mark.parametrize("method,hs,order", [
    ("dp5", [0.02, 0.01, 0.005, 0.0025], 5.0),
    ("dop853", [0.08, 0.06, 0.04, 0.03], 8.0),
    ("radau", [0.02, 0.01, 0.005, 0.0025], 5.0),
])
def test_order_of_convergence_across_events(method, hs, order):
    """Global error at t = 2.2 s (after 3 events) with fixed steps: the slope of log(error)
    against log(h) is the method's order. Events are polished with a step of the method
    itself, so the lower order of the dense output does not show."""
    slope, errs = _convergence_orders(method, hs)
    assert slope > order - 0.7, (slope, errs)


def test_smooth_segment_matches_scipy_dop853():
    loop = hunting.preset("table8.1-lugre")
    x0 = loop.state(x1=-1.0)
    # up to just before the first velocity reversal the LuGre loop is one smooth mode
    tr0 = hunting.simulate(loop.system, x0, (0.0, 5.0), rtol=1e-12, atol=1e-14, stop_mode=1)
    t_end = 0.99 * tr0.events.t[0]
    t_eval = np.linspace(0, t_end, 30)
    tr = hunting.simulate(loop.system, x0, (0.0, t_end), t_eval=t_eval, rtol=1e-12, atol=1e-14)
    p = loop.system.params

    def rhs(t, x):
        out = np.empty(4)
        S.servo_vf(S.V_POS if x[1] >= 0 else S.V_NEG, t, np.ascontiguousarray(x), p, out)
        return out
    sol = solve_ivp(rhs, (0, t_end), x0, method="DOP853", t_eval=t_eval, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(tr.x, sol.y.T, rtol=1e-8, atol=1e-12)


def test_stick_slip_sequence_matches_scipy_event_chaining():
    """A second method: solve_ivp with terminal events, stick phases in closed form."""
    d, ts, _ = scipy_switch_sequence(1.0, 10.0, 10.0, 100.0, 4.0, 2.0, 0.1, 2.0, 1.0, 0.1, 6)
    loop = hunting.preset("table9.1")
    tr = hunting.simulate(loop.system, [0.1, 0.0, 0.0], (0.0, ts[-1] + 0.1))
    k = tr.events.entering(S.STICK)
    np.testing.assert_allclose(tr.events.x_after[k[:6], 0], d, atol=1e-9)
    np.testing.assert_allclose(tr.events.t[k[:6]], ts, atol=1e-8)


@pytest.mark.parametrize("name", ["table9.1", "table8.1-lugre"])
def test_odd_symmetry(name):
    loop = hunting.preset(name)
    assert loop.system.odd
    x0 = loop.state(0.3, 0.1, -0.02)
    a = hunting.simulate(loop.system, x0, (0.0, 6.0), t_eval=np.linspace(0, 6, 50),
                         method="radau" if "lugre" in name else "dop853", rtol=1e-10, atol=1e-13)
    b = hunting.simulate(loop.system, -x0, (0.0, 6.0), t_eval=np.linspace(0, 6, 50),
                         method="radau" if "lugre" in name else "dop853", rtol=1e-10, atol=1e-13)
    np.testing.assert_allclose(a.x, -b.x, atol=1e-9)
    np.testing.assert_array_equal(loop.system.mirror_mode[a.mode], b.mode)


def test_tangential_breakaway_does_not_refire():
    """Break-away with continuous g starts with zero acceleration: the velocity guard starts at
    zero and must not fire again at once."""
    loop = hunting.preset("table9.1")
    tr = hunting.simulate(loop.system, [0.1, 0.0, 0.0], (0.0, 2.0))
    ev = tr.events
    assert ev.mode_from[0] == S.STICK and ev.mode_to[0] == S.SLIP_NEG
    assert ev.t[1] - ev.t[0] > 0.5           # the slip phase lasts, no spurious stick
    acc = loop.system.evaluate(ev.x_after[0], mode=S.SLIP_NEG)[1]
    assert abs(acc) < 1e-9                   # the departure really is tangential


def test_velocity_reversal_without_sticking():
    """With large gains the loop reverses without sticking: the event goes slip- -> slip+."""
    loop = hunting.preset("table9.1", P=100.0, D=0.01)
    tr = hunting.simulate(loop.system, [0.5, 0.0, 0.0], (0.0, 1.0))
    ev = tr.events
    assert ev.mode_from[0] == S.SLIP_NEG and ev.mode_to[0] == S.SLIP_POS
    assert ev.x_after[0, 1] == 0.0


def test_event_at_segment_start_in_stick_does_not_loop():
    """Starting exactly on the break-away boundary |F_nf| = Fs."""
    loop = hunting.preset("table9.1")
    x0 = np.array([0.1, 0.0, 0.3])            # F_nf = -10 (0.1 + 3) = -31 -> slips at once
    tr = hunting.simulate(loop.system, x0, (0.0, 0.2))
    assert tr.success and tr.mode[0] == S.SLIP_NEG
    x0 = np.array([0.1, 0.0, 0.3])
    x0[2] = (4.0 / 10.0 - 0.1) / 10.0          # F_nf = -4 exactly: at the boundary, sticks
    tr = hunting.simulate(loop.system, -x0, (0.0, 0.5))
    assert tr.success and len(tr.events) >= 1 and tr.events.t[0] < 1e-12


def test_buffers_grow_and_results_do_not_depend_on_it():
    loop = hunting.preset("table9.1")
    tr = hunting.simulate(loop.system, [0.1, 0.0, 0.0], (0.0, 200.0), rtol=1e-12, atol=1e-14)
    assert len(tr.t) > 1024 and len(tr.events) > 256 and tr.success
    short = hunting.simulate(loop.system, [0.1, 0.0, 0.0], (0.0, 20.0), rtol=1e-12, atol=1e-14)
    k = len(short.events)
    np.testing.assert_array_equal(tr.events.t[:k], short.events.t)
    assert np.all(np.diff(tr.t) >= 0)


def test_bounds_give_status_not_hang():
    loop = hunting.preset("table9.1")
    tr = hunting.simulate(loop.system, [0.1, 0.0, 0.0], (0.0, 60.0), max_steps=50)
    assert tr.status == hunting.Status.MAX_STEPS and "max_steps" in tr.message
    tr = hunting.simulate(loop.system, [0.1, 0.0, 0.0], (0.0, 60.0), max_events=5)
    assert tr.status == hunting.Status.MAX_EVENTS and len(tr.events) == 5
    with pytest.raises(hunting.ConvergenceError, match="max_events") as ei:
        hunting.simulate(loop.system, [0.1, 0.0, 0.0], (0.0, 60.0), max_events=5, throw=True)
    assert isinstance(ei.value.result, hunting.Trajectory)


def test_stop_mode_counts_entries():
    loop = hunting.preset("table9.1")
    tr = hunting.simulate(loop.system, [0.1, 0.0, 0.0], (0.0, 100.0), stop_mode="stick", stop_count=3)
    assert tr.status == hunting.Status.STOPPED
    assert len(tr.events.entering(S.STICK)) == 3 and tr.mode_final == S.STICK


@pytest.mark.parametrize("sigma0", [1e4, 1e6])
def test_radau_handles_stiff_lugre_loops(sigma0):
    """LuGre with sigma0 up to 1e6 N/m: Radau IIA agrees with DOP853 and needs far fewer steps
    once the bristle dynamics are stiff."""
    loop = hunting.preset("table4.1", sigma0=sigma0, sigma1=np.sqrt(sigma0), P=50.0, D=0.1, I=5.0,
                          force_amplitude=0.0)
    x0 = loop.state(x1=0.05)
    te = np.linspace(0.0, 2.0, 21)
    r = hunting.simulate(loop.system, x0, (0.0, 2.0), method="radau", rtol=1e-8, atol=1e-12, t_eval=te)
    e = hunting.simulate(loop.system, x0, (0.0, 2.0), method="dop853", rtol=1e-10, atol=1e-14, t_eval=te)
    assert r.success and e.success
    # at step ends (t = 2) Radau has its full order; at t_eval points between steps its 3rd-order
    # collocation polynomial interpolates
    np.testing.assert_allclose(r.x[-1], e.x[-1], atol=3e-7)   # global error at rtol = 1e-8
    np.testing.assert_allclose(r.x[:, :3], e.x[:, :3], atol=3e-5)
    if sigma0 >= 1e6:
        assert r.stats["n_steps"] * 5 < e.stats["n_steps"]
