"""What hunting's own measures could see of a blind dataset's hidden effects: an oracle that
knows the truth.

A blind effect is "moderate" by the generator's measure (:mod:`benchmarks.blind.measures`: its
own inverse dynamics, a 30 Hz Butterworth low pass, every sample above 2 % of the top speed).
The diagnosis measures differently (a Savitzky-Golay force balance on the samples it trusts, and
the re-simulated loop), and an effect the generator's measure sees can be below what the
diagnosis's measures can show at all. This module puts the *true* model, the nominal model
changed by the true effects with their true parameters (the model JSON the generator writes for
the nominal plant, written here for the true one), through hunting's own measures:

- ``force_gain``: 1 - RMS(r_true) / RMS(r_nominal) of :func:`hunting.diagnose.kinematics.residual`
  on the samples the force channel uses (the nominal model's :func:`used_samples`), per record
  (without the estimation's own error that the force channel subtracts, the nominal loop's
  residual on its noise-free run: it is common to both residuals and small where applied);
  the force channel cannot name a cause whose exact model does not cut this by its ``min_gain``
  (5 %) on the validation record;
- ``loop_gain``: 1 - RMS(q_true - q) / RMS(q_nominal - q) of the loop re-simulated from the
  measured reference (:func:`hunting.diagnose.resimulate.resimulate`), per record; the loop's
  evidence needs ``LOOP_GAIN`` (50 %) on both records.

An effect neither measure sees at its bar is out of the diagnosis's reach whatever its selection
rules: a miss there is an estimation limit, not a selection error. The causes the diagnosis
judges on evidence of their own (``draw.BEHAVIOUR_CHANNEL``: a dwell growth's break-away
readings, a saturation's or a DAC's output levels) are counted apart: neither measure is their
evidence. The oracle judges nothing and is not a judge: it reads the truth, which no judge may.

    python -m benchmarks.blind.oracle /work/wt/blind-data/reporting46 [--jobs 2]
    python -m benchmarks.blind.oracle /work/wt/blind-data/reporting46 --summary --hunting hunting-<rev> \
        [--append benchmarks/blind/RESULTS_reporting46.md]

Results: <set>/../results/<set name>/oracle/dNNNN.json (resumable, like :mod:`.run`)."""
from __future__ import annotations

import argparse
import json
import math
import os
import time
from dataclasses import fields
from pathlib import Path

import numpy as np

from . import draw, report
from .system import Controller, Curve, Plant, Sensor, nominal_json

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

FORCE_BAR = 0.05     # the force channel's min_gain
LOOP_BAR = 0.50      # the loop channel's LOOP_GAIN (on both records)


def _plant(d: dict) -> Plant:
    keys = {f.name for f in fields(Plant)}
    kw = {k: v for k, v in d.items() if k in keys}
    kw["pos"], kw["neg"] = Curve(**d["pos"]), Curve(**d["neg"])
    for k in ("dwell", "flex", "cogging"):
        if kw.get(k) is not None:
            kw[k] = tuple(tuple(x) if isinstance(x, list) else x for x in kw[k])
    return Plant(**kw)


def _controller(d: dict) -> Controller:
    keys = {f.name for f in fields(Controller)}
    kw = {k: v for k, v in d.items() if k in keys}
    if kw.get("saturation") is None:
        kw["saturation"] = math.inf
    return Controller(**kw)


def true_model_json(truth: dict) -> dict:
    """The model JSON (the schema ``hunting diagnose --model`` reads) of the true system."""
    return nominal_json(_plant(truth["true"]["plant"]), _controller(truth["true"]["controller"]),
                        Sensor(**truth["sensor"]))


def _rms(x) -> float:
    x = np.asarray(x, float)
    return float(np.sqrt(np.mean(x ** 2))) if x.size else float("nan")


def _gains(meas, nominal, base, model, window) -> dict:
    """``model``'s gains over ``base`` on one record: force_gain on the samples the force channel
    uses (``nominal``'s :func:`used_samples`), loop_gain of the loop re-simulated from the measured
    reference (None where a measure cannot be formed), and the number of samples used."""
    from hunting.diagnose.kinematics import kinematics, residual, used_samples
    from hunting.diagnose.resimulate import resimulate
    k = kinematics(meas, nominal.cm, window=window, resolution=nominal.resolution, noise=nominal.sensor_noise,
                   steady=nominal.steady_slide)
    used = used_samples(k, nominal)
    r0, r1 = residual(k, base), residual(k, model)
    ok = used & np.isfinite(r0) & np.isfinite(r1)
    force = 1 - _rms(r1[ok]) / _rms(r0[ok]) if ok.sum() >= 10 and _rms(r0[ok]) > 0 else None
    loop = None
    if nominal.controller is not None and meas.q_ref is not None:
        s0, s1 = resimulate(meas, base), resimulate(meas, model)
        if s0.ok and s1.ok:
            e0, e1 = _rms(s0.q - meas.q), _rms(s1.q - meas.q)
            loop = 1 - e1 / e0 if e0 > 0 else None
    return dict(force_gain=force, loop_gain=loop, used=int(ok.sum()))


def _records(dd: Path):
    """(records {"fit", "val"}, nominal model, true model, filter window [s]) of dataset ``dd``."""
    from hunting.diagnose import NominalModel, load
    from hunting.diagnose.parts import default_window
    truth = json.loads((dd / "truth.json").read_text())
    fit, val = load(dd / "fit.npz"), load(dd / "val.npz")
    nominal = NominalModel.from_json(dd / "model.json")
    true = NominalModel.from_dict(true_model_json(truth))
    return {"fit": fit, "val": val}, nominal, true, default_window(fit, val, nominal)


def measure(dd: Path) -> dict:
    """The oracle's gains for dataset directory ``dd`` (module docstring): per record ``fit`` and
    ``val``, the true model's force_gain and loop_gain over the nominal model (None where a
    measure cannot be formed), and the samples the force channel uses."""
    recs, nominal, true, window = _records(dd)
    return {name: _gains(meas, nominal, nominal, true, window) for name, meas in recs.items()}


def rival(dd: Path, result: dict) -> dict:
    """The true model's gains over the explanation a judge reported (``result``: its result
    record with the ``extended_model`` it reported; the nominal model where it named nothing),
    per record, as :func:`measure`'s: where the truth is not :func:`visible` over it by the bars
    it needs over the nominal model, the data do not tell the reported explanation from the
    truth (the miss is a confusion the records cannot resolve, not a selection error)."""
    from hunting.diagnose import NominalModel
    recs, nominal, true, window = _records(dd)
    ext = result.get("extended_model")
    base = NominalModel.from_dict(ext) if ext else nominal
    return {name: _gains(meas, nominal, base, true, window) for name, meas in recs.items()}


def visible(o: dict) -> str:
    """Which of hunting's measures shows an effect at its bar: "force" (the validation record's
    force gain >= FORCE_BAR), "loop" (both records' loop gains >= LOOP_BAR), "both", or "neither"."""
    f = (o["val"]["force_gain"] or -1) >= FORCE_BAR
    lp = min(o["fit"]["loop_gain"] or -1, o["val"]["loop_gain"] or -1) >= LOOP_BAR
    return "both" if f and lp else "force" if f else "loop" if lp else "neither"


def run(set_dir: Path, jobs: int = 2) -> Path:
    """Measure every effect dataset of ``set_dir`` (clean ones have no effect to see)."""
    from concurrent.futures import ProcessPoolExecutor
    from tqdm import tqdm
    out = set_dir.parent / "results" / set_dir.name / "oracle"
    out.mkdir(parents=True, exist_ok=True)
    todo = [p.parent for p in sorted(set_dir.glob("d[0-9]*/truth.json"))
            if json.loads(p.read_text())["causes"] and not (out / f"{p.parent.name}.json").is_file()]
    with ProcessPoolExecutor(max_workers=max(1, min(jobs, 2)), initializer=os.nice, initargs=(10,)) as ex:
        for dd, res in tqdm(zip(todo, ex.map(_safe, todo)), total=len(todo), desc=f"oracle {set_dir.name}"):
            (out / f"{dd.name}.json").write_text(json.dumps(res, indent=1))
    return out


def misses(set_dir: Path, label: str) -> list:
    """Ids of the moderate effect datasets the judge ``label`` missed: single effects not named
    first, pairs of moderate effects not both found (report.py's rates)."""
    truths = report.load_truths(set_dir)
    rows = report.score(truths, report.load_results(set_dir.parent / "results" / set_dir.name / label))
    return [r["id"] for r in rows if all(e["moderate"] for e in r["effects"]) and r["effects"] and (
        not r["effects"][0]["first"] if len(r["effects"]) == 1 else not all(e["found"] for e in r["effects"]))]


def run_rival(set_dir: Path, label: str, jobs: int = 2) -> Path:
    """:func:`rival` on every miss of the judge ``label`` (:func:`misses`). A result record without
    its extended model (written before run.py kept it) is judged again by the current code, and
    the rival record says whether that named the same causes."""
    from concurrent.futures import ProcessPoolExecutor
    from tqdm import tqdm
    res_dir = set_dir.parent / "results" / set_dir.name
    out = res_dir / "rival" / label
    out.mkdir(parents=True, exist_ok=True)
    todo = [(set_dir / i, res_dir / label / f"{i}.json") for i in misses(set_dir, label)
            if not (out / f"{i}.json").is_file()]
    with ProcessPoolExecutor(max_workers=max(1, min(jobs, 2)), initializer=os.nice, initargs=(10,)) as ex:
        for (dd, _), res in tqdm(zip(todo, ex.map(_safe_rival, todo)), total=len(todo), desc=f"rival {label}"):
            (out / f"{dd.name}.json").write_text(json.dumps(res, indent=1))
    return out


def _safe_rival(args) -> dict:
    dd, result_path = args
    t0 = time.perf_counter()
    try:
        result = json.loads(Path(result_path).read_text())
        extra = {}
        if "extended_model" not in result:
            from .run import judge_hunting
            again = judge_hunting(dd)
            extra = dict(judged_again=True, same_causes=[c["name"] for c in again["causes"]]
                         == [c["name"] for c in result["causes"]])
            result = dict(result, extended_model=again["extended_model"])
        res = dict(rival(dd, result), **extra)
    except Exception as e:                       # one dataset's failure is recorded, not fatal
        res = dict(error=f"{type(e).__name__}: {e}")
    return dict(res, seconds=time.perf_counter() - t0)


def _safe(dd: Path) -> dict:
    t0 = time.perf_counter()
    try:
        res = measure(dd)
    except Exception as e:                       # one dataset's failure is recorded, not fatal
        res = dict(error=f"{type(e).__name__}: {e}")
    return dict(res, seconds=time.perf_counter() - t0)


def summary(set_dir: Path, label: str) -> str:
    """Markdown: the moderate single effects by what the oracle says hunting's measures can show,
    against whether the judge ``label`` named them first."""
    truths = report.load_truths(set_dir)
    res_root = set_dir.parent / "results" / set_dir.name
    oracle = report.load_results(res_root / "oracle")
    rows = report.score(truths, report.load_results(res_root / label))
    lines = [f"Moderate single effects of `{set_dir.name}` by what hunting's own measures show of the exact "
             f"effect (visible: the validation force gain >= {FORCE_BAR:.0%}, or both records' loop gains >= "
             f"{LOOP_BAR:.0%}), against `{label}` naming them first. Causes judged on their own evidence "
             f"({', '.join(draw.BEHAVIOUR_CHANNEL)}) are counted apart.", "",
             "| cause | n | visible | named first (visible) | invisible | named first (invisible) |",
             "|---|---|---|---|---|---|"]
    by, own, misses = {}, {}, []          # by: [visible, first of them, invisible, first]; own: [n, first]
    for r in rows:
        if len(r["causes"]) != 1 or not r["effects"][0]["moderate"] or "error" in oracle.get(r["id"], {"error": 1}):
            continue
        o, e = oracle[r["id"]], r["effects"][0]
        if not e["first"]:
            misses.append((r["id"], e["cause"], e["gain"], o, r["reported"]))
        if e["cause"] in draw.BEHAVIOUR_CHANNEL:
            c = own.setdefault(e["cause"], [0, 0])
            c[0], c[1] = c[0] + 1, c[1] + e["first"]
            continue
        j = 0 if visible(o) != "neither" else 2
        c = by.setdefault(e["cause"], [0, 0, 0, 0])
        c[j], c[j + 1] = c[j] + 1, c[j + 1] + e["first"]
    tot = np.sum(list(by.values()), axis=0, dtype=int) if by else np.zeros(4, int)
    for cause, c in sorted(by.items()):
        lines.append(f"| {cause} | {c[0] + c[2]} | {c[0]} | {c[1]} | {c[2]} | {c[3]} |")
    lines.append(f"| force and loop causes | {tot[0] + tot[2]} | {tot[0]} | {tot[1]} | {tot[2]} | {tot[3]} |")
    if own:
        counts = ", ".join(f"{k} {b}/{a}" for k, (a, b) in sorted(own.items()))
        lines += ["", f"Own evidence (named first / n): {counts}"]
    lines += ["", "Misses (moderate singles not named first): generator gain; oracle force gain fit / val; loop "
              "gain fit / val; reported", "", "| dataset | cause | gain | force fit / val | loop fit / val | "
              "reported |", "|---|---|---|---|---|---|"]

    def f(x):
        return "-" if x is None else f"{x:+.2f}"
    for i, cause, g, o, rep in misses:
        lines.append(f"| {i} | {cause} | {g:.2f} | {f(o['fit']['force_gain'])} / {f(o['val']['force_gain'])} | "
                     f"{f(o['fit']['loop_gain'])} / {f(o['val']['loop_gain'])} | {', '.join(rep) or 'nothing'} |")
    return "\n".join(lines) + "\n"


CLASSES = ("found, not first", "invisible", "confusable", "resolvable", "unmeasured")


def classify(row: dict, o: dict | None, rv: dict | None) -> str:
    """Why a moderate miss (a report.score ``row``) was missed: "found, not first" (a single
    effect's cause reported after another), "invisible" (the exact effect not :func:`visible`
    over the nominal model: ``o``, :func:`measure`'s record), "confusable" (the exact effect not
    visible over the explanation the judge reported: ``rv``, :func:`rival`'s record; the records
    cannot tell the two apart), "resolvable" (the truth visible over what was reported:
    the records resolve it and the judge chose otherwise) or "unmeasured" (no rival record)."""
    if len(row["effects"]) == 1 and row["effects"][0]["found"]:
        return "found, not first"
    if rv is None or "error" in rv:
        return "unmeasured"
    if o is not None and "error" not in o and visible(o) == "neither":
        return "invisible"
    return "confusable" if visible(rv) == "neither" else "resolvable"


def miss_table(set_dir: Path, label: str) -> tuple[str, dict]:
    """(markdown, counts): every moderate miss of the judge ``label`` (:func:`misses`) by
    :func:`classify`, and the rates over the effects the records resolve (the moderate ones less
    the invisible and confusable misses). counts: {"single": {class: n, "n": moderate singles,
    "first": named first}, "pairs": {class: n, "n": moderate pairs, "both": both found}}."""
    truths = report.load_truths(set_dir)
    res_root = set_dir.parent / "results" / set_dir.name
    oracle = report.load_results(res_root / "oracle")
    rivals = report.load_results(res_root / "rival" / label)
    rows = report.score(truths, report.load_results(res_root / label))
    counts = {"single": dict.fromkeys(CLASSES, 0), "pairs": dict.fromkeys(CLASSES, 0)}
    lines = [f"Moderate misses of `{label}` on `{set_dir.name}` by what separates the truth from what was reported: "
             f"the exact effect's gains over the nominal model (invisible: below the bars, validation force gain "
             f"{FORCE_BAR:.0%} or both records' loop gains {LOOP_BAR:.0%}) and over the judge's reported explanation "
             f"(confusable: below the same bars, the records cannot tell the two apart; resolvable: above them, the records resolve the truth better than the report, by its causes or its values).",
             "", "| dataset | truth | reported | class | truth over reported: force fit / val | loop fit / val | "
             "judged again |", "|---|---|---|---|---|---|---|"]

    def f(x):
        return "-" if x is None else f"{x:+.2f}"
    for r in rows:
        if not r["effects"] or not all(e["moderate"] for e in r["effects"]):
            continue
        kind = "single" if len(r["effects"]) == 1 else "pairs"
        c = counts[kind]
        c["n"] = c.get("n", 0) + 1
        ok = r["effects"][0]["first"] if kind == "single" else all(e["found"] for e in r["effects"])
        c["hit"] = c.get("hit", 0) + ok
        if ok:
            continue
        rv = rivals.get(r["id"])
        cls = classify(r, oracle.get(r["id"]), rv)
        c[cls] += 1
        g = rv if rv is not None and "error" not in rv else {"fit": {}, "val": {}}
        again = "" if rv is None or "judged_again" not in rv else ("same causes" if rv["same_causes"] else "other causes")
        lines.append(f"| {r['id']} | {', '.join(r['causes'])} | {', '.join(r['reported']) or 'nothing'} | {cls} | "
                     f"{f(g['fit'].get('force_gain'))} / {f(g['val'].get('force_gain'))} | "
                     f"{f(g['fit'].get('loop_gain'))} / {f(g['val'].get('loop_gain'))} | {again} |")
    lines += ["", "| | n | hit | " + " | ".join(CLASSES) + " | hit rate where resolved |",
              "|---|---|---|" + "---|" * len(CLASSES) + "---|"]
    for kind, c in counts.items():
        n, hit = c.get("n", 0), c.get("hit", 0)
        resolved = n - c["invisible"] - c["confusable"]
        rate = f"{hit / resolved:.1%} ({hit}/{resolved})" if resolved else "-"
        name = "singles named first" if kind == "single" else "pairs both found"
        lines.append(f"| {name} | {n} | {hit} | " + " | ".join(str(c[k]) for k in CLASSES) + f" | {rate} |")
    return "\n".join(lines) + "\n", counts


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("set_dir", type=Path)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--summary", action="store_true", help="print the table against --hunting's results")
    ap.add_argument("--hunting", default=None, help="the judge's result label, e.g. hunting-ddd5d40")
    ap.add_argument("--append", type=Path, default=None, help="append the table to this RESULTS file (report.py's)")
    ap.add_argument("--rival", default=None, metavar="LABEL",
                    help="measure the truth over the explanations the judge LABEL reported on its misses")
    a = ap.parse_args(argv)
    if a.summary:
        if not a.hunting:
            ap.error("--summary needs --hunting LABEL")
        text = summary(a.set_dir, a.hunting)
        if a.append is not None:
            with a.append.open("a") as f:
                f.write("\n### What hunting's measures show of the exact effects (oracle)\n\n" + text)
        print(text, end="")
        return 0
    if a.rival:
        run_rival(a.set_dir, a.rival, a.jobs)
        text = miss_table(a.set_dir, a.rival)[0]
        if a.append is not None:
            with a.append.open("a") as f:
                f.write("\n### Why the moderate misses were missed (oracle over the reported explanations)\n\n" + text)
        print(text, end="")
        return 0
    run(a.set_dir, a.jobs)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
