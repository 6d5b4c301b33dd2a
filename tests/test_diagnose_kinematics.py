"""The force balance's drive: the delayed zero-order-held drive as the position's second
difference sees it, against quadrature of the delayed staircase under the triangular kernel."""
import numpy as np
import pytest

from hunting.diagnose import Measurement, kinematics


@pytest.mark.parametrize("delay", [0.0004, 0.0017, 0.003])
def test_delayed_drive_is_the_second_difference_of_the_delayed_staircase(delay):
    """u held over [t_k, t_k+1) and delayed by a fraction of samples: the second difference of
    the position at t_k sees the staircase weighted by (dt - |s|) / dt^2 over [t_k - dt, t_k +
    dt]. Linear interpolation of the aligned drive is off by 0.4 (of a unit random walk) there."""
    rng = np.random.default_rng(0)
    n, dt, cm = 400, 1e-3, 2.0
    t = np.arange(n) * dt
    u = np.cumsum(rng.normal(size=n))
    kin = kinematics(Measurement(t, np.zeros(n), u), cm, resolution=0.0)
    got = kin.delayed_drive(delay)
    s = np.linspace(-dt, dt, 40001)
    w = (dt - np.abs(s)) / dt ** 2
    for k in range(50, 70):
        j = np.clip(np.floor((t[k] + s - delay) / dt + 1e-12).astype(int), 0, n - 1)
        exact = cm * np.trapezoid(w * u[j], s)
        assert got[k] == pytest.approx(exact, abs=1e-3)
    # whole samples: the aligned drive shifted
    assert np.allclose(kin.delayed_drive(2 * dt)[10:], kin.drive[8:-2])
