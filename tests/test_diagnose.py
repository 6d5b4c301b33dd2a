"""Diagnosis: hidden effects in synthetic data must be found blind and named first, two effects
together found jointly, causes that share a signature reported once, clean data must give no
cause; parameters are final values that the extended model holds; EMPS with its default column
names shows its mismatch; bad input and short or wrongly scaled records get clear answers."""
import json
import os
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from hunting.diagnose import Measurement, NominalModel, diagnose, fit_coulomb_viscous, kinematics, load, save_csv
from hunting.diagnose.report import format_terminal
from hunting.diagnose.synthetic import TruePlant, generate, true_model
from hunting.errors import SystemDefinitionError

NOMINAL = {"plant": {"mass": 95.0, "motor_constant": 35.15},
           "friction": {"law": "coulomb-viscous", "Fc": 20.0, "b": 200.0}}
DURATION = 12.0


def _run(true, seeds=(1, 2), nominal=None, duration=DURATION, **kw):
    """Diagnose a fitting and a validation run of ``true`` (seeds) against ``nominal`` (default
    the Coulomb + viscous NOMINAL without controller), behaviour view off unless asked."""
    nominal = NominalModel.from_dict(NOMINAL) if nominal is None else nominal
    kw.setdefault("behaviour", False)
    return diagnose(generate(true, duration, seed=seeds[0]), nominal, generate(true, duration, seed=seeds[1]), **kw)


def _emps_dir():
    """The EMPS files: $HUNTING_DATA/emps, or ../shared/data/emps beside the checkout."""
    root = Path(__file__).resolve().parents[1]
    for d in ([Path(os.environ["HUNTING_DATA"]) / "emps"] if os.environ.get("HUNTING_DATA") else []) + [
            root.parent / "shared" / "data" / "emps"]:
        if (d / "DATA_EMPS.mat").is_file():
            return d
    pytest.skip("EMPS data not found (set HUNTING_DATA to the directory holding emps/)")


def test_clean_data_gives_no_cause(tmp_path):
    """The true model with its controller on clean data: no cause in any channel, the behaviour
    view re-simulated, and the terminal report says so in words with units and no None; the
    HTML page too, its units as written (str.capitalize made '172 mN RMS' '172 mn rms')."""
    from hunting.diagnose.report import write_report
    true = TruePlant()
    dg = _run(true, nominal=true_model(true), behaviour=True)
    assert dg.causes == []
    assert dg.extended == dg.nominal and dg.behaviour is not None
    text = format_terminal(dg)
    assert "no cause found" in text and "None" not in text and "Rule:" in text
    assert "µm" in text or " m " in text                 # values carry units
    page = write_report(dg, tmp_path).read_text()
    assert "<p>No cause found: " in page and "mN RMS" in page and " rms" not in page


@pytest.mark.parametrize("delay", [0.0, 0.0035])
def test_noise_free_data_of_the_nominal_model_gives_no_cause(delay):
    """Noise-free records of the nominal model itself (1 nm encoder, no actuator noise): the
    residual is the re-simulation's numerical error (1e-5 of the drive force), which a delay of
    150 ns fitted on both records alike; nothing is a cause below 1e-4 of the drive force. With
    a nominal delay of 3.5 samples, applied to first order in the residual, an 82 Hz
    'flexibility' and a 'delay' of +0.33 ms were reported; the delay is applied exactly now."""
    true = replace(TruePlant(), force_noise=0.0, resolution=1e-9, delay=delay)
    dg = _run(true, nominal=true_model(true))
    assert dg.causes == [], [(c.name, c.parameters) for c in dg.causes]


@pytest.mark.parametrize("case", ["offset", "asymmetry", "cogging", "mass", "viscous", "lag", "reversal"])
def test_single_effect_is_named_first_with_its_final_parameters(case):
    """One hidden effect at a moderate size: named first, nothing else selected, its parameters
    the final values (within 5 %), and those are the values the extended model holds."""
    base = TruePlant()
    true, nominal, check = {
        "offset": (replace(base, offset=-3.0), None, {"offset": -3.0}),
        "asymmetry": (replace(base, b_pos=170.0, b_neg=235.0), None, {"b_pos": 170.0, "b_neg": 235.0}),
        "cogging": (replace(base, cog_amplitude=4.0, cog_pitch=0.012), None, {"pitch": 0.012, "amplitude_1": 4.0}),
        "mass": (replace(base, mass=133.0), None, {"mass": 133.0}),
        "viscous": (replace(base, b_pos=500.0, b_neg=500.0), None, {"b": 500.0}),
        "lag": (replace(base, Fs=30.0, vs=0.01, lag=0.02), true_model(replace(base, Fs=30.0, vs=0.01)), {}),
        "reversal": (replace(base, sigma0=1e5), None, {}),
    }[case]
    dg = _run(true, nominal=nominal)
    assert [c.name for c in dg.causes] == [case]
    c = dg.causes[0]
    for k, v in check.items():
        assert c.parameters[k] == pytest.approx(v, rel=0.05), k
    assert c.gain["extended"] < 0.8 * c.gain["nominal"]
    # one number per parameter: the extended model holds the reported values
    ext = dg.extended_model.to_dict()
    held = {"offset": ext["plant"]["offset"], "mass": ext["plant"]["mass"], "b": ext["friction"]["b"],
            "b_pos": ext["friction"]["b"], "b_neg": ext["friction"].get("b_neg"),
            "lag": ext["friction"].get("lag"), "sigma0": ext["friction"].get("sigma0")}
    for k, v in c.parameters.items():
        if k in held:
            assert held[k] == pytest.approx(v, rel=1e-12), k
    if case == "lag":
        assert c.parameters["lag"] == pytest.approx(0.02, rel=0.25)
    if case == "reversal":
        assert c.parameters["sigma0"] == pytest.approx(1e5, rel=0.3)
        assert 0.7 < c.parameters["scale"] < 1.2            # the whole level builds up after a reversal
        assert ext["friction"].get("sigma1") == pytest.approx(c.parameters["sigma1"], rel=1e-12)
    assert all(s is not None and s > 0 for k, s in c.sigma.items() if k not in ("scale",)), c.sigma


@pytest.mark.parametrize("zeta", [0.3])
def test_reversal_refines_the_bristle_damping_with_the_stiffness(zeta):
    """LuGre bristles whose presliding resonance is damped at a ratio other than the search's
    0.5: the refinement frees the damping, so sigma0 is not biased by it and sigma1 is the
    truth's (with the damping ratio held at 0.5, sigma0 was 26 % low). Detection limit kept as
    it is: on this loop a contact damped at 0.7 or more is not found (the search holds 0.5;
    searching three ratios put a reversal on a clean blind tuning dataset)."""
    import numpy as np
    base = TruePlant()
    true = replace(base, sigma0=1e5, sigma1=2 * zeta * np.sqrt(1e5 * base.mass))
    dg = _run(true)
    c = dg.causes[0]
    assert c.name == "reversal"
    assert c.parameters["sigma0"] == pytest.approx(1e5, rel=0.1)        # the 10 %
    assert c.parameters["sigma1"] == pytest.approx(true.sigma1, rel=0.15)
    assert c.parameters["zeta"] == pytest.approx(zeta, rel=0.15)
    assert c.sigma["sigma1"] > 0


@pytest.mark.parametrize("pair", [("offset", "cogging"), ("offset", "asymmetry")])
def test_two_effects_are_found_together(pair):
    """Two effects at once: both selected (jointly: neither passes a one-at-a-time search
    reliably), with their parameters."""
    base = TruePlant()
    true = {("offset", "cogging"): replace(base, offset=2.5, cog_amplitude=3.0, cog_pitch=0.02),
            ("offset", "asymmetry"): replace(base, offset=-2.0, b_pos=160.0, b_neg=230.0)}[pair]
    dg = _run(true, seeds=(3, 4))
    names = {c.name: c for c in dg.causes}
    assert set(names) == set(pair)
    assert names["offset"].parameters["offset"] == pytest.approx(true.offset, abs=0.1 * abs(true.offset))
    if "cogging" in names:
        assert names["cogging"].parameters["pitch"] == pytest.approx(0.02, rel=0.02)
    else:
        assert names["asymmetry"].parameters["b_neg"] == pytest.approx(230.0, rel=0.05)


def test_delay_is_named_alone_and_its_companions_are_alternatives():
    """A transport delay shares its signature with lag and viscous friction: delay is selected,
    its delay within 10 %; the others are at most alternatives."""
    dg = _run(TruePlant(delay=0.004))
    assert [c.name for c in dg.causes] == ["delay"]
    assert dg.causes[0].parameters["delay"] == pytest.approx(0.004, rel=0.1)
    assert {a["name"] for a in dg.alternatives} <= {"viscous", "asymmetry", "lag", "offset", "mass"}


def _two_mass_measurement(seed, m1=75.0, m2=20.0, f0=18.0, zeta=0.05, cm=35.15, Fc=20.0, b=200.0,
                          duration=12.0, dt=1e-3):
    """A motor (m1, measured) driving a load m2 through a spring-damper (f0, zeta): the motor
    follows a smooth multisine; the load is integrated by solve_ivp (not by the cause's
    bilinear filter), and u = (m1 a1 + m2 a2 + F(v1)) / cm with noise; positions quantized."""
    from scipy.integrate import solve_ivp
    rng = np.random.default_rng(seed)
    freqs = np.array([0.2, 0.45, 1.1, 3.3, 7.7, 12.1, 16.9, 23.7, 31.3])
    amps = 0.04 / (1 + freqs ** 2) * rng.uniform(0.7, 1.3, freqs.size)
    ph = rng.uniform(0, 2 * np.pi, freqs.size)
    w = 2 * np.pi * freqs

    def motor(t):
        return ((amps * np.sin(np.multiply.outer(t, w) + ph)).sum(-1),
                (amps * w * np.cos(np.multiply.outer(t, w) + ph)).sum(-1),
                -(amps * w ** 2 * np.sin(np.multiply.outer(t, w) + ph)).sum(-1))
    k, c = m2 * (2 * np.pi * f0) ** 2, 2 * zeta * m2 * 2 * np.pi * f0

    def load(t, y):
        q1, v1, _ = motor(np.array([t]))
        return [y[1], (k * (q1[0] - y[0]) + c * (v1[0] - y[1])) / m2]
    t = np.arange(0.0, duration, dt)
    # a digital drive holds u_k over [t_k, t_k + dt): the force it stands for acts at t_k + dt / 2
    th = t + 0.5 * dt
    q1, v1, a1 = motor(th)
    sol = solve_ivp(load, (0, th[-1]), [q1[0], v1[0]], t_eval=th, rtol=1e-10, atol=1e-13, max_step=dt)
    a2 = (k * (q1 - sol.y[0]) + c * (v1 - sol.y[1])) / m2
    F = m1 * a1 + m2 * a2 + Fc * np.sign(v1) + b * v1
    u = F / cm + rng.normal(0, 0.01, t.size)
    q = np.round((motor(t)[0] + rng.normal(0, 2e-7, t.size)) / 1e-6) * 1e-6
    return Measurement(t, q, u)


@pytest.mark.slow
def test_hidden_flexibility_is_found():
    """A load on a spring behind the motor (75 + 20 kg, 18 Hz, zeta 0.05): the rigid model with the
    total mass sees it as a resonance in the residual; flexibility must be ranked first with its
    frequency and load mass recovered."""
    model = NominalModel.from_dict({"plant": {"mass": 95.0, "motor_constant": 35.15, },
                                    "friction": {"law": "coulomb-viscous", "Fc": 20.0, "b": 200.0},
                                    "sensor": {"resolution": 1e-6, "noise": 2e-7}})
    dg = diagnose(_two_mass_measurement(1), model, _two_mass_measurement(2), behaviour=False)
    c = dg.causes[0]
    assert c.name == "flexibility"
    assert c.parameters["frequency"] == pytest.approx(18.0, rel=0.05)
    assert c.parameters["load_mass"] == pytest.approx(20.0, rel=0.1)
    assert dg.extended < 0.5 * dg.nominal
    ext = dg.extended_model
    assert ext.flexibility is not None and ext.flexibility.frequency == c.parameters["frequency"]
    assert NominalModel.from_dict(ext.to_dict()).flexibility == ext.flexibility     # schema round trip


@pytest.mark.slow
def test_hidden_dwell_is_found():
    """Break-away force growing by 10 N with the rest (time constant 1 s), slow strokes and rests
    of 10 ms .. 3 s: dwell first, its growth recovered, the break-away forces of the validation
    run predicted at least twice as well."""
    true = TruePlant(dwell_gain=10.0, dwell_time=1.0, rest=(0.01, 3.0), stroke_speed=(0.01, 0.03), stroke=0.02)
    dg = _run(true, nominal=true_model(replace(true, dwell_gain=0.0)), duration=60.0)
    c = dg.causes[0]
    assert c.name == "dwell"
    assert c.parameters["gain"] == pytest.approx(10.0, rel=0.5)
    assert c.gain["extended"] < 0.5 * c.gain["nominal"]
    assert dg.extended_model.dwell is not None


def test_hidden_saturation_and_dac_quantization_are_found():
    """Output saturation at 1.4 V and, separately, a 0.5 V DAC step, both missing from the model:
    each found with its exact level, and the re-simulation improves (a 0.05 V step changes the
    re-simulated positions by under 5 % here: below the rule's gain)."""
    nominal = true_model(TruePlant())
    dg = _run(TruePlant(saturation=1.4), nominal=nominal)
    c = dg.causes[0]
    assert c.name == "saturation" and c.parameters["saturation"] == pytest.approx(1.4, rel=1e-6)
    assert c.gain["extended"] < 0.1 * c.gain["nominal"]
    dg = _run(TruePlant(dac_step=0.5), nominal=nominal)
    assert [c.name for c in dg.causes] == ["quantization"]
    assert dg.extended_model.controller["output_resolution"] == pytest.approx(0.5, rel=1e-3)


def test_emps_default_columns_show_the_mismatch(tmp_path):
    """EMPS with the default column names (pulses_N is a known injection inside vir, not a force)
    and the shipped example model: the published symmetric model's mismatch is found (the
    direction-dependent viscous friction of the published asymmetric fit), the force residual
    and the re-simulated drive force improve."""
    d = _emps_dir()
    fit, val = load(d / "DATA_EMPS.mat"), load(d / "DATA_EMPS_PULSES.mat")
    assert val.f_ext is None and val.u_inj is not None and set(np.unique(val.u_inj)) == {0.0, 5.0}
    model = NominalModel.from_json(Path(__file__).resolve().parents[1] / "examples" / "emps" / "model.json")
    dg = diagnose(fit, model, val)
    assert dg.causes[0].name == "asymmetry"
    p = dg.causes[0].parameters
    assert p["b_pos"] < 185.0 and p["b_neg"] > 235.0           # published 166.7 and 240.4
    assert p["b_pos"] == pytest.approx(166.7, rel=0.10) and p["b_neg"] == pytest.approx(240.4, rel=0.10)
    assert dg.extended < 0.5 * dg.nominal
    b = dg.behaviour
    assert b["extended"]["force_rms"] < 0.7 * b["nominal"]["force_rms"]
    # the published symmetric model's validation errors (position 0.0080 %, force 8.94 %)
    rel_f = b["nominal"]["force_rms"] / (35.15065188 * np.sqrt(np.mean(val.u ** 2)))
    assert rel_f < 1.2 * 8.94e-2
    # IDIM least squares with parallel filtering gives the published values within 1 %
    ls, _ = fit_coulomb_viscous(kinematics(fit, 35.15065188))
    assert ls.mass == pytest.approx(95.1089, rel=0.01) and ls.curve.positive.b == pytest.approx(203.5034, rel=0.01)
    assert ls.curve.positive.Fc == pytest.approx(20.3935, rel=0.01)


def test_bad_input_gets_one_clear_error(tmp_path):
    """Missing or dropped columns, ragged rows, NaN, time running backwards or in the wrong unit
    (1 MHz), a record too short to split, a mass that never moves: each an error naming what to
    change."""
    m = generate(TruePlant(), duration=2.0)
    save_csv(m, tmp_path / "d.csv")
    back = load(tmp_path / "d.csv")
    assert np.allclose(back.q, m.q) and np.allclose(back.u, m.u) and np.allclose(back.q_ref, m.q_ref)
    np.savez(tmp_path / "d.npz", t=m.t, qm=m.q, vir=m.u)
    assert np.allclose(load(tmp_path / "d.npz").q, m.q)
    cases = {"t,q\n0,0\n": "no column for 'u'", "t,q,u\n0,0,0\n0.001,0,0,5\n": "line 3 has 4 fields",
             "t,q,u\n0,0,x\n": "'x' is not a number"}
    for i, (text, msg) in enumerate(cases.items()):
        (tmp_path / f"bad{i}.csv").write_text(text)
        with pytest.raises(SystemDefinitionError, match=msg):
            load(tmp_path / f"bad{i}.csv")
    with pytest.raises(SystemDefinitionError, match="'u' cannot be left out"):
        load(tmp_path / "d.csv", {"u": None})
    with pytest.raises(SystemDefinitionError, match="NaN"):
        Measurement(m.t, np.where(m.t > 1, np.nan, m.q), m.u)
    with pytest.raises(SystemDefinitionError, match="t must increase"):
        Measurement(m.t[::-1], m.q, m.u)
    nominal = true_model(TruePlant())
    with pytest.raises(SystemDefinitionError, match="units.*sampled at 1e\\+06 Hz"):
        diagnose(replace(m, t=m.t / 1000), nominal, replace(m, t=m.t / 1000))
    with pytest.raises(SystemDefinitionError, match="too few to split"):
        diagnose(m.part(0.0, 0.2), nominal)
    # a record at rest (within a sensor step): "does not move", not a units disagreement (the
    # quantization's flicker read as sliding samples: reporting21 d0380's first 0.4 s got that)
    res = 1e-6
    still = Measurement(m.t, res * np.round(1e-7 * np.sin(50 * m.t) / res), 0.01 * np.sin(3 * m.t), q_ref=0 * m.t)
    with pytest.raises(SystemDefinitionError, match="does not move: its position spans"):
        diagnose(still, nominal.replace(resolution=res), m)
    with pytest.raises(SystemDefinitionError, match="loop bandwidth"):
        slow = Measurement(m.t[::40] * 1.0, m.q[::40], m.u[::40], q_ref=m.q_ref[::40])
        diagnose(slow, nominal.replace(controller=dict(nominal.controller, sample_time=None)), slow)
    with pytest.raises(SystemDefinitionError, match="unknown keys"):
        NominalModel.from_dict({"plant": {"mass": 1, "masss": 2}, "friction": {"Fc": 1}})


@pytest.mark.parametrize("moving, raises", [(20, False), (200, True)])
def test_units_are_judged_on_enough_sliding_samples(moving, raises):
    """A record that only creeps (independent seed-5 d0078, LuGre presliding: 20 samples at
    30-90 um/s just over the stick speed, the drive near zero) is no units disagreement; 200
    such samples with the model's friction 100 times the drive are."""
    from types import SimpleNamespace
    from hunting.diagnose.guards import MIN_UNIT_SAMPLES, check_units
    assert MIN_UNIT_SAMPLES == 100
    n = 1000
    mask = np.zeros(n, bool)
    mask[:moving] = True
    kin = SimpleNamespace(moving=mask, force=np.full(n, 0.01), a=np.zeros(n), v=np.full(n, 5e-5),
                          t=np.arange(n) * 1e-3)
    nominal = true_model(TruePlant())
    if raises:
        with pytest.raises(SystemDefinitionError, match="disagree in their units"):
            check_units(kin, nominal, "val.npz")
    else:
        assert check_units(kin, nominal, "val.npz") is None


def test_short_record_lists_what_it_cannot_test():
    """A 2 s record: what it is too short for is listed as not tested with the reason, never a
    silent empty report."""
    dg = _run(TruePlant(offset=-3.0), duration=2.5)
    untested = {u["name"]: u["reason"] for u in dg.untested}
    assert "dwell" in untested and "rest ending in motion" in untested["dwell"]
    assert "Not tested on these data" in format_terminal(dg)


def test_cli_diagnose_prints_the_report_and_writes_the_json_contract(tmp_path, capsys):
    from hunting.cli import main
    tp = TruePlant(offset=-3.0)
    save_csv(generate(tp, DURATION, seed=1), tmp_path / "fit.csv")
    save_csv(generate(tp, DURATION, seed=2), tmp_path / "val.csv")
    (tmp_path / "model.json").write_text(json.dumps(NOMINAL))
    rc = main(["diagnose", str(tmp_path / "fit.csv"), "--model", str(tmp_path / "model.json"), "--validate",
               str(tmp_path / "val.csv"), "--json", str(tmp_path / "out.json"), "--report", str(tmp_path / "rep")])
    assert rc == 0
    text = capsys.readouterr().out
    assert "1. offset: a constant force of 3" in text and "None" not in text and "Rule:" in text
    out = json.loads((tmp_path / "out.json").read_text())
    c = out["causes"][0]
    assert c["name"] == "offset" and set(c) >= {"name", "score", "parameters", "sigma", "increments", "gain"}
    assert c["parameters"]["offset"] == pytest.approx(out["extended_model"]["plant"]["offset"])
    assert "prewhitened" in out["rule"]
    assert (tmp_path / "rep" / "index.html").is_file() and (tmp_path / "rep" / "residual.png").stat().st_size > 10_000
    assert "Rule" in (tmp_path / "rep" / "index.html").read_text() or "Criterion" in (tmp_path / "rep" / "index.html").read_text()
    assert "<p>Rule: " in (tmp_path / "rep" / "index.html").read_text()


def _virtual_limms_model(mot, controller, cogging):
    from hunting.models.friction import DirectionalCurve
    return NominalModel(mot.mass, mot.cm, DirectionalCurve(mot.positive, mot.negative), "switch",
                        cogging=(mot.cogging_table(),) if cogging else (), controller=controller,
                        resolution=mot.resolution, sensor_noise=mot.noise)


@pytest.mark.slow
def test_virtual_limms_switch_model_without_cogging_finds_cogging():
    """Chapter 10's motor, slow tracking under the strong PID (section 10.3.2), diagnosed with the
    true Switch model minus its cogging: cogging near the magnets' 15 mm pitch, first."""
    from hunting.experiment import limms as L
    from hunting.experiment.motor import VirtualMotor
    mot = VirtualMotor()

    def run(seed):
        rec, _, _ = L.cogging_experiment(mot, seed=seed)
        return Measurement(rec.t, rec.y, rec.u, q_ref=rec.r)
    S = L.STRONG_PID
    model = _virtual_limms_model(mot, {"type": "pid", "kp": S.kp, "kd": S.kd, "ki": S.ki, "tau_f": S.tau_f}, False)
    dg = diagnose(run(2), model, run(4))
    c = dg.causes[0]
    assert c.name == "cogging" and c.parameters["pitch"] == pytest.approx(0.015, rel=0.03)
    assert dg.extended < 0.6 * dg.nominal
    assert dg.behaviour["extended"]["position_rms"] < 0.7 * dg.behaviour["nominal"]["position_rms"]


@pytest.mark.slow
def test_virtual_limms_switch_model_with_cogging_finds_presliding():
    """The regulator near the equilibrium set (K = 45 < 50.3: the Switch model's set is unstable,
    its integral action winds up until the mass slips): the machine creeps to rest in presliding
    instead. The diagnosis must name presliding from that behaviour, and the LuGre extension must
    predict the rest."""
    from hunting.experiment.limms import regulator_experiment
    from hunting.experiment.motor import VirtualMotor
    mot = VirtualMotor()

    def run(d0, seed):
        rec = regulator_experiment(mot, 45.0, d0, 70.0, seed=seed)
        return Measurement(rec.t, rec.y, rec.u, q_ref=rec.r)
    model = _virtual_limms_model(mot, {"type": "pid", "form": "K", "K": 45.0}, True)
    dg = diagnose(run(20e-6, 3), model, run(18e-6, 9))
    assert [c.name for c in dg.causes] == ["presliding"]
    c = dg.causes[0]
    assert c.p_value < 1e-6
    assert 3e5 < c.parameters["sigma0"] < 3e6                      # true 1.3e6
    b = dg.behaviour
    assert b["measured"]["at_rest"] and b["extended"]["at_rest"] and not b["nominal"]["at_rest"]
    assert b["extended"]["position_rms"] < 0.2 * b["nominal"]["position_rms"]


def test_wrong_stribeck_level_is_found_and_the_event_map_follows(tmp_path):
    """Table 9.1's hunting loop (P = 20) measured, diagnosed with Fs = 3 instead of 4: the force
    channel must move the Stribeck level back (the nominal dip kept, not dropped), and the
    extended model's re-simulated event map must match the measured one where the nominal's
    does not (its hunting cycle is a third of the measured amplitude)."""
    from hunting.diagnose.report import write_report
    from hunting.diagnose.synthetic import regulator
    true = NominalModel.from_dict({"preset": "table9.1", "set": {"P": 20.0}})
    nominal = NominalModel.from_dict({"preset": "table9.1", "set": {"P": 20.0, "Fs": 3.0}})
    fit, val = (regulator(true, d0, 40_000, 1e-3, seed=seed, resolution=1e-5, force_noise=0.05)
                for d0, seed in ((0.5, 1), (0.4, 2)))
    dg = diagnose(fit, nominal, val, causes=["offset", "stribeck", "presliding"])
    assert [c.name for c in dg.causes] == ["stribeck"]
    p, s = dg.causes[0].parameters, dg.causes[0].sigma
    assert p["Fs"] == pytest.approx(4.0, abs=max(3 * s["Fs"], 0.02)) and p["Fc"] == pytest.approx(2.0, abs=0.02)
    # the static level alone at the nominal shape (the stribeck variant ``dip``): vs is the
    # model's own, held, so it has no uncertainty of its own
    assert dg.causes[0].hyper.get("dip") and p["vs"] == 0.1 and s["vs"] is None
    b = dg.behaviour
    m = b["measured"]["map_contraction"]
    assert abs(b["extended"]["map_contraction"] - m) < 0.01 < 0.1 < abs(b["nominal"]["map_contraction"] - m)
    assert b["extended"]["cycle_amplitude"] == pytest.approx(b["measured"]["cycle_amplitude"], rel=0.02)
    html = write_report(dg, tmp_path)
    assert (tmp_path / "event_map.png").is_file() and "event_map.png" in html.read_text()
    saved = json.loads((tmp_path / "diagnosis.json").read_text())
    assert len(saved["behaviour"]["measured"]["event_map"]) == len(b["measured"]["event_map"]) >= 20


def test_floor_reason_claims_numerical_precision_only_for_a_residual_at_that_level():
    """Review (newcomer): a cause rejected by the absolute floor with a 491 mN validation residual
    was said to leave a model that 'already reproduces the data to numerical precision'."""
    from hunting.diagnose.force import _why
    large = dict(p_value=0.0, gain=0.013, rms=0.491, rms_without=0.49122, floor=0.0005)
    text = _why(large, 1e-3, 0.05)
    assert "numerical precision" not in text and "below that floor" in text and "0.491 N" in text
    tiny = dict(p_value=0.0, gain=0.013, rms=2e-4, rms_without=2.2e-4, floor=0.0005)
    assert "numerical precision" in _why(tiny, 1e-3, 0.05)


def test_small_only_marks_a_member_that_fails_only_by_its_size_on_the_sliding_samples():
    """force.small_only: significant, but its change of the friction force below the relevance
    floor (or what it removes below the precision floor), or its validation gain below min_gain,
    or both -> True; failing anything else as well, or nothing at all -> False."""
    from hunting.diagnose.force import small_only
    small = dict(p_value=1e-6, gain=0.3, rms=0.5, rms_without=0.8, floor=1e-4, change=0.01, relevance=0.04)
    assert small_only(small, 1e-3, 0.05, 0.01)
    assert small_only(dict(small, change=1.0, rms_without=0.50005), 1e-3, 0.05, 0.01)   # the precision floor
    assert not small_only(dict(small, change=1.0), 1e-3, 0.05, 0.01)                     # it passes the rule
    assert not small_only(dict(small, p_value=0.5), 1e-3, 0.05, 0.01)                    # not significant too
    assert small_only(dict(small, gain=0.01), 1e-3, 0.05, 0.01)                          # no validation gain too
    assert small_only(dict(small, change=1.0, gain=0.01), 1e-3, 0.05, 0.01)              # the gain alone
    assert not small_only(dict(small, gain=0.01, p_value=0.5), 1e-3, 0.05, 0.01)         # and not significant
    assert not small_only(dict(small, p_reference=0.5), 1e-3, 0.05, 0.01)                # reference fails too


def test_displaced_marks_a_member_that_fails_only_on_its_drop_one_gain():
    """force.displaced: significant out of sample, along the reference and above the relevance
    floor, failing only because the set without it predicts as well (its gain, or what it removes
    below the precision floor) -> True; failing anything else too, or nothing -> False."""
    from hunting.diagnose.force import displaced
    beside = dict(p_value=1e-6, gain=-0.29, rms=0.5, rms_without=0.39, floor=1e-4, change=0.3, relevance=0.04)
    assert displaced(beside, 1e-3, 0.05, 0.01)
    assert displaced(dict(beside, gain=0.3, rms_without=0.50005), 1e-3, 0.05, 0.01)    # the precision floor
    assert not displaced(dict(beside, gain=0.3, rms_without=0.8), 1e-3, 0.05, 0.01)    # it passes the rule
    assert not displaced(dict(beside, p_value=0.5), 1e-3, 0.05, 0.01)                  # not significant too
    assert not displaced(dict(beside, change=0.01), 1e-3, 0.05, 0.01)                  # below the relevance floor
    assert not displaced(dict(beside, p_reference=0.5), 1e-3, 0.05, 0.01)              # reference fails too


def test_no_cause_headline_gives_the_residual_not_a_model_that_explains_the_data():
    """A 3 N offset with only cogging searched: no cause passes, and the report says that no
    cause passed the rule with the residual's size, not that the nominal model explains the data."""
    dg = _run(replace(TruePlant(), offset=-3.0), causes=["cogging"])
    assert dg.causes == [] and dg.nominal > 2.0
    text = format_terminal(dg)
    first = text.splitlines()[0]
    assert "explains the data" not in text and "no cause passed the rule" in first, first
    assert " N RMS" in first and "of the drive force" in first


def test_no_cause_headline_without_the_force_channel_gives_the_re_simulation_error():
    """Where the force channel was not run (reporting32 d0621: the drive at its bound, the plant
    barely moving), the headline said only that no cause passed; it gives the nominal model's
    re-simulated position error beside the measured motion (19.4 mm RMS off over 27.3 mm)."""
    from types import SimpleNamespace
    from hunting.diagnose.report import no_cause_headline
    t = np.linspace(0.0, 1.0, 101)
    dg = SimpleNamespace(nominal=None, behaviour={"nominal": {"position_rms": 0.0194}},
                         validation=Measurement(t, 0.0273 * t, np.zeros(101)))
    assert no_cause_headline(dg) == ("no cause found: no cause passed the rule (the force channel was not run); the "
                                     "nominal model's re-simulated validation position is 19.4 mm RMS off (the "
                                     "measured position spans 27.3 mm)")
    assert no_cause_headline(SimpleNamespace(nominal=None, behaviour=None, validation=None)) == (
        "no cause could be tested on these data")
    dg.behaviour["nominal"]["ok"] = False          # a re-simulation that stopped: no error over part of it
    assert no_cause_headline(dg).endswith("the nominal model's re-simulation of the validation record fails")


def test_validating_on_the_fitting_data_is_warned_and_noted(tmp_path, capsys):
    """Review (newcomer): --validate given the fitting file (or a copy) ran the 'out-of-sample'
    test on the fitting data without a word. Now one warning line on stderr before the work, the
    same note in the report and the JSON; the results are still computed."""
    from hunting.cli import main
    save_csv(generate(TruePlant(), 6.0, seed=1), tmp_path / "fit.csv")
    (tmp_path / "copy.csv").write_bytes((tmp_path / "fit.csv").read_bytes())
    (tmp_path / "model.json").write_text(json.dumps(NOMINAL))
    rc = main(["diagnose", str(tmp_path / "fit.csv"), "--model", str(tmp_path / "model.json"), "--validate",
               str(tmp_path / "copy.csv"), "--json", str(tmp_path / "out.json")])
    assert rc == 0
    cap = capsys.readouterr()
    warn = [line for line in cap.err.splitlines() if "not out of sample" in line]
    assert len(warn) == 1 and warn[0].startswith("warning:") and "copy.csv" in warn[0]
    assert "not out of sample" in cap.out and "Rule:" in cap.out
    notes = json.loads((tmp_path / "out.json").read_text())["notes"]
    assert any("not out of sample" in n for n in notes)
    # separate records: no such note
    dg = _run(TruePlant(), duration=6.0)
    assert not any("not out of sample" in n for n in dg.notes)


def test_sentences_quote_no_model_value_the_nominal_law_lacks():
    """Review (newcomer): a Coulomb + viscous model was said to have a Stribeck velocity
    '(model 1 m/s)' (its internal placeholder); a model without viscous friction gave 'inf times'
    and 'inf %'; a model without offset 'has 0 N'."""
    from hunting.diagnose.causes import CAUSES
    cv = NominalModel.from_dict(NOMINAL)
    # the parameters a Stribeck cause reports (parameters() always gives both directions)
    p = {"Fc": 19.0, "Fs": 30.0, "vs": 0.234, "vs_neg": 0.234}
    s = CAUSES["stribeck"].sentence(p, {}, cv)
    assert "no Stribeck dip" in s and "1 m/s" not in s and "model 20 N" not in s.split("Fc")[0], s
    assert "234 mm/s" in s
    dipped = true_model(replace(TruePlant(), Fs=30.0, vs=0.01))
    assert "(model 10 mm/s)" in CAUSES["stribeck"].sentence(p, {}, dipped)
    s = CAUSES["stribeck"].sentence({**p, "vs_neg": 0.1}, {}, dipped)
    assert "234 mm/s moving positive, 100 mm/s moving negative" in s, s
    coulomb = NominalModel.from_dict({"plant": NOMINAL["plant"], "friction": {"law": "coulomb-viscous", "Fc": 20.0}})
    for name, p in (("viscous", {"b": 200.0}), ("asymmetry", {"b_pos": 190.0, "b_neg": 210.0})):
        s = CAUSES[name].sentence(p, {}, coulomb)
        assert "inf" not in s and "has none" in s, s
    s = CAUSES["offset"].sentence({"offset": -3.0}, {}, cv)
    assert "the model has none" in s and "0 N" not in s, s


def test_counts_in_reasons_agree_with_their_number():
    """Review (newcomer): 'the controller output does not pile up at a bound (1 samples at its
    extreme)'."""
    from hunting.diagnose.causes import CAUSES
    from hunting.diagnose.causes._words import _count
    t = np.arange(400) * 1e-3
    u = 0.5 * np.sin(2 * np.pi * 3.3 * t)
    u[123] = 2.0
    meas = Measurement(t, np.zeros_like(t), u)
    reason = CAUSES["saturation"].judge(meas, meas, None, None, NominalModel.from_dict(NOMINAL), False, 1e-6)["reason"]
    assert "(1 sample at its extreme)" in reason, reason
    assert (_count(0, "rest"), _count(1, "rest"), _count(2, "rest")) == ("0 rests", "1 rest", "2 rests")


def test_a_controller_that_does_not_give_the_measured_u_is_noted():
    """Review (newcomer): a model whose controller does not reproduce the measured u from the
    measured q and q_ref (their PID differentiates the error, the machine's the measurement:
    281 % RMS mismatch) was re-simulated without a word. The model's own controller replays the
    synthetic u exactly; kv 1.5 times too large gives 50 % and a note naming the number."""
    from hunting.diagnose.resimulate import controller_output
    true = TruePlant()
    meas = generate(true, 6.0, seed=1)
    model = true_model(true)
    assert np.max(np.abs(controller_output(meas, model.controller) - meas.u)) < 1e-9
    dg = _run(true, nominal=model, duration=6.0)
    assert not any("controller" in n for n in dg.notes), dg.notes
    wrong = model.replace(controller=dict(model.controller, kv=1.5 * model.controller["kv"]))
    dg = _run(true, nominal=wrong, duration=6.0)
    notes = [n for n in dg.notes if "RMS mismatch to the measured u" in n]
    assert len(notes) == 2 and "50%" in notes[0] and "kv" in notes[0], dg.notes


def test_a_worse_extended_resimulation_is_noted():
    """Review (newcomer): 're-simulated position RMS error 126 µm -> 149 µm' stood in the table
    without a word. A worse extended re-simulation gets a note with both numbers; a better one
    none."""
    from hunting.diagnose.select import worse_resimulation
    view = {"nominal": {"position_rms": 126e-6, "force_rms": 4.5}, "extended": {"position_rms": 149e-6, "force_rms": 2.5}}
    notes = worse_resimulation(view)
    assert len(notes) == 1 and "126 µm -> 149 µm" in notes[0] and "+18%" in notes[0] and "worse" in notes[0], notes
    view["extended"]["position_rms"] = 100e-6
    assert worse_resimulation(view) == []


def test_the_worse_resimulation_note_reaches_the_report(monkeypatch):
    """The note is in the diagnosis (and its report) when a cause was selected and the behaviour
    view's extended errors are larger (the view's errors swapped to make them so)."""
    import hunting.diagnose.behaviour as behaviour
    compare = behaviour.compare

    def swapped(*args, **kw):
        view = compare(*args, **kw)
        return dict(view, nominal=view["extended"], extended=view["nominal"])
    monkeypatch.setattr(behaviour, "compare", swapped)
    true = replace(TruePlant(), offset=-3.0)
    nominal = true_model(true).replace(offset=0.0)
    dg = _run(true, nominal=nominal, duration=6.0, behaviour=True, causes=["offset"])
    assert [c.name for c in dg.causes] == ["offset"]
    assert any("re-simulates the validation run worse" in n for n in dg.notes), dg.notes
    text = format_terminal(dg)
    assert "re-simulates the validation run worse" in text
    # where a reader sees it: right under the findings, before the tables and the rule (it came
    # at the end, after the tables and the rejected and untested causes)
    assert text.index("1. offset:") < text.index("note: ") < text.index("Validation data") < text.index("Rule:")


def test_an_offset_the_data_lack_is_said_so():
    """A model with a 3 N constant force on data without one: the finding is that the model's
    force is not there, not 'a constant force of 1.08 mN pushes the load' (reviewer, 2026-11-23)."""
    from hunting.diagnose.causes import offset
    m = NominalModel.from_dict({"plant": {"mass": 95.0, "motor_constant": 35.15, "offset": 3.0},
                                "friction": {"Fc": 20.0, "b": 200.0}})
    said = offset.sentence({"offset": 0.00108}, {"offset": -2.99892}, m)
    assert said.startswith("the model's constant force of 3 N is not in the data") and "pushes" not in said
    assert "pushes the load towards negative" in offset.sentence({"offset": 1.5}, {"offset": -1.5}, m)


def test_a_cogging_the_data_lack_is_said_so_with_the_merged_harmonics():
    """A model with a 2 N cogging on data without one: the cause's amplitudes are the merged
    harmonics (the model's plus the fitted change: about 0, not the 2 N component cancelling the
    model's), the extended model holds them in place of the model's component, the change is
    the extra field, and the sentence says the model's cogging is not in the data (it said 'a
    force periodic in position that the model lacks ... 2 N'; reviewer's finding)."""
    from hunting.diagnose.causes import cogging
    from hunting.models.plant import Cogging
    true = TruePlant()
    nominal = NominalModel.from_dict(NOMINAL).replace(cogging=(Cogging.sine(2.0, 0.012),))
    dg = _run(true, nominal=nominal, causes=["cogging", "offset"])
    assert [c.name for c in dg.causes] == ["cogging"]
    c = dg.causes[0]
    assert c.parameters["amplitude_1"] < 0.1 and c.increments["amplitude_1"] == pytest.approx(-2.0, abs=0.1)
    held = dg.extended_model.cogging
    assert len(held) == 1 and held[0].period == c.parameters["pitch"]
    for k in range(cogging.HARMONICS):
        assert np.hypot(held[0].data[2 * k], held[0].data[2 * k + 1]) == pytest.approx(c.parameters[f"amplitude_{k + 1}"],
                                                                                       rel=1e-12, abs=1e-15)
    from hunting.diagnose.report import finding
    said = finding(dg, c)
    assert said.startswith("the model's force periodic in position (pitch 12 mm, first harmonic 2 N) is not in the data")
    assert "lacks" not in format_terminal(dg)
    # a cogging the model has at the wrong size: the final amplitude, and the model's beside it
    m = nominal.replace(cogging=(Cogging.harmonic(0.012, cos=[0.0, 0.3], sin=[2.0]),))
    theta = np.array([0.0, 1.5, -0.1, 0.0, 0.2, 0.0])
    p = cogging.parameters(theta, {"pitch": 0.012}, m)
    assert p["amplitude_1"] == pytest.approx(3.5) and p["amplitude_2"] == pytest.approx(np.hypot(0.2, 0.0))
    assert cogging.extend(m, theta, {"pitch": 0.012}).cogging[0].data[:4] == pytest.approx((0.0, 3.5, 0.2, 0.0))
    assert "first harmonic 3.5 N (the model's 2 N)" in cogging.sentence(p, {}, m)


def test_a_rejected_reversal_quotes_no_ratio_over_a_change_that_does_not_show():
    """At the stiffest bristles searched LuGre's build-up is over within a sample, its regressor
    is near zero (1e-11 N) and the fitted scale on clean data is 1e8 or more: the rejection said
    '-1.1e12 times LuGre's' (reviewer). A large scale is not quoted, a negative one is said to
    have the opposite sign, a small one keeps its ratio."""
    import re
    from hunting.diagnose.causes import reversal
    from hunting.diagnose.kinematics import residual
    true = TruePlant()
    m = true_model(true).replace(controller=None)
    meas = generate(true, 4.0, seed=1)
    kin = kinematics(meas, m.cm, window=31 * meas.dt)
    r = residual(kin, m)
    ok = kin.moving & np.isfinite(r)
    h = reversal.hypers(kin, m)[-1]
    x = reversal.design(kin, m, h)[:, 0]
    scale = float(np.dot(x[ok], r[ok]) / np.dot(x[ok], x[ok]))
    assert abs(scale) > 1e4                                  # the meaningless ratio the old text quoted
    for k in (scale, -scale, -1.1e12, 5e3):
        why = reversal.unphysical([k], h, m)
        assert why and not re.search(r"-?\d[\d.]*(e[+-]?\d+)? times", why.replace("10 times", "")), why
    assert "opposite sign" in reversal.unphysical([-0.5], h, m)
    assert "0.04 times LuGre's" in reversal.unphysical([0.04], h, m)
    assert reversal.unphysical([1.0], h, m) is None


def test_a_model_saturation_below_the_measured_output_is_said_first():
    """A model saturating at 1.5 V on a loop whose output reaches 4.7 V: that was only a '27 %
    controller mismatch' note, printed after the rule (reviewer's finding). Now the first note
    gives both numbers, the mismatch note says the saturation is what differs, the notes come
    right under the findings, and the saturation cause holds the measured level, the value the
    extended model's controller holds. The true model (saturation 10 V, never reached) gets
    no such note."""
    from hunting.diagnose.guards import check_saturation
    true = TruePlant()
    fit, val = generate(true, 12.0, seed=1), generate(true, 12.0, seed=2)
    model = true_model(true)
    assert check_saturation((fit, val), model) is None
    low = model.replace(controller=dict(model.controller, saturation=1.5))
    dg = diagnose(fit, low, val)
    top = float(max(np.max(np.abs(fit.u)), np.max(np.abs(val.u))))
    assert dg.notes[0].startswith(f"{val.name}: the measured controller output reaches |u| = {top:.4g}, ")
    assert "the model's saturation level 1.5 " in dg.notes[0]
    assert any("without its saturation at 1.5 it is 0.0%" in n for n in dg.notes), dg.notes
    c = {c.name: c for c in dg.causes}["saturation"]
    assert c.parameters["saturation"] == top == dg.extended_model.controller["saturation"]
    assert c.increments["saturation"] == pytest.approx(top - 1.5)
    text = format_terminal(dg)
    assert text.index("note: ") < text.index("Validation data") < text.index("Rule:")
    # at 2 V only the validation record goes beyond: the note, and the cause says why it is not judged
    from hunting.diagnose.causes import saturation
    at2 = model.replace(controller=dict(model.controller, saturation=2.0))
    assert check_saturation((fit, val), at2).startswith(f"{val.name}: the measured controller output reaches")
    why = saturation.judge(fit, val, None, None, at2, True, 1e-6)["reason"]
    assert why.startswith("the fitting data stay within the model's saturation level 2 (max |u| 1.94")


def test_viscous_sentence_gives_values_not_a_ratio_to_next_to_nothing():
    """A model viscous coefficient of almost nothing: the sentence gives both values, not a ratio
    of 1e9 (the reviewer's reversal finding, the same kind in viscous)."""
    from hunting.diagnose.causes import viscous
    model = NominalModel.from_dict({"plant": {"mass": 1.0}, "friction": {"Fc": 1.0, "b": 1e-9}})
    text = viscous.sentence({"b": 5.0}, {"b": 5.0}, model)
    assert "times" not in text and "5 N s/m" in text
    model = NominalModel.from_dict({"plant": {"mass": 1.0}, "friction": {"Fc": 1.0, "b": 2.0}})
    assert "2.5 times the model's" in viscous.sentence({"b": 5.0}, {"b": 3.0}, model)


def test_presliding_stiffer_than_the_sensor_can_see_is_no_presliding():
    """A stick-channel fit that runs to the stiffest contact whose presliding range Fs / sigma0
    is half the encoder's step is rejected (a Stribeck change on a blind tuning record was
    taken for 1.7e8 N/m bristles, a 0.1 um range, once the re-simulation followed them)."""
    from hunting.diagnose.causes import presliding
    model = NominalModel.from_dict({"plant": {"mass": 1.0}, "friction": {"Fc": 10.0},
                                    "sensor": {"resolution": 1e-6}})
    meas = Measurement(np.arange(100) * 1e-3, np.zeros(100), np.zeros(100))
    assert presliding.stiffest(model, meas) == pytest.approx(2e7)
    assert "stiffest contact" in presliding.at_bound(np.array([1 / 2e7]), meas, model)
    assert presliding.at_bound(np.array([1 / 1e6]), meas, model) is None
