"""The README's diagnosis figures: the EMPS worked example (needs ../shared/data/emps/) and the
measured event maps of table 9.1 with a wrong Stribeck level.

    python docs/figures/make_diagnose_figures.py
"""
from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

from hunting.diagnose import NominalModel, diagnose, fit_coulomb_viscous, kinematics, load
from hunting.diagnose.report import write_report
from hunting.diagnose.synthetic import regulator

HERE = Path(__file__).resolve().parent
EMPS = HERE.parents[1].parent / "shared" / "data" / "emps"


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
    fit = load(EMPS / "DATA_EMPS.mat")
    val = load(EMPS / "DATA_EMPS_PULSES.mat", names={"f_ext": None, "u_inj": "pulses_N"})
    model, _ = fit_coulomb_viscous(kinematics(fit, 35.15065188))
    model = model.replace(controller={"type": "pd-velocity-loop", "kp": 160.18, "kv": 243.45, "sample_time": 1e-3,
                                      "saturation": 10.0})
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
