"""Cold and warm start of ``hunting diagnose`` on 20 s at 1 kHz plus a 20 s validation record
(issue 17, item 10: < 10 s warm, < 30 s cold).

The records are the EMPS-like servo of the README (examples/pd_servo.json) with a hidden 3 N
offset, made by :func:`hunting.diagnose.synthetic.generate` in this process (not timed) and
written as CSV. The command then runs in a fresh process twice with its own empty numba cache
(NUMBA_CACHE_DIR) and model cache, as in ``bench_coldstart.py``: the first run compiles (what a
user meets after installing), the second loads the caches. Wall and CPU seconds are reported
(``--repeat N``: lowest CPU of N cold runs), with the functions that take the compile time.

    python benchmarks/bench_diagnose.py [--repeat 2] [--root DIR] [--clean]

``--clean``: the same servo without the offset, where the diagnosis names nothing and so runs
every check it has.

Measured (2 shared cores, 2026-11-26, main at the method-error change; another process kept
one core busy, so read the CPU column): see docs/diagnosis.md, "Speed".
"""
from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from bench_coldstart import ROOT, _arg, _top, run  # noqa: E402

MODEL = ROOT / "examples" / "pd_servo.json"
DURATION = 20.0      # [s] per record, sampled at the synthetic servo's 1 kHz


def records(directory: str, offset: float = -3.0) -> tuple[str, str]:
    """Write the fitting and validation CSV files into ``directory`` (the servo with a hidden
    ``offset`` [N]); returns their paths."""
    from hunting.diagnose.data import save_csv
    from hunting.diagnose.synthetic import TruePlant, generate
    machine = TruePlant(offset=offset)
    paths = []
    for name, seed in (("fit", 1), ("val", 2)):
        meas = generate(machine, DURATION, seed=seed)
        assert abs(meas.dt - 1e-3) < 1e-9 and meas.n >= 20_000
        path = os.path.join(directory, f"{name}.csv")
        save_csv(meas, path)
        paths.append(path)
    return paths[0], paths[1]


def main() -> None:
    root = Path(_arg("--root", str(ROOT))).resolve()
    repeat = max(1, int(_arg("--repeat", "1")))
    clean = "--clean" in sys.argv
    print(f"hunting from {root}; hunting diagnose on {DURATION:g} s at 1 kHz + validation "
          f"({'clean' if clean else 'a hidden 3 N offset'}); lowest CPU of {repeat}")
    with tempfile.TemporaryDirectory() as data:
        fit, val = records(data, 0.0 if clean else -3.0)
        args = ["diagnose", fit, "--validate", val, "--model", str(MODEL), "--json", os.path.join(data, "d.json")]
        colds = []
        for _ in range(repeat):
            with tempfile.TemporaryDirectory() as tmp:
                cache, models = os.path.join(tmp, "numba"), os.path.join(tmp, "models")
                cold = run(args, cache, models, root)
                warm = run(args, cache, models, root)
            colds.append((cold, warm))
    cold, warm = min(colds, key=lambda c: c[0]["cpu"])
    print(f"{'cold wall/CPU [s]':>19}{'warm wall/CPU [s]':>19}{'compiling [s]':>15}  largest compiles (cold)")
    print(f"{cold['seconds']:>10.1f}/{cold['cpu']:<8.1f}{warm['seconds']:>10.2f}/{warm['cpu']:<8.2f}"
          f"{sum(cold['compile'].values()):>15.1f}  {_top(cold['compile'], 6)}")


if __name__ == "__main__":
    main()
