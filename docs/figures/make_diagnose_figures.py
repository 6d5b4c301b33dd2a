"""The diagnosis figures: the EMPS worked example (its files in $HUNTING_DATA/emps or
../shared/data/emps), the measured event maps of table 9.1 with a wrong Stribeck level, and with
a results directory of the blind benchmark (benchmarks/blind/run.py) the detection rates against
the effect's size (docs/diagnosis.md).

    python docs/figures/make_diagnose_figures.py [RESULTS_DIR SET_DIR]
"""
from __future__ import annotations

import json
import os
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

from hunting.diagnose import NominalModel, diagnose, load
from hunting.diagnose.report import write_report
from hunting.diagnose.synthetic import regulator

HERE = Path(__file__).resolve().parent
EMPS = (Path(os.environ["HUNTING_DATA"]) / "emps" if os.environ.get("HUNTING_DATA")
        else HERE.parents[1].parent / "shared" / "data" / "emps")


def _report(dg, copies: dict) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        write_report(dg, tmp)
        for src, dst in copies.items():
            shutil.copy(Path(tmp) / src, HERE / dst)
            print("wrote", HERE / dst)


def emps() -> None:
    if not (EMPS / "DATA_EMPS.mat").is_file():
        print(f"EMPS data not found in {EMPS}: its figures are not remade", file=sys.stderr)
        return
    fit, val = load(EMPS / "DATA_EMPS.mat"), load(EMPS / "DATA_EMPS_PULSES.mat")
    model = NominalModel.from_json(HERE.parents[1] / "examples" / "emps" / "model.json")
    _report(diagnose(fit, model, val), {"residual.png": "emps_residual.png", "behaviour.png": "emps_behaviour.png"})


def table91_event_map() -> None:
    true = NominalModel.from_dict({"preset": "table9.1", "set": {"P": 20.0}})
    nominal = NominalModel.from_dict({"preset": "table9.1", "set": {"P": 20.0, "Fs": 3.0}})
    fit, val = (regulator(true, d0, 40_000, 1e-3, seed=seed, resolution=1e-5, force_noise=0.05)
                for d0, seed in ((0.5, 1), (0.4, 2)))
    dg = diagnose(fit, nominal, val, causes=["offset", "stribeck", "presliding"])
    _report(dg, {"event_map.png": "diagnose_event_map.png"})


def detection_rates(results: Path, sets: Path) -> None:
    """Share of single-effect datasets whose cause is named first, against the effect's
    validation gain when modelled exactly (the benchmark's effect size), per cause; and the
    clean datasets' false alarms."""
    from hunting.plotting import _plt, save
    plt = _plt()
    rows = []
    for f in sorted(results.glob("d*.json")):
        r = json.loads(f.read_text())
        t = json.loads((sets / f.stem / "truth.json").read_text())
        if len(t["effects"]) == 1:
            e = t["effects"][0]
            names = [c["name"] for c in r.get("causes", [])]
            rows.append((e["cause"], e["gain"], bool(names) and names[0] in e["accept"]))
    edges = np.array([-np.inf, 0.05, 0.15, 0.4, np.inf])
    labels = ["< 0.05", "0.05-0.15", "0.15-0.4", ">= 0.4"]
    causes = sorted({c for c, _, _ in rows})
    fig, ax = plt.subplots(figsize=(9, 4.5))
    for i, c in enumerate(causes):
        g = np.array([x[1] for x in rows if x[0] == c])
        hit = np.array([x[2] for x in rows if x[0] == c])
        k = np.digitize(g, edges) - 1
        rate = [hit[k == b].mean() if np.any(k == b) else np.nan for b in range(4)]
        ax.plot(np.arange(4) + (i - len(causes) / 2) * 0.02, rate, "o-", ms=4, lw=1, label=c)
    ax.set_xticks(range(4), labels)
    ax.set_xlabel("validation gain of the effect when modelled exactly (the benchmark's effect size)")
    ax.set_ylabel("named first")
    ax.set_ylim(-0.05, 1.05)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.set_title(f"blind benchmark ({results.name}): single effects named first against their size", fontsize=10)
    fig.tight_layout()
    save(fig, HERE / "diagnose_detection.png")
    print("wrote", HERE / "diagnose_detection.png")


if __name__ == "__main__":
    if len(sys.argv) == 3:
        detection_rates(Path(sys.argv[1]), Path(sys.argv[2]))
    else:
        emps()
        table91_event_map()
