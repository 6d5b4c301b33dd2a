"""Records of the third, independent generator (benchmarks/independent: its own integrators,
controller, programmes and reading of each cause) that changed the diagnosis, generated here
from their seed and index and judged end to end."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from hunting.diagnose import NominalModel, diagnose, load

ROOT = Path(__file__).resolve().parents[1]


def _record(tmp_path, seed: int, index: int) -> Path:
    """The directory of the independent generator's record ``index`` of set ``seed``, written
    under tmp_path (its script, one record: about a second)."""
    subprocess.run([sys.executable, str(ROOT / "benchmarks" / "independent" / "generate.py"), str(tmp_path),
                    "--seed", str(seed), "--only", str(index)], check=True, capture_output=True, timeout=120)
    return tmp_path / f"d{index:04d}"


def test_dwell_in_the_seven_parameter_form_is_named_from_the_loop(tmp_path):
    """Seed 10 d0051 (held out in the forty-ninth session, looked at in the fiftieth): a 0.50 N
    growth over 0.10 s on Fs 2.5 N in the seven-parameter form (the slip starts from the grown
    force), on a Stribeck model without a growth. The break-away readings suggest it (p = 0.17),
    and Kato's form, the only one the loop fitted before, cut the fitting record's position error
    by 0.8 %: nothing was named. Fitted in both forms, the seven-parameter one is taken and named,
    its gain within 10 % of the truth."""
    dd = _record(tmp_path, 10, 51)
    truth = json.loads((dd / "truth.json").read_text())
    assert truth["causes"] == ["dwell"]
    result = diagnose(load(dd / "fit.npz"), NominalModel.from_json(dd / "model.json"), load(dd / "val.npz"))
    named = result.causes
    assert [c.name for c in named] == ["dwell"]
    assert named[0].parameters["gain"] == pytest.approx(truth["params"]["dFs"], rel=0.1)
    assert result.extended_model.dwell.sliding is True
