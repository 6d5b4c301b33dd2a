"""Friction laws, plants, controllers, presets: values and every error path."""
import math

import numpy as np
import pytest

import hunting
from hunting import SystemDefinitionError
from hunting.models import (PID, Cogging, Coulomb, DirectionalCurve, Discontinuous, LuGre, Plant,
                            StribeckCurve, Switch, Viscous, preset)


@pytest.mark.parametrize("beta", [0.5, 1.0, 2.0, 3.7])
def test_stribeck_family_values(beta):
    c = StribeckCurve(Fc=2.0, Fs=4.0, vs=0.1, beta=beta, b=1.0)
    v = np.array([-0.3, -0.05, 0.02, 0.1, 0.4])
    expect = np.sign(v) * (2.0 + 2.0 * np.exp(-np.abs(v / 0.1) ** beta)) + v
    np.testing.assert_allclose(c.force(v), expect, rtol=1e-14)
    assert c.stick_set == (-4.0, 4.0)
    # the slip limit approaches Fs: continuous stick-slip transition
    assert abs(c.force(1e-9)[0] - 4.0) < 1e-3


def test_discontinuous_coulomb_viscous_and_directional():
    d = Discontinuous(Fc=2.0, Fs=4.0, b=1.0)
    assert d.discontinuous and d.force(1e-12)[0] == pytest.approx(2.0)
    assert d.stick_set == (-4.0, 4.0)
    np.testing.assert_allclose(Coulomb(3.0).force([-1, 2]), [-3, 3])
    np.testing.assert_allclose(Viscous(0.5).force([-2, 4]), [-1, 2])
    dc = DirectionalCurve(StribeckCurve(13.35, 28.3, 0.019, 2, 36.45), StribeckCurve(13.45, 27.5, 0.020, 2, 37.95))
    assert dc.stick_set == (-27.5, 28.3) and not dc.symmetric
    f = dc.force([0.1, -0.1])
    assert f[0] == pytest.approx(13.35 + 14.95 * math.exp(-(0.1 / 0.019) ** 2) + 3.645)
    assert f[1] == pytest.approx(-(13.45 + 14.05 * math.exp(-(0.1 / 0.020) ** 2)) - 3.795)


def test_lugre_steady_state_equals_curve_and_velocity_dependent_damping():
    lg = LuGre(StribeckCurve(0.44, 0.53, 0.02, 2.0, 0.1), sigma0=2.2e4, sigma1=7.58)
    for v in (0.01, -0.03, 0.2):
        g = 0.44 + 0.09 * math.exp(-(v / 0.02) ** 2)
        z_ss = math.copysign(g, v) / 2.2e4
        zdot, F = lg.rates(v, z_ss)
        assert abs(zdot) < 1e-15 and F == pytest.approx(math.copysign(g, v) + 0.1 * v)
    lgv = LuGre(StribeckCurve(1.0, 1.5, 0.001, 2.0, 0.4), sigma0=1e5, sigma1=316.0, vd=0.002)
    zdot, F = lgv.rates(0.002, 0.0)
    assert F == pytest.approx(316.0 * math.exp(-1.0) * zdot + 0.4 * 0.002)


def test_cogging_table_and_harmonics():
    tab = Cogging.table([0.0, 0.01, 0.02], [0.0, 5.0, -5.0])
    np.testing.assert_allclose(tab([-1, 0.005, 0.015, 0.5]), [0.0, 2.5, 0.0, -5.0], atol=1e-12)
    h = Cogging.sine(2.0, 0.015, 0.3)
    q = np.linspace(-0.1, 0.1, 7)
    np.testing.assert_allclose(h(q), 2.0 * np.sin(2 * np.pi * q / 0.015 + 0.3), atol=1e-13)
    # the LiMMS preset's cogging meets the thesis' value and slope at q_d = -0.38 m
    lm = preset("limms-switch")
    assert lm.plant.cogging(-0.38)[0] == pytest.approx(4.866, abs=1e-9)
    assert lm.plant.cogging.slope(-0.38)[0] == pytest.approx(-7.1586e3, rel=1e-6)


def test_pid_forms():
    c = PID.pdi(10, 1, 10)
    assert (c.kp, c.kd, c.ki) == (10, 10, 100)
    k = PID.fixed_shape(0.04)
    assert (k.kp, k.kd, k.ki) == pytest.approx((0.08, 0.04 / (2 * math.pi), 0.04 * 2 * math.pi))


def test_presets_and_overrides():
    for name in ("table9.1", "table8.1-switch", "table8.1-lugre", "limms-switch", "limms-lugre", "table4.1"):
        lp = preset(name)
        assert lp.system.n_states == (4 if "lugre" in name or name == "table4.1" else 3)
    lp = preset("table9.1", P=20, beta="inf")
    assert lp.friction.curve.positive.discontinuous and lp.controller.kp == 20
    lp = preset("table9.1", friction="discontinuous")
    assert lp.friction.curve.positive.discontinuous
    lp = preset("table8.1-lugre", sigma2=0.2)
    assert lp.friction.sigma2 == 0.2
    lp = preset("table9.1", Fs_neg=5.0)
    assert lp.friction.stick_set == (-5.0, 4.0) and not lp.system.odd
    text = hunting.models.describe_presets()
    assert "table8.1-lugre" in text and "[N m/rad]" in text and "[N/m]" in text


def test_equilibrium_set_bounds():
    lp = preset("table9.1")
    assert lp.equilibrium_set() == pytest.approx((-0.04, 0.04))     # |x3| <= Fs / (P I)
    lp = preset("table8.1-switch", K=0.5)
    b = 0.53 / (0.5 * 16 * 2 * math.pi)
    assert lp.equilibrium_set() == pytest.approx((-b, b))


@pytest.mark.parametrize("kw,match", [
    (dict(m=-1.0), r"mass = -1.0 is not allowed: mass must be > 0"),
    (dict(Fs=1.0), r"Fs = 1.0 is not allowed: the static level Fs must be >= Fc = 2.0"),
    (dict(beta=0.0), r"beta = 0.0 is not allowed: beta must be > 0"),
    (dict(beta=-2), r"beta = -2.0 is not allowed"),
    (dict(vs=float("nan")), r"vs = nan is not allowed: vs must be a finite number"),
    (dict(b=float("inf")), r"b = inf is not allowed: b must be finite"),
    (dict(Q=1.0), r"parameter 'Q' is not a parameter of preset 'table9.1'"),
    (dict(model="karnopp"), r"model = 'karnopp' is not allowed: use one of"),
    (dict(P="ten"), r"P = 'ten' is not a number"),
    (dict(eta=0.0), r"eta = 0.0 is not allowed: eta must be > 0"),
])
def test_bad_parameters_name_parameter_value_and_rule(kw, match):
    with pytest.raises(SystemDefinitionError, match=match):
        preset("table9.1", **kw).system


def test_bad_model_objects():
    with pytest.raises(SystemDefinitionError, match=r"sigma0 = 0.0 is not allowed"):
        LuGre(StribeckCurve(1, 2, 0.1), sigma0=0.0, sigma1=1.0)
    with pytest.raises(SystemDefinitionError, match=r"Fc = 0.0 is not allowed for LuGre"):
        LuGre(StribeckCurve(0.0, 2, 0.1), sigma0=1.0, sigma1=1.0)
    with pytest.raises(SystemDefinitionError, match=r"variant = 'fuzzy' is not allowed"):
        Switch(Coulomb(1.0), variant="fuzzy")
    with pytest.raises(SystemDefinitionError, match=r"strictly increasing"):
        Cogging.table([0, 0, 1], [1, 2, 3])
    with pytest.raises(SystemDefinitionError, match=r"preset = 'table99' is not known"):
        preset("table99")
    with pytest.raises(SystemDefinitionError, match=r"external_force = 'x' is not allowed"):
        Plant(1.0, external_force="x")


def test_bad_simulate_arguments():
    sys_ = preset("table9.1").system
    with pytest.raises(SystemDefinitionError, match=r"x0 has shape \(2,\): table9.1 has 3 states"):
        hunting.simulate(sys_, [0.1, 0.0], (0, 1))
    with pytest.raises(SystemDefinitionError, match=r"x0 = \[nan, 0.0, 0.0\] is not allowed"):
        hunting.simulate(sys_, [np.nan, 0.0, 0.0], (0, 1))
    with pytest.raises(SystemDefinitionError, match=r"t_span = \(1, 0\) is not allowed: need finite t0 < t1"):
        hunting.simulate(sys_, [0.1, 0, 0], (1, 0))
    with pytest.raises(SystemDefinitionError, match=r"method = 'euler' is not allowed"):
        hunting.simulate(sys_, [0.1, 0, 0], (0, 1), method="euler")
    with pytest.raises(SystemDefinitionError, match=r"rtol = -1 is not allowed: rtol must be > 0"):
        hunting.simulate(sys_, [0.1, 0, 0], (0, 1), rtol=-1)
    with pytest.raises(SystemDefinitionError, match=r"max_steps = 0 is not allowed"):
        hunting.simulate(sys_, [0.1, 0, 0], (0, 1), max_steps=0)
    with pytest.raises(SystemDefinitionError, match=r"mode = 'glide' is not a mode of table9.1"):
        hunting.simulate(sys_, [0.1, 0, 0], (0, 1), mode0="glide")
    with pytest.raises(SystemDefinitionError, match=r"t_eval must be a non-empty sorted array inside t_span"):
        hunting.simulate(sys_, [0.1, 0, 0], (0, 1), t_eval=[0.5, 0.2])
    with pytest.raises(SystemDefinitionError, match=r"is not a PiecewiseSystem"):
        hunting.simulate(preset("table9.1"), [0.1, 0, 0], (0, 1))


def test_with_params_shares_compiled_functions():
    sys_ = preset("table9.1").system
    s2 = sys_.with_params(kp=20.0)
    assert s2.vector_field is sys_.vector_field and s2.param("kp") == 20.0 and sys_.param("kp") == 10.0
    with pytest.raises(SystemDefinitionError, match=r"parameter 'P' is not a parameter of table9.1"):
        sys_.with_params(P=1.0)


def test_preset_functions_compile_on_first_use_once():
    # importing the models compiles nothing (a user model or `hunting models` must not pay for
    # the preset loops); building a preset's system compiles each protocol function once, for
    # its signature only, and later presets reuse them; the Jacobian compiles only when a kernel
    # that calls it asks for it (system.kernel_jacobian). Run in a fresh process: under xdist an
    # earlier test in the same worker may already have compiled the Jacobian.
    import subprocess
    import sys
    code = ("import hunting.models, hunting.models.servo as S; "
            "from hunting.models import preset; from hunting.system import kernel_jacobian; "
            "fs = (S.servo_vf, S.servo_guards, S.servo_reset, S.servo_mode_of, S.servo_jac); "
            "print([len(f.overloads) for f in fs]); "
            "preset('table9.1').system; s = preset('table8.1-lugre').system; "
            "print([len(f.overloads) for f in fs]); "
            "kernel_jacobian(s, used=False); print([len(f.overloads) for f in fs]); "
            "kernel_jacobian(s); print([len(f.overloads) for f in fs])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-4:] == [
        "[0, 0, 0, 0, 0]", "[1, 1, 1, 1, 0]", "[1, 1, 1, 1, 0]", "[1, 1, 1, 1, 1]"]
    from hunting.models import servo as S
    preset("table9.1").system
    with pytest.raises(TypeError):
        S.servo_vf(0, 0.0, np.zeros(3, dtype=np.int64), np.zeros(3), np.zeros(3))   # no new specialization
