"""Run hunting's diagnosis on records of the independent generator and score it.

    python benchmarks/independent/judge.py DATADIR OUTDIR     # diagnose every record (resumable)
    python benchmarks/independent/judge.py DATADIR OUTDIR --score

DATADIR holds what ``generate.py DATADIR --seed S`` wrote; OUTDIR gets one JSON per record (the
causes with parameters and uncertainties, the rejected and untested causes with their reasons,
the notes, the seconds). Scoring: a clean record with any cause is a false alarm; an effect
record is *named first* when the first cause is the true one or a name that stands for it
(LuGre bristles: ``reversal`` or ``presliding``; a Stribeck change: ``stribeck`` or ``level``;
a Coulomb-level asymmetry, a constant force while sliding: ``asymmetry`` or ``offset``, as in
``benchmarks/blind/draw.py``, and an asymmetry with a Coulomb-level part (variants ``coulomb`` and
``both``, one direction's Fc and Fs scaled): ``level_asymmetry`` too, as in
``benchmarks/blind/report.py``; a dwell growth: ``dwell`` or, in the seven-parameter form,
``dwell_peak``, as in ``benchmarks/blind/report.py``), *found* when it is anywhere in the list."""
from __future__ import annotations

import argparse
import json
import time
import traceback
from collections import defaultdict
from pathlib import Path

ALSO = {"reversal": {"presliding"}, "stribeck": {"level"}, "dwell": {"dwell_peak"}}


def accepted(truth: dict) -> set:
    """The names that count as finding the record's (single) effect."""
    cause = truth["causes"][0]
    names = {cause} | ALSO.get(cause, set())
    variant = truth.get("params", {}).get("variant")
    if cause == "asymmetry" and variant == "coulomb":
        names.add("offset")
    if cause == "asymmetry" and variant in ("coulomb", "both"):
        names.add("level_asymmetry")
    return names


def diagnose_all(data: Path, out: Path) -> None:
    from hunting.diagnose import NominalModel, diagnose, load
    out.mkdir(parents=True, exist_ok=True)
    for dd in sorted(p for p in data.iterdir() if p.is_dir()):
        target = out / f"{dd.name}.json"
        if target.exists():
            continue
        t0 = time.perf_counter()
        try:
            d = diagnose(load(dd / "fit.npz"), NominalModel.from_json(dd / "model.json"), load(dd / "val.npz")).as_dict()
            res = dict(causes=[dict(name=c["name"], parameters=c["parameters"], sigma=c.get("sigma"), gain=c.get("gain"))
                               for c in d["causes"] if c.get("role", "selected") == "selected"],
                       rejected=[dict(name=r["name"], reason=str(r.get("reason"))) for r in d["rejected"]],
                       untested=d["untested"], notes=d["notes"], error=None)
        except Exception as exc:                      # a benchmark records a failure and goes on
            res = dict(causes=[], error=f"{type(exc).__name__}: {exc}", traceback=traceback.format_exc()[-2000:])
        res["seconds"] = time.perf_counter() - t0
        target.write_text(json.dumps(res, default=float))
        print(dd.name, [c["name"] for c in res["causes"]], res["error"] or "", f"{res['seconds']:.1f} s", flush=True)


def score(data: Path, out: Path) -> dict:
    """{'clean': n, 'false_alarms': [(id, names)], 'per_cause': {cause: [n, first, found]},
    'misses': [(id, cause, names)], 'extras': [(id, cause, names)], 'errors': [id]}"""
    s = dict(clean=0, false_alarms=[], per_cause=defaultdict(lambda: [0, 0, 0]), misses=[], extras=[], errors=[])
    for o in sorted(out.glob("d*.json")):
        r = json.loads(o.read_text())
        t = json.loads((data / o.stem / "truth.json").read_text())
        names = [c["name"] for c in r["causes"]]
        if r.get("error"):
            s["errors"].append(o.stem)
        if t["clean"]:
            s["clean"] += 1
            if names:
                s["false_alarms"].append((o.stem, names))
            continue
        ok, cause = accepted(t), t["causes"][0]
        row = s["per_cause"][cause]
        row[0] += 1
        row[1] += bool(names) and names[0] in ok
        row[2] += any(n in ok for n in names)
        if not (names and names[0] in ok):
            s["misses"].append((o.stem, cause, names))
        elif len(names) > 1:
            s["extras"].append((o.stem, cause, names))
    return s


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("data", type=Path)
    ap.add_argument("out", type=Path)
    ap.add_argument("--score", action="store_true", help="score the results in OUT instead of diagnosing")
    a = ap.parse_args(argv)
    if not a.score:
        diagnose_all(a.data, a.out)
        return
    s = score(a.data, a.out)
    n = sum(v[0] for v in s["per_cause"].values())
    first = sum(v[1] for v in s["per_cause"].values())
    print(f"clean records: {s['clean']}, false alarms: {len(s['false_alarms'])} {s['false_alarms']}")
    print(f"effect records: {n}, named first: {first} ({first / max(n, 1):.0%})")
    for cause, (k, f, found) in sorted(s["per_cause"].items()):
        print(f"  {cause:12s} named first {f}/{k}, found {found}/{k}")
    for m in s["misses"]:
        print("  miss", *m)
    for e in s["extras"]:
        print("  extra", *e)
    if s["errors"]:
        print("errors:", s["errors"])


if __name__ == "__main__":
    main()
