"""The diagnosis figures: the EMPS worked example (its files in $HUNTING_DATA/emps or
../shared/data/emps) and the measured event maps of table 9.1 with a wrong Stribeck level. (The
blind benchmark's figure, docs/figures/diagnose_blind_tuning.png, is benchmarks/blind/report.py's.)

    python docs/figures/make_diagnose_figures.py
"""
from __future__ import annotations

import os
import shutil
import sys
import tempfile
from pathlib import Path


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


if __name__ == "__main__":
    emps()
    table91_event_map()
