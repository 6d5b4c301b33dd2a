"""Cold and warm start of the command line, and where the cold start's compile time goes.

Each scenario runs in a fresh process twice with its own empty numba cache directory
(NUMBA_CACHE_DIR): the first run compiles (what a user meets after installing), the second
loads the cache. The cold run also records numba's compile events, so the report lists the
functions that take the compile time (exclusive of the functions they compile in turn).

    python benchmarks/bench_coldstart.py                 # --help, a bad argument, models, simulate, eventmap
    python benchmarks/bench_coldstart.py --full          # and `hunting reproduce ch9` (minutes when cold)
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
import collections, contextlib, io, json, sys, time
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
print(json.dumps(dict(seconds=time.perf_counter() - t0, code=code, compile=dict(excl))))
"""


def run(args: list[str], cache: str) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=str(ROOT))
    out = subprocess.run([sys.executable, "-c", RUNNER, *args], env=env, capture_output=True, text=True,
                         check=True, cwd=tempfile.gettempdir())
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    scenarios = dict(SCENARIOS)
    if "--full" in sys.argv:
        scenarios["reproduce ch9"] = ["reproduce", "ch9", "--out", tempfile.mkdtemp(prefix="ch9-")]
    print(f"{'scenario':<16}{'cold [s]':>10}{'warm [s]':>10}{'compiling [s]':>15}  largest compiles (cold)")
    for name, args in scenarios.items():
        with tempfile.TemporaryDirectory() as cache:
            cold = run(args, cache)
            warm = run(args, cache)
        comp = sorted(cold["compile"].items(), key=lambda kv: -kv[1])
        top = ", ".join(f"{k.rsplit('.', 1)[-1]} {v:.1f}" for k, v in comp[:4] if v > 0.05)
        print(f"{name:<16}{cold['seconds']:>10.1f}{warm['seconds']:>10.2f}{sum(cold['compile'].values()):>15.1f}  {top}")


if __name__ == "__main__":
    main()
