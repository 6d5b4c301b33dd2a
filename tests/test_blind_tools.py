"""The blind benchmark's reading tools: ``history`` (every held-out verdict pooled: Wilson
intervals, the trend per verdict, one common rate) against their defining equations and a direct
maximum-likelihood fit, and ``oracle`` (the truth put through hunting's own measures) on records
whose answer is known."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import optimize, stats

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.blind import generate, history, oracle  # noqa: E402


def test_history_reads_each_verdicts_headline_counts():
    """The counts of RESULTS_reporting45.md's targets table (hunting-ddd5d40): named first 126 of
    140, pairs 10 of 14, false alarms 2 of 300, parameters 214 of 223."""
    rows = {r["set"]: r for r in history.verdicts()}
    r = rows["reporting45"]
    assert r["label"] == "hunting-ddd5d40"
    assert r["named_first"] == (126, 140) and r["both_found"] == (10, 14)
    assert r["false_alarm"] == (2, 300) and r["params"] == (214, 223)
    assert [r["k"] for r in history.verdicts(20)] == sorted(r["k"] for r in history.verdicts(20))


@pytest.mark.parametrize("k, n", [(126, 140), (3, 300), (0, 14), (14, 14)])
def test_wilson_interval_solves_its_defining_equation(k, n):
    """The Wilson bounds are the rates p with (k/n - p)^2 = z^2 p (1 - p) / n, z the normal's 97.5 %
    quantile (at k = 0 or k = n one bound is the rate itself)."""
    z = stats.norm.ppf(0.975)
    lo, hi = history.wilson(k, n)
    for p in (lo, hi):
        if p == k / n and p in (0.0, 1.0):
            continue
        assert (k / n - p) ** 2 == pytest.approx(z * z * p * (1 - p) / n, rel=1e-9)
    assert lo <= k / n <= hi


def test_trend_is_the_binomial_logistic_fit_and_homogeneity_pearsons_statistic():
    """The logit slope against a direct maximum-likelihood fit (Nelder-Mead on the binomial
    log-likelihood), its standard error against the inverse Hessian at the optimum; the one-rate
    test against Pearson's statistic written out (expected counts at the pooled rate)."""
    x = np.arange(20.0, 30.0)
    n = np.array([140, 135, 150, 142, 138, 144, 146, 139, 141, 137], float)
    k = np.array([120, 118, 133, 127, 125, 131, 134, 128, 131, 128], float)   # rising from 86 % to 93 %
    slope, se = history.trend(x, k, n)

    def nll(b):
        p = 1 / (1 + np.exp(-(b[0] + b[1] * x)))
        return -np.sum(k * np.log(p) + (n - k) * np.log1p(-p))
    best = optimize.minimize(nll, [1.0, 0.0], method="Nelder-Mead", options=dict(xatol=1e-10, fatol=1e-12,
                                                                                   maxiter=20000))
    assert slope == pytest.approx(best.x[1], abs=1e-5)
    h = 1e-4
    hess = np.array([[(nll(best.x + h * (ei + ej)) - nll(best.x + h * (ei - ej)) - nll(best.x - h * (ei - ej))
                       + nll(best.x - h * (ei + ej))) / (4 * h * h) for ej in np.eye(2)] for ei in np.eye(2)])
    assert se == pytest.approx(np.sqrt(np.linalg.inv(hess)[1, 1]), rel=1e-3)
    x2, dof, p = history.homogeneity(k, n)
    pooled = k.sum() / n.sum()
    pearson = np.sum((k - n * pooled) ** 2 / (n * pooled) + ((n - k) - n * (1 - pooled)) ** 2 / (n * (1 - pooled)))
    assert x2 == pytest.approx(pearson, rel=1e-10) and dof == k.size - 1
    assert p == pytest.approx(stats.chi2.sf(pearson, k.size - 1), rel=1e-9)
    # the same rate in every verdict: no trend to speak of, one rate not rejected
    flat_k = np.round(0.9 * n)
    s0, se0 = history.trend(x, flat_k, n)
    assert abs(s0) < 2 * se0 and history.homogeneity(flat_k, n)[2] > 0.9


def _write(family: str, index: int, directory: Path) -> Path:
    files, truth, _ = generate.make(family, index)
    dd = directory / f"d{index:04d}"
    dd.mkdir()
    for name in ("fit", "val"):
        np.savez(dd / f"{name}.npz", **files[name])
    (dd / "model.json").write_text(json.dumps(files["model"], default=generate._json))
    (dd / "truth.json").write_text(json.dumps(generate._finite(truth), default=generate._json))
    return dd


def test_the_true_model_of_a_clean_record_is_its_nominal_and_an_effect_is_seen(tmp_path):
    """A clean record's true system is its nominal one: the oracle's true model JSON equals the
    nominal model the generator wrote, and both gains are zero. A strong hidden offset (the test
    family's d0010, the strong half of the size range) is visible to hunting's force residual."""
    dd = _write("test", 0, tmp_path)
    truth = json.loads((dd / "truth.json").read_text())
    assert truth["causes"] == []
    assert oracle.true_model_json(truth) == json.loads((dd / "model.json").read_text())
    o = oracle.measure(dd)
    assert o["val"]["force_gain"] == pytest.approx(0.0, abs=1e-12)
    assert o["val"]["loop_gain"] == pytest.approx(0.0, abs=1e-12)
    dd = _write("test", 10, tmp_path)
    truth = json.loads((dd / "truth.json").read_text())
    assert truth["causes"] == ["offset"]
    assert oracle.true_model_json(truth)["plant"]["offset"] == pytest.approx(truth["effects"][0]["params"]["offset"])
    o = oracle.measure(dd)
    assert o["val"]["force_gain"] > 0.5 and oracle.visible(o) in ("force", "both")


def test_rival_is_the_oracle_over_what_was_reported(tmp_path):
    """The truth over a report: where the judge named nothing, the gains over the nominal model
    (the oracle's own, to the digit); where it reported the true model itself, none (both
    measures 0: the records cannot tell a report from itself, a confusion); where it reported a
    wrong offset, the true one is visible over it."""
    dd = _write("test", 10, tmp_path)
    truth = json.loads((dd / "truth.json").read_text())
    o = oracle.measure(dd)
    assert oracle.rival(dd, {"causes": [], "extended_model": None}) == o
    same = oracle.rival(dd, {"extended_model": oracle.true_model_json(truth)})
    for rec in ("fit", "val"):
        assert same[rec]["force_gain"] == pytest.approx(0.0, abs=1e-12)
        assert same[rec]["loop_gain"] == pytest.approx(0.0, abs=1e-12)
    assert oracle.visible(same) == "neither"
    wrong = oracle.true_model_json(truth)
    wrong["plant"]["offset"] = -wrong["plant"]["offset"]
    assert oracle.visible(oracle.rival(dd, {"extended_model": wrong})) != "neither"


def _row(first: bool, found: bool, n: int = 1) -> dict:
    return {"effects": [dict(first=first, found=found, moderate=True)] * n}


@pytest.mark.parametrize("row, o_gain, rv_gain, expected", [
    (_row(False, True), 0.9, 0.9, "found, not first"),
    (_row(False, False), 0.01, 0.01, "invisible"),        # the exact effect below the bars over the nominal
    (_row(False, False), 0.9, 0.02, "confusable"),        # ... above them, but not over what was reported
    (_row(False, False), 0.9, 0.6, "resolvable"),         # ... and above them over the report too
    (_row(False, False, 2), 0.9, 0.02, "confusable"),     # a pair: one found, the other not separable from it
])
def test_a_miss_is_classed_by_the_oracles_two_measures(row, o_gain, rv_gain, expected):
    def rec(g):
        return {r: dict(force_gain=g, loop_gain=g, used=100) for r in ("fit", "val")}
    assert oracle.classify(row, rec(o_gain), rec(rv_gain)) == expected
    assert oracle.classify(_row(False, False), rec(0.9), None) == "unmeasured"
