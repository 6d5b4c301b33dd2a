"""A resonance searched on the re-simulated loop (hunting.diagnose.loop_resonance): its grid of
frequencies, its fit on a record a flexible load made, and its verdict's bars."""
import numpy as np
import pytest

from hunting.diagnose import Measurement, NominalModel
from hunting.diagnose import loop_resonance
from hunting.diagnose.causes.presliding import LOOP_GAIN
from hunting.diagnose.model import Flexibility

MODEL = {"plant": {"mass": 2.0, "motor_constant": 1.0},
         "friction": {"law": "stribeck", "Fc": 2.0, "Fs": 3.0, "vs": 0.002, "beta": 2.0, "b": 1.0},
         "controller": {"type": "pid", "kp": 2e4, "kd": 150.0, "ki": 1e5},
         "sensor": {"resolution": 1e-7}}


def _made(model, seconds=2.0, dt=1e-3, name="made"):
    """A record of short moves and rests re-simulated with ``model`` (hunting's loop)."""
    from hunting.diagnose.resimulate import resimulate
    t = np.arange(0.0, seconds, dt)
    r = 0.001 * (np.clip(t - 0.2, 0, 0.1) - np.clip(t - 0.9, 0, 0.1) + np.clip(t - 1.5, 0, 0.1)) / 0.1
    push = Measurement(t=t, q=np.zeros_like(t), u=np.zeros_like(t), q_ref=r, name="push")
    sim = resimulate(push, model, substeps=20)
    return Measurement(t=t, q=sim.q, u=sim.u, q_ref=r, name=name)


def test_frequencies_span_three_per_octave_below_the_sampling_bound():
    """At 1 kHz: from 3 Hz to 200 Hz (0.4 of the Nyquist frequency), three per octave; at 100 Hz
    sampling (top 20 Hz) fewer; none where the bound lies below 3 Hz."""
    def record(dt):
        t = np.arange(100) * dt
        return Measurement(t=t, q=0 * t, u=0 * t)
    f = loop_resonance.frequencies(record(1e-3))
    assert f[0] == pytest.approx(3.0) and f[-1] == pytest.approx(200.0)
    assert np.all(np.diff(np.log2(f)) <= 1.0 / 3.0 + 1e-12)
    slow = loop_resonance.frequencies(record(1e-2))
    assert slow[-1] == pytest.approx(20.0) and slow.size < f.size
    assert loop_resonance.frequencies(record(0.2)).size == 0


def test_a_load_the_loop_rings_with_is_fitted_and_named_on_both_records():
    """Two records (short moves and rests) made with a 25 Hz load carrying 30 % of the mass
    (damping 0.03) on a model without it: fitted on the first record's loop, the frequency within
    2 % and the load mass within 10 %; the verdict passes both records' bars and its model holds
    the fitted load. On the nominal model's own records it is not named."""
    nominal = NominalModel.from_dict(MODEL)
    true = nominal.replace(flexibility=Flexibility(0.6, 25.0, 0.03))
    fit, val = _made(true), _made(true, seconds=2.4, name="val")
    r = loop_resonance.judge(fit, val, nominal)
    assert r["significant"], r.get("reason")
    assert r["gain_fit"] >= LOOP_GAIN and r["gain_val"] >= LOOP_GAIN
    assert r["parameters"]["frequency"] == pytest.approx(25.0, rel=0.02)
    assert r["parameters"]["load_mass"] == pytest.approx(0.6, rel=0.1)
    assert r["model"].flexibility.frequency == pytest.approx(r["parameters"]["frequency"], rel=1e-12)
    clean = loop_resonance.judge(_made(nominal), _made(nominal, seconds=2.4, name="val"), nominal)
    assert not clean["significant"]


def test_a_model_with_a_load_already_is_not_searched_again():
    nominal = NominalModel.from_dict(MODEL).replace(flexibility=Flexibility(0.6, 25.0, 0.03))
    t = np.arange(0.0, 1.0, 1e-3)
    m = Measurement(t=t, q=0 * t, u=0 * t, q_ref=0 * t)
    r = loop_resonance.judge(m, m, nominal)
    assert not r["significant"] and "already" in r["reason"]


def test_the_validation_records_own_fit_must_find_the_same_load():
    """Two fits of one load agree (frequency within 5 %, load mass within a factor 1.5; the
    damping ratio, which one record fixes least, may differ: seed-11 d0081's 0.030 and 0.083);
    reporting63 d0277's two records' fits (128.6 Hz, 0.134 kg against 142.8 Hz, 0.367 kg) do not,
    and the words say which."""
    m = NominalModel.from_dict(MODEL)
    x = loop_resonance._coefficients(128.6, 0.134 / m.mass, 0.09)
    assert loop_resonance._disagreement(m, x, loop_resonance._coefficients(131.0, 0.15 / m.mass, 0.1)) is None
    far = loop_resonance._disagreement(m, x, loop_resonance._coefficients(142.8, 0.367 / m.mass, 0.093))
    assert "143 Hz against 129 Hz" in far and "load mass 0.367 kg against 0.134 kg" in far and "damping" not in far
    assert loop_resonance._disagreement(m, x, loop_resonance._coefficients(128.6, 0.134 / m.mass, 0.36)) is None
    assert "does not re-simulate" in loop_resonance._disagreement(m, x, None)
