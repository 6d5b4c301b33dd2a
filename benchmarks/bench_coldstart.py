"""Cold and warm start of the command line, and where the cold start's compile time goes.

Each scenario runs in a fresh process twice with its own empty numba cache directory
(NUMBA_CACHE_DIR) and model cache (HUNTING_CACHE_DIR), so the worktree's own caches are neither
used nor touched: the first run compiles (what a user meets after installing), the second loads
the caches. Both wall and CPU time (user + system of the process, all threads; not of the helper
process that compiles kernels ahead, :mod:`hunting.integrate.ahead`, so compare wall times, or
set HUNTING_COMPILE_AHEAD=0 for the single-process figures) are reported, and ``--repeat N``
keeps the cold run of lowest wall time of N (each in new empty caches). The cold run also records numba's compile
events, so the report lists the functions that take the compile time (exclusive of the
functions they compile in turn). For the user model (examples/pid_lugre.json: PID + LuGre,
4 states) a third run compiles the model alone: library caches warm, model cache empty.

    python benchmarks/bench_coldstart.py                 # every scenario: simulate, event map, a user model, cycle, reproduce ch9
    python benchmarks/bench_coldstart.py --quick         # without reproduce ch9
    python benchmarks/bench_coldstart.py --repeat 3      # lowest wall time of 3 cold runs per scenario
    python benchmarks/bench_coldstart.py --root DIR      # time the hunting tree at DIR (e.g. main)
    python benchmarks/bench_coldstart.py --only ch9      # scenarios whose name contains "ch9"

Measured (2 shared cores, CPU seconds, lowest of 2-3 cold runs; before -> after the change that
compiles the servo functions on first use, inlines only DOP853 into the lean kernel and takes
the batch's work arrays from the caller): see docs/architecture.md, "Kernel structure".

Latest (cold CPU [s], lowest of 2, main and the branch with the forceinline helpers run in
alternation, 2026-11-23; the machine's noise is +-2 s, so read the compile column):

    scenario        main            branch          lean kernel's own compile
    simulate        15.2 / 18.2     15.6 / 15.9     8.0 / 8.7 -> 7.7 / 7.2
    eventmap        17.6 / 19.7     16.2 / 17.6     7.6 / 9.5 -> 6.6 / 7.2
    user model      14.7 / 17.9     16.0 / 16.2     7.2 / 9.4 -> 7.3 / 6.8
    reproduce ch9   23.6-25.5       22.4-26.2       7.6-9.9   -> 6.1-8.7 (medians 8.1 -> 7.1)
    (warm ch9: 7.6-9.9 s CPU on both)
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

USER_MODEL = ROOT / "examples" / "pid_lugre.json"     # 4 states: x, v, xi and the bristle z

SCENARIOS = {
    "--help": ["--help"],
    "bad argument": ["simulate", "table9.1", "--x0", "a,b,c"],
    "models": ["models"],
    "simulate": ["simulate", "table9.1", "--x0", "0.1,0,0", "--t", "5"],
    "eventmap": ["eventmap", "table9.1", "--grid", "0:0.5:51", "--iterate", "2"],
    "user model": ["simulate", "--model", str(USER_MODEL), "--x0", "x=0.5", "--t", "5"],
    "cycle": ["cycle", "--model", str(USER_MODEL), "--x0", "x=0.5", "--json", "{tmp}/cycle.json"],
}
MODEL_SCENARIOS = {"user model"}      # also timed with the library cached and the model cache empty
EXIT_CODES = {"bad argument": 2}       # the exit code each scenario must end with (default 0)

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


def run(args: list[str], numba_cache: str, model_cache: str, root: Path, code: int = 0) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=numba_cache, HUNTING_CACHE_DIR=model_cache, PYTHONPATH=str(root))
    out = subprocess.run([sys.executable, "-c", RUNNER, *args], env=env, capture_output=True, text=True,
                         check=True, cwd=tempfile.gettempdir())
    res = json.loads(out.stdout.strip().splitlines()[-1])
    if res["code"] != code:
        raise RuntimeError(f"hunting {' '.join(args)} exited with {res['code']}, not {code}")
    return res


def _arg(name: str, default: str) -> str:
    return sys.argv[sys.argv.index(name) + 1] if name in sys.argv else default


def _top(compiles: dict, k: int = 4) -> str:
    comp = sorted(compiles.items(), key=lambda kv: -kv[1])
    return ", ".join(f"{name.rsplit('.', 1)[-1]} {v:.1f}" for name, v in comp[:k] if v > 0.05)


def main() -> None:
    scenarios = dict(SCENARIOS)
    root = Path(_arg("--root", str(ROOT))).resolve()
    repeat = max(1, int(_arg("--repeat", "1")))
    if "--quick" not in sys.argv:
        scenarios["reproduce ch9"] = ["reproduce", "ch9", "--out", "{tmp}/ch9"]
    only = _arg("--only", "")
    scenarios = {k: v for k, v in scenarios.items() if only in k}
    print(f"hunting from {root}; lowest wall time of {repeat} cold run(s) per scenario; compiling ahead "
          f"{'off' if os.environ.get('HUNTING_COMPILE_AHEAD') == '0' else 'on'}")
    print(f"{'scenario':<16}{'cold wall/CPU [s]':>19}{'warm wall/CPU [s]':>19}{'compiling [s]':>15}"
          "  largest compiles (cold)")
    for name, args in scenarios.items():
        colds = []
        for _ in range(repeat):
            with tempfile.TemporaryDirectory() as tmp:
                argv = [a.format(tmp=tmp) for a in args]
                cache, models = os.path.join(tmp, "numba"), os.path.join(tmp, "models")
                code = EXIT_CODES.get(name, 0)
                cold = run(argv, cache, models, root, code)
                warm = run(argv, cache, models, root, code)
                lone = (run(argv, cache, os.path.join(tmp, "models2"), root, code) if name in MODEL_SCENARIOS
                        else None)
            colds.append((cold, warm, lone))
        cold, warm, lone = min(colds, key=lambda c: c[0]["seconds"])
        print(f"{name:<16}{cold['seconds']:>10.1f}/{cold['cpu']:<8.1f}{warm['seconds']:>10.2f}/{warm['cpu']:<8.2f}"
              f"{sum(cold['compile'].values()):>15.1f}  {_top(cold['compile'])}")
        if lone is not None:
            model = {k: v for k, v in lone["compile"].items() if k.startswith("hunting_model_")}
            print(f"{'  model alone':<16}{lone['seconds']:>10.1f}/{lone['cpu']:<8.1f}{'':>19}"
                  f"{sum(model.values()):>15.1f}  (library cached, model cache empty: sympy + codegen + numba)")


if __name__ == "__main__":
    main()
