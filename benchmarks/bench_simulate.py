"""hunting.simulate against scipy's solve_ivp on the Table 9.1 loop (issue: foundation).

Both integrate the exact-Filippov Switch loop from the stick state x = (0.1, 0, 0) over 50
stick-slip events (stick entries, break-aways) with DOP853 at the same tolerances; scipy chains
solve_ivp calls with terminal events and steps stick phases in closed form (the usual hand-written
approach). Accuracy of both is measured against a tight hunting run; speed is the ratio of
wall times in this process. Also reports the cold numba compile time and the cached start-up
time, each in a fresh subprocess.

    python benchmarks/bench_simulate.py
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import hunting  # noqa: E402
from hunting.models import servo as S  # noqa: E402
from _timing import best_of  # noqa: E402
from reference import scipy_switch_sequence  # noqa: E402

RTOL, ATOL = 1e-10, 1e-12
N_EVENTS = 50




def startup_times() -> tuple[float, float]:
    code = ("import time; t0 = time.perf_counter(); import hunting; "
            "lp = hunting.preset('table9.1'); hunting.simulate(lp.system, [0.1, 0, 0], (0, 5)); "
            "print(time.perf_counter() - t0)")
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        cold = float(subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                                    check=True).stdout.split()[-1])
        warm = float(subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                                    check=True).stdout.split()[-1])
    return cold, warm


def main() -> None:
    loop = hunting.preset("table9.1")
    x0 = [0.1, 0.0, 0.0]
    n_sticks = len(hunting.simulate(loop.system, x0, (0.0, 1e3), rtol=RTOL, atol=ATOL,
                                    max_events=N_EVENTS).events.entering(S.STICK))

    def run_hunting():
        return hunting.simulate(loop.system, x0, (0.0, 1e3), rtol=RTOL, atol=ATOL, max_events=N_EVENTS)

    def run_scipy():
        return scipy_switch_sequence(1.0, 10.0, 10.0, 100.0, 4.0, 2.0, 0.1, 2.0, 1.0, 0.1, n_sticks,
                                     rtol=RTOL, atol=ATOL)

    def run_unchecked():     # the same run without the growth check (status DIVERGED)
        return hunting.simulate(loop.system, x0, (0.0, 1e3), rtol=RTOL, atol=ATOL, max_events=N_EVENTS,
                                growth=None)

    run_hunting()  # compile / load from cache
    t_h, tr = best_of(run_hunting)
    t_u, _ = best_of(run_unchecked, repeat=20)
    t_h = min(t_h, best_of(run_hunting, repeat=20)[0])
    t_s, (d_s, _, nfev_s) = best_of(run_scipy, repeat=2)
    ref = hunting.simulate(loop.system, x0, (0.0, 1e3), rtol=1e-13, atol=1e-15, max_events=N_EVENTS)
    k_ref = ref.events.entering(S.STICK)
    k = tr.events.entering(S.STICK)
    m = min(len(k), len(d_s), len(k_ref))
    d_ref = ref.events.x_after[k_ref[:m], 0]
    err_h = np.max(np.abs(tr.events.x_after[k[:m], 0] - d_ref))
    err_s = np.max(np.abs(d_s[:m] - d_ref))
    cold, warm = startup_times()
    print(f"Table 9.1 loop, x0 = (0.1, 0, 0), {len(tr.events)} events ({m} stick phases), DOP853 "
          f"rtol={RTOL:g} atol={ATOL:g}")
    print(f"  hunting.simulate : {t_h * 1e3:8.2f} ms  {tr.stats['n_fev']:7d} f evals  max stick-error deviation {err_h:.1e}")
    print(f"  scipy solve_ivp  : {t_s * 1e3:8.2f} ms  {nfev_s:7d} f evals  max stick-error deviation {err_s:.1e}")
    print(f"  speed ratio scipy / hunting: {t_s / t_h:.0f}x")
    print(f"  growth check (status DIVERGED) cost: default / growth=None = {t_h / t_u:.3f}")
    print(f"  start-up (import + first simulate): cold compile {cold:.1f} s, cached {warm:.2f} s")


if __name__ == "__main__":
    main()
