"""Models from descriptions: compile time, cache, and run time against hand-written kernels.

1. Cold compile of a 4-state user model (the PID + LuGre loop of examples/pid_lugre.json) in a
   fresh process with an empty model cache (the library's own kernels come from numba's cache,
   as after any first run): description -> sympy -> generated module -> numba, then the first
   simulate. Then the same in a second process (the model cache hit: no sympy, no compile), and
   in a third process at other parameter values (the same structure: no compile either).
2. Run time of compiled models against hand-written kernels of the same systems, in this
   process (best of several runs, ratio described / hand-written; the issue asks <= 1.5):
   the belt of examples/belt.json against numba functions written here by hand, the Table 9.1
   loop (DOP853, 50 events) and the Table 8.1 LuGre loop (Radau, 20 s; and a flow with
   monodromy matrix) against hunting.models.servo.

    python benchmarks/bench_describe.py
"""
from __future__ import annotations

import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numba
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import hunting  # noqa: E402
from _timing import best_of  # noqa: E402
from hunting import GUARD_SIG, JAC_SIG, MODE_SIG, RESET_SIG, VF_SIG, Mode, PiecewiseSystem  # noqa: E402

# ---------------------------------------------------------------- the belt, written by hand
# p = [m, k, Fc, Fs, vs, vb]; states q, v; w = v - vb; modes slip+, slip-, stick


@numba.njit(VF_SIG, cache=True, error_model="numpy", _nrt=False)
def belt_vf(mode, t, x, p, out):
    out[0] = x[1]
    if mode == 2:
        out[1] = 0.0
        return
    s = 1.0 if mode == 0 else -1.0
    w = x[1] - p[5]
    F = s * (p[2] + (p[3] - p[2]) * math.exp(-s * w / p[4]))
    out[1] = (-p[1] * x[0] - F) / p[0]


@numba.njit(JAC_SIG, cache=True, error_model="numpy", _nrt=False)
def belt_jac(mode, t, x, p, J):
    J[0, 0] = 0.0
    J[0, 1] = 1.0
    J[1, 0] = 0.0
    J[1, 1] = 0.0
    if mode == 2:
        return
    s = 1.0 if mode == 0 else -1.0
    w = x[1] - p[5]
    J[1, 0] = -p[1] / p[0]
    J[1, 1] = (p[3] - p[2]) * math.exp(-s * w / p[4]) / p[4] / p[0]


@numba.njit(GUARD_SIG, cache=True, error_model="numpy", _nrt=False)
def belt_guards(mode, t, x, p, out):
    if mode == 2:
        F = -p[1] * x[0]
        out[0] = p[3] - F
        out[1] = p[3] + F
    else:
        w = x[1] - p[5]
        out[0] = w if mode == 0 else -w
        out[1] = 1.0


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def _belt_rest(t, x, p):
    F = -p[1] * x[0]
    if F > p[3]:
        return 0
    if F < -p[3]:
        return 1
    return 2


@numba.njit(RESET_SIG, cache=True, error_model="numpy", _nrt=False)
def belt_reset(mode, guard, t, x, p, x_out):
    for i in range(x.size):
        x_out[i] = x[i]
    if mode == 2:
        return 0 if guard == 0 else 1
    x_out[1] = p[5]
    return _belt_rest(t, x_out, p)


@numba.njit(MODE_SIG, cache=True, error_model="numpy", _nrt=False)
def belt_mode(t, x, p):
    w = x[1] - p[5]
    if w > 0:
        return 0
    if w < 0:
        return 1
    return _belt_rest(t, x, p)


def belt_by_hand(params) -> PiecewiseSystem:
    return PiecewiseSystem(name="belt (hand)", state_names=("q", "v"),
                           modes=(Mode("slip+"), Mode("slip-"), Mode("stick", "stick", 1)),
                           guard_names=("w / up", "down"), param_names=("m", "k", "Fc", "Fs", "vs", "vb"),
                           params=np.asarray(params, float), vector_field=belt_vf, guards=belt_guards,
                           transition=belt_reset, mode_of=belt_mode, jacobian=belt_jac)


# ---------------------------------------------------------------- compile and start-up
_CHILD = """
import time, resource
t0 = time.perf_counter(); c0 = time.process_time()
import hunting
t1 = time.perf_counter(); c1 = time.process_time()
m = hunting.load_model({path!r}{over})
t2 = time.perf_counter(); c2 = time.process_time()
tr = hunting.simulate(m.system, m.state(), (0, 20), method="radau", rtol=1e-8, atol=1e-11)
t3 = time.perf_counter(); c3 = time.process_time()
import sys
print(t1 - t0, t2 - t1, t3 - t2, c2 - c1, c3 - c2, "sympy" in sys.modules, tr.success)
"""


def startup(cache: str, over: str = "") -> list:
    env = dict(os.environ, HUNTING_CACHE_DIR=cache)
    code = _CHILD.format(path=str(ROOT / "examples" / "pid_lugre.json"), over=over)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True,
                         cwd=str(ROOT)).stdout.split()
    return [float(v) for v in out[:5]] + [out[5] == "True", out[6] == "True"]


def ratio(label: str, run_desc, run_hand, repeat: int = 5) -> float:
    run_desc()
    run_hand()
    t_d, a = best_of(run_desc, repeat)
    t_h, b = best_of(run_hand, repeat)
    r = t_d / t_h
    print(f"  {label:<44} described {t_d * 1e3:8.2f} ms   hand-written {t_h * 1e3:8.2f} ms   ratio {r:5.2f}")
    return r, a, b


def main() -> None:
    print("Compile a 4-state user model (examples/pid_lugre.json: PID + LuGre, 2 modes), fresh processes:")
    with tempfile.TemporaryDirectory() as cache:
        cold = startup(cache)
        warm = startup(cache)
        other = startup(cache, over=", kp=5.0, ki=2.0")
    for label, r in (("empty model cache", cold), ("cached", warm), ("cached, other parameter values", other)):
        print(f"  {label:<32} import {r[0]:5.2f} s   model {r[1]:6.2f} s wall ({r[3]:5.2f} s CPU)   "
              f"first simulate {r[2]:5.2f} s   sympy imported: {r[5]}")

    print("Run time, described / hand-written (same process, best of 5):")
    belt = hunting.load_model(ROOT / "examples" / "belt.json")
    hand = belt_by_hand(belt.params)
    x0 = [0.0, 0.1]
    kw = dict(rtol=1e-10, atol=1e-12, max_events=200)
    r1, a, b = ratio("belt, 200 events (DOP853)", lambda: hunting.simulate(belt.system, x0, (0, 1e4), **kw),
                     lambda: hunting.simulate(hand, x0, (0, 1e4), **kw))
    assert np.allclose(a.events.t, b.events.t, atol=1e-9)

    m91 = hunting.model("table9.1")
    l91 = hunting.preset("table9.1")
    kw = dict(rtol=1e-10, atol=1e-12, max_events=50)
    r2, a, b = ratio("table9.1, 50 events (DOP853)", lambda: hunting.simulate(m91.system, [0.1, 0, 0], (0, 1e3), **kw),
                     lambda: hunting.simulate(l91.system, [0.1, 0, 0], (0, 1e3), **kw))
    assert np.allclose(a.events.t, b.events.t, atol=1e-9)

    ml = hunting.model("table8.1-lugre", K=0.3)
    ll = hunting.preset("table8.1-lugre", K=0.3)
    kw = dict(method="radau", rtol=1e-8, atol=1e-11)
    r3, a, b = ratio("table8.1-lugre K = 0.3, 20 s (Radau)",
                     lambda: hunting.simulate(ml.system, [-1, 0, 0, 0], (0, 20), **kw),
                     lambda: hunting.simulate(ll.system, [-1, 0, 0, 0], (0, 20), **kw))
    from hunting.continuation import flow
    x0 = np.array([0.0, 0.05, -0.01, 2e-5])
    r4, a, b = ratio("table8.1-lugre flow + monodromy, 14 s (Radau)",
                     lambda: flow(ml.system, x0, 14.0, **kw), lambda: flow(ll.system, x0, 14.0, **kw))
    print(f"  worst ratio {max(r1, r2, r3, r4):.2f} (target <= 1.5)")


if __name__ == "__main__":
    main()
