"""Sensitivities with saltation matrices, shooting, Floquet multipliers, continuation."""
import math

import numpy as np
import pytest

from hunting.continuation import ContinuationOptions, continue_orbit, fd_jacobian, find_cycle, flow, shoot
from hunting.continuation.shooting import guess_from_stick_error
from hunting.eventmap import fixed_points
from hunting.models import preset
from user_systems import hopf_system


@pytest.mark.parametrize("name,kw,x0,T,method", [
    ("table9.1", {}, [0.1, -0.2, 0.03], 2.5, "dop853"),                      # stick entry and exit
    ("table9.1", dict(beta="inf"), [0.1, -0.2, 0.03], 2.5, "dop853"),        # exit with a jump in f
    ("table9.1", dict(P=100.0, D=0.01), [0.5, 0.1, 0.0], 0.6, "dop853"),     # reversals without stick
    ("table9.1", dict(model="switch-banded", eta=1e-3), [0.1, -0.2, 0.03], 2.5, "dop853"),
    ("table8.1-lugre", dict(K=0.3), [-0.02, 0.05, 0.01, 1e-5], 0.5, "dop853"),  # kinks at x2 = 0
    ("table8.1-lugre", dict(K=0.3), [-0.02, 0.05, 0.01, 1e-5], 0.5, "radau"),
    ("limms-switch", {}, [0.004, -0.05, 0.001], 4.0, "dop853"),                # cogging
])
def test_monodromy_matches_finite_differences_of_the_flow(name, kw, x0, T, method):
    sys_ = preset(name, **kw).system
    fl = flow(sys_, x0, T, method=method, rtol=1e-11, atol=1e-14)
    assert fl.ok and len(fl.event_times) >= 2
    J = fd_jacobian(sys_, x0, T, rel=1e-6, rtol=1e-12, atol=1e-15)
    assert np.abs(fl.Phi - J).max() <= 1e-6 * np.abs(J).max()


def test_the_variational_kernel_runs_dop853_as_the_full_one_does(monkeypatch):
    """Flows with DOP853 run the variational kernel (no DP5 or Radau step compiled in); the full
    kernel, which carries every method, gives the same states, fundamental matrix, parameter
    sensitivity and events bit for bit."""
    from hunting.integrate import _kernel as K
    sys_ = preset("table8.1-lugre", K=0.3).system
    x0, T = [-0.02, 0.05, 0.01, 1e-5], 0.5
    dp = (preset("table8.1-lugre", K=0.31).system.params - preset("table8.1-lugre", K=0.29).system.params) / 0.02
    assert K.flow_kernel(K.METHOD_DOP853) is K.compiled("variational")
    assert K.flow_kernel(K.METHOD_RADAU) is K.compiled("full")
    a = flow(sys_, x0, T, param_direction=dp)
    monkeypatch.setattr(K, "flow_kernel", lambda method: K.compiled("full"))
    b = flow(sys_, x0, T, param_direction=dp)
    assert a.ok and len(a.event_times) >= 2
    for name in ("x", "Phi", "dx_dmu", "event_times", "modes"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


@pytest.mark.parametrize("name,x0,T", [("table9.1", [0.1, -0.2, 0.03], 5.0),
                                      ("table8.1-lugre", [-0.02, 0.05, 0.01, 1e-5], 2.0)])
def test_the_variational_kernel_stands_in_for_the_lean_one_bit_for_bit(monkeypatch, name, x0, T):
    """A plain DOP853 simulation on the variational kernel (where it stands in for an uncompiled
    lean one, :func:`hunting.integrate._kernel.plain_kind`) gives the lean kernel's times,
    states, modes and events bit for bit."""
    from hunting.integrate import _kernel as K
    from hunting.integrate.simulate import simulate
    system = preset(name).system
    runs = {}
    for kind in ("lean", "variational"):
        monkeypatch.setattr(K, "plain_kind", lambda kind=kind: kind)
        runs[kind] = simulate(system, x0, (0.0, T))
    a, b = runs["lean"], runs["variational"]
    assert a.success and len(a.events.t) >= 2
    for field in ("t", "x", "mode"):
        np.testing.assert_array_equal(getattr(a, field), getattr(b, field), err_msg=field)
    for field in ("t", "x_before", "x_after", "guard", "mode_from", "mode_to"):
        np.testing.assert_array_equal(getattr(a.events, field), getattr(b.events, field), err_msg=field)


@pytest.mark.parametrize("name,kw,par,x0,T,method", [
    ("table9.1", {}, "P", [0.1, -0.2, 0.03], 2.5, "dop853"),                 # stick exit moves with P
    ("table9.1", dict(beta="inf"), "Fs", [0.1, -0.2, 0.03], 2.5, "dop853"),  # the jump in f moves with Fs
    ("table9.1", dict(model="switch-banded", eta=1e-3), "P", [0.1, -0.2, 0.03], 2.5, "dop853"),
    ("table8.1-lugre", {}, "K", [-0.02, 0.05, 0.01, 1e-5], 0.5, "dop853"),
    ("table8.1-lugre", {}, "K", [-0.02, 0.05, 0.01, 1e-5], 0.5, "radau"),
    ("limms-switch", {}, "K", [0.004, -0.05, 0.001], 4.0, "dop853"),
])
def test_parameter_sensitivity_matches_finite_differences(name, kw, par, x0, T, method):
    """d x(T) / d mu from the variational column with forcing f_mu and the guards' and resets'
    mu-derivatives at the events, against central differences of the flow in mu."""
    from hunting.models.presets import resolve_parameters
    mu = float(resolve_parameters(name, kw)[par])
    at = lambda m: preset(name, **{**kw, par: m}).system                          # noqa: E731
    h = 1e-6 * abs(mu)
    dp = (at(mu + h).params - at(mu - h).params) / (2 * h)
    fl = flow(at(mu), x0, T, method=method, rtol=1e-11, atol=1e-14, param_direction=dp)
    assert fl.ok and len(fl.event_times) >= 2
    hf = 1e-6 * abs(mu)
    fd = (flow(at(mu + hf), x0, T, sensitivity=False, rtol=1e-12, atol=1e-15).x
          - flow(at(mu - hf), x0, T, sensitivity=False, rtol=1e-12, atol=1e-15).x) / (2 * hf)
    assert np.abs(fl.dx_dmu - fd).max() <= 1e-6 * np.abs(fd).max()
    plain = flow(at(mu), x0, T, method=method, rtol=1e-11, atol=1e-14)
    assert np.abs(fl.Phi - plain.Phi).max() <= 1e-6 * np.abs(plain.Phi).max()


def test_stick_entry_projects_out_the_velocity():
    """Entering stick makes d x2 / d x0 vanish: a multiplier 0 (thesis chapter 8)."""
    sys_ = preset("table9.1").system
    fl = flow(sys_, [0.1, -0.2, 0.03], 1.2)          # ends inside a stick phase
    assert fl.mode == 2 and np.all(fl.Phi[1] == 0.0)


def test_floquet_multipliers_of_a_known_limit_cycle():
    sys_ = hopf_system(w=2.0)
    po = shoot(sys_, [0.0, -1.05], 3.0, section=0)
    assert po.success
    assert po.period == pytest.approx(math.pi, abs=1e-9)
    assert np.hypot(*po.x0) == pytest.approx(1.0, abs=1e-9)
    assert po.trivial_error < 1e-8
    assert po.multipliers[1].real == pytest.approx(math.exp(-2 * math.pi), rel=1e-6)   # exp(-2 T), T = pi
    assert po.stable and po.amplitude == pytest.approx(1.0, abs=1e-6)


def _switch_cycle(K):
    lp = preset("table8.1-switch", K=K)
    d = next(f.d for f in fixed_points(lp, np.linspace(0.0, 0.01, 401), 2) if f.kind == "cycle" and f.stable)
    x0, T = guess_from_stick_error(lp, d)
    return lp, shoot(lp.system, x0, T)


def test_cycle_from_a_long_simulation():
    res = find_cycle("table8.1-switch", {"x1": -1.0}, params={"K": 0.3})
    assert res.success and "transient" in res.start and res.period == pytest.approx(14.3081346, rel=1e-6)


def test_switch_cycle_is_the_event_map_fixed_point_and_multiplier_is_its_slope():
    lp, po = _switch_cycle(0.3)
    assert po.success and po.stable and po.trivial_error < 1e-8
    lam = sorted(np.abs(po.multipliers[1:]))
    assert lam[0] < 1e-10                                  # stick: multiplier 0
    fps = fixed_points(lp, np.linspace(0.0, 0.01, 401), 2)
    cyc = next(f for f in fps if f.kind == "cycle" and f.stable)
    assert po.amplitude == pytest.approx(cyc.d, rel=1e-7)  # max |x1| is the stick error
    assert lam[1] == pytest.approx(cyc.slope, rel=1e-5)    # multiplier = slope of P^2 at d*


def test_shooting_converges_on_an_unstable_cycle():
    lp = preset("table8.1-switch", K=0.634)
    fps = fixed_points(lp, np.linspace(0.0, 0.01, 1001), 2)
    d_u = next(f for f in fps if f.kind == "cycle" and not f.stable)
    x0, T = guess_from_stick_error(lp, d_u.d)
    po = shoot(lp.system, x0, T)
    assert po.success and not po.stable
    assert po.amplitude == pytest.approx(d_u.d, rel=1e-6)
    assert max(abs(po.multipliers[1:])) == pytest.approx(d_u.slope, rel=1e-4)


def test_continuation_finds_the_switch_fold():
    lp, po = _switch_cycle(0.6)
    base = lp.system
    br = continue_orbit(lambda K: base.with_param_array(preset("table8.1-switch", K=K).system.params), po, 0.6,
                        0.7, param="K", options=ContinuationOptions(max_points=60))
    folds = [s for s in br.special if s.kind == "fold"]
    assert folds and folds[0].param == pytest.approx(0.647, rel=5e-3) and folds[0].precision < 1e-6
    crossing = [s for s in br.special if s.kind == "multiplier_+1"]
    assert crossing and abs(crossing[0].param - folds[0].param) < 1e-4
    # stable before the fold, unstable after
    i = folds[0].index
    assert br.stable[: i + 1].all() and not br.stable[i + 2:].any()


def test_cli_continue_json_contract(tmp_path):
    import json

    from hunting.cli import main
    js = tmp_path / "b.json"
    assert main(["continue", "table8.1-switch", "--param", "K", "--from", "0.6", "--to", "0.7",
                 "--back-to", "0.645", "--json", str(js), "--plot", str(tmp_path / "b.png")]) == 0
    data = json.loads(js.read_text())
    p = data["points"][0]
    assert {"param", "period", "amplitude", "multipliers", "stable"} <= set(p)
    assert len(p["multipliers"]) == 3 and len(p["multipliers"][0]) == 2
    kinds = {s["kind"] for s in data["special_points"]}
    assert "fold" in kinds
    fold = next(s for s in data["special_points"] if s["kind"] == "fold")
    assert fold["param"] == pytest.approx(0.6473391, abs=1e-6)


def test_reproduce_ch8_matches_the_thesis(tmp_path):
    import json

    from hunting.reproduce.ch8 import run
    assert run(tmp_path) == 0
    data = json.loads((tmp_path / "ch8.json").read_text())
    assert all(r["ok"] for r in data["checks"])
    for k in (2, 3, 4, 5, 6):
        assert any(tmp_path.glob(f"fig8_{k}*.png"))


def test_unstable_cycle_of_a_piecewise_linear_relay_oscillator():
    """Closed forms: period 2 pi / w, multipliers 1 and e^(2k), amplitude F (1 + e^k)/(e^k - 1);
    the velocity jumps at y = 0 make non-trivial saltation matrices."""
    from user_systems import relay_system
    delta, F = 0.1, 1.0
    w = math.sqrt(1 - delta ** 2)
    k = delta * math.pi / w
    a = F * (1 + math.exp(k)) / (math.exp(k) - 1)
    sys_ = relay_system(delta, F)
    # guess: a point near x = 0 on the upper half of the cycle
    po = shoot(sys_, [0.0, 0.97 * math.sqrt(a * a - F * F) + 0.0], 2 * math.pi / w * 1.01, section=0)
    assert po.success and not po.stable
    assert po.period == pytest.approx(2 * math.pi / w, rel=1e-9)
    assert po.amplitude == pytest.approx(a, rel=1e-6)
    assert po.trivial_error < 1e-8
    assert abs(po.multipliers[1]) == pytest.approx(math.exp(2 * k), rel=1e-8)


@pytest.mark.parametrize("name", ["table8.1-lugre", "table8.1-switch"])
def test_branch_amplitudes_from_event_states_match_a_sampled_simulation(name):
    """follow() takes each point's amplitude from its flow's event states (x2 = 0 is an event of
    the exact loops); orbit_amplitude samples a fresh simulation at 4001 points plus events."""
    from hunting.continuation import follow, orbit_amplitude
    br = follow(name, "K", 0.3, 0.32)
    assert len(br.mu) >= 2
    for mu, x0, T, a in zip(br.mu, br.x0, br.period, br.amplitude):
        ref = orbit_amplitude(preset(name, K=mu).system, x0, T)
        assert a == pytest.approx(ref, rel=2e-6)         # the flows run at rtol 1e-9 and 1e-10


def test_radau_jacobians_agree_with_dop853_along_a_lugre_branch():
    """The LuGre branch's Jacobian flows by Radau (variational stages solved with the stage
    Jacobians, state-only error control) against the same branch with DOP853 (Phi under error
    control): same points, multipliers within 1e-5 away from the fold."""
    from hunting.continuation import follow
    a = follow("table8.1-lugre", "K", 0.3, 0.33)
    b = follow("table8.1-lugre", "K", 0.3, 0.33, options=ContinuationOptions(jacobian_method="dop853"))
    n = min(len(a.mu), len(b.mu))
    assert n >= 2 and np.allclose(a.mu[:n], b.mu[:n], rtol=1e-6)
    assert np.allclose(np.abs(a.multipliers[:n, 1]), np.abs(b.multipliers[:n, 1]), rtol=1e-5)
    with pytest.raises(ValueError, match="jacobian_method"):
        ContinuationOptions(jacobian_method="euler")


def test_belt_branch_passes_where_the_orbit_leaves_its_first_phase_plane():
    """examples/belt.json from k = 2 down to 0.3: the starting orbit's phase plane q = 0.1509
    stops meeting the orbit near k = 0.436 (the orbit's smallest q rises past it). The branch
    used to turn there in a false fold (exit 0) and retrace the same stable orbits back to k = 2;
    the base point now moves along the orbit and the branch reaches 0.3 with the period of the
    cycle found there on its own."""
    import json
    from pathlib import Path

    import hunting
    from hunting.continuation import follow
    system = hunting.model(json.loads((Path(__file__).resolve().parents[1] / "examples" / "belt.json").read_text()))
    br = follow(system, "k", 2.0, 0.3)
    assert br.status.name == "SUCCESS", br.message
    assert not [s for s in br.special if s.kind == "fold"]
    assert np.all(np.diff(br.mu) < 0) and br.mu[-1] == pytest.approx(0.3, rel=1e-9)
    assert br.stable.all()
    ref = find_cycle(system, params={"k": 0.3})
    assert ref.success and br.period[-1] == pytest.approx(ref.period, rel=1e-6)
    from cycle_systems import belt_reference_cycle          # scipy solve_ivp with the stick event
    assert br.period[-1] == pytest.approx(belt_reference_cycle(k=0.3)["period"], rel=1e-6)
