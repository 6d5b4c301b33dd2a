"""Numerical failures name their cause: a parameter that divides by zero, a transfer function
with no denominator, an initial state beyond what double precision integrates, a stick bound
that moves with the state or lies below the slip force. Each case used to end with advice about
something else (STEP_TOO_SMALL "use radau", ZENO "declare a sliding mode") or to run."""
import numpy as np
import pytest

import hunting
from hunting.cli import main
from hunting.errors import Status, SystemDefinitionError

from test_describe import _with as belt    # the belt description with entries changed ("a__b": value)


# ---------------------------------------------------------------- non-finite at the start
@pytest.mark.parametrize("desc, where, cause", [
    (belt(parameters__m=0.0), "equations['v'] = '(u - F)/m'", "division by m = 0"),
    (belt(parameters__c=0.0, signals__u="-k*(q + 1)/c"), "signals['u'] = '-k*(q + 1)/c'", "division by c = 0"),
    (belt(parameters__vs=0.0, friction__slip="sign(w)*(Fc + 0.01/vs)"), "friction['friction'].slip", "division by vs = 0"),
])
def test_a_parameter_that_divides_by_zero_is_named(desc, where, cause):
    m = hunting.model(desc)
    tr = hunting.simulate(m.system, m.state(), (0.0, 1.0))
    assert tr.status == Status.NON_FINITE, tr.message
    assert where in tr.message and cause in tr.message and "radau" not in tr.message
    assert tr.t.tolist() == [0.0] and np.all(np.isfinite(tr.x))
    with pytest.raises(hunting.ConvergenceError, match="division by"):
        hunting.simulate(m.system, m.state(), (0.0, 1.0), throw=True)


def test_a_failure_later_in_the_run_is_explained_too():
    m = hunting.model(belt(parameters__m=0.0))
    tr = hunting.simulate(m.system, m.state(v=0.1), (0.0, 5.0))      # sticks (finite) until break-away at 2.5
    assert tr.status == Status.NON_FINITE and tr.t[-1] == pytest.approx(2.5)
    assert "equations['v'] = '(u - F)/m' is not finite: division by m = 0" in tr.message


def test_a_system_without_an_explanation_names_the_state_and_the_zero_parameter():
    s = hunting.preset("table9.1").system.with_params(m=0.0)     # a PiecewiseSystem checks nothing
    tr = hunting.simulate(s, [0.1, 0.1, 0.0], (0.0, 1.0))                   # slipping: x2' = (...)/m
    assert tr.status == Status.NON_FINITE and tr.t.tolist() == [0.0]
    assert "dx2/dt = -inf" in tr.message and "(finite with m != 0)" in tr.message


def test_the_command_line_says_it_in_one_status_line(tmp_path, monkeypatch, capsys):
    import json
    monkeypatch.chdir(tmp_path)
    (tmp_path / "m0.json").write_text(json.dumps(belt(parameters__m=0.0)))
    assert main(["simulate", "--model", "m0.json"]) == 1
    out, err = capsys.readouterr()
    assert out.startswith("NON_FINITE:") and "division by m = 0" in out and "Traceback" not in out + err


# ---------------------------------------------------------------- an initial state too large
def test_an_initial_state_beyond_double_precision_is_out_of_bounds(capsys):
    loop = hunting.preset("table9.1")
    tr = hunting.simulate(loop.system, [1e300, 0.0, 0.0], (0.0, 1.0))
    assert tr.status == Status.OUT_OF_BOUNDS and "x1 = 1e+300" in tr.message and "too stiff" not in tr.message
    assert hunting.simulate(loop.system, [1e90, 0.0, 0.0], (0.0, 0.01)).status == Status.SUCCESS
    assert main(["simulate", "table9.1", "--x0", "1e300,0,0", "--t", "1"]) == 1
    assert capsys.readouterr().out.startswith("OUT_OF_BOUNDS:")


# ---------------------------------------------------------------- transfer functions
@pytest.mark.parametrize("tf", ["1/(0*s)", "1/(s - s)", "k/(0*s + 0)"])
def test_a_transfer_function_without_denominator_is_rejected(tf):
    d = belt(blocks=[{"output": "u2", "input": "q", "tf": tf}])
    with pytest.raises(SystemDefinitionError, match=r"blocks\['u2'\].tf = .*the denominator is zero"):
        hunting.model(d)


def test_a_leading_denominator_coefficient_zero_at_the_parameter_values():
    d = belt(parameters__a=0.0, equations__v="(u - u2 - F)/m",
             blocks=[{"output": "u2", "input": "q", "tf": "1/(a*s + 1)"}])
    with pytest.raises(SystemDefinitionError, match=r"blocks\['u2'\]: .*denominator, a, is 0 with a = 0"):
        hunting.model(d)
    m = hunting.model(d, a=0.1)
    assert hunting.simulate(m.system, m.state(q=0.1), (0.0, 1.0)).status == Status.SUCCESS
    with pytest.raises(SystemDefinitionError, match="a = 0"):
        m.with_params(a=0.0)


# ---------------------------------------------------------------- stick bounds
@pytest.mark.parametrize("stick, signals, through", [
    ("Fs - 10*q", {"u": "-k*q"}, "q"),
    ("Fs*(1 + N)", {"u": "-k*q", "N": "0.1*q"}, "N"),
    (["Fs", "Fs + v"], {"u": "-k*q"}, "v"),
])
def test_a_stick_bound_that_moves_with_the_state_is_rejected(stick, signals, through):
    with pytest.raises(SystemDefinitionError, match=f"depends on the state through {through}"):
        hunting.model(belt(friction__stick=stick, signals=signals))


def test_a_stick_bound_below_the_slip_force_is_rejected():
    with pytest.raises(SystemDefinitionError, match=r"slip force at w -> 0- is 0.3, more than .*stick bound '0.1'"):
        hunting.model(belt(friction__stick="0.1", friction__slip="sign(w)*Fc"))
    m = hunting.model(belt(friction__slip="sign(w)*Fc"))                    # Fs = 0.5 >= Fc = 0.3
    with pytest.raises(SystemDefinitionError, match="stick bound 'Fs' = 0.2"):
        m.with_params(Fs=0.2)
    tr = hunting.simulate(m.system, m.state(), (0.0, 5.0))                    # the same law, a bound above it
    assert tr.status == Status.SUCCESS and len(tr.events.t) > 0
