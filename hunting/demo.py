"""Short simulations of chapters 4, 8 and 9, checked against the thesis (`hunting demo`).

* Fig. 9.4: Table 9.1 loop from x(0) = (0.1, 0, 0): a diverging stick-slip sequence whose first
  stick phase has x1 = -0.1223 (thesis; confirmed independently).
* Fig. 8.2: Table 8.1 loops (LuGre and Switch), regulator task theta_d = 1 rad at K = 0.04: both
  end in a hunting cycle, and the two cycles are alike.
* Fig. 4.2: LuGre presliding (Table 4.1): a force ramped to 95 % of Fs and back gives a closed
  hysteresis loop back through zero.
Each check prints the thesis value beside ours and is drawn on its figure; the exit code is
non-zero on a mismatch.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from . import simulate
from ._atomic import write_text
from .models import preset
from .plotting import plot_hysteresis, plot_trajectory, save, thesis_marks
from .reproduce.checks import Ledger


def _cycle_amplitude(tr, t_from: float) -> float:
    sel = tr.t >= t_from
    return float(np.max(np.abs(tr.x[sel, 0])))


def run_demo(out: Path) -> int:
    out.mkdir(parents=True, exist_ok=True)
    L = Ledger("Demo")
    print("Fig. 9.4 -- Table 9.1, x(0) = (0.1, 0, 0)")
    loop = preset("table9.1")
    tr = simulate(loop.system, [0.1, 0.0, 0.0], (0.0, 12.0), throw=True)
    sticks = tr.events.entering(loop.stick_mode)
    d = tr.events.x_after[sticks, 0]
    L.number("first stick error P(0.1) [m]", float(d[0]), -0.1223, 5e-5)
    L.number("stick errors grow in magnitude (1 = yes)", float(np.all(np.diff(np.abs(d)) > 0)), 1.0, 0.0)
    fig = plot_trajectory(tr, title="Fig. 9.4: Table 9.1 loop from (0.1, 0, 0)", stick_modes=[loop.stick_mode],
                          units=loop.system.units)
    thesis_marks(fig.axes[0], tr.events.t[sticks[0]], -0.1223, label="thesis: P(0.1) = -0.1223")
    fig.axes[0].legend(fontsize=7, loc="upper left")
    L.on_figure(fig.axes[0], [("P(0.1) [m]", "first stick error P(0.1) [m]", ".5f")], room=0.35)
    save(fig, out / "fig9_4.png")

    print("Fig. 8.2 -- Table 8.1, theta_d = 1 rad, K = 0.04")
    amps, figs = {}, {}
    for name, method in (("table8.1-switch", "dop853"), ("table8.1-lugre", "radau")):
        lp = preset(name)
        tr = simulate(lp.system, lp.state(x1=-1.0), (0.0, 80.0), method=method, rtol=1e-8, atol=1e-10,
                      throw=True)
        amps[name] = _cycle_amplitude(tr, 60.0)
        figs[name] = plot_trajectory(tr, title=f"Fig. 8.2: {name}, K = 0.04", units=lp.system.units,
                                     stick_modes=[lp.stick_mode] if lp.stick_mode is not None else [])
    L.number("hunting amplitude Switch / LuGre (alike)", amps["table8.1-switch"] / amps["table8.1-lugre"], 1.0, 0.05)
    for name, fig in figs.items():
        L.on_figure(fig.axes[0], [("amplitude Switch/LuGre", "hunting amplitude Switch / LuGre (alike)", ".3f")],
                    room=0.4)
        save(fig, out / f"fig8_2_{name.split('-')[1]}.png")

    print("Fig. 4.2 -- LuGre presliding, Table 4.1")
    lp = preset("table4.1")
    period = lp.plant.external_force[2]
    t_eval = np.linspace(0.0, period, 2001)
    tr = simulate(lp.system, lp.state(), (0.0, period), method="radau", rtol=1e-9, atol=1e-13,
                  t_eval=t_eval, throw=True)
    from .models.plant import FEXT_TRIANGLE, external_force
    force = np.array([external_force(t, FEXT_TRIANGLE, lp.plant.external_force[1], period) for t in tr.t])
    xmax = float(np.max(np.abs(tr.x[:, 0])))
    L.number("displacement after one force cycle / max", float(abs(tr.x[-1, 0]) / xmax), 0.0, 1e-3)
    plot_hysteresis(force, tr.x[:, 0], title="Fig. 4.2: LuGre presliding (Table 4.1): a closed loop, "
                    f"back to {abs(tr.x[-1, 0]) / xmax:.1e} of its width (thesis: 0)", path=out / "fig4_2.png")
    write_text(out / "demo.json", json.dumps(L.rows, indent=2))     # a list of checks (the demo's format)
    return L.finish(out)
