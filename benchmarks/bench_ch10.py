"""Chapter 10 pipeline timings (issue: identification and the linear motor).

1. The sampled-data simulator of the virtual LiMMS (numba, RK4 substeps) against scipy: the same
   K = 10 regulator loop, one solve_ivp (RK45, rtol 1e-8) per 0.2 ms sample with the digital
   PID in Python, over 2 s; agreement and time ratio.
2. Each stage of ``hunting reproduce ch10``: identification, event maps, experimental event map,
   and one K bifurcation diagram (26 gains) for the model (event maps) and the machine
   (simulation).

    python benchmarks/bench_ch10.py
"""
from __future__ import annotations

import time
from dataclasses import replace

import numpy as np
from scipy.integrate import solve_ivp

from hunting.eventmap import attractors, event_map
from hunting.experiment import VirtualMotor, run
from hunting.experiment import limms as X
from hunting.experiment.motor import Q_D, cogging_and_slope
from hunting.models.friction import lugre_rates
from hunting.reproduce.ch10 import K_VALUES, MAP_OPT


def scipy_sampled(motor: VirtualMotor, K: float, d0: float, n: int) -> np.ndarray:
    """The same sampled loop (no noise, no quantization) with solve_ivp between samples."""
    p = motor.params()
    pid = X.regulator(K)
    dt = 1.0 / motor.fs

    def rhs(t, x, u):
        q, v, z = x
        base, s = (4, 1.0) if v >= 0 else (9, -1.0)
        zdot, F = lugre_rates(v, z, s, *p[base:base + 5], p[2], p[3], 0.0)
        return [v, (p[1] * u - cogging_and_slope(q, p[14:])[0] - F) / p[0], zdot]
    x = np.array([Q_D + d0, 0.0, 0.0])
    I, D, e_prev = 0.0, 0.0, None
    qs = np.empty(n)
    for k in range(n):
        e = x[0] - Q_D
        e_prev = e if e_prev is None else e_prev
        I += dt * e
        D = (e - e_prev) / dt
        e_prev = e
        u = float(np.clip(-(pid.kp * e + pid.kd * D + pid.ki * I), -10, 10))
        qs[k] = x[0]
        x = solve_ivp(rhs, (0, dt), x, args=(u,), rtol=1e-8, atol=1e-12).y[:, -1]
    return qs


def main() -> None:
    motor = VirtualMotor()
    clean = replace(motor, resolution=0.0, noise=0.0)
    n = int(2.0 * motor.fs)
    run(clean, X.regulator(10.0), 100, reference=Q_D, x0=(Q_D + 0.01, 0, 0))           # load
    t0 = time.perf_counter()
    rec = run(clean, X.regulator(10.0), n, reference=Q_D, x0=(Q_D + 0.01, 0, 0))
    t_h = time.perf_counter() - t0
    t0 = time.perf_counter()
    q_s = scipy_sampled(clean, 10.0, 0.01, n)
    t_s = time.perf_counter() - t0
    dev = float(np.max(np.abs(rec.q - q_s)))
    print(f"sampled loop, 2 s at 5 kHz: hunting {t_h * 1e3:.1f} ms, scipy per-sample solve_ivp {t_s:.1f} s "
          f"-> {t_s / t_h:.0f}x; max |q difference| {dev:.2e} m")

    stages = {}
    t0 = time.perf_counter()
    idl = X.identify(motor)
    stages["identification (4 experiments + fits)"] = time.perf_counter() - t0
    loop = idl.loop(10.0)
    t0 = time.perf_counter()
    event_map(loop, np.linspace(-0.015, 0.015, 501), 1, derivative=False, options=MAP_OPT)
    event_map(loop, np.linspace(-0.015, 0.015, 501), 6, derivative=False, options=MAP_OPT)
    stages["event maps P and P^6, 501 points"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    X.experimental_event_map(motor, 10.0, np.linspace(-0.015, 0.015, 60))
    stages["experimental event map, 60 runs of 20 s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    for K in K_VALUES:
        attractors(idl.loop(float(K)), np.linspace(-0.015, 0.015, 12), options=MAP_OPT)
    stages[f"model K diagram ({K_VALUES.size} gains, event-map attractors)"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    X.measured_diagram(motor, K_VALUES)
    stages[f"machine K diagram ({K_VALUES.size} gains x 80 s simulated)"] = time.perf_counter() - t0
    for k, v in stages.items():
        print(f"{k:<58} {v:7.1f} s")
    print(f"{'total':<58} {sum(stages.values()):7.1f} s")


if __name__ == "__main__":
    main()
