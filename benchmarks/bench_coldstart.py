"""Cold and warm start of the command line, and where the cold start's compile time goes.

Each scenario runs in a fresh process twice with its own empty numba cache directory
(NUMBA_CACHE_DIR) and model cache (HUNTING_CACHE_DIR): the first run compiles (what a user meets
after installing), the second loads the caches. Both wall and CPU time (user + system of the
process, all threads) are reported: on a shared machine the CPU time is the steadier number.
The cold run also records numba's compile events, so the report lists the functions that take
the compile time (exclusive of the functions they compile in turn).

    python benchmarks/bench_coldstart.py                 # --help, a bad argument, models, simulate, eventmap
    python benchmarks/bench_coldstart.py --full          # and `hunting reproduce ch9` (a minute when cold)
    python benchmarks/bench_coldstart.py --root DIR      # time the hunting tree at DIR (e.g. main)
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

SCENARIOS = {
    "--help": ["--help"],
    "bad argument": ["simulate", "table9.1", "--x0", "a,b,c"],
    "models": ["models"],
    "simulate": ["simulate", "table9.1", "--x0", "0.1,0,0", "--t", "5"],
    "eventmap": ["eventmap", "table9.1", "--grid", "0:0.5:51", "--iterate", "2"],
}

# runs the command line inside a listener for numba's compile events; prints a JSON summary last
RUNNER = r"""
import collections, contextlib, io, json, os, sys, time
t0 = time.perf_counter()
from numba.core import event as ev
excl, stack = collections.defaultdict(float), []
class Listener(ev.Listener):
    def on_start(self, event):
        d = event.data.get("dispatcher")
        stack.append([d.py_func.__module__ + "." + d.py_func.__qualname__ if d else "?", time.perf_counter()])
    def on_end(self, event):
        name, start = stack.pop()
        dt = time.perf_counter() - start
        excl[name] += dt
        if stack:
            excl[stack[-1][0]] -= dt
ev.register("numba:compile", Listener())
from hunting.cli import main
with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
    code = main(sys.argv[1:])
cpu = sum(os.times()[:2])
print(json.dumps(dict(seconds=time.perf_counter() - t0, cpu=cpu, code=code, compile=dict(excl))))
"""


def run(args: list[str], cache: str, root: Path) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, HUNTING_CACHE_DIR=cache, PYTHONPATH=str(root))
    out = subprocess.run([sys.executable, "-c", RUNNER, *args], env=env, capture_output=True, text=True,
                         check=True, cwd=tempfile.gettempdir())
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    scenarios = dict(SCENARIOS)
    root = Path(sys.argv[sys.argv.index("--root") + 1]).resolve() if "--root" in sys.argv else ROOT
    if "--full" in sys.argv:
        scenarios["reproduce ch9"] = ["reproduce", "ch9", "--out", tempfile.mkdtemp(prefix="ch9-")]
    print(f"hunting from {root}")
    print(f"{'scenario':<16}{'cold wall/CPU [s]':>19}{'warm wall/CPU [s]':>19}{'compiling [s]':>15}"
          "  largest compiles (cold)")
    for name, args in scenarios.items():
        with tempfile.TemporaryDirectory() as cache:
            cold = run(args, cache, root)
            warm = run(args, cache, root)
        comp = sorted(cold["compile"].items(), key=lambda kv: -kv[1])
        top = ", ".join(f"{k.rsplit('.', 1)[-1]} {v:.1f}" for k, v in comp[:4] if v > 0.05)
        print(f"{name:<16}{cold['seconds']:>10.1f}/{cold['cpu']:<8.1f}{warm['seconds']:>10.2f}/{warm['cpu']:<8.2f}"
              f"{sum(cold['compile'].values()):>15.1f}  {top}")


if __name__ == "__main__":
    main()
