"""The diagnosis' guards against its own estimation: the nominal model's residual on its
noise-free loop (:mod:`hunting.diagnose.method_error`), causes that veto their own
identification (reversal's scale within two standard uncertainties of zero) and sets whose
members cancel each other (collinear signatures). Records come from
the blind benchmark's independent generator (clean tuning-side datasets on which the diagnosis
without these guards reported causes)."""
from __future__ import annotations

import numpy as np
import pytest

from hunting.diagnose.causes import reversal
from hunting.diagnose.data import Measurement
from hunting.diagnose.kinematics import kinematics, residual, used_samples
from hunting.diagnose.method_error import method_error
from hunting.diagnose.model import NominalModel
from hunting.diagnose.select import diagnose
from hunting.diagnose.stats import NoiseModel

from blind_records import blind_record


_dataset = blind_record


def _used_kinematics(fit, val, model):
    """(kf, kv): the records' kinematics as the diagnosis forms them (its default window, the
    model's sensor, the force channel's used samples as ``moving``)."""
    from dataclasses import replace
    from hunting.diagnose.select import default_window
    w = default_window(fit, val, model)
    from hunting.diagnose.parts import sensor_settings
    sensor = sensor_settings(model)
    return tuple(replace(k, moving=used_samples(k, model)) for k in (kinematics(m, model.cm, window=w, **sensor)
                                                                     for m in (fit, val)))


@pytest.fixture(scope="module")
def noise_free():
    fit, val, model, truth = _dataset("tuning-clean", 22, noise=False)
    assert truth["causes"] == []
    return fit, val, model


def test_noise_free_clean_record_reports_nothing(noise_free):
    """A clean record without noise is the nominal model's own: nothing to report. Without the
    method's error subtracted, the estimation's bias at this record's fast velocity changes
    passed as viscous (score 1.05) and Stribeck (0.48) effects, p < 1e-100."""
    fit, val, model = noise_free
    d = diagnose(fit, model, val, behaviour=False)
    assert d.causes == [], [(c.name, c.score) for c in d.causes]
    assert any("nominal model's own on its noise-free closed loop" in n for n in d.notes)


def test_method_error_is_what_the_record_leaves(noise_free):
    """On the noise-free record the method's error is the data's residual itself where it is
    applied: subtracting it leaves less than 10 % of the residual's RMS there."""
    fit, _, model = noise_free
    kin = kinematics(fit, model.cm, window=31 * fit.dt, resolution=model.resolution, noise=model.sensor_noise)
    from dataclasses import replace
    kin = replace(kin, moving=used_samples(kin, model))
    e = method_error(fit, kin, model)
    assert e is not None and e.valid.sum() >= 100
    r = residual(kin, model)[e.valid]
    left = r - e.force[e.valid]
    assert np.sqrt(np.mean(left ** 2)) < 0.1 * np.sqrt(np.mean(r ** 2))
    assert np.all(e.force[~e.valid] == 0.0)


def test_method_error_needs_a_controller(noise_free):
    fit, _, model = noise_free
    kin = kinematics(fit, model.cm, resolution=model.resolution)
    assert method_error(fit, kin, model.replace(controller=None)) is None


def test_reversal_dither_on_clean_data_is_not_identified():
    """A clean record whose noise dithers the friction force near velocity reversals: the reversal
    passed the validation test (p = 6e-22) with a scale of 2.2 +- 5.9, i.e. no identified
    build-up. It was then rejected at the identification step; since the bristles are integrated
    with the velocity linear between samples (:mod:`hunting.diagnose.bristles`), its fitted
    change has the opposite sign of LuGre's build-up and it is rejected as not physical at the
    search. Either way nothing is reported, and the reason says why."""
    fit, val, model, truth = _dataset("tuning-clean", 11)
    assert truth["causes"] == []
    d = diagnose(fit, model, val, behaviour=False)
    assert d.causes == [], [(c.name, c.score) for c in d.causes]
    rows = [r for r in d.rejected if r["name"] == "reversal"]
    assert len(rows) == 1
    assert "not identified" in rows[0]["reason"] or "opposite sign of LuGre's build-up" in rows[0]["reason"]


def test_reversal_identification_rule():
    assert reversal.unidentified({"scale": 2.2}, {"scale": 5.9})
    assert reversal.unidentified({"scale": -0.5}, {"scale": 0.3})
    assert reversal.unidentified({"scale": 1.0}, {"scale": 0.05}) is None
    assert reversal.unidentified({"scale": 1.0}, {"scale": None}) is None


def test_noise_model_of_a_zero_residual():
    """A model that fits its own noise-free data leaves an exactly zero residual: white, zero
    variance, not a singular Yule-Walker system."""
    nm = NoiseModel.fit(np.zeros(500), np.zeros(500, np.int64))
    assert nm.order == 0 and nm.sigma2 == 0.0


def test_cancelling_members_are_not_an_explanation():
    """A clean record (tuning d0040: PD + velocity loop, 0.4 ms sampling, 1209 sliding samples)
    on which delay, level and mass fitted together cancelled each other: 8.8e8 kg, 2.6e7 s and a
    level scaled by 2.7e10, a 2 % validation residual left, reported as three causes. Members whose
    own force change exceeds three drive-force RMS are not physical, and nothing is reported."""
    fit, val, model, truth = _dataset("tuning", 40)
    assert truth["causes"] == []
    d = diagnose(fit, model, val, behaviour=False)
    assert d.causes == [], [(c.name, c.parameters) for c in d.causes]


def test_cancelling_rule_names_the_member():
    from hunting.diagnose.force import CANCEL, Library
    fit, val, model, _ = _dataset("tuning", 41)
    from dataclasses import replace
    kf = kinematics(fit, model.cm, window=31 * fit.dt, resolution=model.resolution, noise=model.sensor_noise)
    kv = kinematics(val, model.cm, window=31 * fit.dt, resolution=model.resolution, noise=model.sensor_noise)
    kf, kv = (replace(k, moving=used_samples(k, model)) for k in (kf, kv))
    lib = Library(["offset", "mass"], kf, kv, model, kf.moving, kv.moving, 10)
    ex = lib.fit([("offset", 0), ("mass", 0)])
    theta = ex.theta.copy()
    assert not lib.cancelling(ex.members, theta, {})
    x_mass = lib.X_thin[:, lib.slot[("mass", 0)][0][0]]
    theta[1] = 2 * CANCEL * lib.drive_rms / np.sqrt(np.mean(x_mass ** 2))    # twice the allowed force change
    why = lib.cancelling(ex.members, theta, {})
    assert list(why) == ["mass"] and "times the drive force's" in why["mass"]


def test_validation_noise_model_survives_a_cancelled_library_fit():
    """tuning d0207: a 0.081 N offset (61 % of the validation residual when modelled) and a
    0.6 ms delay too small to matter. The whole library fitted on the fitting data predicted the
    validation data worse than nothing, and a noise model of that residual made the offset's test
    p = 0.2: nothing was reported. Without the library's unphysical members the noise model is the
    noise's and the offset is found, within 1 % of the truth. Since the forty-eighth session the
    delay is searched on the validation record's blocks too (its drive force changes more than 3
    times faster than the one-way fitting record's: delay.unseen) and found, 0.65 ms for a true
    0.60, and the offset's value is the blocks' joint fit with it, within 2 %."""
    fit, val, model, truth = _dataset("tuning", 207)
    assert truth["causes"] == ["offset", "delay"]
    d = diagnose(fit, model, val, behaviour=False)
    got = {c.name: c.parameters for c in d.causes}
    assert set(got) == {"offset", "delay"}, got
    true = {e["cause"]: e["params"] for e in truth["effects"]}
    assert got["offset"]["offset"] == pytest.approx(true["offset"]["offset"], rel=0.02)
    assert got["delay"]["delay"] == pytest.approx(true["delay"]["delay"], rel=0.1)


def _found(d, name):
    return next((c for c in d.causes if c.name == name), None)


def test_ten_sample_delay_is_estimated_with_its_instrument():
    """A 2.0 ms delay at 5 kHz (reporting5 d0306): the delay's regressor is made of the measured
    drive, which feedback fills with the sensor's noise. Prewhitened least squares put it at
    7.4 ms, the validation data rejected that (gain -164 %) and nothing was reported; with the
    noise-free loop's regressor as instrument it is found first, within 5 %."""
    fit, val, model, truth = _dataset("reporting5", 306)
    d = diagnose(fit, model, val, behaviour=False)
    true = truth["effects"][0]["params"]["delay"]
    assert d.causes and d.causes[0].name == "delay", [c.name for c in d.causes]
    assert d.causes[0].parameters["delay"] == pytest.approx(true, rel=0.05)


def test_reversal_reports_the_extension_own_bristle_stiffness():
    """LuGre presliding after reversals (reporting5 d0477, sigma0 = 2.07e5 N/m, damping ratio
    0.35): with the build-up's scale free, a scale 0.33 at 2.7 times the damping fitted as well
    and sigma0 came out 63 % low; the extension builds up the whole level, and refined with the
    scale held at 1 its sigma0 is within 5 %, the scale re-estimated there near 1. Refined on the
    loop together with the damping (kept: the validation record's position error is no worse) it
    is 7 % high, within 10 %, and within two of its stated uncertainties."""
    fit, val, model, truth = _dataset("reporting5", 477)
    d = diagnose(fit, model, val, behaviour=False)
    c = _found(d, "reversal")
    assert c is not None, [x.name for x in d.causes]
    true = truth["effects"][0]["params"]["sigma0"]
    loop = c.gain["refined_on_loop"]
    assert loop["force_channel_values"]["sigma0"] == pytest.approx(true, rel=0.05)
    assert loop["refined"] <= loop["force_channel"]
    assert c.parameters["sigma0"] == pytest.approx(true, rel=0.1)
    assert abs(c.parameters["sigma0"] - true) <= 2 * c.sigma["sigma0"]
    assert 0.7 < c.parameters["scale"] < 1.3


def test_stiff_bristles_without_creep_are_found_by_the_loop():
    """LuGre bristles (reporting13 d0449, sigma0 = 1.22e5 N/m: friction builds up over 17 um)
    on a loop whose rests show no creep beyond the sensor's counts: the force channel's samples
    leave out the turns and stops where the bristles act, and the start code reported nothing.
    Re-simulated with bristles fitted on the fitting record's position, the loop follows both
    records by more than LOOP_GAIN better: presliding, sigma0 within 5 %."""
    from hunting.diagnose.causes import presliding
    fit, val, model, truth = _dataset("reporting13", 449)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["presliding"], [(c.name, c.parameters) for c in d.causes]
    c = d.causes[0]
    assert c.parameters["sigma0"] == pytest.approx(truth["effects"][0]["params"]["sigma0"], rel=0.05)
    assert c.p_value is None and "re-simulated with LuGre bristles" in c.gain["evidence"]
    assert 1 - c.gain["extended"] / c.gain["nominal"] >= presliding.LOOP_GAIN
    from hunting.diagnose.report import finding
    assert "no creep shows at rest" in finding(d, c)      # not "the mass creeps where the model holds it still"


def test_bristles_the_loop_confirms_out_of_sample_below_the_fitting_bar_are_named():
    """reporting20 d0505 (LuGre bristles, sigma0 = 3.9e5 N/m, no creep at rest): fitted on the
    fitting record's loop they cut its position error by 58 % and the validation record's by 49 %,
    out of sample. The validation bar was LOOP_GAIN and nothing was named; it is
    LOOP_VALIDATION_GAIN now (clean development records whose fitting cut passed reached -1.6 %
    at most), and presliding is named. The bars judge the admission's fit (its cuts, read here
    from :func:`~hunting.diagnose.causes.presliding.loop_evidence`); the reported gain is the
    refined bristles' (sigma0 and zeta refined together), whose validation cut is larger."""
    from hunting.diagnose.causes.presliding import LOOP_GAIN, LOOP_VALIDATION_GAIN, loop_evidence
    fit, val, model, truth = _dataset("reporting20", 505)
    assert [e["cause"] for e in truth["effects"]] == ["reversal"]
    evidence = loop_evidence(fit, val, model)
    assert "reason" not in evidence, evidence.get("reason")
    cut_fit, cut_val = (1 - after / before for before, after in (evidence["fit"], evidence["val"]))
    assert cut_fit >= LOOP_GAIN and LOOP_VALIDATION_GAIN <= cut_val < LOOP_GAIN
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["presliding"], [(c.name, c.parameters) for c in d.causes]
    c = d.causes[0]
    assert f"at least {LOOP_GAIN:.0%} and {LOOP_VALIDATION_GAIN:.0%} needed" in c.gain["evidence"]
    assert 1 - c.gain["extended"] / c.gain["nominal"] >= cut_val


def test_loop_evidence_below_its_bar_reports_nothing():
    """A clean record (reporting14 d0100) whose loop LuGre bristles follow 37 % better on the
    fitting record: below LOOP_GAIN, rejected with both the creep test's and the loop's reason."""
    fit, val, model, truth = _dataset("reporting14", 100)
    assert truth["causes"] == []
    d = diagnose(fit, model, val, behaviour=False)
    assert d.causes == []
    row = next(r for r in d.rejected if r["name"] == "presliding")
    assert row["step"] == "loop" and "50% needed" in row["reason"] and "; and LuGre bristles cut" in row["reason"]


def test_loop_evidence_fits_the_bristle_damping_ratio():
    """reporting26 d0323 (LuGre, sigma0 7.24e5 N/m at damping ratio 0.98; no creep shows at rest):
    at the old fixed ratio 0.5 the loop's best sigma0 came out 3.2 times low and made the
    validation record's position error 41 % worse. Fitted at ratios 0.5 and 1, ratio 1 is kept,
    sigma0 and sigma1 come out within 10 %, the validation error falls by more than LOOP_VALIDATION_GAIN,
    and sigma0 comes with a standard uncertainty."""
    from hunting.diagnose.causes import presliding
    fit, val, model, truth = _dataset("reporting26", 323)
    true = truth["effects"][0]["params"]
    v = presliding.loop_evidence(fit, val, model)
    assert "reason" not in v, v["reason"]
    assert v["hyper"] == {"zeta": 1.0}
    p = presliding.parameters(v["theta"], v["hyper"], model)
    assert p["sigma0"] == pytest.approx(true["sigma0"], rel=0.1)
    assert p["sigma1"] == pytest.approx(true["sigma1"], rel=0.1)
    assert 1 - v["val"][1] / v["val"][0] > presliding.LOOP_VALIDATION_GAIN
    assert v["sigma_lg"] is not None and v["sigma_lg"] > 0
    held = presliding.fit_behaviour(fit, model, None, max_evals=presliding.LOOP_EVALS, step=presliding.LOOP_STEP,
                                    hyper={"zeta": 0.5})[0]
    assert 1.0 / held[0] < 0.5 * true["sigma0"]         # the ratio held at 0.5 reads sigma0 far too low


@pytest.mark.parametrize("family, index", [("reporting5", 491), ("reporting7", 519)])
def test_presliding_stiffness_is_fitted_on_the_creep(family, index):
    """Creep where the model sticks (reporting5 d0491, sigma0 = 6.5e5 N/m; reporting7 d0519,
    4.9e6 N/m): fitted on the whole record's position error the stiffness came out 15 % high on
    d0491 (the sliding phases' timing dominates); fitted on the stick segments' creep it is
    within 5 %."""
    fit, val, model, truth = _dataset(family, index)
    d = diagnose(fit, model, val, behaviour=False)
    c = _found(d, "presliding")
    assert c is not None, [x.name for x in d.causes]
    assert c.parameters["sigma0"] == pytest.approx(truth["effects"][0]["params"]["sigma0"], rel=0.05)


def test_creep_error_removes_each_segment_mean():
    """The creep error compares shapes: an offset per segment costs nothing, a slope does."""
    from hunting.diagnose.causes.presliding import creep_error
    q = np.zeros(100)
    sim = q.copy()
    sim[10:30] += 1e-3                      # segment 1 shifted: no creep error
    sim[50:70] += np.linspace(0, 2e-6, 20)  # segment 2 creeps by 2 um
    segs = [(10, 29), (50, 69)]
    ramp = np.linspace(0, 2e-6, 20)
    expect = np.sqrt(np.sum((ramp - ramp.mean()) ** 2) / 40)
    assert creep_error(sim, q, segs) == pytest.approx(expect, rel=1e-12)
    assert creep_error(sim[:5], q, segs) == float("inf")


@pytest.mark.parametrize("controller, m, cm, b", [
    ({"type": "pid", "kp": 1707.7, "kd": 114.6, "ki": 8149.4}, 12.35, 4.79, 49.3),           # reporting6 d0425
    ({"type": "pid", "kp": 33.76, "kd": 1.656, "ki": 307.9, "tau_f": 0.00313}, 0.691, 26.2, 17.7),  # d0018
    ({"type": "pd-velocity-loop", "kp": 40.0, "kv": 3.0}, 12.35, 4.79, 2.0)])
def test_delay_margin_agrees_with_python_control(controller, m, cm, b):
    """The nominal loop's delay margin (phase margin over crossover) against python-control's
    stability_margins on the same continuous loop, within 0.5 %; a fitted delay beyond it is not
    physical (reporting6 d0425: a 71 ms 'delay' on a one-way record whose loop has a 29 ms
    margin) and one below it is."""
    import control
    from hunting.diagnose.causes import delay
    from hunting.diagnose.loop import delay_margin
    model = NominalModel.from_dict({"plant": {"mass": m, "motor_constant": cm},
                                    "friction": {"law": "coulomb-viscous", "Fc": 15.0, "b": b},
                                    "controller": controller})
    s = control.tf("s")
    if controller["type"] == "pid":
        C = controller["kp"] + controller["ki"] / s + controller["kd"] * s / (controller.get("tau_f", 0.0) * s + 1)
    else:
        C = controller["kv"] * (controller["kp"] + s)
    _, pm, _, _, wgc, _ = control.stability_margins(C * cm / (m * s ** 2 + b * s))
    want = np.radians(pm) / wgc
    got = delay_margin(model)
    assert got == pytest.approx(want, rel=5e-3)
    assert "delay margin" in delay.unphysical([1.2 * want], {}, model)
    assert delay.unphysical([0.8 * want], {}, model) is None


@pytest.mark.parametrize("family, index, bristles", [("reporting6", 216, False), ("reporting6", 251, False),
                                                     ("reporting6", 337, True), ("tuning", 160, True)])
def test_presliding_needs_creep_that_follows_the_force(family, index, bristles):
    """Clean records whose mass slides slowly or slips where the nominal model sticks (reporting6
    d0216, d0251: presliding was reported) move against the force changes; LuGre records
    (reporting6 d0337, tuning d0160) creep with them, the quasi-static regressor explaining
    more than 99 % of the motion."""
    from hunting.diagnose.causes import presliding
    from hunting.diagnose.select import default_window
    fit, val, model, truth = _dataset(family, index)
    assert ("reversal" in truth["causes"]) == bristles
    kin = kinematics(fit, model.cm, window=default_window(fit, val, model), resolution=model.resolution,
                     noise=model.sensor_noise)
    segs = presliding.segments(kin, model)
    why = presliding.not_following(kin, model, segs)
    assert (why is None) == bristles, why


def test_an_offset_on_a_one_way_record_is_said_to_be_a_level_too():
    """reporting6 d0369: a Coulomb level 30 % low (-1.58 N) on a record that moves one way only,
    reported as an offset of -1.57 N; the level cause cannot be tested there. The report says
    the offset is the same force as a level 1.57 N lower in that direction; moving the other
    way, the same offset is a level that much higher. Nothing is said without the untested level."""
    from types import SimpleNamespace
    from hunting.diagnose.select import Cause, one_way_offset
    model = NominalModel.from_dict({"plant": {"mass": 1.0}, "friction": {"Fc": 5.37, "b": 1.0}})
    off = Cause("offset", 0.5, 10.0, 1e-9, {"offset": -1.57}, {"offset": 0.01}, {})
    why = [{"name": "level", "reason": "the record moves one way only (0% of the sliding samples the other way): ..."}]
    kin = SimpleNamespace(v=np.full(100, 0.02), moving=np.ones(100, bool))
    note, = one_way_offset([off], why, model, kin)
    assert "(positive)" in note and "1.57 N lower" in note
    kin.v = -kin.v
    assert "1.57 N higher" in one_way_offset([off], why, model, kin)[0]
    assert one_way_offset([off], [], model, kin) == []


def test_force_channel_needs_three_windows_of_sliding():
    """tuning-clean d0108: the validation record slides for 0.6 smoothing windows (29 ms of used
    samples over a 48 ms window), and a 'viscous' was judged there and reported on clean data.
    The force channel is skipped with the reason, naming both numbers."""
    fit, val, model, truth = _dataset("tuning-clean", 108)
    assert truth["causes"] == []
    d = diagnose(fit, model, val, behaviour=False)
    assert d.causes == []
    note = next(n for n in d.notes if n.startswith("force channel skipped"))
    assert "span 0.6 filter windows (0.0483 s)" in note and "fewer than 3" in note


def test_lugre_nominal_with_a_dip_gives_no_mass():
    """reporting6 d0151: a clean record of a LuGre contact (sigma0 1.7e7 N/m, sigma1 / sigma0
    1.6 ms) on a Stribeck curve. The bristles' lag makes the sliding force differ from the static
    curve by about sigma1 g'(|v|) a / sigma0, an inertia-like force; with the static curve in the
    balance it was reported as a mass change of -2.9 % (p = 2e-7). With the bristles integrated
    along the measured velocity nothing is reported."""
    fit, val, model, truth = _dataset("reporting6", 151)
    assert truth["causes"] == [] and model.law == "lugre"
    d = diagnose(fit, model, val, behaviour=False)
    assert d.causes == [], [(c.name, c.parameters) for c in d.causes]


def test_offset_on_a_one_way_fitting_record_is_found():
    """reporting8 d0314: an offset of -1.37 N (97 % of the validation residual) on a fitting
    record that moves one way only. There offset, level and Stribeck are one signature; the whole
    library fitted on it predicted the two-way validation record worse than nothing, and a noise
    model of that residual made every test insignificant (offset p = 1). The nominal validation
    residual is the noise picture instead, and the offset is found."""
    fit, val, model, truth = _dataset("reporting8", 314)
    assert truth["causes"] == ["offset"]
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["offset"]
    assert d.causes[0].parameters["offset"] == pytest.approx(truth["effects"][0]["params"]["offset"], rel=0.02)


def test_direction_dependent_stribeck_dip_comes_alone():
    """reporting8 d0401: a Stribeck dip added to a Coulomb-viscous model, its velocity 0.0116 m/s
    moving positive and 0.0300 m/s moving negative. With one velocity for both directions the
    misfit went to an invented offset and asymmetry; with one per direction (refined apart, and
    the members the refinement leaves idle dropped) the dip comes alone, both velocities within
    2 % and Fs within 1 % of the truth."""
    fit, val, model, truth = _dataset("reporting8", 401)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["stribeck"], [(c.name, c.parameters) for c in d.causes]
    p, pos, neg = d.causes[0].parameters, truth["true"]["plant"]["pos"], truth["true"]["plant"]["neg"]
    assert p["vs"] == pytest.approx(pos["vs"], rel=0.02) and p["vs_neg"] == pytest.approx(neg["vs"], rel=0.02)
    assert p["Fs"] == pytest.approx(pos["Fs"], rel=0.01)


def test_a_set_the_validation_data_prefer_replaces_the_bic_choice():
    """reporting8 d0501: a mass change (0.02 kg) on a fitting record of gentle accelerations: alone
    it has BIC +5 there and removes 72 % of the validation residual; the BIC-best {delay,
    flexibility} removes 26 % and held its tests. The rival set, whose cause holds on the validation
    data too, replaces it."""
    fit, val, model, truth = _dataset("reporting8", 501)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["mass"], [(c.name, c.parameters) for c in d.causes]
    assert d.causes[0].parameters["mass"] == pytest.approx(truth["effects"][0]["params"]["mass"], rel=0.02)


def test_reversal_bristles_carry_the_rest_force():
    """reporting8 d0477 without noise: LuGre bristles (sigma0 2.94e5 N/m) on a record with long
    rests. Integrated through a rest, the bristle deflection kept the motion's before it, while
    the data's relaxed with the holding force: the build-up after each rest came out twice the
    data's, and sigma0 35 % high at a damping ratio of 2. With the rests' force carried by the
    bristles sigma0 is within 3 % and the damping ratio within 10 % of the truth (0.83)."""
    import math
    fit, val, model, truth = _dataset("reporting8", 477, noise=False)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["reversal"], [(c.name, c.parameters) for c in d.causes]
    p, e = d.causes[0].parameters, truth["effects"][0]["params"]
    assert p["sigma0"] == pytest.approx(e["sigma0"], rel=0.03)
    assert p["zeta"] == pytest.approx(e["sigma1"] / (2 * math.sqrt(e["sigma0"] * model.mass)), rel=0.1)


def test_instrument_loop_saturates_where_the_data_do():
    """reporting9 d0568: a frictional memory (lag 0.33 of the force residual) beside a saturation
    the model lacks. The instrument trajectory re-simulated the nominal loop without it, did not
    follow the saturated record, and the lag failed its instrument check (p = 0.92). With the
    measured saturation in the instrument's loop both are found."""
    fit, val, model, truth = _dataset("reporting9", 568)
    assert sorted(truth["causes"]) == ["lag", "saturation"]
    d = diagnose(fit, model, val, behaviour=False)
    assert sorted(c.name for c in d.causes) == ["lag", "saturation"], [(c.name, c.parameters) for c in d.causes]


# reporting9 d0344: a cogging of pitch 0.646 mm over a 36 mm stroke (56 periods). The pitch from
# the binned spectrum was 0.5 % short, the phase drifted by a third of a period over the stroke,
# and the cogging's validation gain fell under 5 %; refined on the cause's own filtered design the
# pitch is within 0.2 %. reporting10 d0428: a pitch of 0.703 mm over a fitting stroke of 1.39 mm
# (two periods less 1 %), beyond the longest wavelength searched then (half the stroke): the three
# candidates were 0.07-0.40 mm and nothing held out of sample; searched to the stroke over 1.5,
# with the longest wavelength a candidate where the spectrum falls from it, within 0.1 %.
# reporting22 d0330: a 0.767 mm pitch over an 84 mm stroke (109 periods); the spectrum's peaks were
# 0.746 and 0.790 mm, the sidebands of a cogging the filter passes where the motion is slow, and
# nothing held out of sample; their midpoint, refined on the filtered design, is within 0.1 %.
# reporting70 d0512 (0.94 mm over 44 periods) and d0442 (0.72 mm with its second and third
# harmonics): the diagnosis' window, half a period of the loop's bandwidth (82 and 77 ms), passes
# the cogging only where the motion is slow, and its spectrum put the candidates 2.3 % and 1.8 %
# off; nothing was named on d0512 and a Stribeck change on d0442. The spectrum read through 31
# samples has both pitches within 0.1 %.
@pytest.mark.parametrize("family, index, pitch_rel", [("reporting9", 344, 2e-3), ("reporting10", 428, 1e-3),
                                                     ("reporting22", 330, 1e-3), ("reporting70", 512, 1e-3),
                                                     ("reporting70", 442, 1e-3)],
                         ids=["many-periods", "two-periods", "sidebands", "long-window", "long-window-harmonics"])
def test_cogging_pitch_is_found(family, index, pitch_rel):
    fit, val, model, truth = _dataset(family, index)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["cogging"], [(c.name, c.parameters) for c in d.causes]
    p, e = d.causes[0].parameters, truth["effects"][0]["params"]
    assert p["pitch"] == pytest.approx(e["pitch"], rel=pitch_rel)
    assert p["amplitude_1"] == pytest.approx(e["amplitude_1"], rel=0.05)


def test_cogging_ripple_below_the_relevance_floor_is_no_cause():
    """cogging.unidentified on a model of Coulomb level 2 N (floor 0.3 %: 6 mN): a new ripple of
    5 mN RMS is no cause, one of 8 mN is; a change of a cogging the model has at that pitch is
    not judged by the floor (moving the model's harmonics is part of it)."""
    from hunting.diagnose import NominalModel
    from hunting.diagnose.causes import cogging
    from hunting.models.plant import Cogging
    model = NominalModel.from_dict({"plant": {"mass": 1.0}, "friction": {"law": "coulomb-viscous", "Fc": 2.0}})
    ripple = lambda r: [r, 0.0, 0.0, 0.0, 0.0, 0.0]  # noqa: E731  (a first harmonic of RMS r/sqrt(2))
    assert "below 0.3%" in cogging.unidentified({"pitch": 1e-3}, {}, model=model, theta=ripple(5e-3 * 2 ** 0.5))
    assert cogging.unidentified({"pitch": 1e-3}, {}, model=model, theta=ripple(8e-3 * 2 ** 0.5)) is None
    known = model.replace(cogging=(Cogging.harmonic(1.0e-3, [0.5], [0.0]),))
    assert cogging.unidentified({"pitch": 1.01e-3}, {}, model=known, theta=ripple(1e-4)) is None
    # three harmonics, their RMS taken numerically over a period, scaled to 1 % either side of the floor
    theta = np.array([0.3, -0.2, 0.15, 0.1, -0.05, 0.12])
    q = np.linspace(0.0, 1e-3, 20001)[:-1]
    rms = float(np.sqrt(np.mean((cogging._harmonics(q, 1e-3) @ theta) ** 2)))
    assert "below" in cogging.unidentified({"pitch": 1e-3}, {}, model=model, theta=theta * 0.99 * 6e-3 / rms)
    assert cogging.unidentified({"pitch": 1e-3}, {}, model=model, theta=theta * 1.01 * 6e-3 / rms) is None


def test_cogging_variant_whose_harmonics_repeat_sooner_is_not_its_pitch():
    """cogging.unphysical: harmonics that all sit at multiples of 3 (or 2) of a variant's
    fundamental make a ripple of a third (half) of its pitch; a fundamental holding 5 % of the
    power (above SUBPERIOD_SHARE) keeps the variant."""
    from hunting.diagnose import NominalModel
    from hunting.diagnose.causes import cogging
    model = NominalModel.from_dict({"plant": {"mass": 1.0}, "friction": {"law": "coulomb-viscous", "Fc": 2.0}})
    third = [0.01, 0.0, 0.0, 0.0, 1.0, 0.5]
    assert "pitch / 3" in cogging.unphysical(third, {"pitch": 3e-3}, model)
    assert "pitch / 2" in cogging.unphysical([0.0, 0.01, 0.8, 0.0, 0.0, 0.0], {"pitch": 2e-3}, model)
    assert cogging.unphysical([0.25, 0.0, 0.0, 0.0, 1.0, 0.0], {"pitch": 3e-3}, model) is None
    assert cogging.unphysical([1.0, 0.0, 0.3, 0.0, 0.2, 0.0], {"pitch": 1e-3}, model) is None


def test_cogging_beside_a_delay_at_its_own_pitch():
    """reporting70 d0545: a 2.778 mm cogging (19 N) beside a 1.46 ms delay. Read through the short
    window the candidates were 1.89, 2.766 and 8.311 mm, and the last, three times the pitch, fitted
    the cogging as its third harmonic better than the second did as its first: named at 8.31 mm,
    its first amplitude 99 % low. Such a variant is not a cogging of its pitch: the cogging is
    named at its own pitch (within 0.2 %) beside the delay."""
    _cogging_named_beside(*_dataset("reporting70", 545), "delay", pitch_rel=2e-3)


def _cogging_named_beside(fit, val, model, truth, other: str, pitch_rel: float):
    """The diagnosis names the true cogging and ``other``, the pitch within ``pitch_rel`` and the
    first amplitude within 5 %."""
    e = next(x for x in truth["effects"] if x["cause"] == "cogging")["params"]
    d = diagnose(fit, model, val, behaviour=False)
    assert sorted(c.name for c in d.causes) == sorted(["cogging", other]), [(c.name, c.parameters) for c in d.causes]
    p = next(c for c in d.causes if c.name == "cogging").parameters
    assert p["pitch"] == pytest.approx(e["pitch"], rel=pitch_rel)
    assert p["amplitude_1"] == pytest.approx(e["amplitude_1"], rel=0.05)


def test_clean_record_names_no_ripple_below_the_floor():
    """reporting70 d0214, clean: the pitch search read through 31 samples found a 4.1 mm ripple of
    3.6 mN RMS (0.13 % of the 2.75 N Coulomb level) that passed its test (p = 3e-4, validation
    gain 8 %). Below the relevance floor it is no cause: nothing is named, and its row says why."""
    fit, val, model, truth = _dataset("reporting70", 214)
    assert not truth["effects"]
    d = diagnose(fit, model, val, behaviour=False)
    assert d.causes == [], [(c.name, c.parameters) for c in d.causes]
    assert any(r["name"] == "cogging" and "ripple" in r["reason"] for r in d.rejected), d.rejected


def test_cogging_pitch_beside_a_friction_curve_change():
    """reporting66 d0546: a 5.56 mm cogging (1.86 N) beside a Stribeck change (Fs 16.9 -> 19.8 N),
    the validation record's stroke 11 periods from the fitting record's. Searched on the nominal
    residual alone, the Stribeck change leaked into the harmonics and the best pitch was the
    refinement's -1 % edge: the cogging predicted the validation record 6 % worse and only the
    Stribeck change was named. Fitted beside the friction curve's error terms, the pitch candidate
    is within 0.3 %, and both causes are named, the pitch within 0.1 % and the amplitude 5 %."""
    from hunting.diagnose import parts
    from hunting.diagnose.causes import cogging
    from hunting.diagnose.kinematics import kinematics
    fit, val, model, truth = _dataset("reporting66", 546)
    e = next(x for x in truth["effects"] if x["cause"] == "cogging")["params"]
    kf = kinematics(fit, model.cm, window=parts.default_window(fit, val, model), **parts.sensor_settings(model))
    pitches = [h["pitch"] for h in cogging.hypers(kf, model)]
    assert min(abs(p / e["pitch"] - 1) for p in pitches) < 3e-3, pitches
    _cogging_named_beside(fit, val, model, truth, "stribeck", pitch_rel=1e-3)


def test_validation_only_search_keeps_a_found_pitch():
    """reporting67 d0600: a 2.54 mm cogging (0.41 N) beside a small lag, found on the 10.3 mm
    fitting stroke at 2.56 mm. The validation record's blocks (3.3 mm, 1.3 periods of it), on
    which the validation-only search refits the found causes, have pitch candidates only at 2.31
    mm and shorter; with the longest-wavelength candidate screened (1.16 mm and shorter) the
    cogging failed there and a level asymmetry was named in its place. Refitted at the pitch it was
    found at, the cogging is named, pitch within 1.5 % and amplitude within 5 %."""
    fit, val, model, truth = _dataset("reporting67", 600)
    e = next(x for x in truth["effects"] if x["cause"] == "cogging")["params"]
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes][:1] == ["cogging"], [(c.name, c.parameters) for c in d.causes]
    assert "level_asymmetry" not in [c.name for c in d.causes]
    p = d.causes[0].parameters
    assert p["pitch"] == pytest.approx(e["pitch"], rel=0.015)
    assert p["amplitude_1"] == pytest.approx(e["amplitude_1"], rel=0.05)


def test_a_cause_displaced_by_a_partner_comes_back_in_its_place():
    """reporting67 d0513: the Stribeck velocity 7.9 mm/s for the model's 5.7, the fitting record
    sliding up to 1.3 mm/s (where the change is a small viscous-like slope), the validation record
    to 6.5. On the validation record's blocks the best set held the Stribeck change beside a
    viscous one; beside it the Stribeck change's drop-one gain was -29 % and it was dropped for
    good, and the viscous change (b 57 -> 98 N s/m) was named, although alone the Stribeck change
    fits the blocks better (BIC -9) and predicts the others as well (84 % against 82 %). A cause
    displaced only by a partner may come back as a rival in its place (force.displaced): the
    Stribeck change is named, its static level within 2 %, and no viscous change."""
    fit, val, model, truth = _dataset("reporting67", 513)
    e = truth["effects"][0]["params"]
    d = diagnose(fit, model, val, behaviour=False)
    names = [c.name for c in d.causes]
    assert names[:1] == ["stribeck"], [(c.name, c.parameters) for c in d.causes]
    assert "viscous" not in names
    assert d.causes[0].parameters["Fs"] == pytest.approx(e["Fs"], rel=0.02)


def test_a_mass_change_only_the_validation_record_accelerates_enough_to_show_is_found():
    """reporting65 d0501: the mass 12 % high, the fitting record creeping at 2.6 mm/s^2 RMS, the
    validation record accelerating at 0.11 m/s^2. On the fitting record the change's BIC was +4.7
    and nothing was judged; it removes 87 % of the validation residual. As a cause only the
    validation record can show (mass.unseen: its acceleration more than 3 times the fitting
    record's) it is searched on that record's blocks: named, within 3 %."""
    fit, val, model, truth = _dataset("reporting65", 501)
    e = truth["effects"][0]["params"]
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["mass"], [(c.name, c.parameters) for c in d.causes]
    assert d.causes[0].parameters["mass"] == pytest.approx(e["mass"], rel=0.03)


def test_a_small_mass_change_only_the_validation_blocks_show_is_not_named():
    """reporting67 d0291, clean: the validation record accelerates 6.8 times harder than the
    fitting record, and its blocks read the mass 2.3 % high at 4.6 standard uncertainties, which
    removed 38 % of their residual. A change that small is the estimation's own on such a record
    (mass.MIN_CHANGE_SHARE): nothing is named, and the mass row says why."""
    fit, val, model, truth = _dataset("reporting67", 291)
    assert not truth["effects"]
    d = diagnose(fit, model, val, behaviour=False)
    assert d.causes == [], [(c.name, c.parameters) for c in d.causes]
    assert any(r["name"] == "mass" and "estimation's own error" in r["reason"] for r in d.rejected), d.rejected


def test_mass_unresolved_needs_a_change_beyond_its_uncertainty_and_the_floor():
    """mass.unresolved on a 1 kg model: 5 % at 2.5 sigma is resolved; 5 % at 1.5 sigma is not
    (the uncertainty); 2 % at 20 sigma is not (the floor); a missing sigma is not."""
    from types import SimpleNamespace
    from hunting.diagnose.causes import mass
    model = SimpleNamespace(mass=1.0)
    found = lambda m, s: SimpleNamespace(parameters={"mass": m}, sigma={} if s is None else {"mass": s})  # noqa: E731
    assert mass.unresolved(found(1.05, 0.02), model) is None
    assert "uncertainty" in mass.unresolved(found(0.95, 0.0334), model)
    assert "estimation's own error" in mass.unresolved(found(1.02, 0.001), model)
    assert mass.unresolved(found(1.05, None), model) is not None


def test_curve_terms_remove_a_friction_curve_error_and_keep_a_periodic_force():
    """cogging._without_curve on a known residual: a level, a viscous and a Stribeck error per
    direction (of widths other than the basis's) leave less than 2 % of their RMS; a periodic force
    in position keeps more than 90 % of its RMS (the basis does not absorb what the pitch search
    looks for)."""
    from types import SimpleNamespace
    from hunting.diagnose.causes import cogging
    t = np.linspace(0.0, 20.0, 20001)
    v = 0.05 * np.sin(2 * np.pi * 0.3 * t) + 0.004 * np.sin(2 * np.pi * 2.1 * t)
    q = np.cumsum(v) * (t[1] - t[0])
    kin = SimpleNamespace(vf=v, q=q, slide=np.abs(v) > 1e-3, moving=np.abs(v) > 1e-3)
    kin.sliding = lambda x: np.where(kin.slide[:, None] if np.ndim(x) == 2 else kin.slide, x, 0.0)
    curve = np.where(v > 0, 0.4 + 3.0 * v + 0.8 * np.exp(-(v / 0.007) ** 2),
                     -0.2 + 5.0 * v - 0.5 * np.exp(-(v / 0.012) ** 2)) * kin.slide
    periodic = 0.3 * np.sin(2 * np.pi * q / 0.0021) * kin.slide
    m = kin.moving
    rms = lambda x: float(np.sqrt(np.mean(x[m] ** 2)))
    assert rms(cogging._without_curve(kin, curve)) < 0.02 * rms(curve)
    assert rms(cogging._without_curve(kin, periodic)) > 0.9 * rms(periodic)


def test_a_resonance_above_the_loop_bandwidth_is_found():
    """reporting22 d0321: a 1.9 kg load at 14.8 Hz (damping ratio 0.13) behind a loop of 5 Hz
    bandwidth. The nominal residual's spectrum has no clear peak there (the load's lag shows as a
    broad rise); with the masked acceleration as the candidates' regressor its strongest peak
    gave one candidate, 18.1 Hz at damping 0.45, and flexibility lost to delay, lag and mass, all
    three reported. With :func:`design_acceleration` (the design's own regressor) a candidate lies
    within 20 % of the resonance, and the diagnosis names flexibility alone at its frequency."""
    from dataclasses import replace as dc_replace

    from hunting.diagnose.causes import flexibility
    from hunting.diagnose.select import default_window
    fit, val, model, truth = _dataset("reporting22", 321)
    true = truth["effects"][0]["params"]
    from hunting.diagnose.parts import sensor_settings
    kin = kinematics(fit, model.cm, window=default_window(fit, val, model), **sensor_settings(model))
    kin = dc_replace(kin, moving=used_samples(kin, model))
    near = [h for h in flexibility.hypers(kin, model) if abs(np.log(h["frequency"] / true["frequency"])) < np.log(1.2)
            and abs(np.log(h["damping"] / true["damping"])) < np.log(2.0)]
    assert near
    d = diagnose(fit, model, val, behaviour=False, causes=["flexibility", "delay", "lag", "mass"])
    assert [c.name for c in d.causes] == ["flexibility"], [(c.name, c.parameters) for c in d.causes]
    assert d.causes[0].parameters["frequency"] == pytest.approx(true["frequency"], rel=0.05)


def test_the_peak_grid_steps_within_a_light_resonances_bandwidth():
    """flexibility._peak_factors: the grid spans PEAK_SPAN about a spectral peak in steps of at
    most the damping ratio (half the half-power bandwidth 2 zeta f), so a resonance at damping
    0.025 has a grid point within 1.3 % of its frequency wherever its peak lies; at least three
    points at heavy damping."""
    from hunting.diagnose.causes import flexibility

    lo, hi = flexibility.PEAK_SPAN
    for zeta in (0.01, 0.025, 0.05, 0.1, 0.2, 0.4, 1.0):
        s = flexibility._peak_factors(zeta)
        assert s[0] == pytest.approx(lo) and s[-1] == pytest.approx(hi)
        assert s.size >= 3
        assert np.max(np.diff(s)) <= zeta + 1e-12
    s = flexibility._peak_factors(0.025)
    for x in np.linspace(lo, hi, 101):
        assert np.min(np.abs(s - x)) <= 0.0125 + 1e-12


def test_the_band_scan_keeps_the_best_grid_point_of_each_damping_ratio():
    """flexibility._scan on a criterion with its minimum at 14.8 Hz and damping 0.1, inf (no
    positive load mass) below 5 Hz: per damping ratio of DAMPING the grid frequency nearest the
    minimum, none from the excluded part; no scan where the band spans less than 1.2 times."""
    from hunting.diagnose.causes import flexibility

    def ss(z):
        f, zeta = np.exp(z[0]), np.exp(z[1])
        return np.inf if f < 5.0 else np.log(f / 14.8) ** 2 + np.log(zeta / 0.1) ** 2
    out = flexibility._scan(ss, 2.0, 100.0)
    assert len(out) == len(flexibility.DAMPING)
    assert sorted(np.exp(z[1]) for z in out) == pytest.approx(sorted(flexibility.DAMPING))
    step = 2.0 ** (1.0 / flexibility.SCAN_PER_OCTAVE)
    assert all(abs(np.log(np.exp(z[0]) / 14.8)) <= np.log(step) / 2 + 1e-9 for z in out)
    assert flexibility._scan(lambda z: np.inf, 2.0, 100.0) == []
    assert flexibility._scan(ss, 10.0, 11.0) == []


def test_a_fitting_record_that_hardly_slides_gives_way_to_the_validation_record():
    """reporting9 d0398: the fitting record creeps at 0.3 mm/s and, read as the free mass reads
    it, has no usable sample; the validation record's sine and move hold an offset of 79 % of its
    residual. The validation record split 60/40 in time gives two parts the force channel can use
    (the diagnosis now reads the creep as slides first: the previous test)."""
    from hunting.diagnose.parts import informative, sensor_settings, split_validation
    fit, val, model, truth = _dataset("reporting9", 398)
    kf, kv = _used_kinematics(fit, val, model)
    assert not informative(kf) and informative(kv)
    parts = split_validation(val, model, sensor_settings(model), None)
    assert parts is not None
    first, last, _, kfirst, klast = parts
    assert first.n + last.n == val.n and first.t[-1] < last.t[0]
    assert informative(kfirst) and informative(klast)


def test_a_validation_record_that_ends_at_rest_is_split_into_alternate_blocks():
    """reporting40 d0444: a viscous change of 27 % (validation gain 0.48 when modelled) behind a
    fitting record that never slides (0 usable samples) and a validation record whose last 40 %
    is rests and a slow sine (the 60/40 split in time leaves it too few): the force channel was
    skipped and nothing was reported. Fitted on alternate blocks of the validation record and
    judged on the others, the viscous change is named alone, b within 2 %; the report says how it
    was judged and holds no force residual on the fitting record. A clean record on the same path
    (reporting39 d0026) reports nothing."""
    fit, val, model, truth = _dataset("reporting40", 444)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["viscous"], ([(c.name, c.parameters) for c in d.causes], d.notes)
    assert d.causes[0].parameters["b"] == pytest.approx(truth["effects"][0]["params"]["b"], rel=0.02)
    assert any("alternate blocks of 8 filter windows of the validation data" in n for n in d.notes), d.notes
    assert np.all(np.isnan(d.r_fit_nominal))
    fit, val, model, truth = _dataset("reporting39", 26)
    assert not truth["effects"]
    d = diagnose(fit, model, val, behaviour=False)
    assert d.causes == [] and any("alternate blocks" in n for n in d.notes), ([c.name for c in d.causes], d.notes)


def test_stribeck_velocity_between_grid_points_is_found():
    """reporting9 d0443: the Stribeck velocity changed from 5.7 to 3.1 mm/s in both directions,
    below the slowest used speed (9.8 mm/s). The best grid point (9.8 and 4.9 mm/s) left 15 times
    the residual of the truth on the fitting data, and a level change was named. Moved off the
    grid by Nelder-Mead before the search, the dip is named alone, vs within 5 %."""
    fit, val, model, truth = _dataset("reporting9", 443)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["stribeck"], [(c.name, c.parameters) for c in d.causes]
    p, e = d.causes[0].parameters, truth["effects"][0]["params"]
    assert p["vs"] == pytest.approx(e["vs"], rel=0.05) and p["vs_neg"] == pytest.approx(e["vs"], rel=0.05)
    assert p["Fs"] == pytest.approx(e["Fs"], rel=0.02)


def test_stick_slip_below_the_count_is_not_judged_by_the_force_channel():
    """reporting9 d0482: an offset of 3.10 N on a validation record whose used samples were 78 %
    stick-slip below the encoder's count (a slow move on a falling Stribeck branch), judged by
    their excess over the stick set: the offset, fitted within 0.1 %, removed 16 % of the
    validation residual there and failed its test, and `viscous` was named. On sliding samples
    alone the offset is named, within 1 %."""
    fit, val, model, truth = _dataset("reporting9", 482)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["offset"], [(c.name, c.parameters) for c in d.causes]
    assert d.causes[0].parameters["offset"] == pytest.approx(truth["effects"][0]["params"]["offset"], rel=0.01)


def test_a_cause_only_the_validation_record_shows_is_searched_there():
    """reporting10 d0313: the Coulomb level 8 % low in both directions; the fitting record slides
    one way only, where a common level is a constant force and ``level`` is untestable, and
    nothing was reported. Searched on alternate blocks of the two-way validation record, the level
    is named within 1 %, and the report says where it was fitted."""
    fit, val, model, truth = _dataset("reporting10", 313)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["level"], [(c.name, c.parameters) for c in d.causes]
    assert d.causes[0].parameters["Fc"] == pytest.approx(truth["effects"][0]["params"]["Fc"], rel=0.01)
    assert any("cannot show" in n and "alternate blocks" in n for n in d.notes), d.notes
    assert d.extended_model.curve.positive.Fc == pytest.approx(d.causes[0].parameters["Fc"], rel=1e-9)
    # the summary's force residual is the whole extended model's, with the level in it
    assert d.extended < 0.3 * d.nominal, (d.nominal, d.extended)


def test_a_cause_fitted_on_the_validation_record_holds_beside_the_causes_found_before():
    """reporting10 d0370: an offset of 0.089 N, fitted 7 % high on a fitting record that slides
    one way. On the validation record, with that offset held, a viscous asymmetry (3.4 and 5.7
    N s/m for a true 4.4 both ways) took up the difference and passed; with the offset refitted
    beside it, it does not hold and only the offset is named."""
    fit, val, model, truth = _dataset("reporting10", 370)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["offset"], [(c.name, c.parameters) for c in d.causes]
    assert any(r["name"] == "asymmetry" and "alternate blocks" in r["reason"] for r in d.rejected), d.rejected


def test_causes_found_beside_a_validation_only_cause_are_refitted_with_it():
    """reporting33 d0413: a Coulomb asymmetry (an offset of 8.11 N while sliding) with a viscous
    one (b+ 709.5, b- 268.3 for a nominal 488.9 N s/m); the fitting record slides one way only.
    There the offset took up the viscous change times the speed (11.3 N, 39 % high) and the
    asymmetry, fitted on top of it on the validation record's blocks, came out 561 / 431 N s/m.
    Fitted together on those blocks: every value within 2 % of the truth, and the extended
    model holds the values reported."""
    fit, val, model, truth = _dataset("reporting33", 413)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["offset", "asymmetry"], [(c.name, c.parameters) for c in d.causes]
    true = truth["effects"][0]["params"]
    got = {k: v for c in d.causes for k, v in c.parameters.items()}
    for key in ("offset", "b_pos", "b_neg"):
        assert got[key] == pytest.approx(true[key], rel=0.02), (key, got[key], true[key])
    ext = d.extended_model
    assert ext.offset == pytest.approx(got["offset"], rel=1e-9)
    assert (ext.curve.positive.b, ext.curve.negative.b) == pytest.approx((got["b_pos"], got["b_neg"]), rel=1e-9)
    # every value comes with an uncertainty that covers the truth
    for c in d.causes:
        for key, s in c.sigma.items():
            assert s > 0 and abs(c.parameters[key] - true[key]) < 3 * s, (key, c.parameters[key], s, true[key])
    assert d.extended < 0.5 * d.nominal, (d.nominal, d.extended)


def test_a_cause_the_fitting_record_saw_in_place_of_a_validation_only_cause_is_not_reported():
    """reporting34 d0427: a viscous asymmetry alone (b+ 11.29, b- 9.68 N s/m for a nominal 10.48)
    behind a fitting record that slides one way, where b+ times a nearly constant speed is an
    offset: 0.21 N was found there and the asymmetry fitted on top of it on the validation
    record's blocks (10.8 and 10.1 N s/m). Searched together on the blocks, which show both
    directions, the offset does not hold: the asymmetry alone is named, within 1 %, and the offset
    is rejected with the reason."""
    fit, val, model, truth = _dataset("reporting34", 427)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["asymmetry"], [(c.name, c.parameters) for c in d.causes]
    true = truth["effects"][0]["params"]
    for key in ("b_pos", "b_neg"):
        assert d.causes[0].parameters[key] == pytest.approx(true[key], rel=0.01), key
    assert d.extended_model.offset == model.offset
    assert any(r["name"] == "offset" and "saw asymmetry's effect" in r["reason"] for r in d.rejected), d.rejected


def test_a_general_cause_the_blocks_choose_replaces_its_special_case_found_on_a_one_way_record():
    """reporting41 d0371: a viscous asymmetry (b+ 371.3, b- 176.2 N s/m for a nominal 273.8)
    behind a fitting record that slides 91 % one way and a validation record whose judging blocks
    slide 93 % one way. The fitting record read it as an offset, a level and a viscous change,
    and the asymmetry chosen alone on the validation record's blocks clashed with the viscous
    change (asymmetry generalises it). Replacing it, judged with the found causes from the
    nominal model: the asymmetry alone, b+ and b- within 2 %, and the three rejected with the
    reason."""
    fit, val, model, truth = _dataset("reporting41", 371)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["asymmetry"], [(c.name, c.parameters) for c in d.causes]
    true = truth["effects"][0]["params"]
    for key in ("b_pos", "b_neg"):
        assert d.causes[0].parameters[key] == pytest.approx(true[key], rel=0.02), key
    ext = d.extended_model
    assert (ext.curve.positive.b, ext.curve.negative.b) == pytest.approx(
        (d.causes[0].parameters["b_pos"], d.causes[0].parameters["b_neg"]), rel=1e-9)
    assert ext.offset == model.offset and ext.curve.positive.Fc == model.curve.positive.Fc
    for name in ("offset", "level", "viscous"):
        assert any(r["name"] == name and "saw asymmetry's effect" in r["reason"] for r in d.rejected), name


def test_a_stribeck_velocity_above_the_fitting_records_speeds_is_searched_on_the_validation_record():
    """reporting41 d0331: vs 7.32 mm/s for a nominal 2.70 (Fc 0.419, Fs 0.692 N unchanged), the
    fitting record sliding one way up to 4.3 mm/s (90th percentile), the validation record's sine
    up to 22 mm/s. Fitted on the fitting record the change predicted the validation record 37 %
    worse than the nominal and nothing was named for a change of 94 % of its residual; searched on
    the validation record's alternate blocks, Fc, Fs and vs are within 1 %."""
    fit, val, model, truth = _dataset("reporting41", 331)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["stribeck"], ([(c.name, c.parameters) for c in d.causes], d.rejected)
    true, got = truth["effects"][0]["params"], d.causes[0].parameters
    for key in ("Fc", "Fs", "vs"):
        assert got[key] == pytest.approx(true[key], rel=0.01), (key, got[key], true[key])
    assert any("a Stribeck velocity above" in n and "alternate blocks" in n for n in d.notes), d.notes
    assert d.extended_model.curve.positive.vs == pytest.approx(got["vs"], rel=1e-9)


def test_a_set_that_predicts_the_validation_data_worse_than_nothing_gives_way_to_its_best_subset():
    """reporting41 d0363: a resonance (12.94 Hz, damping 0.030, 1.26 kg behind the whole) behind a
    fitting record sliding 82 % one way, where an offset and a level are fitted against each
    other: the fitting data's best set {offset, level, flexibility} predicts the validation data
    at 3.33 N RMS against the nominal 0.470, and the resonance, judged beside that misprediction,
    failed first and nothing was named. The set's largest subset that predicts better replaces it
    first: the resonance alone, frequency and load mass within 1 %."""
    fit, val, model, truth = _dataset("reporting41", 363)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["flexibility"], ([(c.name, c.parameters) for c in d.causes], d.rejected)
    true, got = truth["effects"][0]["params"], d.causes[0].parameters
    assert got["frequency"] == pytest.approx(true["frequency"], rel=0.01)
    assert got["load_mass"] == pytest.approx(true["load_mass"], rel=0.02)
    assert d.extended < 0.5 * d.nominal, (d.nominal, d.extended)
    assert any("predicts the validation data worse than the nominal model" in r["reason"] for r in d.rejected
               if r["name"] in ("offset", "level")), d.rejected


def test_a_resonance_above_the_fitting_records_band_is_searched_on_the_validation_record():
    """reporting34 d0349 (8.31 Hz, damping 0.095, 0.21 kg behind 2.1 kg): the fitting record's
    acceleration is the encoder's noise above 6.6 Hz, the validation record's only above 50 Hz.
    No candidate on the fitting record, nothing reported before; searched on the validation
    record's alternate blocks (their band the whole record's) and judged on the others, the
    resonance is named, its frequency within 1 %."""
    fit, val, model, truth = _dataset("reporting34", 349)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["flexibility"], ([(c.name, c.parameters) for c in d.causes], d.rejected)
    true, got = truth["effects"][0]["params"], d.causes[0].parameters
    assert got["frequency"] == pytest.approx(true["frequency"], rel=0.01)
    assert got["damping"] == pytest.approx(true["damping"], rel=0.1)
    assert got["load_mass"] == pytest.approx(true["load_mass"], rel=0.02)
    assert any("a resonance above" in n and "alternate blocks" in n for n in d.notes), d.notes
    assert d.extended_model.flexibility.frequency == pytest.approx(got["frequency"], rel=1e-9)
    assert not any(r["name"] == "flexibility" for r in d.rejected), d.rejected


def test_a_band_within_the_estimates_spread_is_no_reason_for_a_search_but_the_motions_excitation_is():
    """reporting34 d0321 (34.9 Hz): fitting band 21.3 Hz, validation band 37.5 Hz, a factor 1.76,
    inside the band estimate's spread over noise seeds of one machine (2.05): not a band the
    fitting record lacks. The validation record's motion excites the resonance and the fitting
    record's hardly does (the best candidate, 34.7 Hz, explains 92 and 19 % of their force
    residuals): that is the reason the validation-only search runs for flexibility there."""
    from hunting.diagnose.causes import flexibility
    fit, val, model, _ = _dataset("reporting34", 321)
    kf, kv = _used_kinematics(fit, val, model)
    hf, hv = flexibility.band(kf)[1], flexibility.band(kv)[1]
    assert 1.5 < hv / hf < flexibility.UNSEEN_FACTOR, (hf, hv)
    why = flexibility.unseen(kf, kv, model)
    assert why is not None and why.startswith("a resonance the fitting record's motion does not excite: at 34."), why


def test_the_blocks_choose_again_without_a_cause_the_fitting_record_could_show():
    """reporting64 d0495 (Fc and Fs 28 % low on a Coulomb-viscous model; a fitting record 92 % one
    way, which cannot show a level): on the validation record's blocks the first choice held a
    Stribeck dip whose velocity, 2.5 mm/s, lies in the fitting record's speeds (``seen``), and the
    level, which alone cut the blocks' residual by 94 %, lost to it and was never judged alone:
    nothing was named. Chosen again without the dip, the level is named, Fc within 0.1 %."""
    fit, val, model, truth = _dataset("reporting64", 495)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["level"], ([(c.name, c.parameters) for c in d.causes], d.rejected)
    true = truth["effects"][0]["params"]
    assert d.causes[0].parameters["Fc"] == pytest.approx(true["Fc"], rel=1e-3)
    row = next(r for r in d.rejected if r["name"] == "stribeck")
    assert "lies in the fitting record's speeds" in row["reason"], row


def test_a_cause_the_fitting_records_loop_barely_shows_is_confirmed_by_the_validation_records():
    """reporting62 d0307 (a 24.7 Hz load of 0.76 kg, damping 0.027): fitted on the force residual
    (24.4 Hz, 0.70 kg, damping 0.040) it fails only the out-of-sample significance (p = 0.004). On
    the loop at those values the validation record's position error falls by 85 %, the fitting
    record's, whose motion barely excites the load, by 10 %: with both bars at LOOP_GAIN it was not
    named; the fitting record's error need only not grow (CONFIRMATION_FITTING_BAR). LuGre bristles
    keep both bars (the stick channel fits them on the loop)."""
    from hunting.diagnose import select
    fit, val, model, truth = _dataset("reporting62", 307)
    row = dict(name="flexibility", theta=np.array([0.7025]), hyper={"frequency": 24.417, "damping": 0.0395},
               reason="not significant out of sample (p = 0.0041 >= 0.001)", significance_only=True)
    strict = select._confirmed_on_loop([row], [row], model, fit, val, "on the force residual")
    assert strict[1] is None and "(50% on both needed)" in strict[0][0]["reason"], strict[0]
    rejected, cause, ext = select._confirmed_on_loop([row], [row], model, fit, val, "on the force residual",
                                                     fitting_bar=select.CONFIRMATION_FITTING_BAR)
    assert cause is not None and cause.name == "flexibility" and rejected == [], rejected
    assert cause.parameters["load_mass"] == pytest.approx(truth["effects"][0]["params"]["load_mass"], rel=0.1)
    assert "the fitting record no worse" in cause.gain["evidence"], cause.gain
    assert ext.flexibility.frequency == pytest.approx(24.417)


def test_a_resonance_at_the_top_of_the_fitting_records_band_is_the_validation_records_to_show():
    """reporting61 d0433 (26.0 Hz, damping 0.057): the fitting record's band ends at 25.6 Hz, the
    validation record's at 31.7 Hz (a factor 1.24, no band the fitting record lacks). The fitting
    record's candidates stop at EDGE of its band's top, so none was formed there although the
    resonance explains 89 % of its force residual; the validation record's best candidate, 25.9 Hz,
    lies at that top: the fitting record cannot fit it, the validation record's blocks can. The
    start code named nothing; with the rule the diagnosis names the resonance at 25.8 Hz."""
    from hunting.diagnose.causes import flexibility
    fit, val, model, truth = _dataset("reporting61", 433)
    kf, kv = _used_kinematics(fit, val, model)
    hf, hv = flexibility.band(kf)[1], flexibility.band(kv)[1]
    assert hv / hf < flexibility.UNSEEN_FACTOR and flexibility.hypers(kf, model) == [], (hf, hv)
    why = flexibility.unseen(kf, kv, model)
    assert why is not None and why.startswith("a resonance at the top of the fitting record's band: "), why
    # the rule's reach is the band's top: a candidate further above it is the band factor's to judge
    assert flexibility.EDGE * hf < truth["effects"][0]["params"]["frequency"] <= hf / flexibility.EDGE


def test_a_resonance_the_fitting_records_motion_does_not_excite_is_searched_on_the_validation_record():
    """reporting53 d0503 (25.6 Hz, damping 0.022, 1.74 kg): both records' bands reach 50 Hz, but
    the fitting record's motion hardly excites the resonance (the true one gains 0.6 % there, 55 %
    on the validation record). Its best candidate explains 79 % of the validation record's force
    residual and 1 % of the fitting record's, so it is searched on the validation record's
    alternate blocks: named alone (a delay before), frequency within 2 %, load mass within 15 %;
    and the fitting record's small share there is no sign that it could show it (``seen``)."""
    from hunting.diagnose.causes import flexibility
    fit, val, model, truth = _dataset("reporting53", 503)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["flexibility"], ([(c.name, c.parameters) for c in d.causes], d.rejected)
    true, got = truth["effects"][0]["params"], d.causes[0].parameters
    assert got["frequency"] == pytest.approx(true["frequency"], rel=0.02)
    assert got["load_mass"] == pytest.approx(true["load_mass"], rel=0.15)
    assert any("does not excite" in n and "alternate blocks" in n for n in d.notes), d.notes
    kf = kinematics(fit, model.cm, resolution=model.resolution)
    hyper = {"frequency": true["frequency"], "damping": true["damping"]}
    assert flexibility.residual_share(kf, model, hyper) < flexibility.SEEN_SHARE
    assert flexibility.seen(hyper, kf, model) is None


def test_seen_rejects_a_resonance_the_fitting_record_shows_in_its_band():
    """reporting52 d0433 (16.1 Hz, found on the fitting record): there the true resonance lies in
    the fitting record's band and explains nearly all of its force residual, so one found on the
    validation record alone there would be the fitting record's to show (``seen`` gives the
    reason); above that band it would not be."""
    from hunting.diagnose.causes import flexibility
    fit, _, model, truth = _dataset("reporting52", 433)
    kf = kinematics(fit, model.cm, resolution=model.resolution)
    true = truth["effects"][0]["params"]
    hyper = {"frequency": true["frequency"], "damping": true["damping"]}
    share = flexibility.residual_share(kf, model, hyper)
    assert share > 0.9
    # the same share from an independent least-squares fit of the residual about its mean on the
    # regressor (a load mass alone, no constant)
    from hunting.diagnose.kinematics import residual
    from hunting.diagnose.model import highpass_response
    r = residual(kf, model)
    m = kf.moving & np.isfinite(r)
    y = r[m] - r[m].mean()
    x = -highpass_response(kf.filtered(kf.a_inst), kf.dt, hyper["frequency"], hyper["damping"])[m]
    coef, *_ = np.linalg.lstsq(x[:, None], y, rcond=None)
    assert coef[0] > 0 and share == pytest.approx(1.0 - np.sum((y - x * coef[0]) ** 2) / np.sum(y ** 2), rel=1e-9)
    # and near the share of the force channel's own regressor (the slide mask after the filter):
    # on moving samples with no stick within H_a's reach the two regressors are one (linear,
    # time-invariant filters commute), here to rounding
    xd = flexibility.design(kf, model, hyper)[m, 0]
    assert np.max(np.abs(x - xd)) <= 1e-6 * np.max(np.abs(xd))
    coef, *_ = np.linalg.lstsq(xd[:, None], y, rcond=None)
    assert share == pytest.approx(1.0 - np.sum((y - xd * coef[0]) ** 2) / np.sum(y ** 2), rel=0.02)
    assert flexibility.residual_shares(kf, model, [hyper, hyper]) == pytest.approx([share, share], rel=1e-12)
    why = flexibility.seen(hyper, kf, model)
    assert why is not None and "lies in the fitting record's band" in why, why
    above = dict(hyper, frequency=1.1 * flexibility.band(kf)[1])
    assert flexibility.seen(above, kf, model) is None


def test_a_resonance_the_fitting_record_could_show_is_not_named_from_the_validation_record(monkeypatch):
    """The same search (reporting34 d0349) where the fitting record's band would hold the resonance
    found (``seen`` says so): that record showed none there, so the resonance is rejected with
    that reason (in its one row) and nothing is named."""
    from hunting.diagnose.causes import flexibility
    monkeypatch.setattr(flexibility, "seen", lambda hyper, kf, model, parameters: "inside the fitting record's band (test)")
    fit, val, model, _ = _dataset("reporting34", 349)
    d = diagnose(fit, model, val, behaviour=False)
    assert d.causes == [], [(c.name, c.parameters) for c in d.causes]
    # one row: the fitting record's own verdict, where it has one, then the validation record's
    rows = [r for r in d.rejected if r["name"] == "flexibility"]
    assert len(rows) == 1 and "inside the fitting record's band (test)" in rows[0]["reason"], rows
    assert d.extended_model.flexibility is None


def test_a_resonance_the_fitting_record_cannot_test_at_all_is_not_held_to_its_band():
    """reporting35 d0321 (26.5 Hz, 0.33 kg): the fitting record has fewer than 512 sliding
    samples, so flexibility is untestable there although its band reaches 200 Hz; the band check
    (``seen``) is for a record that could test the resonance, and the validation record's
    resonance is named (it was lost to that check in a first version of it)."""
    fit, val, model, truth = _dataset("reporting35", 321)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["flexibility"], ([(c.name, c.parameters) for c in d.causes], d.rejected)
    true = truth["effects"][0]["params"]
    assert d.causes[0].parameters["frequency"] == pytest.approx(true["frequency"], rel=0.01)
    assert d.causes[0].parameters["load_mass"] == pytest.approx(true["load_mass"], rel=0.1)


def test_a_resonance_rejected_on_both_searches_has_one_row_with_both_reasons():
    """reporting35 d0391 (85.4 Hz, beyond what the motion excites: a validation gain of 0): the
    fitting record's band (43.5 Hz) and the validation record's (200 Hz) each reject it; the
    report has one row for it saying both."""
    fit, val, model, _ = _dataset("reporting35", 391)
    d = diagnose(fit, model, val, behaviour=False)
    assert "flexibility" not in [c.name for c in d.causes]
    rows = [r for r in d.rejected if r["name"] == "flexibility"]
    assert len(rows) == 1, rows
    assert "; and where only the validation record can show it: " in rows[0]["reason"], rows[0]


def test_a_pitch_longer_than_the_fitting_stroke_is_searched_on_the_validation_record():
    """reporting36 d0588: an offset (-1.10 N) beside a cogging of 1.97 mm pitch (1.46 N); the
    fitting record moves 0.36 mm, a fifth of a period, the validation record 17 mm. Only the
    offset was named (0.88 N, 20 % low: the fitting record carried part of the ripple in it). The
    pitches the fitting stroke cannot show are searched on the validation record's alternate
    blocks and judged on the others: both are named, each value within 2 %; and a pitch the
    fitting stroke could show (``seen``) is not named from the validation record."""
    fit, val, model, truth = _dataset("reporting36", 588)
    d = diagnose(fit, model, val, behaviour=False)
    assert sorted(c.name for c in d.causes) == ["cogging", "offset"], ([(c.name, c.parameters) for c in d.causes],
                                                                      d.rejected)
    got = {k: v for c in d.causes for k, v in c.parameters.items()}
    for e in truth["effects"]:
        for key in ("offset", "pitch", "amplitude_1"):
            if key in e["params"]:
                assert got[key] == pytest.approx(e["params"][key], rel=0.02), (key, got[key], e["params"][key])
    assert any("cogging: a pitch longer than" in n for n in d.notes), d.notes
    assert d.extended_model.offset == pytest.approx(got["offset"], rel=1e-9)
    assert [c.period for c in d.extended_model.cogging] == pytest.approx([got["pitch"]], rel=1e-9)


def test_a_pitch_the_fitting_stroke_shows_is_not_named_from_the_validation_record(monkeypatch):
    """cogging.seen on its own: a pitch within the fitting stroke over MIN_PERIODS is one that
    record could show (reason), a longer one is not (None); and the search of reporting36 d0588
    with every pitch declared seen names the offset alone, the cogging rejected with that reason."""
    from types import SimpleNamespace
    from hunting.diagnose.causes import cogging
    kin = SimpleNamespace(q=np.linspace(0.0, 3e-3, 200), moving=np.ones(200, dtype=bool))
    assert cogging.stroke(kin) == pytest.approx(3e-3)
    assert cogging.seen({"pitch": 1.9e-3}, kin, None) is not None
    assert cogging.seen({"pitch": 2.1e-3}, kin, None) is None
    monkeypatch.setattr(cogging, "seen", lambda hyper, kf, model, parameters: "a pitch the fitting stroke shows (test)")
    fit, val, model, _ = _dataset("reporting36", 588)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["offset"], [(c.name, c.parameters) for c in d.causes]
    assert any(r["name"] == "cogging" and "a pitch the fitting stroke shows (test)" in r["reason"]
               for r in d.rejected), d.rejected


def test_dwell_with_few_fitting_rests_is_judged_over_both_records():
    """reporting10 d0436: a dwell growth of 0.047 N (time 37 ms) with 4 rests ending in motion in
    the fitting record (5 needed to fit three parameters) and 9 in the validation record: left
    untested before. Judged over the 13 rests (the growth test pooled; the gain predicted on all 13,
    each by the others or by the growth fitted on the fitting record's loop), it is named, gain
    within 25 %."""
    fit, val, model, truth = _dataset("reporting10", 436)
    d = diagnose(fit, model, val, causes=["dwell"], behaviour=False)
    assert [c.name for c in d.causes] == ["dwell"], (d.rejected, d.untested)
    assert "13 rests of both records" in d.causes[0].gain["metric"]
    assert d.causes[0].parameters["gain"] == pytest.approx(truth["effects"][0]["params"]["gain"], rel=0.25)


def test_dwell_with_few_validation_rests_is_judged_over_both_records():
    """reporting21 d0492: a dwell growth of 0.136 N (time 39 ms) with 6 rests ending in motion in
    the fitting record and 1 in the validation record (3 needed to judge on it alone): left
    untested before. Pooled like a short fitting record, the rests suggest a growth and the loop
    re-simulated with it follows both records better: named, gain within 10 %."""
    fit, val, model, truth = _dataset("reporting21", 492)
    d = diagnose(fit, model, val, causes=["dwell"], behaviour=False)
    assert [c.name for c in d.causes] == ["dwell"], (d.rejected, d.untested)
    assert d.causes[0].parameters["gain"] == pytest.approx(truth["effects"][0]["params"]["gain"], rel=0.10)


def test_dwell_growth_the_rests_resolve_out_of_sample_is_named_before_a_static_level():
    """reporting21 d0380: a dwell growth of 0.43 N (time 0.12 s) on a Coulomb-viscous nominal
    model, 6 rests of 0.15-0.65 s (3 per direction), all breaking away above Fs. The growth test
    cannot reach alpha on them and the excess was named a higher static level (stribeck). The
    growth fitted on the other rests predicts each rest's excess to under half the level's error:
    dwell is named, the static level listed as the same evidence's other reading. Its parameters
    come from the fitting record's loop, which follows that record better than the rests' fit
    (level 0.06 N, gain 0.35 N): gain and time within 5 % of the truth's."""
    fit, val, model, truth = _dataset("reporting21", 380)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["dwell"], [(c.name, c.parameters) for c in d.causes]
    c = d.causes[0]
    assert "the growth fitted on the others beside a level per direction predicts each rest's" in c.gain["evidence"]
    alt = next(a for a in d.alternatives if a["name"] == "stribeck")
    assert alt["kind"] == "same evidence" and alt["replaces"] == "dwell"
    assert "fitted on the fitting record's re-simulated loop" in c.gain["evidence"]
    p, true = c.parameters, truth["effects"][0]["params"]
    assert p["gain"] == pytest.approx(true["gain"], rel=0.05) and p["time"] == pytest.approx(true["time"], rel=0.05)


def test_dwell_the_growth_test_misses_is_named_on_the_loop():
    """reporting15 d0394: a dwell growth of 1.01 N (time 0.43 s) whose break-away readings rise
    with the rest too weakly for the growth test (p = 0.17; nothing was named). The growth fitted
    on the fitting record's re-simulated loop cuts both records' position error by more than
    LOOP_GAIN: named on that evidence (no p-value), its gain within 5 %."""
    from hunting.diagnose.causes.presliding import LOOP_GAIN
    fit, val, model, truth = _dataset("reporting15", 394)
    d = diagnose(fit, model, val, causes=["dwell"], behaviour=False)
    assert [c.name for c in d.causes] == ["dwell"], d.rejected
    c = d.causes[0]
    assert c.p_value is None and "the rests suggest a growth" in c.gain["evidence"]
    assert 1 - c.gain["extended"] / c.gain["nominal"] >= LOOP_GAIN
    assert c.parameters["gain"] == pytest.approx(truth["effects"][0]["params"]["gain"], rel=0.05)


def test_dwell_parameters_come_from_the_loop_where_it_follows_the_record_better():
    """reporting14 d0310: a dwell growth of 13.4 N (time 79 ms), found by the growth test. Fitted
    on the break-away readings its gain was 16 % off; fitted on the fitting record's re-simulated
    loop, which follows that record better, within 5 %, and the evidence says where it came from."""
    fit, val, model, truth = _dataset("reporting14", 310)
    d = diagnose(fit, model, val, causes=["dwell"], behaviour=False)
    assert [c.name for c in d.causes] == ["dwell"], d.rejected
    c = d.causes[0]
    assert c.p_value < 1e-3 and "fitted on the fitting record's re-simulated loop" in c.gain["evidence"]
    assert c.parameters["gain"] == pytest.approx(truth["effects"][0]["params"]["gain"], rel=0.05)
    assert d.extended_model.dwell.gain == pytest.approx(c.parameters["gain"])


def test_dwell_whose_break_away_readings_show_nothing_is_named_on_the_loop_unprompted():
    """reporting28 d0366: a 12.6 N dwell growth (time 0.105 s) over Fs = 17.5 N; three of the
    validation record's break-aways are read on force ramps of 20-29 N, and the growth test on
    the 11 rests gives p = 0.39, above the loop's gate: nothing was named. The growth fitted on the
    fitting record's loop anyway cuts both records' position errors by more than LOOP_GAIN: named
    on that evidence, its gain within 10 % and covered by two stated uncertainties. With the fine
    gain line at every time of the grid (the fortieth session) the fit reaches the valley at the
    growth's own time (0.094 s, 11 % short, 95 and 91 % of the two records' errors cut): the
    time states an uncertainty that covers the truth too. Before, from the grid's best time, the
    fit ended at 9 ms, which every rest outlasts (no uncertainty; gain 4.8 % low, 75 % cut on the
    validation record)."""
    from hunting.diagnose.causes.presliding import LOOP_GAIN
    fit, val, model, truth = _dataset("reporting28", 366)
    d = diagnose(fit, model, val, causes=["dwell"], behaviour=False)
    assert [c.name for c in d.causes] == ["dwell"], d.rejected
    c, true = d.causes[0], truth["effects"][0]["params"]
    assert c.p_value is None and "alone show no growth" in c.gain["evidence"]
    assert 1 - c.gain["extended"] / c.gain["nominal"] >= LOOP_GAIN
    assert c.parameters["gain"] == pytest.approx(true["gain"], rel=0.1)
    assert abs(c.parameters["gain"] - true["gain"]) <= 2 * c.sigma["gain"]
    assert c.parameters["time"] == pytest.approx(true["time"], rel=0.2)
    assert abs(c.parameters["time"] - true["time"]) <= 2 * c.sigma["time"]


def test_no_unprompted_dwell_beside_a_static_level_the_force_channel_moved():
    """reporting28 d0303: a Stribeck change (Fs 15.62 N); the force channel fits Fs = 15.26 +- 0.19
    N, and a 0.8 N growth complete within 24 ms, fitted on the loop unprompted (growth test p =
    0.66), cut both records' position errors by 57 and 65 %: it stands for the static level's
    error. Beside the friction-curve cause it is not named, and the rejection says why."""
    fit, val, model, truth = _dataset("reporting28", 303)
    assert truth["causes"] == ["stribeck"]
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["stribeck"], [(c.name, c.parameters) for c in d.causes]
    row = next(r for r in d.rejected if r["name"] == "dwell")
    assert "cannot be told from that level's error" in row["reason"]


def test_dwell_loop_verdict_without_static_friction_fails_instead_of_raising(monkeypatch):
    """A model with no static friction has no break-away to grow: the loop fits nothing (its model
    stays without a dwell), and the verdict is a failure with its reason, not an AttributeError."""
    from hunting.diagnose import resimulate
    from hunting.diagnose.causes import dwell_loop
    fit, val, model, _ = _dataset("reporting28", 366)
    from hunting.models.friction import DirectionalCurve, Viscous
    bare = model.replace(curve=DirectionalCurve(Viscous(5.0), Viscous(5.0)))
    monkeypatch.setattr(resimulate, "position_rms_error", lambda meas, m: 1e-5)
    v = dwell_loop.unprompted(fit, val, bare, np.array([0.1, 0.3]), "no growth read")
    assert v["significant"] is False and "no growth could be fitted" in v["evidence"]


def test_a_clean_record_whose_rests_hint_at_growth_gets_no_dwell_from_the_loop():
    """reporting13 d0261 (clean): the break-away readings rise with the rest at p = 0.007, not
    enough for the growth test; the growth fitted on the loop cuts the fitting record's position
    error by 7.5 %, below even the prompted bar (PROMPTED_FIT_GAIN, 20 %), and the rejection says
    so."""
    from hunting.diagnose.causes.dwell_loop import PROMPTED_FIT_GAIN
    fit, val, model, truth = _dataset("reporting13", 261)
    assert truth["causes"] == []
    d = diagnose(fit, model, val, causes=["dwell"], behaviour=False)
    assert d.causes == []
    row = next(r for r in d.rejected if r["name"] == "dwell")
    assert "fitted on the fitting record's loop the growth cuts" in row["reason"]
    assert f"({PROMPTED_FIT_GAIN:.0%} needed)" in row["reason"]


def test_asymmetry_judged_on_a_validation_record_that_moves_one_way():
    """reporting28 d0483: viscous coefficients 16.6 (b+) and 7.3 N s/m (b-) against a nominal
    11.9; the fitting record's sines slide both ways, the validation record is one positive move.
    Untestable there, the asymmetry went unnamed (the viscous change fitted on both ways is none).
    The validation record still judges the fitted b+: named, both within 2 %."""
    fit, val, model, truth = _dataset("reporting28", 483)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["asymmetry"], [(c.name, c.parameters) for c in d.causes]
    true = truth["effects"][0]["params"]
    for k in ("b_pos", "b_neg"):
        assert d.causes[0].parameters[k] == pytest.approx(true[k], rel=0.02)


def test_stribeck_at_the_nominal_velocity_above_most_fitting_speeds():
    """reporting10 d0359: the static level 7.45 -> 8.56 N at the nominal Stribeck velocity 0.060
    m/s, above the fitting record's 90th percentile speed (0.049 m/s; it reaches 0.22). The
    search's grid ended there, a level and a viscous change fitted better than any dip it held,
    and both were named. With the nominal velocity a candidate wherever the record slides past it,
    the dip is named alone, Fs within 1 %."""
    fit, val, model, truth = _dataset("reporting10", 359)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["stribeck"], [(c.name, c.parameters) for c in d.causes]
    assert d.causes[0].parameters["Fs"] == pytest.approx(truth["effects"][0]["params"]["Fs"], rel=0.01)


def test_stribeck_dip_fitted_on_a_one_way_record_is_taken_symmetric():
    """reporting10 d0485: the Stribeck velocity 0.66 -> 0.94 mm/s in both directions; the fitting
    record slides one way only. The other direction's velocity changed nothing in the fit, the tie
    between the searched ratios went to vs / 8, and the dip failed on the validation record's other
    direction (gain -58 %). Taken symmetric, it is named with vs within 2 % for both directions and
    no uncertainty quoted for the direction the fit never saw."""
    fit, val, model, truth = _dataset("reporting10", 485)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["stribeck"], [(c.name, c.parameters) for c in d.causes]
    p, e = d.causes[0].parameters, truth["effects"][0]["params"]
    assert p["vs"] == pytest.approx(e["vs"], rel=0.02) and p["vs_neg"] == p["vs"]
    assert d.causes[0].sigma["vs_neg"] is None and d.causes[0].sigma["vs"] > 0
    assert d.causes[0].gain["extended"] < 0.2 * d.causes[0].gain["nominal"]


def test_break_away_excess_after_every_rest_is_a_static_level_with_dwell_its_alternative():
    """reporting11 d0422: a dwell growth of 1.97 N complete in 0.14 s; the 4 rests (2 + 2, both
    directions) last 0.7-2.0 s and each breaks away about 1.9 N above Fs. Too few rests for the
    growth test, and a growth its null (a level per direction) could not see anyway. Without a
    growth the rests cannot tell a dwell effect from a higher static level: the level verdict (no
    p-value: its rule is said instead) names the static level (stribeck, Fs up by the truth's gain
    within 5 %) and lists the dwell reading, gain within 5 %, as the alternative of the same
    evidence."""
    from hunting.diagnose.report import format_terminal
    fit, val, model, truth = _dataset("reporting11", 422)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["stribeck"], [(c.name, c.parameters) for c in d.causes]
    c = d.causes[0]
    gain = truth["effects"][0]["params"]["gain"]
    assert c.p_value is None and "every one of the 4 rests" in c.gain["evidence"]
    assert c.parameters["Fs"] - model.curve.positive.Fs == pytest.approx(gain, rel=0.05)
    assert c.parameters["Fs"] == pytest.approx(d.extended_model.curve.positive.Fs, rel=1e-12)
    alt = next(a for a in d.alternatives if a["name"] == "dwell")
    assert alt["kind"] == "same evidence" and alt["replaces"] == "stribeck"
    assert alt["parameters"]["gain"] == pytest.approx(gain, rel=0.05)
    text = format_terminal(d)
    assert "evidence: every one of the 4 rests" in text and "dwell (the same evidence read in place of stribeck)" in text
    # the force channel's verdict on stribeck (sliding samples) is a note, not a rejection of the named cause
    assert all(r["name"] != "stribeck" for r in d.rejected)
    assert any(n.startswith("stribeck is named from the dwell cause's own evidence") for n in d.notes)


def test_break_away_excess_the_sliding_samples_contradict_as_a_static_level_is_dwell():
    """reporting24 d0352: a dwell growth of 6.15 N in 73 ms; the 14 rests last 0.13-2.6 s, each
    breaks away about 5.8 N above Fs, and no growth is resolved. The static-level reading (Fs
    raised at the model's own Stribeck velocity) makes the force residual on the sliding samples
    of both records 10 % larger: the sliding friction is the model's, so the excess is the
    break-away's alone and dwell is named (the start code named stribeck), its gain within 10 %
    of the truth, the static level its alternative of the same evidence."""
    from hunting.diagnose.causes.dwell import SLIDING_WORSE
    fit, val, model, truth = _dataset("reporting24", 352)
    assert truth["causes"] == ["dwell"] and model.curve.positive.Fs > model.curve.positive.Fc
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["dwell"], [(c.name, c.parameters) for c in d.causes]
    c = d.causes[0]
    assert c.parameters["gain"] == pytest.approx(truth["effects"][0]["params"]["gain"], rel=0.1)
    assert d.extended_model.dwell.gain == pytest.approx(c.parameters["gain"])
    worse = float(c.gain["evidence"].split("records grows by ")[1].split("%")[0]) / 100
    assert worse >= SLIDING_WORSE
    alt = next(a for a in d.alternatives if a["name"] == "stribeck")
    assert alt["kind"] == "same evidence" and alt["replaces"] == "dwell"


@pytest.mark.parametrize("index, contradicted", [(436, True), (401, False)])
def test_the_sliding_samples_judge_the_static_level_reading_of_a_break_away_excess(index, contradicted):
    """reporting24 d0436 (a dwell growth) and d0401 (a true Stribeck Fs change): every rest breaks
    away above Fs with no growth resolved, and both models' curves have a dip. Against the force
    residual on the sliding samples of both records (computed here independently of the rule's
    code): with Fs raised by the reading, d0436's grows by orders of magnitude and the static level
    is contradicted (dwell named, the static level its ``also``); d0401's falls by three quarters
    and the static level stays the reading named (``instead``)."""
    from hunting.diagnose.causes import dwell
    from hunting.diagnose.resimulate import resolution_of
    from hunting.diagnose.select import _can_simulate
    fit, val, model, truth = _dataset("reporting24", index)
    kf, kv = _used_kinematics(fit, val, model)
    v = dwell.judge(fit, val, kf, kv, model, _can_simulate(fit, val, model), resolution_of(fit.q))["otherwise"]
    static = (v["also"] if contradicted else v["instead"])["model"]
    r0 = np.concatenate([residual(k, model)[k.moving] for k in (kf, kv)])
    r1 = np.concatenate([residual(k, static)[k.moving] for k in (kf, kv)])
    worse = np.sqrt(np.mean(r1 ** 2) / np.mean(r0 ** 2)) - 1
    if contradicted:
        assert "instead" not in v and worse > 10 and "grows by" in v["evidence"]
    else:
        assert "also" not in v and worse < -0.5


def test_break_away_excess_where_a_stribeck_change_is_untested_names_the_static_level():
    """reporting9 d0317: a Stribeck change (a higher Fs) on a record with too few sliding samples
    for the force channel. Every break-away is higher: the static level is named from the rests
    (it was rejected, "stribeck would explain it as well", before break-away levels were read as
    a static level), Fs within 10 % of the truth."""
    fit, val, model, truth = _dataset("reporting9", 317)
    assert [e["cause"] for e in truth["effects"]] == ["stribeck"]
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["stribeck"], [(c.name, c.parameters) for c in d.causes]
    assert d.causes[0].parameters["Fs"] == pytest.approx(truth["effects"][0]["params"]["Fs"], rel=0.1)


def test_dwell_break_away_excess_beside_a_coulomb_level():
    """reporting10 d0584: a Coulomb level 6 % low and a dwell growth of 7.2 N complete in 35 ms;
    the rests last 0.5-1.75 s. The force channel names the level; a Stribeck change alone would
    also lower the residual, but the level (its family) already fits the curve's static force, so
    the break-away excess above it is named as dwell, gain within 5 % (only the level before)."""
    fit, val, model, truth = _dataset("reporting10", 584)
    d = diagnose(fit, model, val, behaviour=False)
    assert sorted(c.name for c in d.causes) == ["dwell", "level"], [(c.name, c.parameters) for c in d.causes]
    gain = next(e["params"]["gain"] for e in truth["effects"] if e["cause"] == "dwell")
    assert next(c for c in d.causes if c.name == "dwell").parameters["gain"] == pytest.approx(gain, rel=0.05)


def test_dwell_growth_not_below_the_coulomb_level_on_a_stribeck_change():
    """reporting12 d0429: a Stribeck change (Fs 0.78 N, Fc 0.45 N). The break-away readings rise
    with the rest (p < 1e-3), and a free growth fit put the level at -0.86 N and the gain at 4.4 N
    (5.6 times Fs): `dwell` was named first, before the Stribeck change. With the break-away held
    at or above the Coulomb level the growth fell; on this LuGre nominal model dwell is now not
    judged at all (its contact never rests), and only the Stribeck change is named."""
    fit, val, model, truth = _dataset("reporting12", 429)
    assert [e["cause"] for e in truth["effects"]] == ["stribeck"]
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["stribeck"], [(c.name, c.parameters) for c in d.causes]
    # its nominal model is LuGre, whose contact never rests: the growth is not judged at all since
    # the forty-sixth session (it had been rejected: the break-away falls with the rest)
    assert "never rests" in next(u for u in d.untested if u["name"] == "dwell")["reason"]


def test_shape_gain_is_the_validation_gain_of_the_best_non_negative_multiple():
    """The size-free gain of a noise-free loop's prediction: e = 2 y + n with n orthogonal to y
    gives rms(e) / rms(n) - 1 at any scale of y; a prediction that points away explains nothing."""
    from hunting.diagnose.force import _shape_gain
    rng = np.random.default_rng(3)
    y = rng.standard_normal(500)
    n = rng.standard_normal(500)
    n -= (n @ y) / (y @ y) * y
    e = 2.0 * y + n
    exact = np.sqrt(np.mean(e ** 2)) / np.sqrt(np.mean(n ** 2)) - 1
    assert _shape_gain(e, 0.1 * y) == pytest.approx(exact, rel=1e-12)
    assert _shape_gain(e, -y) == pytest.approx(0.0, abs=1e-15)
    assert _shape_gain(e, np.zeros(500)) == 0.0


@pytest.mark.parametrize("index, cause, words", [
    (241, "delay", ("along the noise-free loop its part explains 0.",
                    "its prediction along the reference trajectory does not explain the validation data")),
    (51, "lag", ("delay, lag together explain 0.0%",))])
def test_noise_fed_cause_must_explain_along_the_noise_free_loop(index, cause, words):
    """Clean records of reporting13, each with a noise-fed cause that passed every earlier test.
    d0241: a 5.1 ms delay, validation gain 29 % and p < 1e-40 on the measured regressor, which
    feedback fills with the actuator's noise; along the noise-free loops its shape explains 0.3 %,
    and its p_reference (0.006) passed by chance. Since the forty-first session (the resonance's
    candidates changed the set it is judged in) its p_reference is 0.016 and it fails there first:
    either is the noise-free loop's verdict. d0051: a delay and a lag fitted against each other,
    each explaining 30 % of the validation residual beside the other's measured part; together
    along the reference they explain nothing."""
    fit, val, model, truth = _dataset("reporting13", index)
    assert truth["effects"] == []
    d = diagnose(fit, model, val, behaviour=False)
    assert d.causes == [], [(c.name, c.parameters) for c in d.causes]
    reason = next(r for r in d.rejected if r["name"] == cause)["reason"]
    assert any(w in reason for w in words), reason


@pytest.mark.parametrize("family, index, name, key, rel", [("reporting14", 314, "offset", "offset", 0.1)])
def test_a_record_that_mostly_sticks_names_its_cause_by_the_loop(family, index, name, key, rel):
    """A record whose loop slides too little for the force balance (fewer than 100 usable samples
    under either reading of its slides: the force channel is skipped): reporting14 d0314, a
    constant force of -1.83 N. Each candidate's one parameter fitted on the fitting record's
    re-simulated loop: the true cause cuts both records' position error by more than LOOP_GAIN
    (the start code reported nothing), its parameter within ``rel``; the other candidates are
    rejected at the loop step. (reporting15 d0439, Fc and Fs 1.87 times the model's, was named
    this way until its slow slides were read as its loop holds them: see the next test.)"""
    from hunting.diagnose.causes.presliding import LOOP_GAIN
    fit, val, model, truth = _dataset(family, index)
    d = diagnose(fit, model, val, behaviour=False, causes=["offset", "level", "viscous", "mass", "delay", "lag"])
    assert [c.name for c in d.causes] == [name], [(c.name, c.parameters) for c in d.causes]
    c = d.causes[0]
    assert c.parameters[key] == pytest.approx(truth["effects"][0]["params"][key], rel=rel)
    assert c.p_value is None and "too few sliding samples" in c.gain["evidence"]
    assert 1 - c.gain["extended"] / c.gain["nominal"] >= LOOP_GAIN
    assert d.extended_model.to_dict() != model.to_dict()
    rows = [r for r in d.rejected if r.get("step") == "loop"]
    assert rows and all(r["reason"].startswith("fewer than 100 sliding samples") for r in rows)


def test_slow_slides_the_loop_holds_are_read_where_the_default_reading_leaves_too_few():
    """reporting15 d0439 (Fc and Fs 1.87 times the model's; its loop held slow slides on the
    falling branch, which the free mass's rule read as sticks: the force channel was skipped and
    the level named from the loop): read as its loop holds them, the force channel names the
    change itself (as a Stribeck change, which the benchmark accepts for a level), Fc within 3 %,
    at a p-value, and the report says how the slides were read. reporting9 d0398 (a fitting
    record creeping at 0.3 mm/s with no usable sample, an offset; the validation record's 60/40
    split found it within 5 %): the creep reads as slides, and the offset is named from the
    fitting record within 1 %."""
    for family, index, key, rel in (("reporting15", 439, "Fc", 0.03), ("reporting9", 398, "offset", 0.01)):
        fit, val, model, truth = _dataset(family, index)
        d = diagnose(fit, model, val, behaviour=False)
        assert len(d.causes) == 1 and d.causes[0].name in truth["effects"][0]["accept"], [
            (c.name, c.parameters) for c in d.causes]
        c = d.causes[0]
        assert c.parameters[key] == pytest.approx(truth["effects"][0]["params"][key], rel=rel)
        assert c.p_value is not None and c.p_value < 1e-3
        assert any(n.startswith("slow slides read as the model's loop holds them") for n in d.notes), d.notes


def test_a_clean_record_that_mostly_sticks_gets_nothing_from_the_loop():
    """reporting15 d0094 (clean, force channel skipped; on the development scan a level change
    fitted its fitting record's loop 71 % better and the validation record's 26 %): no candidate
    cuts both records' position error by LOOP_GAIN, nothing is named, and each rejection says
    why."""
    fit, val, model, truth = _dataset("reporting15", 94)
    assert truth["causes"] == []
    d = diagnose(fit, model, val, behaviour=False, causes=["offset", "level", "viscous", "mass", "delay", "lag"])
    assert d.causes == []
    rows = [r for r in d.rejected if r.get("step") == "loop"]
    assert {r["name"] for r in rows} >= {"offset", "level", "mass", "delay"}
    assert all("50% needed" in r["reason"] for r in rows)


def test_the_loop_channel_names_only_the_best_candidate_on_the_fitting_record(monkeypatch):
    """The loop channel's rule on given errors: the candidate that cuts the fitting record's
    position error most is named when it cuts both records' by LOOP_GAIN; others that pass are
    alternatives; when the best fails on the validation record, none behind it is named (that
    choice would be made by the validation gain)."""
    from hunting.diagnose import loop_channel, resimulate
    model = NominalModel.from_dict({"preset": "table9.1", "set": {"P": 20.0}})
    t = np.arange(100) * 1e-3
    fit, val = (Measurement(t, np.zeros(100), np.zeros(100), q_ref=np.zeros(100), name=n) for n in ("fit", "val"))
    fitted = {"offset": 0.3, "level": 0.1, "mass": 0.45, "delay": 0.9, "viscous": 1.0, "lag": 1.0}

    def changed(m):
        if m is model:
            return None
        return ("offset" if m.offset != model.offset else "mass" if m.mass != model.mass
                else "level" if m.curve != model.curve else "other")

    def run(validation):
        monkeypatch.setattr(loop_channel, "fit_one", lambda name, meas, m, span, grid=None: (0.5, fitted[name]))
        monkeypatch.setattr(resimulate, "position_rms_error",
                            lambda meas, m: 1.0 if changed(m) is None else validation[changed(m)])
        return loop_channel.judge(fit, val, model, list(fitted))
    # level fits best (90 % on the fitting record); offset and mass pass too
    v = run({"level": 0.2, "offset": 0.3, "mass": 0.4})
    assert v["cause"]["name"] == "level" and {r["name"] for r in v["alternatives"]} == {"offset", "mass"}
    # the best fails on the validation record: offset would pass behind it, and is not named
    v = run({"level": 0.8, "offset": 0.3, "mass": 0.4})
    assert v["cause"] is None and v["alternatives"] == []
    reasons = {r["name"]: r["reason"] for r in v["rejected"]}
    assert "level fitted the fitting record's loop better" in reasons["offset"]
    assert "cuts the validation record's position error by 20.0%" in reasons["level"]


@pytest.mark.parametrize("index, key, rel", [(513, "Fs", 0.01), (387, "vs", 0.05)])
def test_a_stribeck_change_on_a_record_too_slow_for_the_force_channel_is_judged_on_the_loop(index, key, rel):
    """reporting23 d0513 (the dip Fs - Fc 11 % lower) and d0387 (vs 3.9 times the nominal): loops that
    barely slide, whose force channel is skipped, and which the start code left unnamed or named
    presliding. The Stribeck curve's two loop forms (the static level at the nominal shape, the
    Stribeck velocity) fitted on the fitting record's loop: the true change is named, its
    parameter close to the truth, on the loop's evidence."""
    fit, val, model, truth = _dataset("reporting23", index)
    assert truth["causes"] == ["stribeck"] and truth["effects"][0]["variant"] == key
    d = diagnose(fit, model, val, causes=["stribeck", "level", "offset"], behaviour=False)
    assert [c.name for c in d.causes] == ["stribeck"], [(c.name, c.parameters) for c in d.causes]
    c = d.causes[0]
    assert c.hyper["evidence"] == "loop" and "too few sliding samples" in c.gain["evidence"]
    assert c.parameters[key] == pytest.approx(truth["effects"][0]["params"][key], rel=rel)
    assert d.extended_model.curve.positive.Fs == pytest.approx(c.parameters["Fs"])
    assert d.extended_model.curve.positive.vs == pytest.approx(c.parameters["vs"])
    # the loop fit's standard uncertainty (hunting.diagnose.loop_sigma) is stated and covers the truth
    assert c.sigma[key] is not None and c.sigma[key] > 0
    assert abs(c.parameters[key] - truth["effects"][0]["params"][key]) <= 2 * c.sigma[key]


def test_a_stribeck_change_that_follows_only_the_fitting_loop_is_not_named():
    """reporting21 d0288 (clean, the force channel skipped): a Stribeck change fitted on the
    fitting record's loop cuts its position error by 81 %, and makes the validation record's twice
    as large. The validation record holds the bar: nothing is named."""
    fit, val, model, truth = _dataset("reporting21", 288)
    assert truth["causes"] == []
    d = diagnose(fit, model, val, causes=["stribeck"], behaviour=False)
    assert d.causes == []
    (row,) = [r for r in d.rejected if r["name"] == "stribeck"]
    assert row["step"] == "loop" and "validation record's position error" in row["reason"]


def test_a_delay_the_reference_check_cannot_confirm_is_judged_on_the_loop():
    """reporting15 d0488, a transport delay of 4.2 ms: significant on the validation residual, but
    its prediction along the noise-free reference trajectory does not hold (the check against the
    loop's reaction to its own noise), and the start code reported nothing. Fitted on the fitting
    record's re-simulated loop it cuts both records' position error by more than LOOP_GAIN: named,
    the delay within 5 %, with the force channel's p-value and the loop's evidence."""
    from hunting.diagnose.causes.presliding import LOOP_GAIN
    fit, val, model, truth = _dataset("reporting15", 488)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["delay"], [(c.name, c.parameters) for c in d.causes]
    c = d.causes[0]
    assert c.parameters["delay"] == pytest.approx(truth["effects"][0]["params"]["delay"], rel=0.05)
    assert c.p_value < 1e-3 and "not along the reference trajectory" in c.gain["evidence"]
    assert 1 - c.gain["extended"] / c.gain["nominal"] >= LOOP_GAIN
    assert d.extended_model.delay == pytest.approx(c.parameters["delay"])
    assert abs(c.parameters["delay"] - truth["effects"][0]["params"]["delay"]) <= 2 * c.sigma["delay"]


def test_a_clean_cause_the_reference_check_rejects_stays_rejected_on_the_loop():
    """reporting15 d0008 (clean): a noise-fed cause that fails only along the reference
    trajectory; fitted on the loop it cuts the fitting record's position error by 18 %, less than
    LOOP_GAIN, and the rejection says so. (A flexibility of the band scan fails only there too;
    it has no one-parameter loop extension, so the loop does not judge it.)"""
    from hunting.diagnose.loop_channel import spans
    fit, val, model, truth = _dataset("reporting15", 8)
    assert truth["causes"] == []
    d = diagnose(fit, model, val, behaviour=False)
    assert d.causes == []
    rows = [r for r in d.rejected if r.get("reference_only") and r["name"] in spans(model, fit)]
    assert rows and all("; and on the loop: " in r["reason"] for r in rows)


def test_a_friction_force_change_below_the_relevance_floor_is_not_a_cause():
    """reporting20 d0086 (clean, 500 Hz, 3.5 s; Fc = 10.7 N, Fs = 17.0 N): the validation residual
    is 82 mN, 0.8 % of Fc, and a Stribeck change of 20 mN RMS (Fs 0.2 % higher) passed every test
    (p = 2.2e-5, validation gain 18 %). It moves the force by less than RELEVANCE of the Coulomb
    level: not a cause. Nothing is named, and the rejection says why."""
    from hunting.diagnose.force import RELEVANCE
    fit, val, model, truth = _dataset("reporting20", 86)
    assert truth["causes"] == []
    d = diagnose(fit, model, val, behaviour=False)
    assert d.causes == [], [(c.name, c.parameters) for c in d.causes]
    reasons = {r["name"]: r for r in d.rejected}
    floor = RELEVANCE * 0.5 * (model.curve.positive.Fc + model.curve.negative.Fc)
    assert f"is below {floor:.3g} N, {RELEVANCE:.1%} of the mean Coulomb level" in reasons["stribeck"]["reason"]
    # significant and large against the residual: only the floor rejected it
    row = reasons["stribeck"]
    assert row["p_value"] < 1e-3 and row["validation_gain"] > 0.05
    assert row["reason"].startswith("its force change")
    assert not any(w in row["reason"] for w in ("not significant", "validation gain", "reference trajectory"))


def test_a_true_friction_change_just_above_the_relevance_floor_is_still_named():
    """reporting18 d0429: a Stribeck change (the dip's velocity moved) whose force change on the
    validation record's sliding samples is 0.39 % of Fc, the smallest among the true
    friction-curve findings of the development sets: it stays named."""
    from hunting.diagnose.causes import stribeck
    from hunting.diagnose.force import relevance_floor
    fit, val, model, truth = _dataset("reporting18", 429)
    d = diagnose(fit, model, val, behaviour=False)
    assert "stribeck" in [c.name for c in d.causes], [(c.name, c.parameters) for c in d.causes]
    assert [e["cause"] for e in truth["effects"]] == ["stribeck"]
    # the record probes the floor: its force change, recomputed from the cause's own design on the
    # validation kinematics (not the library's fitted part), lies within 2 floors of it
    c = next(c for c in d.causes if c.name == "stribeck")
    kv = d.kin_val
    f = stribeck.design(kv, model, c.hyper) @ c.theta + stribeck.shift(kv, model, c.hyper)
    ok = np.isfinite(f) & kv.moving
    change = float(np.sqrt(np.mean(f[ok] ** 2)))
    assert 1.0 < change / relevance_floor(model, "stribeck") < 2.0


def test_relevance_floor_is_sized_on_the_coulomb_level_for_friction_force_causes_only():
    from hunting.diagnose.causes import CAUSES
    from hunting.diagnose.force import RELEVANCE, _fails, _why, relevance_floor
    model = NominalModel.from_dict({"plant": {"mass": 2.0}, "friction": {"law": "stribeck", "Fc": 4.0, "Fs": 5.0,
                                                                          "vs": 0.01, "b": 1.0, "Fc_neg": 2.0,
                                                                          "Fs_neg": 3.0, "vs_neg": 0.01, "b_neg": 1.0}})
    friction = {n for n, m in CAUSES.items() if getattr(m, "FRICTION_FORCE", False)}
    assert friction == {"offset", "asymmetry", "level", "level_asymmetry", "stribeck", "viscous", "dwell_peak"}
    for name in CAUSES:
        expected = RELEVANCE * 3.0 if name in friction else 0.0
        assert relevance_floor(model, name) == pytest.approx(expected)
    t = dict(p_value=1e-9, gain=0.3, rms=1.0, rms_without=1.3, floor=1e-4, relevance=0.009)
    assert _fails(dict(t, change=0.0089), 1e-3, 0.05, 0.01) and not _fails(dict(t, change=0.0091), 1e-3, 0.05, 0.01)
    assert "is below 0.009 N, 0.3% of the mean Coulomb level" in _why(dict(t, change=0.0089), 1e-3, 0.05)
    assert not _fails(t, 1e-3, 0.05, 0.01)           # hand-built rows without a size are not judged by it
    # a cause below the floor that also fails along the reference does not fail "only along the
    # reference": the loop admission (which refits it on the loop) does not take it back
    from hunting.diagnose.force import reference_only
    small = dict(t, change=0.0089, p_reference=0.5)
    assert _fails(small, 1e-3, 0.05, 0.01) and not reference_only(small, 1e-3, 0.05, 0.01)
    assert reference_only(dict(small, change=0.0091), 1e-3, 0.05, 0.01)


def test_a_drive_below_the_coulomb_friction_is_said_where_the_force_channel_is_skipped(noise_free):
    """reporting22 d0561: the controller saturates at +-1.02 N, below the model's Coulomb friction
    (1.66 N; Fs 2.79 N), and the mass moves 50 um in either record: the force channel is skipped
    for too few sliding samples, and the report says why there are so few (the saturation is
    named). A record that slides has no such note (the noise-free clean record), and neither has
    one whose force channel runs: reporting16 d0509, a true Coulomb level 0.6 times the model's,
    slides on a drive below the model's Fc in both records, and its level change is the finding."""
    from hunting.diagnose.guards import check_breakaway
    fit, val, model, truth = _dataset("reporting22", 561)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["saturation"], [(c.name, c.parameters) for c in d.causes]
    skipped = [i for i, n in enumerate(d.notes) if n.startswith("force channel skipped")]
    said = [n for n in d.notes if "never exceeds 1.017 N" in n and "Coulomb friction 1.663 N" in n]
    assert skipped and len(said) == 2, d.notes
    assert check_breakaway(noise_free[:2], noise_free[2]) == []
    fit, val, model, truth = _dataset("reporting16", 509)
    assert len(check_breakaway((fit, val), model)) == 2
    d = diagnose(fit, model, val, behaviour=False, causes=["level"])
    assert [c.name for c in d.causes] == ["level"]
    assert not any("never exceeds" in n for n in d.notes), d.notes


def test_a_refinement_that_leaves_the_physical_range_is_not_reported():
    """reporting38 d0443: a Stribeck dip (Fs 11.06 N over Fc 10.17 N) on a fitting record that
    moves one way only, where an offset and a change of the Coulomb level are the same force.
    The search split their common force into -0.22 and +0.22 N; the refinement's re-estimate into
    -2.2e8 N each, and the report named a Stribeck level of -2.2e8 N beside an offset of -2.2e8 N
    (the extended model's validation force error 6.8e7 N RMS against 0.59). A refined fit that is
    not physical is replaced by the grid variants' (refine._unrefined): every reported level is
    positive, Fs within 5 % of the truth, the offset below the Coulomb level, and the extended
    model's validation error below the nominal one's."""
    fit, val, model, truth = _dataset("reporting38", 443)
    d = diagnose(fit, model, val, behaviour=False)
    got = {c.name: c.parameters for c in d.causes}
    assert "stribeck" in got, ([(c.name, c.parameters) for c in d.causes], d.rejected)
    assert got["stribeck"]["Fc"] > 0 and got["stribeck"]["Fs"] > got["stribeck"]["Fc"], got
    assert got["stribeck"]["Fs"] == pytest.approx(truth["effects"][0]["params"]["Fs"], rel=0.05)
    assert abs(got.get("offset", {}).get("offset", 0.0)) < model.curve.negative.Fc, got
    assert d.extended < d.nominal, (d.nominal, d.extended)


def test_the_validation_test_is_not_whitened_by_the_effect_it_tests():
    """reporting38 d0341: the Coulomb and static levels 42 % above a LuGre nominal model's, on
    records of 107 thinned validation samples. The whole library fitted on the fitting record
    predicted the validation record badly, and the AR model of that validation residual (phi =
    0.95, the effect itself) made the out-of-sample test a differencing filter: the level's part
    explained 99 % of the raw validation residual and read t = 0.77, and nothing was named. The
    tests now prewhiten with the fitting record's noise model: the level is named (as ``stribeck``,
    which the draw accepts: the levels scaled at the nominal shape), first, with Fs within 10 %."""
    fit, val, model, truth = _dataset("reporting38", 341)
    d = diagnose(fit, model, val, behaviour=False)
    names = [c.name for c in d.causes]
    assert names and names[0] in truth["effects"][0]["accept"], (names, d.rejected)
    assert d.causes[0].parameters["Fs"] == pytest.approx(truth["effects"][0]["params"]["Fs"], rel=0.1)


def test_stribeck_unseen_and_seen_read_the_records_top_speeds():
    """stribeck.unseen on its own: a validation record sliding more than UNSEEN_FACTOR times
    faster (90th percentile speed) than the fitting record gives a reason, one within it none;
    stribeck.seen: a dip velocity at most the fitting record's top speed is one that record could
    show (reason), a faster one is not (None), and the static level alone (``dip``) is judged at the
    nominal curve's vs."""
    from types import SimpleNamespace
    from hunting.diagnose.causes import stribeck
    def kin(top):
        v = -np.linspace(0.1, 1.0, 1000) * top / 0.91      # 90th percentile |v| ~ top
        return SimpleNamespace(v=v, moving=np.ones(v.size, bool))
    fit, _, model, _ = _dataset("reporting41", 331)
    kf = kin(0.004)
    assert stribeck.top_speed(kf) == pytest.approx(0.004, rel=0.01)
    assert stribeck.unseen(kf, kin(0.004 * stribeck.UNSEEN_FACTOR * 1.1), model) is not None
    assert stribeck.unseen(kf, kin(0.004 * stribeck.UNSEEN_FACTOR * 0.9), model) is None
    assert stribeck.seen({"vs": 0.003, "vs_neg": 0.003}, kf, model) is not None
    assert stribeck.seen({"vs": 0.003, "vs_neg": 0.006}, kf, model) is None
    nominal_vs = model.curve.positive.vs
    assert (stribeck.seen({"dip": True}, kin(2 * nominal_vs), model) is not None
            and stribeck.seen({"dip": True}, kin(0.5 * nominal_vs), model) is None)


def test_an_offset_ranked_below_a_set_that_does_not_beat_the_nominal_model_is_judged_next():
    """reporting42 d0496: an offset of 2.04 N, the fitting record sliding one way. The fitting
    data's BIC ranked {stribeck, viscous, mass} first (-1869.5) and the offset alone fourth
    (-1859.6); the mass failed its test and the Stribeck and viscous changes left predicted the
    validation data worse than the nominal model. The empty set left then is no verdict: the next
    set that holds none of the dropped causes, the offset, is judged, and it explains 98 % of the
    validation residual. Before, the validation record's blocks named a viscous asymmetry and a
    Stribeck change in its place."""
    fit, val, model, truth = _dataset("reporting42", 496)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["offset"], [(c.name, c.parameters) for c in d.causes]
    assert d.causes[0].parameters["offset"] == pytest.approx(truth["effects"][0]["params"]["offset"], rel=0.02)
    assert d.extended_model.offset == pytest.approx(d.causes[0].parameters["offset"], rel=1e-9)
    assert any(r["name"] == "stribeck" and "does not beat {nominal model}" in r["reason"] for r in d.rejected)


def test_a_saturation_reached_in_three_excursions_is_named():
    """reporting42 d0353: the controller output, not quantized, holds 9.144536069429746 for 9, 10
    and 17 samples in three excursions of the two records, the machine's saturation, which the
    model lacks. At a coincidence tolerance of 1e-6 of the maximum the two excursions beside the
    maximum's gave p = 0.008 and nothing was named for a cut of 90 % of the re-simulated
    validation position error; at 1e-9, p = 8e-6 and the saturation is named at its true level."""
    from hunting.diagnose.causes.saturation import evidence, records_output
    fit, val, model, truth = _dataset("reporting42", 353)
    assert evidence(records_output(fit, val))[3] < 1e-4
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["saturation"], [(c.name, c.parameters) for c in d.causes]
    level = truth["effects"][0]["params"]["saturation"]
    assert d.causes[0].parameters["saturation"] == pytest.approx(level, rel=1e-6)
    assert d.extended_model.controller["saturation"] == pytest.approx(level, rel=1e-6)
    assert d.causes[0].gain["extended"] < 0.2 * d.causes[0].gain["nominal"]


def test_a_growth_the_rests_suggest_is_named_on_a_smaller_validation_cut():
    """reporting41 d0310: a dwell growth of 20.7 N (time 0.17 s). Its rests suggest it (p = 0.063
    < GATE); the growth fitted on the fitting record's loop cuts that record's position error by
    58 % and the validation record's by 22.5 %, below the unprompted bar of 40 % and above the
    prompted one of 20 %: named, its gain within 10 %."""
    from hunting.diagnose.causes.dwell_loop import GATE, PROMPTED_VALIDATION_GAIN
    from hunting.diagnose.causes.presliding import LOOP_VALIDATION_GAIN
    assert PROMPTED_VALIDATION_GAIN < LOOP_VALIDATION_GAIN
    fit, val, model, truth = _dataset("reporting41", 310)
    d = diagnose(fit, model, val)
    assert [c.name for c in d.causes] == ["dwell"], [(c.name, c.parameters) for c in d.causes]
    c = d.causes[0]
    assert c.parameters["gain"] == pytest.approx(truth["effects"][0]["params"]["gain"], rel=0.1)
    assert "p = " in c.gain["evidence"] and f"< {GATE:g}" in c.gain["evidence"]
    assert d.extended_model.dwell.gain == pytest.approx(c.parameters["gain"], rel=1e-9)


def test_a_growth_the_rests_suggest_is_named_on_a_smaller_fitting_cut():
    """reporting43 d0464: a dwell growth of 0.39 N (time 49 ms). Its rests suggest it (p = 0.0036);
    fitted on the fitting record's loop it cuts that record's position error by 40 %, below the
    bristles' 50 %, and the validation record's by 69 %: named at the prompted bars (20 % each),
    its gain within 25 %."""
    fit, val, model, truth = _dataset("reporting43", 464)
    d = diagnose(fit, model, val)
    assert [c.name for c in d.causes] == ["dwell"], [(c.name, c.parameters) for c in d.causes]
    assert d.causes[0].parameters["gain"] == pytest.approx(truth["effects"][0]["params"]["gain"], rel=0.25)
    assert "at least 20% and 20% needed" in d.causes[0].gain["evidence"]


def test_presliding_stiffness_is_refined_with_its_damping():
    """reporting44 d0365 (LuGre, sigma0 = 1.02e5 N/m at damping ratio 0.70; creep at rest): the
    creep fit at the held damping ratio 0.5 read sigma0 35 % high. Refined together with the
    damping on the fitting record's loop (:func:`presliding.refine_stiffness`), sigma0 comes out
    within 5 % and the damping ratio within 10 %, and the validation record's position error is
    no worse than at the admitted fit."""
    fit, val, model, truth = _dataset("reporting44", 365)
    true = truth["true"]["plant"]
    zeta = true["sigma1"] / (2.0 * np.sqrt(true["sigma0"] * model.mass))
    d = diagnose(fit, model, val, behaviour=False)
    c = _found(d, "presliding")
    assert c is not None, [x.name for x in d.causes]
    assert c.parameters["sigma0"] == pytest.approx(true["sigma0"], rel=0.05)
    assert c.parameters["zeta"] == pytest.approx(zeta, rel=0.1)
    assert c.parameters["sigma1"] == pytest.approx(true["sigma1"], rel=0.1)
    assert c.gain["extended"] < c.gain["nominal"]


def test_a_resonance_the_old_candidates_missed_is_named_on_the_force_residual():
    """reporting44 d0419: a 13.9 Hz load at damping ratio 0.025 behind the motor. With the masked
    acceleration as the candidates' regressor the significance test, whitened with an AR model
    that took the ill-fitted ringing for noise, gave p = 0.32 and the loop had to confirm it; with
    :func:`design_acceleration` the force residual alone names it."""
    fit, val, model, truth = _dataset("reporting44", 419)
    true = truth["effects"][0]["params"]
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["flexibility"], [(c.name, c.parameters) for c in d.causes]
    c = d.causes[0]
    assert c.parameters["load_mass"] == pytest.approx(true["load_mass"], rel=0.05)
    assert c.parameters["frequency"] == pytest.approx(true["frequency"], rel=0.05)
    assert c.p_value is not None and c.p_value < 1e-3


def test_a_cause_the_whitened_test_misses_is_confirmed_on_the_loop():
    """reporting53 d0309: LuGre bristles (sigma0 5.3e4 N/m) behind a static model. The force
    channel fits the reversal's build-up, but its out-of-sample test gives p = 0.018 and nothing
    else passes. Re-simulated at the fitted values, the loop follows both records by more than
    LOOP_GAIN better: the reversal is named, its evidence the loop's."""
    from hunting.diagnose.causes.presliding import LOOP_GAIN
    fit, val, model, truth = _dataset("reporting53", 309)
    d = diagnose(fit, model, val, behaviour=False)
    assert [c.name for c in d.causes] == ["reversal"], [(c.name, c.parameters) for c in d.causes]
    c = d.causes[0]
    assert c.p_value is None and "nothing fitted on the loop" in c.gain["evidence"]
    assert 1 - c.gain["extended"] / c.gain["nominal"] >= LOOP_GAIN
    assert all("theta" not in r for r in d.rejected)
    assert "reversal" not in [a["name"] for a in d.alternatives]


def test_resonance_load_mass_is_refined_on_the_loop():
    """reporting44 d0307 (a 1.66 kg load at 7.49 Hz, damping ratio 0.10, behind 7.1 kg): the force
    channel's fit traded the load mass against the damping (1.66 -> 2.03 kg, +22 %, at 0.128).
    Refitted on the fitting record's re-simulated loop (:func:`flexibility.refine_on_loop`) the
    load mass is within 10 % and the damping within 25 % (the loop's error is rugged in the damping:
    the refinement reached 0.120, +20 %, at 3.7e-3 stated, on the fifty-fifth session's machine,
    within 15 % on the earlier ones, with the start code as with the final one; the force
    channel's 0.128 is +27 %), the extended model holds those values,
    the validation record's position error is no larger than at the force channel's by more than
    the sensor's floor (0.72 against 0.66 um at a 0.42 um encoder, floor 0.12 um: the two follow
    the record equally well), and each refined value has a standard uncertainty."""
    fit, val, model, truth = _dataset("reporting44", 307)
    m2, _, zeta = truth["true"]["plant"]["flex"]
    d = diagnose(fit, model, val, behaviour=False)
    c = _found(d, "flexibility")
    assert c is not None, [x.name for x in d.causes]
    assert c.parameters["load_mass"] == pytest.approx(m2, rel=0.1)
    assert c.parameters["damping"] == pytest.approx(zeta, rel=0.25)
    assert d.extended_model.flexibility.load_mass == c.parameters["load_mass"]
    loop = c.gain["refined_on_loop"]
    resolution = np.min(np.diff(np.unique(val.q)))
    assert loop["refined"] <= loop["force_channel"] + resolution / np.sqrt(12.0)
    assert c.sigma["load_mass"] > 0 and c.sigma["damping"] > 0
    # the stiffness m2 (2 pi f)^2 carries the refined load mass's uncertainty at least
    relative = c.sigma["load_mass"] / c.parameters["load_mass"]
    assert c.sigma["stiffness"] >= c.parameters["stiffness"] * relative * (1 - 1e-9)


def test_grid_minimum_finds_an_analytic_minimum_within_its_bounds(monkeypatch):
    """loop_grid.grid_minimum on a quadratic bowl with minimum at (0.37, -0.12) (the 'model' at
    (x, y) is the point, its 'error' the bowl): after three finer rounds the point is within a
    quarter of the first grid's step of it (the last grid's spacing), every point is evaluated
    once (at most 9 x 7 + 3 x 24 calls), and a y_range that excludes the minimum holds y at its
    edge."""
    import threading

    from hunting.diagnose import resimulate
    from hunting.diagnose.loop_grid import grid_minimum
    calls, lock = [], threading.Lock()

    def bowl(meas, point):
        x, y = point
        with lock:
            calls.append((x, y))
        return (x - 0.37) ** 2 + 2.0 * (y + 0.12) ** 2
    monkeypatch.setattr(resimulate, "position_rms_error", bowl)
    xs, ys = np.linspace(-1.0, 1.0, 9), np.linspace(-1.0, 1.0, 7)
    c, x, y = grid_minimum(None, lambda a, b: (a, b), xs, ys, 3)
    assert abs(x - 0.37) <= (xs[1] - xs[0]) / 4 and abs(y + 0.12) <= (ys[1] - ys[0]) / 4
    assert c == pytest.approx((x - 0.37) ** 2 + 2.0 * (y + 0.12) ** 2)
    assert len(calls) == len(set(calls)) <= 9 * 7 + 3 * 24
    _, x2, y2 = grid_minimum(None, lambda a, b: (a, b), xs, ys, 3, (0.0, 1.0))
    assert y2 == 0.0 and abs(x2 - 0.37) <= (xs[1] - xs[0]) / 4
