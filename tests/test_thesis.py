"""Thesis checks of the foundation (Figs. 4.2, 8.2, 9.4) and banded Switch -> exact Filippov."""
import numpy as np
import pytest

import hunting
from hunting.demo import run_demo
from hunting.models import servo as S


def test_fig_9_4_diverging_stick_slip_sequence():
    loop = hunting.preset("table9.1")
    tr = hunting.simulate(loop.system, [0.1, 0.0, 0.0], (0.0, 12.0))
    k = tr.events.entering(S.STICK)
    d = tr.events.x_after[k, 0]
    assert d[0] == pytest.approx(-0.1223, abs=5e-5)          # thesis P(0.1) = -0.1223
    assert np.all(np.sign(d[1:]) == -np.sign(d[:-1]))         # alternating sides
    assert np.all(np.diff(np.abs(d)) > 0)                     # diverging


def _hunting_cycle(name, method):
    lp = hunting.preset(name)          # K = 0.04, theta_d = 1 rad, start at rest at theta = 0
    tr = hunting.simulate(lp.system, lp.state(x1=-1.0), (0.0, 100.0), method=method, rtol=1e-8,
                          atol=1e-10)
    late = tr.t > 70.0
    # successive velocity maxima of the late response: a periodic cycle
    return tr, np.max(np.abs(tr.x[late, 0])), np.max(tr.x[late, 1])


def test_fig_8_2_both_loops_hunt_and_the_cycles_are_alike():
    tr_s, amp_s, vmax_s = _hunting_cycle("table8.1-switch", "dop853")
    tr_l, amp_l, vmax_l = _hunting_cycle("table8.1-lugre", "radau")
    assert tr_s.success and tr_l.success
    # still moving late in the run: hunting, not settled
    for tr in (tr_s, tr_l):
        assert np.ptp(tr.x[tr.t > 70, 0]) > 0.05
    assert amp_s == pytest.approx(amp_l, rel=0.03)
    assert vmax_s == pytest.approx(vmax_l, rel=0.05)
    # the Switch loop sticks twice per cycle: stick phases keep occurring
    st = tr_s.stick_intervals([S.STICK])
    assert np.sum(st[:, 0] > 70) >= 2


def test_fig_4_2_lugre_presliding_loop_closes():
    lp = hunting.preset("table4.1")
    period = lp.plant.external_force[2]
    tr = hunting.simulate(lp.system, lp.state(), (0.0, period), method="radau", rtol=1e-9, atol=1e-13,
                          t_eval=np.linspace(0, period, 801))
    x, z = tr.x[:, 0], tr.x[:, 3]
    assert np.max(np.abs(z)) <= 1.5 / 1e5               # |z| <= Fs / sigma0 from z(0) = 0
    assert abs(x[-1]) < 1e-3 * np.max(np.abs(x))         # back through zero after a cycle
    # initially dx/dt = dz/dt (thesis: x1 and x3 start with equal derivatives)
    np.testing.assert_allclose(x[:20], z[:20], rtol=0.05, atol=1e-12)


@pytest.mark.parametrize("beta,final_err", [(2.0, 1e-6), (float("inf"), 1.5e-4)])
def test_banded_switch_converges_to_exact_filippov(beta, final_err):
    """Stick errors of the banded variant approach the exact ones as eta -> 0: linearly in eta
    for beta = 2, like sqrt(eta) for the discontinuous curve (break-away starts with zero
    acceleration in the transition band, so crossing the band takes ~ sqrt(eta))."""
    exact = hunting.preset("table9.1", beta=beta)
    tr = hunting.simulate(exact.system, [0.1, 0.0, 0.0], (0.0, 3.0))
    d_exact = tr.events.x_after[tr.events.entering(S.STICK)[:2], 0]
    errs = []
    for eta in (1e-3, 1e-4, 1e-5, 1e-6):
        lp = hunting.preset("table9.1", beta=beta, model="switch-banded", eta=eta)
        tb = hunting.simulate(lp.system, [0.1, 0.0, 0.0], (0.0, 3.0))
        d = tb.events.x_after[tb.events.entering(S.BAND_STICK)[:2], 0]
        errs.append(np.max(np.abs(d - d_exact)))
    assert errs[-1] < final_err and errs[-1] < errs[0] / 20
    assert all(b <= a * 1.01 for a, b in zip(errs, errs[1:]))


def test_demo_main_job_passes(tmp_path):
    assert run_demo(tmp_path) == 0
    for name in ("fig9_4.png", "fig8_2_switch.png", "fig8_2_lugre.png", "fig4_2.png"):
        assert (tmp_path / name).stat().st_size > 10000
    import json
    rows = json.loads((tmp_path / "demo.json").read_text())
    assert len(rows) == 4 and all(r["ok"] for r in rows)


def test_chapter_10_reproducer_quick(tmp_path):
    """The whole chapter-10 pipeline on the virtual LiMMS (identification, equilibrium analysis,
    time responses, event maps, experimental event map, diagrams on a coarse K grid): every check
    against the thesis passes and every figure is written."""
    from hunting.reproduce.ch10 import run
    assert run(tmp_path, quick=True) == 0
    for k in range(4, 13):
        assert (tmp_path / f"fig10_{k}.png").stat().st_size > 10_000
    import json
    res = json.loads((tmp_path / "ch10.json").read_text())
    assert all(row["ok"] for row in res["checks"])
