"""The diagnosis on records of the independent generator (benchmarks/independent/: written from
a one-page specification by an engineer who saw neither hunting's code nor the blind benchmark's
generator). A few records of its seed-1 set, drawn here: clean ones get nothing, and one effect
each of four causes is named first (reversal as LuGre bristles: ``reversal`` or ``presliding``).
The whole set's rates are in docs/diagnosis.md."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

from hunting.diagnose import NominalModel, diagnose, load

ROOT = Path(__file__).resolve().parents[1]
CLEAN = (4, 5, 7, 10)
EFFECTS = {45: ("mass",), 49: ("offset",), 53: ("reversal", "presliding"), 44: ("delay",)}


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    out = tmp_path_factory.mktemp("independent")
    ids = ",".join(str(i) for i in (*CLEAN, *EFFECTS))
    subprocess.run([sys.executable, str(ROOT / "benchmarks" / "independent" / "generate.py"), str(out), "--seed", "1",
                    "--only", ids], check=True, capture_output=True)
    return out


def _names(records, i):
    dd = records / f"d{i:04d}"
    truth = json.loads((dd / "truth.json").read_text())
    dg = diagnose(load(dd / "fit.npz"), NominalModel.from_json(dd / "model.json"), load(dd / "val.npz"))
    return truth, [c.name for c in dg.causes]


@pytest.mark.parametrize("i", CLEAN)
def test_a_clean_record_of_the_independent_generator_gets_no_cause(records, i):
    truth, names = _names(records, i)
    assert truth["clean"]
    assert names == []


@pytest.mark.parametrize("i", sorted(EFFECTS))
def test_an_effect_of_the_independent_generator_is_named_first(records, i):
    truth, names = _names(records, i)
    assert truth["causes"] == [EFFECTS[i][0]]
    assert names and names[0] in EFFECTS[i], names
