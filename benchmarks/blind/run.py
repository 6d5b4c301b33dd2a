"""Run the judges on a set of blind datasets: ``hunting.diagnose.diagnose`` (the diagnosis under
test, exactly as ``hunting diagnose FIT --model M --validate VAL`` runs it) and the sparse-
regression peer (:mod:`benchmarks.blind.peer`). One JSON result per dataset and judge, so a run
is resumable (existing results are kept); at most two worker processes, niced; a progress bar.

    python -m benchmarks.blind.run /work/wt/blind-data/tuning [--judge hunting|peer|both]
        [--label LABEL] [--jobs 2]

Results go to <set>/../results/<set name>/<label>/dNNNN.json (label: "hunting-<git rev>" of the
hunting package imported, "peer" for the peer)."""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import time
import traceback
from pathlib import Path

MAX_JOBS = 2
# one BLAS thread per worker: the machine's two cores are shared, and small least-squares
# problems only slow down when their threads contend (the variables only act before numpy loads)
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")


def hunting_label() -> str:
    """hunting-<short rev>[-dirty]: the last commit that changed the imported hunting package
    (and whether its files differ from it)."""
    import hunting
    root = Path(hunting.__file__).resolve().parents[1]
    try:
        rev = subprocess.run(["git", "-C", str(root), "log", "-1", "--format=%h", "--", "hunting"], capture_output=True, text=True,
                             timeout=20).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--", "hunting"], capture_output=True,
                               text=True, timeout=20).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "hunting-unknown"
    return f"hunting-{rev or 'unknown'}" + ("-dirty" if dirty else "")


def judge_hunting(dd: Path) -> dict:
    """The diagnosis on one dataset directory: selected causes in rank order with their
    parameters, their standard uncertainties (``sigma``; a parameter without one is left out), p-value, score and validation gain (the metric without and with the cause), the
    alternatives' names, notes, the rejected causes' names with their reasons and the extended model (what a later
    look at a miss needs, without running the diagnosis again)."""
    from hunting.diagnose import NominalModel, diagnose, load
    fit, val = load(dd / "fit.npz"), load(dd / "val.npz")
    model = NominalModel.from_json(dd / "model.json")
    d = diagnose(fit, model, val).as_dict()
    selected = [c for c in d.get("causes", []) if c.get("role", "selected") == "selected"]
    alts = [c["name"] for c in d.get("causes", []) if c.get("role") == "alternative"]
    alts += [a["name"] for a in d.get("alternatives", []) or [] if a["name"] not in alts]
    return dict(causes=[dict(name=c["name"], parameters=_floats(c.get("parameters", {})),
                             sigma=_floats(c.get("sigma") or {}), p_value=c.get("p_value"), score=c.get("score"),
                             gain=c.get("gain")) for c in selected],
                alternatives=alts, notes=d.get("notes", []), gain=d.get("gain"),
                rejected=[dict(name=r.get("name"), reason=r.get("reason")) for r in d.get("rejected", []) or []],
                untested=[dict(name=u.get("name"), reason=u.get("reason")) for u in d.get("untested", []) or []],
                extended_model=d.get("extended_model"))


def judge_peer(dd: Path) -> dict:
    from . import peer
    return peer.judge(dd)


JUDGES = {"hunting": judge_hunting, "peer": judge_peer}


def _floats(d: dict) -> dict:
    out = {}
    for k, v in d.items():
        try:
            out[k] = float(v)
        except (TypeError, ValueError):
            continue
    return out


def _one(args) -> tuple[str, float]:
    judge, dd, out = args
    t0 = time.perf_counter()
    try:
        res = JUDGES[judge](Path(dd))
        res["error"] = None
    except Exception as exc:                 # a judge that fails is a result, not a crash
        res = dict(causes=[], error=f"{type(exc).__name__}: {exc}", traceback=traceback.format_exc(limit=5))
    res["seconds"] = time.perf_counter() - t0
    res["id"] = Path(dd).name
    tmp = Path(out).with_suffix(".tmp")
    tmp.write_text(json.dumps(res, indent=1, default=float))
    tmp.replace(out)                         # atomic: a killed run leaves no half-written result
    return Path(dd).name, res["seconds"]


def _nice():
    # the pool's processes fill the cores: no re-simulation threads inside each
    os.environ.setdefault("HUNTING_THREADS", "1")
    try:
        os.nice(10)
    except OSError:
        pass


def results_dir(set_dir: Path, label: str) -> Path:
    return set_dir.parent / "results" / set_dir.name / label


def run(set_dir: Path, judge: str, label: str | None = None, jobs: int = MAX_JOBS, ids=None,
        progress: bool = True) -> Path:
    """Judge every dataset of ``set_dir`` not judged yet; returns the results directory."""
    from multiprocessing import get_context

    from tqdm import tqdm
    label = label or (hunting_label() if judge == "hunting" else judge)
    out = results_dir(set_dir, label)
    out.mkdir(parents=True, exist_ok=True)
    todo = [dd for dd in sorted(set_dir.glob("d[0-9]*")) if (ids is None or dd.name in ids)
            and not (out / f"{dd.name}.json").is_file()]
    jobs = max(1, min(int(jobs), MAX_JOBS))
    work = [(judge, str(dd), str(out / f"{dd.name}.json")) for dd in todo]
    bar = tqdm(total=len(work), desc=f"{judge} on {set_dir.name} ({label})", disable=not progress)
    if jobs == 1:
        _nice()
        for w in work:
            _one(w)
            bar.update()
    else:
        with get_context("spawn").Pool(jobs, initializer=_nice) as pool:
            for _ in pool.imap_unordered(_one, work):
                bar.update()
    bar.close()
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("set_dir", type=Path)
    ap.add_argument("--judge", choices=("hunting", "peer", "both"), default="both")
    ap.add_argument("--label", default=None, help="results label of the hunting judge (default hunting-<git rev>)")
    ap.add_argument("--jobs", type=int, default=MAX_JOBS)
    a = ap.parse_args(argv)
    for j in (("hunting", "peer") if a.judge == "both" else (a.judge,)):
        print(run(a.set_dir, j, a.label if j == "hunting" else None, a.jobs))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
