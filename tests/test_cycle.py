"""find_cycle from rough starts, against independent solvers and the thesis; its status codes;
follow by parameter name."""
import doctest
import math

import numpy as np
import pytest

import hunting
from hunting import find_cycle, follow, preset, simulate
from hunting.continuation import ContinuationOptions, OrbitStatus, StartOptions, resolve, shoot
from cycle_systems import (BELT_DESCRIPTION, PID_LUGRE_DESCRIPTION, belt_reference_cycle, belt_system,
                           family_system)


def test_lugre_k004_cycle_from_the_event_map_and_from_the_regulator_task():
    """Issue 19: the Table 8.1 LuGre cycle at K = 0.04 (the old start search only began at
    K = 0.05). Both ways in give the same orbit, and a plain simulation of Fig. 8.2's regulator
    task (independent of the search) ends on it."""
    a = find_cycle("table8.1-lugre", params={"K": 0.04})
    b = find_cycle("table8.1-lugre", {"x1": -1.0}, params={"K": 0.04})
    for r in (a, b):
        assert r.status == OrbitStatus.SUCCESS and r.stable
        assert r.trivial_error < 1e-8
        assert list(np.abs(r.multipliers)) == sorted(np.abs(r.multipliers), reverse=True)
        assert set(r.x0) == {"x1", "x2", "x3", "x4"}
    assert "event map" in a.start and "transient" in b.start
    assert a.period == pytest.approx(b.period, rel=1e-8)
    assert a.maximum["x1"] == pytest.approx(b.maximum["x1"], rel=1e-7)
    lp = preset("table8.1-lugre", K=0.04)
    tr = simulate(lp.system, lp.state(x1=-1.0), (0.0, 150.0), rtol=1e-10, atol=1e-13)
    late = tr.t > 150.0 - a.period
    assert np.max(tr.x[late, 0]) == pytest.approx(a.maximum["x1"], rel=1e-5)
    assert np.min(tr.x[late, 0]) == pytest.approx(a.minimum["x1"], rel=1e-5)


@pytest.mark.parametrize("written", ["description", "by hand"])
@pytest.mark.parametrize("start", [None, {"q": 2.0, "v": -1.0}, [-0.5, 0.3]])
def test_belt_cycle_matches_solve_ivp(written, start):
    """The moving-belt block of issue 19 (exponential law), as a model description and written
    by hand as a user would: period, stick and slip durations and extremes against scipy's
    solve_ivp with the stick phase and its events written in the test (tests/cycle_systems.py)."""
    ref = belt_reference_cycle()
    system = hunting.model(BELT_DESCRIPTION) if written == "description" else belt_system()
    r = find_cycle(system, start)
    assert r.success and r.stable
    assert r.period == pytest.approx(ref["period"], rel=1e-9)
    assert [p.kind for p in r.phases] in (["slip", "stick"], ["stick", "slip"])
    dur = {p.kind: p.duration for p in r.phases}
    assert dur["stick"] == pytest.approx(ref["stick"], rel=1e-8)
    assert dur["slip"] == pytest.approx(ref["slip"], rel=1e-8)
    for k, name in (("q_min", ("minimum", "q")), ("q_max", ("maximum", "q")), ("v_min", ("minimum", "v")),
                    ("v_max", ("maximum", "v"))):
        assert getattr(r, name[0])[name[1]] == pytest.approx(ref[k], abs=1e-8)
    # stick projects out the velocity: multipliers 1 and 0
    assert abs(r.multipliers[0]) == pytest.approx(1.0, abs=1e-8) and abs(r.multipliers[1]) < 1e-10


def test_pid_lugre_loop_closes_under_solve_ivp():
    """The PID + LuGre loop of Canudas de Wit et al. (1995) as a user's model description
    (sigma0 = 1e5, sigma1 = sqrt(1e5), sigma2 = 0.4, Fc = 1, Fs = 1.5, vs = 1e-3, kp = 3, kd = 6,
    ki = 4, unit mass, set point 1) from its default start (at rest at q = 0). The orbit found is
    integrated over one period by scipy's Radau with the equations written here: it closes and
    has the same extremes; the same loop as a preset (hand-written kernels, event-map start)
    has the same period."""
    from scipy.integrate import solve_ivp
    r = find_cycle(hunting.model(PID_LUGRE_DESCRIPTION))
    assert r.success and r.stable and "transient" in r.start
    assert r.state_names == ("q", "v", "ie", "z")
    m, Fc, Fs, vs, s0, s1, s2 = 1.0, 1.0, 1.5, 1e-3, 1e5, math.sqrt(1e5), 0.4
    kp, kd, ki, qd = 3.0, 6.0, 4.0, 1.0

    def rhs(t, y):
        q, v, ie, z = y
        e = q - qd
        g = Fc + (Fs - Fc) * math.exp(-(v / vs) ** 2)
        zd = v - s0 * abs(v) * z / g
        return [v, (-(kp * e + kd * v + ki * ie) - (s0 * z + s1 * zd + s2 * v)) / m, e, zd]
    x0 = r.x0_array
    sol = solve_ivp(rhs, (0.0, r.period), x0, method="Radau", rtol=1e-10, atol=1e-13, dense_output=True)
    assert sol.status == 0
    size = np.array([r.maximum[k] - r.minimum[k] for k in r.state_names])
    assert np.max(np.abs(sol.y[:, -1] - x0) / size) < 1e-7
    y = sol.sol(np.linspace(0.0, r.period, 20001))
    for i, k in enumerate(r.state_names):
        assert y[i].max() == pytest.approx(r.maximum[k], abs=1e-6 * size[i])
        assert y[i].min() == pytest.approx(r.minimum[k], abs=1e-6 * size[i])
    same = find_cycle("table4.1", params=dict(P=3.0, D=2.0, I=4.0 / 3.0, force_amplitude=0.0, q_d=1.0))
    assert same.period == pytest.approx(r.period, rel=1e-7)


@pytest.mark.parametrize("overrides,d_star", [({}, 0.2523), ({"beta": 1}, 0.2314), ({"beta": 0.5}, 0.1786),
                                              ({"curve": "discontinuous"}, 0.1485)])
def test_table_9_2_and_9_3_cycles_by_name(overrides, d_star):
    """Tables 9.2-9.3 (confirmed values): the stable cycle's stick error is max x1. For beta < 1
    the flow's sensitivities are unbounded at break-away, so the result comes from the event map
    alone (multiplier = slope of P^2)."""
    r = find_cycle("table9.1", params=overrides)
    assert r.success and r.stable and "event map" in r.start          # the whole map's range is searched
    assert r.maximum["x1"] == pytest.approx(d_star, abs=1e-4)
    assert r.minimum["x1"] == pytest.approx(-r.maximum["x1"], rel=1e-8)
    assert [p.kind for p in r.phases].count("stick") == 2          # symmetric: two stick phases a period
    assert sum(p.duration for p in r.phases) == pytest.approx(r.period, rel=1e-12)


def test_unstable_cycle_of_table_9_2_by_name():
    r = find_cycle("table9.1", which="unstable")
    assert r.success and not r.stable
    assert r.maximum["x1"] == pytest.approx(0.00336, abs=1e-5)
    assert abs(r.multipliers[0]) == pytest.approx(1.25, abs=0.01)     # slope of P^2 at d2* (Table 9.2)


def test_status_codes_say_why_there_is_no_cycle():
    eq = find_cycle("table9.1", {"x3": 0.01})                  # F_nf = -1 N inside the stick set
    assert eq.status == OrbitStatus.EQUILIBRIUM and "rest" in eq.message and not eq.x0
    esc = find_cycle("table9.1", {"x1": 0.3}, params={"P": -5})
    assert esc.status == OrbitStatus.ESCAPE
    short = find_cycle("table9.1", {"x1": 0.3}, start=StartOptions(t_max=2.0))
    assert short.status == OrbitStatus.NO_RECURRENCE and "t_max" in short.message
    none = find_cycle("table8.1-lugre", params={"K": 0.3}, which="unstable")
    assert none.status == OrbitStatus.NO_CYCLE
    with pytest.raises(hunting.ConvergenceError, match="EQUILIBRIUM"):
        find_cycle("table9.1", {"x3": 0.01}, throw=True)
    # a family of cycles (a state that never moves): the shooting Jacobian is singular
    po = shoot(family_system(), [0.0, -1.05, 0.3], 3.0)
    assert po.status == OrbitStatus.SINGULAR_JACOBIAN and "not isolated" in po.message
    assert eq.as_dict()["status"] == "EQUILIBRIUM" and "period" not in eq.as_dict()


def test_bad_arguments_name_themselves():
    with pytest.raises(hunting.SystemDefinitionError, match="x0 names 'q'"):
        find_cycle("table9.1", {"q": 1.0})
    with pytest.raises(hunting.SystemDefinitionError, match="x0 = 'abc'"):
        find_cycle("table9.1", "abc")
    with pytest.raises(hunting.SystemDefinitionError, match="period_guess"):
        find_cycle("table9.1", [0.1, 0, 0], period_guess=-1.0)
    with pytest.raises(hunting.SystemDefinitionError, match="start = end = 0.6"):
        follow("table8.1-switch", "K", 0.6, 0.6)
    with pytest.raises(hunting.SystemDefinitionError, match="parameter 'Q' is not a parameter"):
        follow("table9.1", "Q", 10.0, 12.0)
    with pytest.raises(hunting.SystemDefinitionError, match="parameter 'nope' is not a parameter of belt"):
        follow(belt_system(), "nope", 0.1, 0.2)
    with pytest.raises(hunting.SystemDefinitionError, match="is a choice"):
        follow("table9.1", "model", 1.0, 2.0)


def test_continuation_starts_at_the_stable_cycle_anywhere_on_the_map():
    """Issue 18: `continue table9.1 --param P --from 10 --to 12` found no cycle because the start
    search stopped at d = 0.05; the cycle is at d = 0.2523."""
    br = follow("table9.1", "P", 10.0, 12.0)
    assert br.status == OrbitStatus.SUCCESS and len(br.mu) >= 3
    assert br.amplitude[0] == pytest.approx(0.2523, abs=1e-4)
    assert br.stable.all() and br.mu[-1] >= 12.0
    # the end point against a fresh search at that P
    end = find_cycle("table9.1", params={"P": float(br.mu[-1])})
    assert br.period[-1] == pytest.approx(end.period, rel=1e-7)
    assert br.state_names == ("x1", "x2", "x3")


def test_follow_a_hand_written_system_by_parameter_name():
    """No system_at: the belt speed by name, each point against the solve_ivp reference."""
    br = follow(belt_system(), "vb", 0.1, 0.13, options=ContinuationOptions(ds=0.1))
    assert br.status == OrbitStatus.SUCCESS and len(br.mu) >= 3
    for mu, T in zip(br.mu[::2], br.period[::2]):
        assert T == pytest.approx(belt_reference_cycle(vb=mu)["period"], rel=1e-7)
    lens = resolve(belt_system()).lens("vb")
    assert lens.affine and np.array_equal(lens.direction(0.1), [0, 0, 0, 0, 0, 1.0])


def test_lugre_fold_by_name():
    """The LuGre branch's cyclic fold K = 0.6203 (TARGETS.md, confirmed with AUTO-07p), started
    near it by the by-name path, with a point limit that reports its own status."""
    start = find_cycle("table8.1-lugre", params={"K": 0.6}, throw=True)
    br = follow("table8.1-lugre", "K", 0.6, 0.7, stop_at=0.615, orbit=start.orbit)
    folds = [s for s in br.special if s.kind == "fold"]
    assert br.status == OrbitStatus.SUCCESS and folds
    assert folds[0].param == pytest.approx(0.6203, abs=1e-4)
    short = follow("table8.1-lugre", "K", 0.6, 0.7, orbit=start.orbit, options=ContinuationOptions(max_points=3))
    assert short.status == OrbitStatus.POINT_LIMIT and "max_points" in short.message and len(short.mu) == 3
    none = follow("table9.1", "P", 10.0, 12.0, x0={"x3": 0.01})
    assert none.status == OrbitStatus.NO_START and len(none.mu) == 0 and "no cycle at P = 10" in none.message


def test_docstring_examples():
    import hunting.continuation.cycle as C
    import hunting.continuation.hunting_branch as H
    import hunting.continuation.shooting as S
    import hunting.continuation.status as St
    import hunting.continuation.target as T
    import hunting.continuation.transient as Tr
    import hunting.eventmap.family as F
    for mod in (C, H, S, St, T, Tr, F):
        res = doctest.testmod(mod, optionflags=doctest.ELLIPSIS)
        assert res.failed == 0, mod.__name__


def test_follow_a_described_lugre_loop_by_name():
    """The PID + LuGre model's branch in kp: its shooting section is the one the search chose
    (the position is almost stationary where the search found its x0), the end point against a
    fresh search."""
    m = hunting.model(PID_LUGRE_DESCRIPTION)
    br = follow(m, "kp", 3.0, 3.3)
    assert br.status == OrbitStatus.SUCCESS and br.mu[-1] >= 3.3 and len(br.mu) < 20
    end = find_cycle(m.with_params(kp=float(br.mu[-1])))
    assert br.period[-1] == pytest.approx(end.period, rel=1e-7)
