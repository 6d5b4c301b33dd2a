"""The diagnosis' re-simulation engine against scipy's solve_ivp on the same sampled loop.

Problem: the table 9.1 servo (unit mass, Switch friction with a Stribeck curve) at P = 20 under
its PID updated every 1 ms with a zero-order hold, from rest at an error of 0.5 for 20 s
(hunting: about 15 stick-slip cycles). hunting.diagnose.resimulate integrates each sample
interval with fixed RK4 substeps and the exact Filippov stick; the scipy baseline is the usual
hand-written loop: one solve_ivp call per sample interval (DOP853, terminal event at v = 0, the
same stick test and the same discrete PID). Accuracy: the largest position error over the
samples against a converged hunting run (4000 substeps, itself checked against 2000); speed:
wall-time ratios in this process at comparable accuracy. Inside 1 ms intervals DOP853 is at
rounding level for every rtol; hunting's RK4 substeps are too from 4 substeps on, because each
stop (v = 0) is located by Newton on the step length, not by interpolation.

    python benchmarks/bench_resimulate.py
"""
from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from _timing import best_of
from hunting.diagnose import NominalModel
from hunting.diagnose.data import Measurement
from hunting.diagnose.resimulate import resimulate

DT, T_END, D0 = 1e-3, 20.0, 0.5
SET = {"P": 20.0}
FLOOR = 1e-12            # [m] errors below this are rounding (|q| <= 0.5)




def scipy_loop(model: NominalModel, n: int, rtol: float) -> np.ndarray:
    """Positions at the n sample instants, one solve_ivp call per sample interval."""
    c = model.controller
    kp, kd, ki = c["kp"], c["kd"], c["ki"]
    pos = model.curve.positive                    # symmetric curve in table 9.1
    m, cm = model.mass, model.cm

    def level(a):
        return pos.Fc + (pos.Fs - pos.Fc) * math.exp(-(a / pos.vs) ** pos.beta)

    q, v, stuck = D0, 0.0, True
    e0 = q
    integ = -(0.0 + kp * e0) / ki - DT * e0       # the first output equals the measured u[0] = 0
    prev = e0
    out = np.empty(n)
    for k in range(n):
        e = q
        integ += DT * e
        deriv = (e - prev) / DT
        prev = e
        fa = cm * -(kp * e + kd * deriv + ki * integ)
        out[k] = q
        t, t_end = 0.0, DT
        for _ in range(3):                        # at most a stop and a restart per interval
            if stuck:
                if abs(fa) <= pos.Fs:
                    break
                stuck = False
                s = 1.0 if fa > 0 else -1.0
            else:
                s = 1.0 if v > 0 else -1.0

            def rhs(_, x, s=s):
                return [x[1], (fa - s * level(abs(x[1])) - pos.b * x[1]) / m]

            def stop(_, x, s=s):
                return s * x[1]
            stop.terminal, stop.direction = True, -1
            sol = solve_ivp(rhs, (t, t_end), [q, v], method="DOP853", rtol=rtol, atol=rtol * 1e-2, events=stop)
            q, v = float(sol.y[0, -1]), float(sol.y[1, -1])
            if sol.status != 1:
                break
            t, v, stuck = float(sol.t_events[0][0]), 0.0, True
            q = float(sol.y_events[0][0][0])
    return out


def main() -> None:
    model = NominalModel.from_dict({"preset": "table9.1", "set": SET})
    n = int(T_END / DT)
    t = np.arange(n) * DT
    meas = Measurement(t, np.full(n, D0), np.zeros(n), q_ref=np.zeros(n))

    def ours(sub):
        return resimulate(meas, model, resolution=0.0, substeps=sub).q
    ref = ours(4000)
    check = float(np.max(np.abs(ours(2000) - ref)))
    print(f"reference: 4000 substeps, against 2000: {check:.2e}; |q| <= {np.max(np.abs(ref)):.3g}")
    print(f"{'method':<28}{'time [s]':>10}{'max error':>12}")
    rows = {}
    for sub in (4, 10, 20, 40):
        ours(sub)
        el, q = best_of(lambda: ours(sub), repeat=3)
        rows[f"hunting substeps={sub}"] = (el, float(np.max(np.abs(q - ref))))
    for rtol in (1e-6, 1e-8, 1e-10):
        el, q = best_of(lambda: scipy_loop(model, n, rtol), repeat=1)
        rows[f"scipy DOP853 rtol={rtol:g}"] = (el, float(np.max(np.abs(q - ref))))
    for name, (el, err) in rows.items():
        print(f"{name:<28}{el:>10.4f}{err:>12.2e}")
    print(f"speed ratios (scipy time / hunting time) where hunting's error is at most the scipy run's or "
          f"below {FLOOR:g} (rounding level):")
    for sname, (st, serr) in rows.items():
        if not sname.startswith("scipy"):
            continue
        ok = [(el, name) for name, (el, err) in rows.items()
              if name.startswith("hunting") and err <= max(serr, FLOOR)]
        if ok:
            el, name = min(ok)
            print(f"  {sname}: {name} is {st / el:.0f}x faster")
        else:
            print(f"  {sname}: no hunting setting as accurate")


if __name__ == "__main__":
    main()
