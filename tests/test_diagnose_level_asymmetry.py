"""The friction level scaled apart in the two directions (``level_asymmetry``): its regressor is the
extension's change of the sliding friction (the curves' own force law, numba), its untestable
cases, and its relation to ``level``, of which it is the general case."""
import numpy as np
import pytest

from hunting.diagnose import Measurement, NominalModel, kinematics
from hunting.diagnose.causes import CAUSES, level, level_asymmetry, offset

DT = 1e-3
STRIBECK = {"plant": {"mass": 1.0, "motor_constant": 1.0},
            "friction": {"law": "stribeck", "Fc": 10.0, "Fs": 15.0, "vs": 0.01, "beta": 2.0, "b": 50.0},
            "controller": {"type": "pid", "kp": 4e4, "kd": 400.0, "ki": 0.0}}


def _kin(q: np.ndarray):
    t = np.arange(q.size) * DT
    return kinematics(Measurement(t=t, q=q, u=np.zeros_like(t), name="sine"), 1.0, resolution=1e-8, noise=0.0)


def _sine(amp: float = 0.01, f: float = 1.0, duration: float = 3.0):
    t = np.arange(int(duration / DT)) * DT
    return amp * np.sin(2 * np.pi * f * t)


def _model(**friction):
    return NominalModel.from_dict(dict(STRIBECK, friction=dict(STRIBECK["friction"], **friction)))


# the negative direction's own curve: each column must read its own direction's level
ASYMMETRIC = {"Fc_neg": 6.0, "Fs_neg": 12.0, "vs_neg": 0.02, "b_neg": 30.0}


@pytest.mark.parametrize("theta, curve", [((0.2, -0.3), {}), ((0.0, 0.5), {}), ((-0.4, 0.0), {}),
                                          ((0.2, -0.3), ASYMMETRIC), ((-0.1, 0.4), ASYMMETRIC)])
def test_regressor_is_the_extension_change_of_the_sliding_friction(theta, curve):
    """design @ theta equals the extended model's sliding friction less the nominal one's, both from
    the curves' force law (DirectionalCurve.force), on every sample of a two-way sine (with the
    sliding mask and filter of the force channel), and the parameters are the extension's levels;
    on a symmetric nominal curve and on one whose directions differ."""
    model = _model(**curve)
    kin = _kin(_sine())
    X = level_asymmetry.design(kin, model, {})
    ext = level_asymmetry.extend(model, np.array(theta), {})
    change = kin.sliding(ext.curve.force(kin.vf) - model.curve.force(kin.vf))
    assert X.shape == (kin.t.size, 2)
    assert np.max(np.abs(X @ np.array(theta) - change)) <= 1e-9 * np.max(np.abs(change))
    p = level_asymmetry.parameters(np.array(theta), {}, model)
    assert (p["Fc_pos"], p["Fs_pos"]) == pytest.approx((ext.curve.positive.Fc, ext.curve.positive.Fs))
    assert (p["Fc_neg"], p["Fs_neg"]) == pytest.approx((ext.curve.negative.Fc, ext.curve.negative.Fs))
    assert (p["scale_pos"], p["scale_neg"]) == pytest.approx((1 + theta[0], 1 + theta[1]))


def test_equal_factors_are_the_level_cause():
    """Its special case k+ = k-: the two columns summed are level's regressor (NESTS level, and a
    set cannot hold both: EXCLUDES)."""
    model = _model()
    kin = _kin(_sine())
    X = level_asymmetry.design(kin, model, {})
    np.testing.assert_allclose(X.sum(axis=1), level.design(kin, model, {})[:, 0], rtol=0, atol=1e-9)
    assert "level" in level_asymmetry.NESTS and "level" in level_asymmetry.EXCLUDES
    assert CAUSES["level_asymmetry"] is level_asymmetry


def test_untestable_without_a_dip_one_way_or_without_friction():
    """A Coulomb curve (no dip: level and offset say the same), a fitting record that slides one way
    (a validation record still judges), no friction to scale."""
    two_way, one_way = _kin(_sine()), _kin(np.linspace(0.0, 0.05, 3000))
    assert level_asymmetry.untestable(two_way, _model()) is None
    assert "no Stribeck dip" in level_asymmetry.untestable(two_way, _model(Fs=10.0))
    assert "no Stribeck dip" in level_asymmetry.untestable(two_way, _model(beta=float("inf")))
    assert "moves one way only" in level_asymmetry.untestable(one_way, _model())
    assert level_asymmetry.untestable(one_way, _model(), validation=True) is None
    assert "no Coulomb or static friction" in level_asymmetry.untestable(two_way, _model(Fc=0.0, Fs=0.0))


def test_a_level_pushing_along_the_motion_is_not_physical():
    model = _model()
    assert level_asymmetry.unphysical(np.array([0.1, -0.2]), {}, model) is None
    assert "pushing along the motion" in level_asymmetry.unphysical(np.array([0.1, -1.2]), {}, model)


def test_sentence_names_each_direction_and_skips_an_unchanged_one():
    model = _model()
    text = level_asymmetry.sentence(level_asymmetry.parameters(np.array([0.001, -0.28]), {}, model), {}, model)
    assert "for positive velocities the model's (Fc = 10 N, Fs = 15 N)" in text
    assert "for negative velocities 28 % lower than the model's (Fc = 7.2 N, Fs = 10.8 N instead of 10 N, 15 N)" in text


def test_an_offset_is_nearly_in_its_span_above_the_stribeck_velocity_and_excluded():
    """Sliding well above vs the levels are Fc, and levels moved apart are a constant force: the
    offset's regressor is fitted by the two columns to within 5 % RMS (a set holding both cancels
    them against each other, reporting31 d0125), so the two are never in one set."""
    model = _model(vs=0.002)
    kin = _kin(_sine(amp=0.02))
    X = level_asymmetry.design(kin, model, {})
    y = offset.design(kin, model, {})[:, 0]
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    assert np.sqrt(np.mean((y - X @ coef) ** 2)) < 0.05 * np.sqrt(np.mean(y ** 2))
    assert "offset" in level_asymmetry.EXCLUDES
