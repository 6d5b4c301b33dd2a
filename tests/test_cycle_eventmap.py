"""Stick-exit maps of systems that are not ServoLoops: a PID servo written as equations (or by
hand) through StickFamily, against the thesis' loop; clear errors where no 1-D map exists."""
import numpy as np
import pytest

import hunting
from hunting import preset
from hunting.eventmap import evaluate_map, fixed_points, stick_family
from cycle_systems import PID_LUGRE_DESCRIPTION, belt_system
from user_systems import two_mass_system

# the chapter-9 loop in the position q (not the error), set point q_d = 0.5: the stick error is
# measured from the frozen value at which the integral's drift stops
PID_SWITCH = {
    "name": "pid-switch",
    "parameters": {"m": 1.0, "P": 10.0, "D": 1.0, "I": 10.0, "qd": 0.5, "Fc": 2.0, "Fs": 4.0, "vs": 0.1, "b": 1.0},
    "states": ["q", "v", "ie"],
    "signals": {"e": "q - qd", "u": "-P*(e + D*v + I*ie)"},
    "equations": {"q": "v", "v": "(u - F)/m", "ie": "e"},
    "friction": {"force": "F", "velocity": "v", "model": "switch",
                 "slip": "sign(w)*(Fc + (Fs - Fc)*exp(-(w/vs)**2)) + b*w", "stick": "Fs"}}


def test_stick_family_of_the_hand_written_loop_is_its_event_map():
    lp = preset("table9.1")
    fam = stick_family(lp.system)
    assert (fam.d_state, fam.drift_state, fam.surface_state, fam.d0) == (0, 2, 1, 0.0)
    d = np.concatenate([-np.geomspace(1e-4, 0.4, 40), np.geomspace(1e-4, 0.4, 40)])
    X1, m1 = lp.breakaway_state(d)
    X2, m2 = fam.breakaway_state(d)
    assert np.array_equal(m1, m2) and np.abs(X1 - X2).max() < 1e-14
    a, b = evaluate_map(lp, d, 2), evaluate_map(fam, d, 2)
    assert np.abs(a.image - b.image).max() < 1e-12
    assert np.abs(a.stick_time - b.stick_time).max() < 1e-9


def test_pid_servo_written_as_equations_has_the_table_9_2_map():
    """Table 9.2 (confirmed: 0.00336 unstable, slope 1.25; 0.2523 stable, slope 0.78; the
    equilibrium set's slope 0.86) from a user's description in the position q."""
    m = hunting.model(PID_SWITCH)
    fam = stick_family(m)
    assert m.state_names[fam.d_state] == "q" and m.state_names[fam.drift_state] == "ie"
    assert fam.d0 == pytest.approx(0.5, abs=1e-15)
    fps = fixed_points(m, np.linspace(0.0, 0.4, 401), 2)
    eq = next(f for f in fps if f.kind == "equilibrium")
    cyc = [f for f in fps if f.kind == "cycle"]
    ref = fixed_points(preset("table9.1"), np.linspace(0.0, 0.4, 401), 2)
    ref_cyc = [f for f in ref if f.kind == "cycle"]
    assert eq.stable and eq.slope == pytest.approx(0.86, abs=0.01)
    assert [round(f.d, 4) for f in cyc] == [0.0034, 0.2523]
    for f, r in zip(cyc, ref_cyc):
        assert f.d == pytest.approx(r.d, rel=1e-9) and f.slope == pytest.approx(r.slope, rel=1e-5)
        assert f.stable == r.stable


def test_systems_without_a_one_parameter_stick_family_are_named():
    with pytest.raises(hunting.SystemDefinitionError, match="every stick phase ends at the same state"):
        stick_family(belt_system())
    with pytest.raises(hunting.SystemDefinitionError, match="exactly one stick mode"):
        stick_family(preset("table8.1-lugre").system)
    with pytest.raises(hunting.SystemDefinitionError, match="time-invariant"):
        stick_family(two_mass_system())          # sinusoidal drive of mass 2
    with pytest.raises(hunting.SystemDefinitionError, match="not a one-parameter family"):
        stick_family(two_mass_system(A=0.0))     # mass 2 moves while mass 1 sticks
    with pytest.raises(hunting.SystemDefinitionError, match="one Switch friction contact"):
        stick_family(hunting.model(PID_LUGRE_DESCRIPTION))


def test_map_diagram_of_a_model_by_parameter_name():
    """The fold of Table 9.1's cycle pair (P = 21.015, thesis: between 21 and 22) from the
    described PID servo, its gain swept by name."""
    from hunting.eventmap import map_diagram
    dg = map_diagram(hunting.model(PID_SWITCH), "P", [20.5, 21.5], d_max=0.4)
    folds = [s for s in dg.special if s.kind == "fold"]
    assert len(folds) == 1 and folds[0].param == pytest.approx(21.015, abs=2e-3)
