"""Event maps: thesis tables, invariants, second methods (simulation, banded model)."""
import json

import numpy as np
import pytest

import hunting
from hunting import analysis as A
from hunting.cli import main
from hunting.eventmap import (basins, check_resolution, evaluate_map, event_map, fixed_points, linear_origin,
                              map_diagram, origin_slope, stick_map)
from hunting.models import servo as S

GRID = np.linspace(0.0, 0.5, 501)


@pytest.mark.parametrize("kw,cycles,eq_stable", [
    (dict(), [(0.0034, False), (0.2523, True)], True),          # Table 9.2
    (dict(beta=1.0), [(0.2314, True)], False),                  # Table 9.3
    (dict(beta=0.5), [(0.1786, True)], False),
    (dict(beta="inf"), [(0.1485, True)], False),
])
def test_thesis_fixed_points_of_p2(kw, cycles, eq_stable):
    fps = fixed_points(hunting.preset("table9.1", **kw), GRID, 2)
    eq = [f for f in fps if f.kind == "equilibrium"]
    cyc = [f for f in fps if f.kind == "cycle"]
    assert len(eq) == 1 and eq[0].stable == eq_stable
    assert [(round(f.d, 4), f.stable) for f in cyc] == cycles
    for f in cyc:
        assert f.iterate == 2 and f.residual < 1e-11
        assert f.stable == (abs(f.slope) < 1)
        np.testing.assert_allclose(f.orbit, [f.d, -f.d], atol=1e-10)    # symmetric cycle


def test_map_is_odd_and_its_first_iterate_matches_simulation():
    loop = hunting.preset("table9.1")
    d = np.linspace(0.01, 0.5, 25)
    a = evaluate_map(loop, d)
    b = evaluate_map(loop, -d)
    np.testing.assert_allclose(a.image, -b.image, atol=1e-12)
    both = evaluate_map(loop, np.concatenate([d, -d]))      # odd loop: each |d| integrated once
    np.testing.assert_allclose(both.image[d.size:], b.image, atol=1e-12)
    tr = hunting.simulate(loop.system, [0.1, 0.0, 0.0], (0.0, 3.0), rtol=1e-12, atol=1e-15)
    assert stick_map(loop, 0.1)[0] == pytest.approx(tr.events.x_after[1, 0], abs=1e-11)
    assert stick_map(loop, 0.1, 2)[0] == pytest.approx(tr.events.x_after[3, 0], abs=1e-11)


def test_coulomb_map_is_linear_in_d():
    loop = hunting.preset("table9.1", Fc=4.0)
    d = np.array([1e-4, 1e-3, 0.01, 0.1, 0.5])
    mv = evaluate_map(loop, d, 1)
    np.testing.assert_allclose(mv.image / d, mv.image[0] / d[0], rtol=1e-9)


def test_derivative_chain_rule_and_finite_differences():
    loop = hunting.preset("table9.1")
    fps = fixed_points(loop, GRID, 2)
    stable = next(f for f in fps if f.kind == "cycle" and f.stable)
    em = event_map(loop, [stable.d, -stable.d], 1)
    # d P^2/dd at d* = P'(d*) P'(P(d*)) (chain rule over the orbit)
    assert em.derivative[0] * em.derivative[1] == pytest.approx(stable.slope, rel=1e-6)
    # the derivative against a difference quotient with a 100x larger step
    h = 1e-3 * stable.d
    mv = evaluate_map(loop, [stable.d - h, stable.d + h], 1)
    assert em.derivative[0] == pytest.approx((mv.image[1] - mv.image[0]) / (2 * h), rel=1e-5)
    assert "central differences" in em.derivative_method


def test_fixed_point_is_a_periodic_orbit_of_the_full_system():
    loop = hunting.preset("table9.1")
    d_star = next(f.d for f in fixed_points(loop, GRID, 2) if f.kind == "cycle" and f.stable)
    X0, mode0 = loop.breakaway_state([d_star])
    tr = hunting.simulate(loop.system, X0[0], (0.0, 50.0), mode0=int(mode0[0]), rtol=1e-12, atol=1e-15,
                          stop_mode="stick", stop_count=2)
    assert tr.status == hunting.Status.STOPPED
    assert tr.x_final[0] == pytest.approx(d_star, abs=1e-10)


@pytest.mark.parametrize("model,tol", [("switch", 1e-6), ("switch-banded", 2e-4)])
def test_stable_cycle_is_what_long_simulation_converges_to(model, tol):
    """Second method: simulate for a long time from d = 0.1 and read the stick errors; the
    banded Switch model (eta = 1e-6) converges to the same cycle to within its band error."""
    loop = hunting.preset("table9.1", model=model, eta=1e-6)
    tr = hunting.simulate(loop.system, [0.1, 0.0, 0.0], (0.0, 400.0), rtol=1e-10, atol=1e-13)
    stick = S.STICK if model == "switch" else S.BAND_STICK
    d = tr.events.x_before[tr.events.entering(stick), 0]
    assert np.abs(d[-6:]) == pytest.approx(0.25230480641, abs=tol)


def test_bifurcation_fold_between_21_and_22():
    dg = map_diagram("table9.1", "P", [20.0, 21.0, 22.0])
    folds = [s for s in dg.special if s.kind == "fold"]
    assert list(dg.n_cycles()) == [2, 2, 0] and len(folds) == 1
    f = folds[0]
    assert 21 < f.param < 22 and f.precision < 1e-4
    # just below the fold the pair exists, just above it does not
    below = fixed_points(hunting.preset("table9.1", P=f.interval[0]), np.linspace(0, 0.1, 401), 2)
    above = fixed_points(hunting.preset("table9.1", P=f.interval[1] + 1e-3), np.linspace(0, 0.1, 401), 2)
    assert sum(x.kind == "cycle" for x in above) == 0
    assert sum(x.kind == "cycle" for x in below) in (0, 2)   # a near-tangent pair may not bracket


def test_equilibrium_stability_change_for_beta_1():
    dg = map_diagram("table9.1", "P", [26.0, 27.0], overrides=dict(beta=1.0))
    sp = [s for s in dg.special if s.kind == "equilibrium_stability"]
    assert len(sp) == 1 and 26 < sp[0].param < 27 and sp[0].data["stable_above"] == 1.0


def test_analytic_conditions():
    assert A.critical_value(lambda P: hunting.preset("table9.1", beta=1.0, P=P), 10, 40) == pytest.approx(29.0)
    assert A.critical_value(lambda K: hunting.preset("limms-switch", K=K), 1, 200) == pytest.approx(50.3389, abs=1e-4)
    assert A.stability_condition(hunting.preset("table9.1")).holds is True
    assert A.stability_condition(hunting.preset("table9.1", beta=0.5)).holds is None
    assert A.stability_condition(hunting.preset("table9.1", beta="inf")).holds is False
    b_star = A.critical_damping(lambda b: hunting.preset("table9.1", Fc=4.0, b=b))
    assert b_star == pytest.approx(-1.253, abs=5e-4)
    # b = 0 (linear part marginal) is still stable, just below b* is not
    assert abs(A.coulomb_map_slope(hunting.preset("table9.1", Fc=4.0, b=0.0))) < 1
    assert abs(A.coulomb_map_slope(hunting.preset("table9.1", Fc=4.0, b=b_star - 0.01))) > 1


def test_basins_split_at_the_unstable_cycle():
    loop = hunting.preset("table9.1")
    fps = fixed_points(loop, GRID, 2)
    grid = np.array([-0.4, -0.003, -0.001, 0.001, 0.003, 0.004, 0.1, 0.4])
    b = basins(loop, grid, fps)
    names = [b.attractors[i].kind if i >= 0 else "none" for i in b.attractor]
    assert names == ["cycle", "equilibrium", "equilibrium", "equilibrium", "equilibrium", "cycle", "cycle", "cycle"]


def test_maps_with_cogging_and_direction_dependent_friction_are_not_assumed_odd():
    lp = hunting.preset("table9.1", Fs_neg=5.0)
    assert not lp.odd
    a, b = evaluate_map(lp, [0.1]), evaluate_map(lp, [-0.1])
    assert abs(a.image[0] + b.image[0]) > 1e-3
    lm = hunting.preset("limms-switch")
    mv = evaluate_map(lm, np.linspace(-0.015, 0.015, 31), 1)
    assert mv.ok[mv.d != 0].all()
    # break-away state: the force reaches the stick limit exactly, cogging included
    X, mode = lm.breakaway_state([0.004])
    assert lm.nonfriction_force(X[0]) == pytest.approx(-27.9, abs=1e-9)


def test_errors_are_named():
    with pytest.raises(hunting.SystemDefinitionError, match="event maps need the exact Switch model"):
        evaluate_map(hunting.preset("table8.1-lugre"), [0.1])
    with pytest.raises(hunting.SystemDefinitionError, match="iterate = 0 is not allowed"):
        evaluate_map(hunting.preset("table9.1"), [0.1], 0)
    with pytest.raises(hunting.SystemDefinitionError, match="d must be finite"):
        evaluate_map(hunting.preset("table9.1"), [np.nan])


def test_cli_eventmap_json_contract(tmp_path):
    js = tmp_path / "m.json"
    assert main(["eventmap", "table9.1", "--set", "beta=inf", "--grid", "0:0.5:101", "--iterate", "2",
                 "--json", str(js), "--plot", str(tmp_path / "m.png")]) == 0
    data = json.loads(js.read_text())
    assert len(data["grid"]) == len(data["image"]) == len(data["status"]) == 101
    fp = data["fixed_points"]
    assert {"d", "iterate", "slope", "stable", "kind"} <= set(fp[0])
    cyc = [f for f in fp if f["kind"] == "cycle"]
    assert cyc[0]["d"] == pytest.approx(0.1485, abs=1e-4) and cyc[0]["stable"] is True
    assert main(["eventmap", "table9.1", "--grid", "0:0.5"]) == 2


def test_reproduce_ch9_matches_the_thesis(tmp_path):
    from hunting.reproduce.ch9 import run
    assert run(tmp_path) == 0
    data = json.loads((tmp_path / "ch9.json").read_text())
    assert all(r["ok"] for r in data["checks"]) and len(data["checks"]) >= 30
    facts = {r["check"]: r for r in data["checks"] if isinstance(r["ours"], bool)}
    # a label that claims "unstable" carries True where the thesis has it unstable (Tables 9.2-9.4)
    for label in ("d2* unstable", "beta=1: equilibrium set unstable", "beta=0.5: equilibrium set unstable",
                  "discontinuous: equilibrium set unstable"):
        assert facts[label]["ours"] is True and facts[label]["thesis"] is True, label
    for name in ("fig9_4", "fig9_5", "fig9_6", "fig9_7", "fig9_8", "fig11_1", "fig11_3"):
        assert (tmp_path / f"{name}.png").stat().st_size > 20000


def test_attractors_find_the_table_9_2_cycle_and_the_equilibrium():
    """Iterating P finds the stable cycle of Table 9.2 (period 2, d3* = 0.2523, P^2 slope
    0.783) from starts outside the unstable cycle, and the equilibrium set from starts inside."""
    from hunting.eventmap import attractors
    loop = hunting.preset("table9.1")
    atts = attractors(loop, [0.001, -0.002, 0.05, 0.3, -0.4])
    kinds = {a.kind for a in atts}
    assert kinds == {"equilibrium", "cycle"}
    cyc = next(a for a in atts if a.kind == "cycle")
    assert cyc.period == 2
    assert np.sort(np.abs(cyc.d)) == pytest.approx([0.2523048, 0.2523048], abs=1e-6)
    assert cyc.multiplier == pytest.approx(0.7829, abs=2e-3)
    assert cyc.basin == 3
    eq = next(a for a in atts if a.kind == "equilibrium")
    assert eq.basin == 2
    with pytest.raises(hunting.SystemDefinitionError, match="starts"):
        attractors(loop, [np.nan])


# ---------------------------------------------------------------- the slope at the equilibrium set
def _secant(loop, k, delta):
    """P^k(delta)/delta and P^k(-delta)/(-delta): finite differences of the true map at 0."""
    mv = evaluate_map(loop, [delta, -delta], k)
    return mv.image[0] / delta, mv.image[1] / -delta


@pytest.mark.parametrize("name, kw, k, delta, rtol", [
    ("table9.1", dict(), 2, 4e-8, 2e-6),                # beta = 2: P^2(d)/d = slope + O(d)
    ("table9.1", dict(Fc=4.0), 2, 1e-3, 1e-8),          # Coulomb: P^2 is linear, exact
    ("table9.1", dict(beta=1.0, P=27.0), 2, 1e-9, 1e-4),  # beta = 1: the Stribeck slope enters
    ("table9.1", dict(Fs_neg=5.0, b_neg=2.0), 1, 4e-8, 1e-5),   # direction-dependent: two sides
    ("limms-switch", dict(K=55.0), 1, 3e-8, 1e-5),      # cogging stiffness alpha at the setpoint
])
def test_slope_at_the_origin_from_the_linearization_matches_fine_differences(name, kw, k, delta, rtol):
    loop = hunting.preset(name, **kw)
    lin = linear_origin(loop, k)
    right, left = _secant(loop, k, delta)
    assert lin.slope_right == pytest.approx(right, rel=rtol)
    assert lin.slope_left == pytest.approx(left, rel=rtol)


def test_slope_at_the_origin_is_the_thesis_value_and_decides_stability():
    eq = origin_slope(hunting.preset("table9.1"), 2)
    assert eq.method == "linearization" and eq.slope_right == pytest.approx(0.857, abs=5e-4)   # Table 9.2
    # beta = 1: unstable up to P = 26, stable from P = 27 (Fig. 9.8, confirmed in TARGETS)
    assert origin_slope(hunting.preset("table9.1", beta=1.0, P=26.0), 2).slope_right == pytest.approx(1.0818, abs=1e-4)
    assert origin_slope(hunting.preset("table9.1", beta=1.0, P=27.0), 2).stable
    assert not origin_slope(hunting.preset("table9.1", beta=1.0, P=26.0), 2).stable
    # no linearization for beta < 1 and the discontinuous curve: probes see the jump
    assert linear_origin(hunting.preset("table9.1", beta=0.5), 2) is None
    disc = origin_slope(hunting.preset("table9.1", beta="inf"), 2)
    assert disc.method == "probes" and disc.behaviour == "discontinuous" and not disc.stable
    # an unstable linear loop: the linearized slip never returns to stick, the slope is unbounded
    assert origin_slope(hunting.preset("table9.1", P=-5.0), 2).behaviour == "steep"
    # the linearized slip decays onto the equilibrium set without returning: P^k(d) = o(d)
    sw = hunting.preset("table8.1-switch", K=0.2)
    assert linear_origin(sw, 2).slope_right == 0.0 and origin_slope(sw, 2).stable
    assert abs(_secant(sw, 1, 1e-5)[0]) < 1e-6


# ---------------------------------------------------------------- grids that cannot resolve the map
def _analyse(grid, **kw):
    loop = hunting.preset("table9.1", **kw)
    em = event_map(loop, grid, 2, derivative=False)
    return check_resolution(em, fixed_points(loop, grid, 2, emap=em))


def test_a_grid_far_too_coarse_keeps_the_equilibrium_stable_and_says_so():
    res = _analyse(np.linspace(0.0, 1e6, 11))
    eq = next(f for f in res.fixed if f.kind == "equilibrium")
    assert eq.stable and eq.slope == pytest.approx(0.8568, abs=1e-4)        # was "unstable, slope 1.40"
    text = " ".join(res.warnings)
    assert "does not resolve the map" in text and "every image lies within" in text
    a, b, n = res.suggested_grid
    assert a == 0 and 0.64 < b < 1.0 and n >= 400
    again = _analyse(np.linspace(a, b, n))                  # the suggestion resolves it
    assert again.ok and [round(f.d, 4) for f in again.fixed if f.kind == "cycle"] == [0.0034, 0.2523]


def test_a_cycle_between_the_origin_and_the_first_grid_point_is_found_and_flagged():
    res = _analyse(np.linspace(0.0, 0.5, 11))
    cyc = [f for f in res.fixed if f.kind == "cycle"]
    assert [(round(f.d, 5), f.stable) for f in cyc] == [(0.00336, False), (0.2523, True)]
    assert cyc[0] in res.unbracketed and any("0.0033558" in w for w in res.warnings)
    a, b, n = res.suggested_grid
    assert _analyse(np.linspace(a, b, n)).ok


@pytest.mark.parametrize("kw", [dict(), dict(beta="inf"), dict(beta=1.0)])
def test_the_thesis_grid_resolves_the_thesis_maps(kw):
    assert _analyse(GRID, **kw).warnings == []


def test_cli_eventmap_reports_resolution_warnings(tmp_path, capsys):
    js = tmp_path / "m.json"
    assert main(["eventmap", "table9.1", "--grid", "0:1e6:11", "--iterate", "2", "--json", str(js)]) == 0
    out, err = capsys.readouterr()
    assert "equilibrium" in out and "stable" in out and "unstable" not in out
    assert "hunting: warning: suggested grid: 0:0.81:501" in err
    data = json.loads(js.read_text())
    assert data["suggested_grid"] == "0:0.81:501" and any("does not resolve" in w for w in data["warnings"])
