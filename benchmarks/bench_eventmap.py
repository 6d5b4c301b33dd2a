"""Event maps against a plain scipy implementation (issue: event maps).

1. The event map P of Table 9.1 (beta = 2) on 1001 points of [0, 0.5]: hunting.event_map (numba,
   parallel over grid points) against a plain loop of solve_ivp calls (DOP853 with terminal
   events, the usual hand-written event map), same tolerances, both checked against a tight
   reference (target: image accurate to 1e-8). Reports points per second per core and the ratio.
2. The full Fig. 9.8: 4 friction curves x 22 gains P = 10..31, fixed points of P^2 refined, folds
   and stability changes refined in P.

    python benchmarks/bench_eventmap.py
"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

import hunting
from hunting.eventmap import MapOptions, event_map, map_diagram

RTOL, ATOL = 1e-10, 1e-12


def scipy_event_map(d_grid, rtol=RTOL, atol=ATOL):
    m, kp, kd, ki, Fs, Fc, vs, b = 1.0, 10.0, 10.0, 100.0, 4.0, 2.0, 0.1, 1.0

    def rhs(t, x, s):
        F = -(kp * x[0] + kd * x[1] + ki * x[2])
        g = Fc + (Fs - Fc) * np.exp(-(x[1] / vs) ** 2)
        return [x[1], (F - s * g - b * x[1]) / m, x[0]]

    def stop(t, x, s):
        return x[1]
    stop.terminal = True
    out = np.empty(len(d_grid))
    for i, d in enumerate(d_grid):
        if d == 0:
            out[i] = 0.0
            continue
        target = -np.sign(d) * Fs
        x = np.array([d, 0.0, (-target - kp * d) / ki])
        s = -np.sign(d)
        t = 0.0
        for _ in range(50):
            stop.direction = -s
            sol = solve_ivp(rhs, (t, t + 100.0), x, method="DOP853", rtol=rtol, atol=atol, events=stop, args=(s,))
            t, x = sol.t_events[0][0], sol.y_events[0][0].copy()
            x[1] = 0.0
            F = -(kp * x[0] + ki * x[2])
            if abs(F) <= Fs:
                break
            s = -s
        out[i] = x[0]
    return out


def main() -> None:
    loop = hunting.preset("table9.1")
    grid = np.linspace(0.0, 0.5, 1001)
    opt = MapOptions(rtol=RTOL)
    event_map(loop, grid[:10], 1, derivative=False, options=opt)      # compile / load
    ts = []
    for _ in range(5):
        t0 = time.perf_counter()
        em = event_map(loop, grid, 1, derivative=False, options=opt)
        ts.append(time.perf_counter() - t0)
    t_h = min(ts)
    ref = event_map(loop, grid, 1, derivative=False, options=MapOptions(rtol=1e-13)).image
    t0 = time.perf_counter()
    sc = scipy_event_map(grid)
    t_s = time.perf_counter() - t0
    cores = os.cpu_count() or 1
    err_h = np.max(np.abs(em.image - ref))
    err_s = np.max(np.abs(sc - ref))
    print(f"Event map P, Table 9.1 (beta = 2), 1001 points on [0, 0.5], DOP853 rtol={RTOL:g} atol={ATOL:g}")
    print(f"  hunting.event_map : {t_h * 1e3:8.1f} ms  {grid.size / t_h / cores:9.0f} points/s/core "
          f"({cores} cores)  max error {err_h:.1e}")
    print(f"  scipy solve_ivp   : {t_s * 1e3:8.1f} ms  {grid.size / t_s:9.0f} points/s (1 core)   max error {err_s:.1e}")
    print(f"  speed ratio scipy / hunting: {t_s / t_h:.0f}x (per core: {t_s / t_h / cores:.0f}x)")

    t0 = time.perf_counter()
    out = {}
    for name, kw in (("beta=2", dict(beta=2.0)), ("beta=1", dict(beta=1.0)), ("beta=0.5", dict(beta=0.5)),
                     ("discontinuous", dict(beta="inf"))):
        out[name] = map_diagram("table9.1", "P", np.arange(10, 32, dtype=float), overrides=kw)
    t_f = time.perf_counter() - t0
    fold = next(s.param for s in out["beta=2"].special if s.kind == "fold")
    print(f"Fig. 9.8 (4 curves x 22 gains, fixed points refined, fold and stability changes refined): "
          f"{t_f:.2f} s; beta=2 fold at P = {fold:.5f}")


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    main()
