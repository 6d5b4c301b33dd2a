"""The friction-level cause and the saturation cause's p-value.

level: a Coulomb (and static) level that differs from the model's by one factor in both
directions is named alone, with the factor's levels as final values (the newcomer's report of
2026-11-23 gave ``stribeck`` with Fc 463 mN for a true 1 N, beside an invented ``viscous`` and
``cogging``). saturation: an output that never saturated, but whose quantized smooth peaks sit on
their top level for many samples, is not evidence of a bound (the sample count gave p = 4e-166)."""
from dataclasses import replace

import numpy as np
import pytest

from hunting.diagnose import NominalModel, diagnose
from hunting.diagnose.causes.saturation import p_value, pile_up
from hunting.diagnose.synthetic import TruePlant, generate, true_model

NOMINAL = {"plant": {"mass": 95.0, "motor_constant": 35.15},
           "friction": {"law": "coulomb-viscous", "Fc": 20.0, "b": 200.0}}


@pytest.mark.parametrize("case", ["coulomb up", "stribeck down"])
def test_friction_level_is_named_alone_with_its_levels(case):
    """Coulomb + viscous model with Fc 20 N, truth 36 N; Stribeck model (Fc 20, Fs 30 N), truth
    both levels 0.7 times that: ``level`` alone, Fc (and Fs) within 5 %, the extended model holds
    them, stribeck at most an alternative."""
    base = TruePlant()
    if case == "coulomb up":
        true, nominal, k = replace(base, Fc_pos=36.0, Fc_neg=36.0), NominalModel.from_dict(NOMINAL), 1.8
    else:
        stribeck = replace(base, Fs=30.0, vs=0.01)
        true = replace(stribeck, Fc_pos=14.0, Fc_neg=14.0, Fs=21.0)
        nominal, k = true_model(stribeck).replace(controller=None), 0.7
    dg = diagnose(generate(true, 12.0, seed=1), nominal, generate(true, 12.0, seed=2), behaviour=False)
    assert [c.name for c in dg.causes] == ["level"], [(c.name, c.parameters) for c in dg.causes]
    p = dg.causes[0].parameters
    assert p["scale"] == pytest.approx(k, rel=0.05)
    assert p["Fc"] == pytest.approx(k * nominal.curve.positive.Fc, rel=0.05)
    assert p["Fs"] == pytest.approx(k * nominal.curve.positive.Fs, rel=0.05)
    ext = dg.extended_model.curve
    assert (ext.positive.Fc, ext.negative.Fs) == pytest.approx((p["Fc"], p["Fs"]), rel=1e-12)
    assert ext.positive.b == nominal.curve.positive.b
    assert all(s and s > 0 for s in dg.causes[0].sigma.values())
    assert "stribeck" not in [c.name for c in dg.causes]


def _old_p(u):
    """The sample-count p-value this module replaced (for the record: what the test guards)."""
    from scipy import stats
    a = np.abs(u)
    U, du = a.max(), 0.01
    top = np.sum(a >= U - 0.5 * du)
    below = np.sum((a < U - 0.5 * du) & (a >= U - 1.5 * du))
    return stats.binom.sf(top - 1, top + below, 0.5)


def test_saturation_p_value_is_calibrated_on_quantized_smooth_peaks():
    """A 0.5 Hz output quantized to 1 % of its amplitude, never clipped: its 10 peaks sit on the
    top level for 640 samples against 460 on the level below; counted as independent samples that
    was p = 3e-8 (below alpha = 1e-3: a false alarm), counted as excursions (none a plateau) it is
    no evidence. The same output clipped at 90 % of its peak is."""
    t = np.arange(0.0, 10.0, 1e-3)
    u = np.round(np.sin(2 * np.pi * 0.5 * t + 0.3) / 0.01) * 0.01
    assert _old_p(u) < 1e-3                     # the old rule's false alarm
    assert p_value(*pile_up(u)[2:]) > 0.05
    clipped = np.clip(u, -0.9, 0.9)
    assert p_value(*pile_up(clipped)[2:]) < 1e-6


def test_saturation_p_value_false_alarm_rate_under_the_null():
    """Smooth random outputs (1-4 sinusoids, 0.5-5 kHz, quantized to 1e-4..3e-2 of the peak or
    not, sometimes with noise), none clipped: no p below 0.01 in 200 draws."""
    rng = np.random.default_rng(7)
    ps = []
    for _ in range(200):
        fs = rng.choice([500.0, 1000.0, 2000.0, 5000.0])
        t = np.arange(int(rng.uniform(2, 6) * fs)) / fs
        u = sum(rng.uniform(0.2, 1) * np.sin(2 * np.pi * rng.uniform(0.1, 3) * t + rng.uniform(0, 6.3))
                for _ in range(int(rng.integers(1, 5))))
        u = u + (rng.uniform(0, 0.02) * rng.standard_normal(t.size) if rng.random() < 0.5 else 0.0)
        if rng.random() < 0.8:
            du = np.exp(rng.uniform(np.log(1e-4), np.log(3e-2))) * np.max(np.abs(u))
            u = np.round(u / du) * du
        ps.append(p_value(*pile_up(u)[2:]))
    assert np.mean(np.array(ps) < 0.01) == 0.0


def test_position_noise_is_read_from_unquantized_positions():
    """White noise of 1 um on a smooth 1 kHz motion (3 cm, 0.5-1.3 Hz) is read within 10 % from
    the third differences; the noise-free motion reads as (almost) none. With it, a record that is
    not quantized and whose model declares no sensor noise classifies rests as stuck: a mass
    resting for 0.3 s between two moves is stuck there (but for the noise's rare 4-sigma ranges),
    not sliding on noise."""
    from hunting.diagnose import Measurement, kinematics
    from hunting.diagnose.kinematics import position_noise
    t = np.arange(0.0, 10.0, 1e-3)
    q = 0.02 * np.sin(2 * np.pi * 0.5 * t) + 0.01 * np.sin(2 * np.pi * 1.3 * t)
    noise = 1e-6 * np.random.default_rng(3).standard_normal(t.size)
    assert position_noise(q + noise) == pytest.approx(1e-6, rel=0.1)
    assert position_noise(q) < 1e-8
    move = np.clip((t - 1.0) / 0.5, 0, 1) * 0.01 - np.clip((t - 1.8) / 0.5, 0, 1) * 0.01
    kin = kinematics(Measurement(t[:3000], move[:3000] + noise[:3000], np.zeros(3000)), 1.0)
    rest = (t[:3000] > 1.55) & (t[:3000] < 1.75)
    assert kin.noise == pytest.approx(1e-6, rel=0.2)
    assert np.mean(~kin.slide[rest]) > 0.95          # noise 0 taken at its word: none (every sample slides)


def _saturation_p(u):
    """The saturation judge's p-value of an output u alone (both tests of the null)."""
    from hunting.diagnose.causes.saturation import evidence
    return evidence(u)[3]


def test_saturation_touched_one_sample_at_a_time_is_evidence():
    """A noisy, unquantized output whose peaks exceed a bound by a hair, so each of its excursions
    touches the bound for one or two samples and leaves no plateau (tuning d0084, d0162): the
    plateau count alone saw nothing (p = 1); 27 of 67 excursions reaching one height within 1e-6,
    each with its own shape, are a bound."""
    rng = np.random.default_rng(11)
    t = np.arange(0.0, 10.0, 1e-3)
    raw = np.sin(2 * np.pi * 1.0 * t) + 1e-3 * rng.standard_normal(t.size)
    u = np.clip(raw, -1.001, 1.001)                         # 33 samples beyond, in 27 separate touches
    assert p_value(*pile_up(u)[2:]) > 0.05                  # the plateau test alone: no evidence
    assert _saturation_p(u) < 1e-6
    assert _saturation_p(raw) > 0.05                        # the same output unclipped


def test_saturation_coinciding_peaks_calibrated_on_sampled_replicas():
    """Periodic outputs (every true peak the same height: the worst case for coinciding sampled
    peaks) with white noise from 1e-13 (rounding) to 3e-2 of the amplitude, unquantized, 0.5-5 kHz,
    never clipped: no p below 0.01 in 300 draws (the coincidence tolerance is 1e-9 of the
    maximum: noise below it leaves replicas, which the shape test tells apart)."""
    rng = np.random.default_rng(3)
    ps = []
    for _ in range(300):
        fs = rng.choice([500.0, 1000.0, 2000.0, 5000.0])
        t = np.arange(int(rng.uniform(2, 8) * fs)) / fs
        f = rng.uniform(0.2, 5)
        u = np.sin(2 * np.pi * f * t + rng.uniform(0, 6.3))
        if rng.random() < 0.5:
            u = u + 0.3 * np.sin(2 * np.pi * 2 * f * t + rng.uniform(0, 6.3))
        u = u + 10 ** rng.uniform(-13, -1.5) * rng.standard_normal(t.size)
        ps.append(_saturation_p(u))
    assert np.mean(np.array(ps) < 0.01) == 0.0


def test_saturation_pile_up_is_read_in_both_records():
    """A machine that saturated only in its validation run (reporting6 d0311: 4 samples at the
    bound in the fitting record, 2441 of 3426 in the validation one, nothing reported) is
    saturated all the same: the excursions of both records are the trials. The fitting record
    here peaks at 0.8 and never reaches the bound; the validation one is clipped at 1.0. Alone the
    fitting record is no evidence; the pair is, at the validation record's level. The same record
    given twice counts once."""
    from types import SimpleNamespace
    from hunting.diagnose.causes.saturation import evidence, records_output
    t = np.arange(0.0, 6.0, 1e-3)
    q = np.sin(t)
    fit = SimpleNamespace(u=0.8 * np.sin(2 * np.pi * 0.7 * t), q=q, n=t.size)
    val = SimpleNamespace(u=np.clip(1.6 * np.sin(2 * np.pi * 0.9 * t + 0.4), -1.0, 1.0), q=q + 1, n=t.size)
    assert evidence(fit.u)[3] > 0.05
    U, _, _, p = evidence(records_output(fit, val))
    assert U == pytest.approx(1.0) and p < 1e-6
    assert np.array_equal(records_output(fit, SimpleNamespace(u=fit.u.copy(), q=q.copy(), n=t.size)), fit.u)
