"""The diagnosis on records of the independent generator (benchmarks/independent/: written from
a one-page specification by an engineer who saw neither hunting's code nor the blind benchmark's
generator). A few records of its seed-1 set, drawn here: clean ones get nothing, and one effect
each of six causes is named first (reversal as LuGre bristles: ``reversal`` or ``presliding``; its
dwell, in the seven-parameter form, as ``dwell_peak`` (or ``dwell``), its gain within 10 %; its
asymmetry, one direction's level scaled, as ``level_asymmetry``).
The whole set's rates are in docs/diagnosis.md."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

from hunting.diagnose import NominalModel, diagnose, load

ROOT = Path(__file__).resolve().parents[1]
CLEAN = (4, 5, 7, 10)
EFFECTS = {45: ("mass",), 49: ("offset",), 53: ("reversal", "presliding"), 44: ("delay",), 67: ("dwell", "dwell_peak"),
           66: ("asymmetry", "level_asymmetry")}


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    out = tmp_path_factory.mktemp("independent")
    ids = ",".join(str(i) for i in (*CLEAN, *EFFECTS))
    subprocess.run([sys.executable, str(ROOT / "benchmarks" / "independent" / "generate.py"), str(out), "--seed", "1",
                    "--only", ids], check=True, capture_output=True)
    return out


def _one(tmp_path, seed: int, index: int) -> Path:
    """The directory of record ``index`` of the generator's set ``seed``, drawn alone under tmp_path."""
    subprocess.run([sys.executable, str(ROOT / "benchmarks" / "independent" / "generate.py"), str(tmp_path), "--seed",
                    str(seed), "--only", str(index)], check=True, capture_output=True)
    return tmp_path / f"d{index:04d}"


def _diagnosis(records, i):
    dd = records / f"d{i:04d}"
    truth = json.loads((dd / "truth.json").read_text())
    return truth, diagnose(load(dd / "fit.npz"), NominalModel.from_json(dd / "model.json"), load(dd / "val.npz"))


def _names(records, i):
    truth, dg = _diagnosis(records, i)
    return truth, [c.name for c in dg.causes]


@pytest.mark.parametrize("i", CLEAN)
def test_a_clean_record_of_the_independent_generator_gets_no_cause(records, i):
    truth, names = _names(records, i)
    assert truth["clean"]
    assert names == []


@pytest.mark.parametrize("i", sorted(EFFECTS))
def test_an_effect_of_the_independent_generator_is_named_first(records, i):
    truth, names = _names(records, i)
    assert truth["causes"] == [EFFECTS[i][0]]
    assert names and names[0] in EFFECTS[i], names


def test_the_seven_parameter_dwell_is_found_by_the_force_channel_and_reported_once(records):
    """d0067's dwell (the Stribeck peak after a rest of t grown by dFs (1 - exp(-t / tau))): named
    ``dwell_peak`` with its gain within 10 % of dFs; Kato's own-channel ``dwell`` is then not
    judged again (one family)."""
    truth, dg = _diagnosis(records, 67)
    c = dg.causes[0]
    assert c.name == "dwell_peak"
    assert c.parameters["gain"] == pytest.approx(truth["params"]["dFs"], rel=0.1)
    assert [u["reason"] for u in dg.as_dict()["untested"] if u["name"] == "dwell"] == [
        "reported as dwell_peak: the force channel found that cause of its family"]


def test_one_direction_level_scaled_is_named_as_such(records):
    """d0066: the negative direction's Fc and Fs scaled by 0.63 (the generator's Coulomb asymmetry;
    read as a level and a constant force before ``level_asymmetry``): named alone, both directions'
    Coulomb levels within 1 % of the truth."""
    truth, dg = _diagnosis(records, 66)
    assert [c.name for c in dg.causes] == ["level_asymmetry"]
    p = dg.causes[0].parameters
    assert p["Fc_neg"] == pytest.approx(truth["params"]["Fc_neg"], rel=0.01)
    assert p["Fc_pos"] == pytest.approx(truth["params"]["Fc_pos"], rel=0.01)


def test_a_noise_free_clean_record_gets_reasons_in_words_not_relative_changes_of_nothing(records):
    """d0004 is the nominal model's own noise-free loop: the validation force residual and the
    re-simulated position error are exactly 0. The reasons said a cause 'changes the validation
    residual by -100.0%' (0 over 0), a dwell growth 'cuts the position error by -999.0%' and a
    'validation gain -5.3e+293%' (a ratio to 1e-300); they say what happened now, and the JSON
    is strict (no NaN or Infinity)."""
    import re
    from hunting.diagnose.report import format_terminal
    truth, dg = _diagnosis(records, 4)
    assert truth["clean"] and dg.causes == [] and dg.nominal == 0.0
    text = format_terminal(dg)
    assert not re.search(r"-100\.0%|999\.0%|inf%|nan|e\+\d\d\d?%", text), text
    reasons = {r["name"]: r["reason"] for r in dg.rejected}
    assert "validation residual (0 N RMS) is at numerical precision" in reasons["stribeck"]
    assert "makes its re-simulated position error" in reasons["dwell"] and "against 0 m without" in reasons["dwell"]
    json.dumps(dg.as_dict(), allow_nan=False)


def test_a_build_up_outside_lugres_range_at_the_refined_bristles_is_not_named(tmp_path):
    """Seed 8 d0041: a lightly damped resonance (35 Hz, 60 % of the mass on the spring) whose
    fitting record slides too little to test it. The force channel's reversal, refined with the
    scale held at 1, re-estimated the build-up at 5.85 times LuGre's at sigma0 = 997 kN/m, outside
    the range the search accepts as LuGre's (0.3..3), and was named first; it was rejected at the
    identification step since the twenty-ninth session, and since the thirtieth (the validation
    tests' noise model from the fitting record where the validation residual's innovations are
    more than 4 times its own) already out of sample (p = 0.49); no bristles are named for a
    resonance. The identification step itself: test_reversal_identification_judges_the_refined_scale."""
    dd = _one(tmp_path, 8, 41)
    assert json.loads((dd / "truth.json").read_text())["causes"] == ["flexibility"]
    dg = diagnose(load(dd / "fit.npz"), NominalModel.from_json(dd / "model.json"), load(dd / "val.npz"))
    assert "reversal" not in [c.name for c in dg.causes], [(c.name, c.parameters, c.sigma) for c in dg.causes]
    row = next(r for r in dg.rejected if r["name"] == "reversal")
    assert ((row["step"] == "identification" and "times LuGre's (accepted 0.3..3" in row["reason"])
            or (row["step"] == "validation" and "not significant out of sample" in row["reason"])), row


def test_dwell_in_the_seven_parameter_form_is_named_from_the_loop(tmp_path):
    """Seed 10 d0051 (held out in the forty-ninth session, looked at in the fiftieth): a 0.50 N
    growth over 0.10 s on Fs 2.5 N in the seven-parameter form (the slip starts from the grown
    force), on a Stribeck model without a growth. The break-away readings suggest it (p = 0.17),
    and Kato's form, the only one the loop fitted before, cut the fitting record's position error
    by 0.8 %: nothing was named. Fitted in both forms, the seven-parameter one is taken and named,
    its gain within 10 % of the truth."""
    dd = _one(tmp_path, 10, 51)
    truth = json.loads((dd / "truth.json").read_text())
    assert truth["causes"] == ["dwell"]
    dg = diagnose(load(dd / "fit.npz"), NominalModel.from_json(dd / "model.json"), load(dd / "val.npz"))
    assert [c.name for c in dg.causes] == ["dwell"]
    assert dg.causes[0].parameters["gain"] == pytest.approx(truth["params"]["dFs"], rel=0.1)
    assert dg.extended_model.dwell.sliding is True


@pytest.mark.parametrize("seed, index", [(10, 86), (11, 81)])
def test_a_resonance_of_a_record_that_barely_slides_is_named_from_the_loop(tmp_path, seed, index):
    """Seed 10 d0086 (held out in the forty-ninth session, looked at in the fiftieth): a 19.5 Hz
    load carrying 26 % of the mass (damping ratio 0.029) on records with fewer than 100 sliding
    samples: the force channel is skipped, and no one-parameter loop candidate passes. The load
    fitted on the fitting record's loop is named, its frequency within 2 % and its load mass
    within 10 % of the truth. Seed 11 d0081 (held out in the fiftieth until the loop's resonance
    met it: 18.4 Hz, 51 % of the mass): the validation record's own fit agreed in frequency and
    load mass and not in damping (0.083 against 0.030), which is no longer asked."""
    dd = _one(tmp_path, seed, index)
    truth = json.loads((dd / "truth.json").read_text())
    assert truth["causes"] == ["flexibility"]
    dg = diagnose(load(dd / "fit.npz"), NominalModel.from_json(dd / "model.json"), load(dd / "val.npz"))
    assert [c.name for c in dg.causes] == ["flexibility"]
    p, s = dg.causes[0].parameters, dg.causes[0].sigma
    assert p["frequency"] == pytest.approx(truth["params"]["f_res"], rel=0.02)
    assert p["load_mass"] == pytest.approx(truth["params"]["m2"], rel=0.1)
    assert dg.extended_model.flexibility.load_mass == pytest.approx(p["load_mass"], rel=1e-12)
    assert all(s[k] is None or s[k] > 0 for k in ("frequency", "load_mass", "damping", "stiffness"))
    assert "force channel skipped" in " ".join(dg.notes)


def test_reversal_identification_judges_the_refined_scale():
    """reversal.unidentified on its own: a scale outside SCALE_RANGE or within MIN_SCALE_Z
    uncertainties of zero is not LuGre's build-up; a scale near 1 far from zero is."""
    from hunting.diagnose.causes import reversal
    assert reversal.unidentified({"scale": 1.0}, {"scale": 0.05}) is None
    assert "times LuGre's" in reversal.unidentified({"scale": 5.85}, {"scale": 1.43})
    assert "times LuGre's" in reversal.unidentified({"scale": 0.2}, {"scale": 0.01})
    assert "within 2 standard uncertainties" in reversal.unidentified({"scale": 1.0}, {"scale": 0.6})


@pytest.mark.parametrize("index, name, key, truth_key", [(78, "asymmetry", "b_neg", "b_neg"),
                                                         (57, "cogging", "amplitude_1", "A"),
                                                         (50, "level_asymmetry", "Fc_neg", "Fc_neg")])
def test_a_slow_slide_held_by_a_stiff_loop_is_read_as_a_slide(tmp_path, index, name, key, truth_key):
    """Seed 11 (held out in the fiftieth session, looked at in the fifty-first): records that move
    at 1-3 mm/s inside their model's Stribeck dip under PIDs whose damping outweighs the curve's
    negative slope many times. The free mass's rule (a slide on a falling branch is stick-slip
    below the count) called them sticks, the force channel was skipped, and nothing was named:
    d0078 a viscous asymmetry (b_neg ×1.95), d0057 cogging (0.53 N), d0050 a Coulomb level 22 %
    lower the negative way (a count every 11 samples: the long span and the map's velocity sign
    as well). Read as slides where the default reading leaves too few, each is named, its
    parameter within 5 % of the truth, and the report says how the slides were read."""
    dd = _one(tmp_path, 11, index)
    truth = json.loads((dd / "truth.json").read_text())
    dg = diagnose(load(dd / "fit.npz"), NominalModel.from_json(dd / "model.json"), load(dd / "val.npz"))
    assert [c.name for c in dg.causes] == [name]
    assert dg.causes[0].parameters[key] == pytest.approx(truth["params"][truth_key], rel=0.05)
    assert not any("force channel skipped" in n for n in dg.notes)
    assert any(n.startswith("slow slides read as the model's loop holds them") for n in dg.notes)
