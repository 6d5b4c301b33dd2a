"""Datasets of the blind benchmark's generator (benchmarks/blind, which shares no code with
hunting) for the tests: one record pair drawn by family and index, as ``hunting diagnose`` reads it."""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

from hunting.diagnose.data import Measurement
from hunting.diagnose.model import NominalModel

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.blind import generate  # noqa: E402


def blind_record(family: str, index: int, noise: bool = True):
    """(fit, val, model, truth) of a blind dataset, optionally regenerated without sensor and
    actuator noise (the same draws, multiplied by zero, so the references are the same)."""
    if noise:
        files, truth, _ = generate.make(family, index)
    else:
        orig = generate.run

        def quiet(plant, ctrl, sensor, r, dt, i=None, s=None, **kw):
            return orig(plant, ctrl, sensor, r, dt, None if i is None else 0 * i, None if s is None else 0 * s, **kw)
        mp = pytest.MonkeyPatch()
        mp.setattr(generate, "run", quiet)
        try:
            files, truth, _ = generate.make(family, index)
        finally:
            mp.undo()
    model = NominalModel.from_dict(files["model"])
    return Measurement(**files["fit"], name="fit"), Measurement(**files["val"], name="val"), model, truth
