"""The virtual LiMMS: its sampled-data simulator against the exact hybrid integrator, and the
identification toolkit run on its signals (issue: identification, chapter 10)."""
from dataclasses import replace

import numpy as np
import pytest

from hunting.errors import SystemDefinitionError
from hunting.experiment import DiscretePID, VirtualMotor, run
from hunting.experiment import limms as L
from hunting.experiment.motor import F_QD, Q_D, SLOPE_QD
from hunting.integrate import simulate
from hunting.models import PID, LuGre, Plant, ServoLoop


def test_synthetic_cogging_honours_the_thesis():
    m = VirtualMotor()
    F, dF = m.cogging_force(np.array([Q_D]))
    assert F[0] == pytest.approx(F_QD, abs=1e-9) and dF[0] == pytest.approx(SLOPE_QD, rel=1e-9)
    q = np.arange(-0.52, 0.0, 1e-5)
    F, dF = m.cogging_force(q)
    assert np.max(np.abs(dF)) <= 1e4
    # slope consistent with the force (finite differences)
    assert np.max(np.abs(np.gradient(F, q)[5:-5] - dF[5:-5])) < 1e-3 * np.max(np.abs(dF))
    # dominant spatial period ~ 15 mm on both parts, different patterns on the two parts
    for lo, hi in ((-0.5, -0.3), (-0.3, -0.05)):
        sel = (q > lo) & (q < hi)
        spec = np.abs(np.fft.rfft(F[sel] - F[sel].mean()))
        k = np.fft.rfftfreq(sel.sum(), 1e-5)
        assert 1 / k[np.argmax(spec)] == pytest.approx(0.015, rel=0.05)
    a = F[(q > -0.45) & (q < -0.33)]
    b = F[(q > -0.27) & (q < -0.15)]
    assert abs(np.std(a) - np.std(b)) > 0.5 or abs(np.corrcoef(a[:b.size], b[:a.size])[0, 1]) < 0.9


def test_sampled_simulator_matches_the_exact_integrator():
    """At 100 kHz without quantization the sampled loop tends to the continuous one: the hunting
    kernel (events at v = 0, DOP853) on the same LuGre plant with the true cogging table."""
    m = replace(VirtualMotor(), fs=100_000.0, substeps=2, resolution=0.0, noise=0.0)
    K, d0, T = 10.0, 0.01, 2.0
    loop = ServoLoop(Plant(m.mass, m.cm, setpoint=Q_D, cogging=m.cogging_table(2e-6)),
                     LuGre(m.curve, sigma0=m.sigma0, sigma1=m.sigma1), PID.fixed_shape(K))
    n = int(T * m.fs)
    rec = run(m, L.regulator(K), n, reference=Q_D, x0=(Q_D + d0, 0.0, 0.0))
    tr = simulate(loop.system, [d0, 0, 0, 0], (0, rec.t[-1]), t_eval=rec.t, method="radau", rtol=1e-8, atol=1e-12)
    assert tr.success, tr.message
    err = np.max(np.abs((rec.q - Q_D) - tr.x[:, 0]))
    assert err < 2e-3 * np.max(np.abs(tr.x[:, 0])), err


def test_substeps_converge():
    m = VirtualMotor()
    a = run(m, L.regulator(10.0), 10_000, reference=Q_D, x0=(Q_D + 0.01, 0, 0))
    b = run(replace(m, substeps=40), L.regulator(10.0), 10_000, reference=Q_D, x0=(Q_D + 0.01, 0, 0))
    assert np.max(np.abs(a.q - b.q)) < 1e-7


def _check_identified(motor, idl):
    m_rel = idl.m / motor.mass - 1
    assert abs(m_rel) < 0.01, m_rel
    for key, true in (("positive", motor.positive), ("negative", motor.negative)):
        f = idl.friction[key].values
        assert f["Fs"] == pytest.approx(true.Fs, rel=0.02)
        assert f["Fc"] == pytest.approx(true.Fc, rel=0.02)
        assert f["vs"] == pytest.approx(true.vs, rel=0.05)
        assert f["b"] == pytest.approx(true.b, rel=0.05)
    # presliding: LuGre's softening at the excitation level biases sigma0 low by ~5 %
    assert idl.presliding.values["sigma0"] == pytest.approx(motor.sigma0, rel=0.15)
    assert idl.presliding.values["sigma1"] == pytest.approx(motor.sigma1, rel=0.15)
    q = np.arange(-0.48, -0.05, 1e-4)
    Ft, dFt = motor.cogging_force(q)
    err = idl.cogging(q) - Ft
    # ~0.35 N rms whatever the amplitude: the strong PID turning 1 um encoder steps into force
    assert np.sqrt(np.mean(err ** 2)) < 0.5
    assert np.sqrt(np.mean(err ** 2)) < 0.08 * np.sqrt(np.mean(Ft ** 2))
    assert np.sqrt(np.mean((idl.cogging.slope(q, dq=2e-4) - dFt) ** 2)) < 0.15 * np.sqrt(np.mean(dFt ** 2))


def test_identification_recovers_the_virtual_limms():
    """Tolerances: m/cm 1 % (coherence > 0.99 on 30-140 Hz, 72 averages); Stribeck levels 2 %,
    vs and b 5 % (12 speeds per direction, force noise ~0.05 N after averaging); sigma0, sigma1
    15 % (LuGre's presliding nonlinearity, not noise, dominates; the thesis' own spread across
    positions is a factor 4); cogging table within 0.5 N and 8 % rms of its amplitude (the error,
    0.35 N rms, is the strong PID's reaction to 1 um encoder steps), slope within 15 % rms."""
    motor = VirtualMotor()
    idl = L.identify(motor)
    _check_identified(motor, idl)
    assert idl.cogging.slope(np.array([Q_D]), dq=2e-4)[0] == pytest.approx(SLOPE_QD, rel=0.1)


@pytest.mark.parametrize("seed", [11])
def test_identification_finds_a_hidden_motor(seed):
    """A random cogging pattern, friction levels and sigma0 hidden in the motor must be found."""
    motor = VirtualMotor.random(seed)
    _check_identified(motor, L.identify(motor, seed=seed))


def test_stick_phase_detection_on_a_hunting_record():
    m = VirtualMotor()
    rec = L.regulator_experiment(m, 10.0, 0.01, 20.0)
    ph = L.stick_phases(rec, m.resolution)
    assert len(ph) >= 6
    # during a detected stick phase the true velocity is tiny (presliding only)
    for a, b in ph[:6]:
        assert np.max(np.abs(rec.qd[a:b])) < 2e-3


def test_bad_input_is_named():
    m = VirtualMotor()
    with pytest.raises(SystemDefinitionError, match="n ="):
        run(m, None, 0)
    with pytest.raises(SystemDefinitionError, match="reference"):
        run(m, None, 10, reference=np.zeros(3))
    with pytest.raises(SystemDefinitionError, match="substeps"):
        replace(m, substeps=0)
    with pytest.raises(SystemDefinitionError, match="tau_f"):
        DiscretePID(1.0, 0.0, 0.0, tau_f=-1.0)
    with pytest.raises(SystemDefinitionError, match="model"):
        L.IdentifiedLiMMS(74.4, None, {}, None, None, 0.0).loop(10.0, model="coulomb")


def test_discrete_pid_frf_is_the_law_the_simulator_runs():
    """DiscretePID.frf against the numba loop itself: a motor too heavy to move, a sinusoidal
    reference, and the recorded feedback u_c = -C(e) read at the excitation frequency."""
    m = replace(VirtualMotor(), mass=1e15, resolution=0.0, noise=0.0)
    pid = DiscretePID(kp=8.2e3, kd=53.0, ki=3.8e5, tau_f=4.3e-4)
    n, f0 = 50_000, 37.0                                  # 10 s, 370 whole periods
    t = np.arange(n) / m.fs
    r = 1e-5 * np.sin(2 * np.pi * f0 * t)
    rec = run(m, pid, n, reference=r, x0=(0.0, 0.0, 0.0), u_max=1e9)
    e = rec.y - r
    sel = slice(n // 2, n)                              # after the integrator's start-up
    ph = np.exp(-2j * np.pi * f0 * t[sel])
    C_meas = np.sum(-rec.uc[sel] * ph) / np.sum(e[sel] * ph)
    C = pid.frf(np.array([f0]), m.fs)[0]
    assert abs(C_meas / C - 1) < 1e-3, (C_meas, C)
