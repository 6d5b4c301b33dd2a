"""``hunting diagnose --model DESCRIPTION``: a model description (the equations format of
``hunting simulate --model``) maps onto the diagnosis' nominal model exactly, field by field,
and gives the same diagnosis as the nominal-model JSON it equals; a description with no exact
reading (rational friction law, moving belt, two contacts, a lead-lag controller, ...) is one
line naming the part and exit 2."""
import json
from dataclasses import fields
from pathlib import Path

import pytest

from hunting.cli import main
from hunting.diagnose import NominalModel, save_csv
from hunting.diagnose.model import nominal_from_description
from hunting.diagnose.synthetic import TruePlant, generate
from hunting.errors import SystemDefinitionError

ROOT = Path(__file__).resolve().parents[1]

# The test suite's Coulomb + viscous nominal (tests/test_diagnose.py's NOMINAL) with the EMPS-like
# PD loop of hunting.diagnose.synthetic (u = kv (kp (q_ref - q) - v)) as a continuous PID whose
# derivative acts on the measurement: kp = kv kp = 38880, kd = kv = 243.
PD_JSON = {"plant": {"mass": 95.0, "motor_constant": 35.15, "offset": 0.0},
           "friction": {"law": "coulomb-viscous", "Fc": 20.0, "b": 200.0},
           "controller": {"type": "pid", "kp": 38880.0, "kd": 243.0, "ki": 0.0, "derivative_on": "measurement"}}
PD_DESCRIPTION = json.loads((ROOT / "examples" / "pd_servo.json").read_text())    # README's example

# Direction-dependent Stribeck levels, an offset, two cogging harmonics, a viscous term written in
# the equation, and a PID with a filtered derivative on the error as one transfer-function block.
STRIBECK_JSON = {"plant": {"mass": 2.0, "motor_constant": 1.5, "offset": 0.3,
                           "cogging": [{"pitch": 0.02, "cos": [0.3, 0.1], "sin": [0.2, 0.0]}]},
                 "friction": {"law": "switch", "Fc": 1.0, "Fs": 1.4, "vs": 0.01, "beta": 1.5, "b": 0.5,
                              "Fc_neg": 0.8, "Fs_neg": 1.2, "vs_neg": 0.02, "beta_neg": 2.0, "b_neg": 0.4},
                 "controller": {"type": "pid", "kp": 200.0, "kd": 10.0, "ki": 50.0, "tau_f": 0.002}}
STRIBECK_DESCRIPTION = {
    "parameters": {"m": 2.0, "cm": 1.5, "F0": 0.3, "bq": 0.1, "r": 0.0, "kp": 200.0, "ki": 50.0, "kd": 10.0,
                   "tau_f": 0.002, "Fc": 1.0, "Fs": 1.4, "vs": 0.01, "beta": 1.5, "b": 0.4,
                   "Fc_neg": 0.8, "Fs_neg": 1.2, "vs_neg": 0.02, "b_neg": 0.3, "p": 0.02},
    "states": ["q", "v"],
    "signals": {"F_cog": "0.3*cos(2*pi*q/p) + 0.2*sin(2*pi*q/p) + 0.1*cos(4*pi*q/p)"},
    "blocks": [{"output": "u", "input": "r - q", "tf": "kp + ki/s + kd*s/(tau_f*s + 1)"}],
    "equations": {"q": "v", "v": "(cm*u - F - bq*v - F0 - F_cog)/m"},
    "friction": {"force": "F", "velocity": "v", "model": "switch",
                 "slip": "(1 + sign(w))/2*(Fc + (Fs - Fc)*exp(-(abs(w)/vs)**beta) + b*w)"
                         " + (1 - sign(w))/2*(-Fc_neg - (Fs_neg - Fc_neg)*exp(-(w/vs_neg)**2) + b_neg*w)",
                 "stick": ["Fs_neg", "Fs"]}}

LUGRE_JSON = {"plant": {"mass": 1.0, "motor_constant": 1.0, "offset": 0.0},
              "friction": {"law": "lugre", "Fc": 1.0, "Fs": 1.5, "vs": 0.001, "beta": 2.0, "b": 0.4,
                           "sigma0": 1e5, "sigma1": 316.22776601683796},
              "controller": {"type": "pid", "kp": 3.0, "kd": 6.0, "ki": 4.0, "derivative_on": "measurement"}}


def _same(a: NominalModel, b: NominalModel):
    """Every field equal (exactly: the readings round to the values written), the source aside."""
    for f in fields(NominalModel):
        if f.name != "source":
            assert getattr(a, f.name) == getattr(b, f.name), f.name
    assert a.to_dict() == b.to_dict()


@pytest.mark.parametrize("description, nominal", [
    (PD_DESCRIPTION, PD_JSON), (STRIBECK_DESCRIPTION, STRIBECK_JSON),
    (json.loads((ROOT / "examples" / "pid_lugre.json").read_text()), LUGRE_JSON)],
    ids=["pd-measurement", "stribeck-pid-block", "pid-lugre-example"])
def test_a_hand_written_description_maps_to_its_nominal_model_field_by_field(description, nominal):
    _same(nominal_from_description(description), NominalModel.from_dict(nominal))
    _same(NominalModel.from_dict(description), NominalModel.from_dict(nominal))


def test_a_lead_block_is_a_pid_with_a_filtered_derivative_on_the_error():
    """K (1 + s/10)/(1 + s/100) = K + 0.09 K s/(0.01 s + 1): exactly a PD with tau_f = 0.01 s."""
    d = _variant(blocks=[{"output": "u", "input": "q_ref - q", "tf": "kp*kv*(1 + s/10)/(1 + s/100)"}], signals={})
    c = nominal_from_description(d).controller
    assert c == {"type": "pid", "kp": 38880.0, "kd": pytest.approx(0.09 * 38880.0, rel=1e-15), "ki": 0.0,
                 "tau_f": pytest.approx(0.01, rel=1e-15)}


@pytest.mark.parametrize("name", ["table9.1", "table8.1-switch", "table8.1-lugre"])
def test_the_presets_written_as_descriptions_map_to_the_preset_nominal_models(name):
    """The thesis loops as descriptions (hunting.models.servo_description, error coordinates
    x1 = q - q_d: PDI and fixed-shape PIDs, Stribeck exponent 2, LuGre) against the preset path."""
    from hunting.models import preset_description
    _same(nominal_from_description(preset_description(name)), NominalModel.from_dict({"preset": name}))


@pytest.mark.parametrize("name", ["limms-switch", "limms-lugre"])
def test_cogging_harmonics_are_read_off_the_velocity_equation(name):
    """Chapter 10's motor: F_cog = A sin(2 pi (x1 + q_d)/pitch + phase) in the description's
    position state x1 = q - q_d. The description's position state is the data's q, so the two
    agree where the frames do (q_d = 0): every field equal, the cogging component too."""
    from hunting.models import preset_description
    _same(nominal_from_description(preset_description(name, q_d=0.0)),
          NominalModel.from_dict({"preset": name, "set": {"q_d": 0.0}}))


def test_diagnose_gives_the_same_report_with_the_description_or_the_json(tmp_path):
    """Synthetic data with a hidden 3 N offset: the CLI's JSON report (causes, parameters,
    gains, extended model) is the same with either model file."""
    tp = TruePlant(offset=-3.0)
    save_csv(generate(tp, 8.0, seed=1), tmp_path / "fit.csv")
    save_csv(generate(tp, 8.0, seed=2), tmp_path / "val.csv")
    (tmp_path / "model.json").write_text(json.dumps(PD_JSON))
    (tmp_path / "description.json").write_text(json.dumps(PD_DESCRIPTION))
    out = {}
    for m in ("model.json", "description.json"):
        assert main(["diagnose", str(tmp_path / "fit.csv"), "--validate", str(tmp_path / "val.csv"), "--model",
                     str(tmp_path / m), "--json", str(tmp_path / f"{m}.out")]) == 0
        out[m] = json.loads((tmp_path / f"{m}.out").read_text())
    a, b = out["model.json"], out["description.json"]
    assert a["causes"] and a["causes"][0]["name"] == "offset"
    assert a == b


TWO_CONTACTS = {
    "parameters": {"m": 1.0, "k": 2.0, "Fc": 0.3},
    "states": ["q", "v", "q2", "v2"],
    "signals": {"u": "-k*q"},
    "equations": {"q": "v", "v": "(u - F - F2)/m", "q2": "v2", "v2": "(F2 - q2)/m"},
    "friction": [{"force": "F", "velocity": "v", "model": "switch", "slip": "sign(w)*Fc", "stick": "Fc"},
                 {"force": "F2", "velocity": "v - v2", "model": "switch", "slip": "sign(w)*Fc", "stick": "Fc"}]}


def _variant(**changes):
    d = json.loads(json.dumps(PD_DESCRIPTION))
    for key, value in changes.items():
        section, _, name = key.partition("__")
        if name:
            d[section][name] = value
        else:
            d[section] = value
    return d


UNMAPPABLE = [
    (ROOT / "examples" / "pid_rational.json", "friction['friction'].slip: the positive-direction force is not of the "
                                              "Stribeck form"),
    (ROOT / "examples" / "belt.json", "friction['friction'].velocity = 'v - vb' is not a velocity state"),
    (TWO_CONTACTS, "friction has 2 contacts"),
    (ROOT / "examples" / "loopshaped.yaml", "blocks['u']: the controller from q to 'u' is not a PID"),
    (_variant(blocks=[{"output": "u", "input": "q_ref - q", "tf": "kp*kv*(1 + s/10)/(1 + s/100)*(1 + s)/(1 + 10*s)"}],
              signals={}),
     "blocks['u']: the controller from q to 'u' is not a PID"),
    (_variant(friction__slip="sign(w)*(Fc + 5*exp(-(w/0.01)**2)*(1 + 0.01*abs(w))) + b*w",
              friction__stick="Fc + 5"), "the positive-direction force is not of the Stribeck form"),
    (_variant(friction__stick="1.2*Fc"), "friction['friction'].stick: the positive-direction stick bound is 24"),
    (_variant(equations={"q": "v", "v": "(cm*u - F - 3*tanh(q/0.01))/m"}), "has a term in ['q']"),
    (_variant(equations={"q": "v", "v": "(cm*u - F - 3*sin(q/0.01) - sin(sqrt(2)*q/0.01))/m"}),
     "not harmonics of one pitch"),
    (_variant(signals={"u": "min(kv*(kp*(q_ref - q) - v), 10)"}), "signals['u']: the controller is not linear"),
    (_variant(signals={"u": "min(max(kv*(kp*(q_ref - q) - v), -5), 10)"}), "allowed a symmetric saturation"),
    (_variant(signals={"u": "kv*(kp*(q_ref - q) - v) + 2"}), "are not one reference r"),
]


@pytest.mark.parametrize("description, expected", UNMAPPABLE,
                         ids=["rational-law", "moving-belt", "two-contacts", "loop-shaped", "lead-lag",
                              "near-stribeck", "stick-above-Fs", "position-force", "incommensurate-cogging",
                              "one-sided-limit", "asymmetric-saturation", "feedforward"])
def test_a_description_without_a_reading_is_one_line_and_exit_2(tmp_path, capsys, description, expected):
    data = tmp_path / "d.csv"
    data.write_text("t,q,u\n0,0,0\n0.001,0,0\n")
    if isinstance(description, dict):
        path = tmp_path / "model.json"
        path.write_text(json.dumps(description))
    else:
        path = description
    assert main(["diagnose", str(data), "--model", str(path)]) == 2
    lines = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith(f"hunting: error: model description {path}: "), lines
    assert expected in lines[0] and "Traceback" not in lines[0], lines[0]
    if not isinstance(description, dict):
        with pytest.raises(SystemDefinitionError, match="no reading|not a velocity|contacts|not of the"):
            nominal_from_description(description)


def test_docstring_examples():
    import doctest

    from hunting.describe import mechanical
    from hunting.diagnose import model
    for mod in (mechanical, model):
        res = doctest.testmod(mod)
        assert res.failed == 0 and res.attempted > 0


def test_a_symmetric_saturation_is_the_controller_saturation():
    """The synthetic servo's 10 V limit written as min(max(u, -10), 10), either nesting."""
    for u in ("min(max(kv*(kp*(q_ref - q) - v), -umax), umax)", "max(-umax, min(umax, kv*(kp*(q_ref - q) - v)))"):
        d = _variant(signals={"u": u})
        d["parameters"]["umax"] = 10.0
        _same(nominal_from_description(d), NominalModel.from_dict(
            {**PD_JSON, "controller": {**PD_JSON["controller"], "saturation": 10.0}}))


def test_an_open_loop_description_has_no_controller_and_its_gain_is_read():
    """u a parameter (the data's u drives the plant directly): no controller, cm read off."""
    d = _variant(parameters={"m": 95.0, "cm": 35.15, "Fc": 20.0, "b": 200.0, "u": 0.0}, signals={})
    model = nominal_from_description(d)
    assert model.controller is None and model.cm == 35.15 and model.mass == 95.0


@pytest.mark.parametrize("u, on", [("-kp*(q - r) - kd*(v - 0.1*cos(t)) - ki*xi", "error"),
                                   ("-kp*(q - r) - kd*v - ki*xi", "measurement"),
                                   ("-kp*(q - r) - kd*(v - 0.2*cos(t)) - ki*xi", None)])
def test_where_the_derivative_acts_is_read_from_a_reference_signal_of_t(u, on):
    """r = 0.1 sin t: kd (v - r') is the derivative on the error, kd v on the measurement, and a
    wrong r' (0.2 cos t) is neither: refused, naming the terms."""
    d = _variant(parameters={"m": 1.0, "cm": 1.0, "Fc": 0.5, "b": 0.1, "kp": 50.0, "kd": 5.0, "ki": 20.0},
                 states=["q", "v", "xi"], equations={"q": "v", "v": "(cm*u - F)/m", "xi": "q - r"},
                 signals={"r": "0.1*sin(t)", "u": u})
    if on is None:
        with pytest.raises(SystemDefinitionError, match="are not one reference r entering as the error"):
            nominal_from_description(d)
        return
    c = nominal_from_description(d).controller
    assert (c["kp"], c["kd"], c["ki"], c.get("derivative_on", "error")) == (50.0, 5.0, 20.0, on)


READ_ONCE = r"""
import json, sys
from hunting.diagnose.model import nominal_from_description
m = nominal_from_description(sys.argv[1])
print(json.dumps(dict(model=m.to_dict(), sympy="sympy" in sys.modules)))
"""


def test_a_description_read_once_loads_from_the_cache_without_sympy(tmp_path):
    """The nominal model read off a description is cached by the description's text and the
    reading code: a second process loads it without importing sympy (~1.3 s of a warm
    diagnose), with the same model; an entry that is not a nominal model is read again."""
    import os
    import subprocess
    import sys
    env = dict(os.environ, HUNTING_CACHE_DIR=str(tmp_path))
    path = str(Path(__file__).resolve().parents[1] / "examples" / "pd_servo.json")

    def read():
        out = subprocess.run([sys.executable, "-c", READ_ONCE, path], env=env, capture_output=True, text=True,
                             timeout=300, check=True)
        return json.loads(out.stdout.strip().splitlines()[-1])
    first, second = read(), read()
    assert first["sympy"] and not second["sympy"]
    assert second["model"] == first["model"] == nominal_from_description(path).to_dict()
    entries = list((tmp_path / "readings").glob("*.json"))
    assert len(entries) == 1
    entries[0].write_text('{"plant": 1}')
    third = read()
    assert third["sympy"] and third["model"] == first["model"]
