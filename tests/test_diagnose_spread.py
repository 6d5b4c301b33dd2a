"""The force channel's uncertainties widened to the spread between the two records
(hunting.diagnose.spread)."""
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from hunting.diagnose import Measurement, NominalModel, diagnose
from hunting.diagnose import spread
from hunting.diagnose.select import Cause

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from benchmarks.blind import generate  # noqa: E402


def _cause(parameters, sigma):
    return Cause("delay", 0.5, 3.0, 1e-4, parameters, sigma, dict(metric="m", nominal=1.0, extended=0.5))


def test_widen_takes_the_larger_of_the_stated_uncertainty_and_the_spread():
    c = _cause({"a": 1.0, "b": 2.0, "c": 3.0}, {"a": 0.01, "b": 0.5, "c": None})
    out, = spread.widen([c], {"delay": {"a": 1.3, "b": 2.1, "c": 9.0}})
    assert out.sigma["a"] == pytest.approx(0.3 / math.sqrt(2))      # the spread is larger
    assert out.sigma["b"] == 0.5                                    # the stated one is larger
    assert out.sigma["c"] is None                                   # nothing stated: nothing invented
    assert out.parameters == c.parameters                           # the values stay the fitting record's


def test_widen_leaves_a_parameter_the_fitting_record_did_not_estimate():
    """A parameter the fitting record's variant holds (a Stribeck dip's Fc: the nominal value,
    stated +-0) gets no uncertainty from its difference to the validation record's value."""
    c = _cause({"Fc": 10.0, "Fs": 15.0}, {"Fc": 0.0, "Fs": 0.1})
    out, = spread.widen([c], {"delay": {"Fc": 11.0, "Fs": 15.0}})
    assert out.sigma == {"Fc": 0.0, "Fs": 0.1}


def test_widen_keeps_a_cause_without_a_validation_value():
    c = _cause({"a": 1.0}, {"a": 0.01})
    assert spread.widen([c], {}) == [c]
    out, = spread.widen([c], {"delay": {"a": float("nan")}})
    assert out.sigma["a"] == 0.01


def test_a_lag_whose_record_noise_understates_its_uncertainty_gets_the_spread(monkeypatch):
    """reporting29 d0434: a 14.1 ms friction lag, fitted 6.6 ms on the fitting record with a
    within-record uncertainty of 0.4 ms (20 of them off); the same explanation fitted on the
    validation record gives another value, and the spread covers the truth within 2."""
    files, truth, _ = generate.make("reporting29", 434)
    fit, val = (Measurement(**files[k], name=k) for k in ("fit", "val"))
    model = NominalModel.from_dict(files["model"])
    seen = {}
    real = spread.widen

    def spy(causes, values):
        seen.update(within={c.name: dict(c.sigma) for c in causes}, values=values)
        return real(causes, values)
    monkeypatch.setattr(spread, "widen", spy)
    lag = next(c for c in diagnose(fit, model, val).causes if c.name == "lag")
    true = truth["effects"][0]["params"]["lag"]
    assert abs(lag.parameters["lag"] - true) > 2 * seen["within"]["lag"]["lag"]
    assert "lag" in seen["values"]["lag"]
    assert abs(lag.parameters["lag"] - true) <= 2 * lag.sigma["lag"]
    assert lag.sigma["lag"] == pytest.approx(abs(lag.parameters["lag"] - seen["values"]["lag"]["lag"]) / np.sqrt(2))
