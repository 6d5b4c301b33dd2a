"""Tables, figure and targets of the blind benchmark from the truths and the judges' results.

Scoring rules (one place, used by the report and the tests):
- a dataset's reported causes are the judge's selected causes in rank order (alternatives are
  not causes);
- clean dataset: a false alarm when anything is reported; per cause: when that cause is;
- an effect is *found* when a reported name is in its ``accept`` list, *named first* when the
  first reported cause is;
- *extras*: reported causes no effect of the dataset accepts;
- *moderate*: an effect whose validation gain when modelled exactly (``truth.json`` gain,
  computed without hunting) is at least MODERATE = 0.15;
- parameter error: for a found effect, |reported - true| / |true| of the primary parameters
  (``draw.PRIMARY`` of the reported name) that both the report and the truth hold;
- uncertainty: where the judge states a standard uncertainty sigma for such a parameter,
  |reported - true| / sigma; the truth is *covered* when that is at most COVER_Z = 2 (about 95 %
  of the parameters for honest, normal uncertainties).

Targets (issue 17, item 7), on the reporting seeds: overall false alarms <= 5 % of the clean
datasets and <= 1 % per cause; moderate single effects named first in >= 95 %; two-effect datasets
with both effects moderate: both found in >= 90 %; found moderate effects with every compared
parameter within 10 % of the truth: >= 95 %."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from . import draw

MODERATE = 0.15
TARGETS = dict(false_alarm=0.05, false_alarm_cause=0.01, named_first=0.95, both_found=0.90, params=0.95)
PARAM_TOL = 0.10
COVER_Z = 2.0
GAIN_BINS = (-math.inf, 0.05, 0.15, 0.3, 0.6, math.inf)


def load_truths(set_dir: Path) -> dict:
    return {p.parent.name: json.loads(p.read_text()) for p in sorted(Path(set_dir).glob("d[0-9]*/truth.json"))}


def load_results(res_dir: Path) -> dict:
    return {p.stem: json.loads(p.read_text()) for p in sorted(Path(res_dir).glob("d[0-9]*.json"))}


def reported(result: dict) -> list:
    """[(name, parameters)] in rank order."""
    return [(c["name"], c.get("parameters", {})) for c in result.get("causes", [])]


# names that stand for a truth's cause besides those its draw listed (``accept``), for causes the
# diagnosis learnt to name in a second form after the sets were drawn: a dwell growth found by
# the force channel in the seven-parameter form (``dwell_peak``, of dwell's family) is a dwell
FORMS = {"dwell": ("dwell_peak",)}
# ... and for the variants whose draw accepted a constant force (``offset``: an asymmetry with a
# Coulomb-level part): the levels of the two directions scaled apart (``level_asymmetry``, whose
# Fc_pos and Fc_neg are judged against the truth's) name that asymmetry too
COULOMB_FORMS = {"asymmetry": ("level_asymmetry",)}


def accept_names(effect: dict) -> set:
    """The reported names that count as finding a truth's ``effect``: its draw's ``accept``
    and the cause's FORMS (COULOMB_FORMS where the draw accepted ``offset``)."""
    extra = COULOMB_FORMS.get(effect["cause"], ()) if "offset" in effect["accept"] else ()
    return set(effect["accept"]) | set(FORMS.get(effect["cause"], ())) | set(extra)


def score(truths: dict, results: dict) -> dict:
    """Per-dataset outcome rows for the datasets that have both a truth and a result."""
    rows = []
    for i, t in truths.items():
        if i not in results:
            continue
        res = results[i]
        rep = reported(res)
        names = [n for n, _ in rep]
        accepts = [accept_names(e) for e in t["effects"]]
        accepted = set().union(*accepts) if accepts else set()
        effects = []
        for e, accept in zip(t["effects"], accepts):
            found = [k for k, n in enumerate(names) if n in accept]
            errs, zs = {}, {}
            if found:
                name, pars = rep[found[0]]
                sig = res["causes"][found[0]].get("sigma") or {}
                for p in draw.PRIMARY.get(name, ()):
                    if p in pars and p in e["params"] and e["params"][p] != 0:
                        errs[p] = abs(pars[p] - e["params"][p]) / abs(e["params"][p])
                        s = sig.get(p)
                        zs[p] = abs(pars[p] - e["params"][p]) / s if s is not None and s > 0 else None
            effects.append(dict(cause=e["cause"], variant=e.get("variant", ""), gain=e["gain"], frac=e["frac"],
                                found=bool(found), first=bool(names) and names[0] in accept,
                                moderate=e["gain"] >= MODERATE, errors=errs, z=zs))
        rows.append(dict(id=i, causes=t["causes"], reported=names, extras=[n for n in names if n not in accepted],
                         effects=effects, error=res.get("error"), seconds=res.get("seconds", float("nan"))))
    return rows


def summary(rows: list) -> dict:
    """The benchmark's rates (see the module docstring)."""
    clean = [r for r in rows if not r["causes"]]
    single = [r for r in rows if len(r["causes"]) == 1]
    pairs = [r for r in rows if len(r["causes"]) == 2]
    names = sorted({n for r in rows for n in r["reported"]} | set(draw.ALL_CAUSES))
    fa_cause = {n: _rate(sum(n in r["reported"] for r in clean), len(clean)) for n in names}
    mod_single = [r for r in single if r["effects"][0]["moderate"]]
    mod_pairs = [r for r in pairs if all(e["moderate"] for e in r["effects"])]
    found_mod = [e for r in single + pairs for e in r["effects"] if e["found"] and e["moderate"] and e["errors"]]
    return dict(
        n_clean=len(clean), n_single=len(single), n_pairs=len(pairs),
        false_alarm=_rate(sum(bool(r["reported"]) for r in clean), len(clean)),
        false_alarm_cause=fa_cause,
        named_first=_rate(sum(r["effects"][0]["first"] for r in mod_single), len(mod_single)),
        found_single=_rate(sum(r["effects"][0]["found"] for r in mod_single), len(mod_single)),
        n_moderate_single=len(mod_single),
        both_found=_rate(sum(all(e["found"] for e in r["effects"]) for r in mod_pairs), len(mod_pairs)),
        both_found_all=_rate(sum(all(e["found"] for e in r["effects"]) for r in pairs), len(pairs)),
        n_moderate_pairs=len(mod_pairs),
        params=_rate(sum(all(v <= PARAM_TOL for v in e["errors"].values()) for e in found_mod), len(found_mod)),
        n_params=len(found_mod),
        params_sigma=_rate(sum(z is not None for e in found_mod for z in e["z"].values()),
                           sum(len(e["z"]) for e in found_mod)),
        params_covered=_rate(sum(z <= COVER_Z for e in found_mod for z in e["z"].values() if z is not None),
                             sum(z is not None for e in found_mod for z in e["z"].values())),
        extras_on_effects=_rate(sum(bool(r["extras"]) for r in single + pairs), len(single + pairs)),
        errors=sum(r["error"] is not None for r in rows),
        seconds=float(np.nanmedian([r["seconds"] for r in rows])) if rows else float("nan"))


def _rate(k, n):
    return (k / n if n else float("nan"), int(k), int(n))


def targets(s: dict) -> list:
    """[(name, value, bar, passed, margin, text)] for the item-7 targets."""
    out = []
    fa = s["false_alarm"]
    out.append(("false alarms, overall", fa[0], TARGETS["false_alarm"], fa[0] <= TARGETS["false_alarm"],
                TARGETS["false_alarm"] - fa[0], f"{fa[1]}/{fa[2]} clean datasets"))
    worst = max(s["false_alarm_cause"].items(), key=lambda kv: kv[1][0] if kv[1][2] else -1)
    out.append(("false alarms, worst cause", worst[1][0], TARGETS["false_alarm_cause"],
                worst[1][0] <= TARGETS["false_alarm_cause"], TARGETS["false_alarm_cause"] - worst[1][0],
                f"{worst[0]}: {worst[1][1]}/{worst[1][2]}"))
    for key, label in (("named_first", "moderate single effects named first"),
                       ("both_found", "two moderate effects both found"),
                       ("params", "found causes' parameters within 10 %")):
        v = s[key]
        out.append((label, v[0], TARGETS[key], bool(v[0] >= TARGETS[key]), v[0] - TARGETS[key], f"{v[1]}/{v[2]}"))
    return out


def confusion(rows: list, kind: str = "single") -> tuple[list, list, dict]:
    """(row labels, column labels, counts {(row, col): (any rank, first)}) of true cause against
    reported cause; rows: clean and each single cause (kind "single"), or each effect of the
    two-effect datasets (kind "pairs")."""
    cols = sorted({n for r in rows for n in r["reported"]}) + ["nothing", "error"]
    table: dict = {}
    labels = []

    def add(label, r):
        if label not in labels:
            labels.append(label)
        names = r["reported"]
        keys = [(n, k == 0) for k, n in enumerate(dict.fromkeys(names))]
        if r["error"] is not None:
            keys = [("error", True)]
        elif not names:
            keys = [("nothing", True)]
        for n, first in keys:
            a, f = table.get((label, n), (0, 0))
            table[(label, n)] = (a + 1, f + int(first))
        a, f = table.get((label, "n"), (0, 0))
        table[(label, "n")] = (a + 1, 0)
    for r in rows:
        if kind == "single" and not r["causes"]:
            add("clean", r)
    for c in draw.ALL_CAUSES:
        for r in rows:
            if kind == "single" and r["causes"] == [c]:
                add(c, r)
            elif kind == "pairs" and len(r["causes"]) == 2 and c in r["causes"]:
                add(c, r)
    return labels, cols, table


def detection_by_gain(rows: list, cause: str) -> list:
    """[(bin label, n, found, named first)] of the single-effect datasets of ``cause``."""
    out = []
    effs = [r["effects"][0] for r in rows if r["causes"] == [cause]]
    for lo, hi in zip(GAIN_BINS[:-1], GAIN_BINS[1:]):
        sel = [e for e in effs if lo <= e["gain"] < hi]
        label = f"< {hi:g}" if lo == -math.inf else (f">= {lo:g}" if hi == math.inf else f"{lo:g}-{hi:g}")
        out.append((label, len(sel), sum(e["found"] for e in sel), sum(e["first"] for e in sel)))
    return out


def parameter_errors(rows: list) -> dict:
    """{cause: {parameter: [(relative error, error / stated sigma or None)]}} of the found effects
    (any size)."""
    out: dict = {}
    for r in rows:
        for e in r["effects"]:
            for p, v in e["errors"].items():
                out.setdefault(e["cause"], {}).setdefault(p, []).append((v, e["z"].get(p)))
    return out


def figure(judged: dict, path: Path) -> None:
    """Detection against validation gain, one panel per cause (single-effect datasets): per gain
    bin the share named first (solid step) and found at any rank (dashed), with the bin's count;
    dots: datasets at 1 (named first), 0.5 (found, not first) or 0 (missed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    causes = list(draw.ALL_CAUSES)
    ncol = 5
    nrow = math.ceil(len(causes) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(3.3 * ncol, 2.7 * nrow), sharey=True)
    colors = {"hunting": "C0", "peer": "C3"}
    lo_edge, hi_edge = -0.2, 1.0
    for ax, cause in zip(axes.flat, causes):
        for k, (name, rows) in enumerate(judged.items()):
            effs = [r["effects"][0] for r in rows if r["causes"] == [cause]]
            if not effs:
                continue
            col = colors.get(name.split("-")[0], f"C{k + 1}")
            g = np.clip([e["gain"] for e in effs], lo_edge, hi_edge)
            y = np.array([1.0 if e["first"] else (0.5 if e["found"] else 0.0) for e in effs]) + (k - 0.5) * 0.05
            ax.plot(g, y, "o", ms=3, color=col, alpha=0.45)
            for lo, hi in zip(GAIN_BINS[:-1], GAIN_BINS[1:]):
                sel = [e for e in effs if lo <= e["gain"] < hi]
                if not sel:
                    continue
                x0, x1 = max(lo, lo_edge), min(hi, hi_edge)
                first = np.mean([e["first"] for e in sel])
                found = np.mean([e["found"] for e in sel])
                dy = (k - 0.5) * 0.025                 # judges' equal rates side by side
                ax.hlines(first + dy, x0, x1, color=col, lw=2.0, label=f"{name}: named first")
                ax.hlines(found + dy, x0, x1, color=col, lw=1.0, ls="--", label=f"{name}: found")
                ax.text(0.5 * (x0 + x1), first + 0.04 + 0.09 * k, str(len(sel)), color=col, fontsize=6,
                        ha="center")
        ax.axvline(MODERATE, color="0.5", lw=0.8, ls=":")
        ax.set_title(cause, fontsize=9)
        ax.set_ylim(-0.1, 1.2)
        ax.set_xlim(lo_edge - 0.02, hi_edge + 0.02)
        ax.grid(alpha=0.3)
    for ax in axes.flat[len(causes):]:
        ax.axis("off")
    handles, labels = axes.flat[0].get_legend_handles_labels()
    uniq = dict(zip(labels, handles))
    axes.flat[len(causes)].legend(uniq.values(), uniq.keys(), fontsize=8, loc="center",
                                  title="bins: gain < .05, .05-.15, .15-.3, .3-.6, >= .6\nnumbers: datasets per bin",
                                  title_fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("validation gain when modelled", fontsize=8)
    for ax in axes[:, 0]:
        ax.set_ylabel("detection rate", fontsize=8)
    fig.suptitle("blind benchmark: detection against effect size (single effects; dotted: moderate = "
                 f"{MODERATE:g}; gains below {lo_edge:g} drawn at it)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _pct(v) -> str:
    return "n/a" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{100 * v:.1f} %"


def markdown(set_name: str, judged: dict, figure_name: str | None = None) -> str:
    """The benchmark's tables for one seed set, every judge side by side."""
    S = {name: summary(rows) for name, rows in judged.items()}
    names = list(judged)
    first = S[names[0]]
    L = [f"## Set `{set_name}`: {first['n_clean']} clean, {first['n_single']} single-effect, "
         f"{first['n_pairs']} two-effect datasets", ""]
    L += ["### Targets (issue 17, item 7)", "", "| target | bar | " + " | ".join(names) + " |",
          "|---|---|" + "---|" * len(names)]
    T = {n: targets(S[n]) for n in names}
    for k, row in enumerate(T[names[0]]):
        cells = []
        for n in names:
            label, v, bar, ok, margin, text = T[n][k]
            cells.append(f"{'PASS' if ok else 'FAIL'} {_pct(v)} ({text}; margin {100 * margin:+.1f} pts)")
        cmp = "<=" if "false" in row[0] else ">="
        L.append(f"| {row[0]} | {cmp} {_pct(row[2])} | " + " | ".join(cells) + " |")
    L += ["", "PASS/FAIL lines:", "", "```"]
    for n in names:
        for label, v, bar, ok, margin, text in T[n]:
            L.append(f"{n}: {'PASS' if ok else 'FAIL'} {label}: {_pct(v)} (bar {_pct(bar)}, margin "
                     f"{100 * margin:+.1f} pts; {text})")
    L += ["```", ""]
    if len(names) > 1:
        a, b = names[0], names[1]
        L += [f"Difference {a} - {b}: false alarms {100 * (S[a]['false_alarm'][0] - S[b]['false_alarm'][0]):+.1f} pts "
              f"(lower is better), moderate single effects named first "
              f"{100 * (S[a]['named_first'][0] - S[b]['named_first'][0]):+.1f} pts, found "
              f"{100 * (S[a]['found_single'][0] - S[b]['found_single'][0]):+.1f} pts, two effects both found "
              f"{100 * (S[a]['both_found'][0] - S[b]['both_found'][0]):+.1f} pts (higher is better).", ""]
    L += ["### Overview", "", "| | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]
    for key, label in (("false_alarm", "clean datasets with any cause reported"),
                       ("named_first", "moderate single effects named first"),
                       ("found_single", "moderate single effects found (any rank)"),
                       ("both_found", "two moderate effects: both found"),
                       ("both_found_all", "two effects of any size: both found"),
                       ("extras_on_effects", "effect datasets with an extra (wrong) cause"),
                       ("params", "found moderate causes with parameters within 10 %"),
                       ("params_sigma", "their parameters with a stated standard uncertainty"),
                       ("params_covered", f"of those, truth within {COVER_Z:g} stated uncertainties")):
        L.append(f"| {label} | " + " | ".join(f"{_pct(S[n][key][0])} ({S[n][key][1]}/{S[n][key][2]})"
                                              for n in names) + " |")
    L.append("| judge failures (exceptions) | " + " | ".join(str(S[n]["errors"]) for n in names) + " |")
    L.append("| median seconds per dataset | " + " | ".join(f"{S[n]['seconds']:.2g}" for n in names) + " |")
    L += ["", "### False alarms per cause on clean data", "",
          "| cause | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]
    causes = sorted(set().union(*[S[n]["false_alarm_cause"] for n in names]))
    for c in causes:
        L.append(f"| {c} | " + " | ".join(
            f"{_pct(S[n]['false_alarm_cause'].get(c, (0, 0, 0))[0])} ({S[n]['false_alarm_cause'].get(c, (0, 0, 0))[1]})"
            for n in names) + " |")
    for n in names:
        for kind, title in (("single", "single effects (and clean)"), ("pairs", "effects of the two-effect datasets")):
            labels, cols, tab = confusion(judged[n], kind)
            cols = [c for c in cols if any((lab, c) in tab for lab in labels)]
            L += ["", f"### Confusion, {n}: {title}", "",
                  "Rows: true cause (n datasets); columns: reported causes, count at any rank (count ranked first).", "",
                  "| true \\ reported | n | " + " | ".join(cols) + " |", "|---|---|" + "---|" * len(cols)]
            for lab in labels:
                cells = []
                for c in cols:
                    a, f = tab.get((lab, c), (0, 0))
                    cells.append("" if not a else (f"{a}" if c in ("nothing", "error") else f"{a} ({f})"))
                L.append(f"| {lab} | {tab[(lab, 'n')][0]} | " + " | ".join(cells) + " |")
    L += ["", "### Detection against effect size (single effects)", "",
          "Validation gain when the true effect is modelled exactly (computed without hunting); "
          "cells: named first / found / n.", "",
          "| cause | judge | " + " | ".join(lab for lab, *_ in detection_by_gain([], "offset")) + " |",
          "|---|---|" + "---|" * (len(GAIN_BINS) - 1)]
    for c in draw.ALL_CAUSES:
        for n in names:
            cells = [f"{f1}/{fd}/{k}" if k else "" for _, k, fd, f1 in detection_by_gain(judged[n], c)]
            L.append(f"| {c} | {n} | " + " | ".join(cells) + " |")
    if figure_name:
        L += ["", f"![detection against effect size]({figure_name})", ""]
    L += ["", "### Parameter errors of found causes (relative to the true final value)", "",
          f"Uncertainty stated: share of the values that come with a standard uncertainty; covered: of those, "
          f"the share whose truth lies within {COVER_Z:g} of them.", "",
          "| cause | parameter | judge | n | median | within 10 % | uncertainty stated | covered |",
          "|---|---|---|---|---|---|---|---|"]
    for n in names:
        for c, pars in sorted(parameter_errors(judged[n]).items()):
            for p, vz in sorted(pars.items()):
                v = np.asarray([a for a, _ in vz])
                z = np.asarray([b for _, b in vz if b is not None])
                L.append(f"| {c} | {p} | {n} | {v.size} | {100 * np.median(v):.1f} % | {_pct(np.mean(v <= PARAM_TOL))} | "
                         f"{z.size}/{v.size} | {_pct(np.mean(z <= COVER_Z)) if z.size else '-'} |")
    L += ["", "### Effect sizes (validation gain when modelled, single effects)", "",
          "| cause | n | gain >= 0.15 | median gain |", "|---|---|---|---|"]
    rows0 = judged[names[0]]
    for c in draw.ALL_CAUSES:
        g = [r["effects"][0]["gain"] for r in rows0 if r["causes"] == [c]]
        if g:
            L.append(f"| {c} | {len(g)} | {sum(x >= MODERATE for x in g)} | {np.median(g):.2f} |")
    return "\n".join(L) + "\n"


PEER_THRESHOLD = Path(__file__).with_name("peer_threshold.json")


def peer_results(res_dir: Path, threshold: float) -> dict:
    """The peer's results with the causes it reports at ``threshold``."""
    from . import peer
    return {i: dict(r, causes=peer.at_threshold(r, threshold)) if "thresholds" in r else r
            for i, r in load_results(res_dir).items()}


def choose_peer_threshold(set_dir: Path, res_dir: Path) -> float:
    """Fix the peer's threshold on the clean datasets of a TUNING set and store it in
    PEER_THRESHOLD (the reporting set is then judged with it, never chosen on it)."""
    from . import peer
    truths = load_truths(set_dir)
    clean = [r for i, r in load_results(res_dir).items() if i in truths and not truths[i]["causes"]
             and "thresholds" in r]
    th = peer.choose_threshold(clean)
    PEER_THRESHOLD.write_text(json.dumps(dict(threshold=th, chosen_on=Path(set_dir).name, clean_datasets=len(clean),
                                              rule="smallest threshold with <= 5 % of the clean datasets reporting "
                                                   "anything"), indent=1) + "\n")
    return th


def write(set_dir: Path, judges: dict, out_md: Path, figure_path: Path | None = None, *, title: str = "",
          preamble: str = "") -> dict:
    """Score the judges {name: results} (results: {dataset id: result}) on ``set_dir``; write the
    markdown (and the figure). Returns {name: summary}."""
    truths = load_truths(set_dir)
    judged = {name: score(truths, results) for name, results in judges.items()}
    if figure_path is not None:
        figure(judged, figure_path)
    rules = "Scoring rules and targets (benchmarks/blind/report.py):\n\n" + __doc__.split("\n\n", 1)[1] + "\n\n"
    md = (f"# {title}\n\n" if title else "") + preamble + rules + markdown(Path(set_dir).name, judged,
                                                                            figure_path.name if figure_path else None)
    out_md.write_text(md)
    return {n: summary(r) for n, r in judged.items()}


def main(argv=None) -> int:
    import argparse
    from .run import results_dir
    ap = argparse.ArgumentParser(description="tables, figure and targets of the blind benchmark")
    ap.add_argument("set_dir", type=Path)
    ap.add_argument("--hunting", required=True, help="results label of the hunting run (e.g. hunting-deb45a5)")
    ap.add_argument("--peer", action="store_true", help="add the sparse-regression peer")
    ap.add_argument("--choose-threshold", action="store_true",
                    help="fix the peer's threshold on this (tuning) set and store it")
    ap.add_argument("--out", type=Path, default=Path(__file__).with_name("RESULTS.md"))
    ap.add_argument("--title", default="Blind benchmark of hunting diagnose")
    ap.add_argument("--note", default="", help="a paragraph under the title (what was run)")
    a = ap.parse_args(argv)
    judges = {a.hunting: load_results(results_dir(a.set_dir, a.hunting))}
    pre = a.note + "\n\n" if a.note else ""
    if a.peer:
        pdir = results_dir(a.set_dir, "peer")
        if a.choose_threshold:
            choose_peer_threshold(a.set_dir, pdir)
        meta = json.loads(PEER_THRESHOLD.read_text())
        judges["peer"] = peer_results(pdir, meta["threshold"])
        pre += (f"Peer: pysindy STLSQ on the force residual, threshold {meta['threshold']:.3g} chosen on the "
               f"`{meta['chosen_on']}` set ({meta['rule']}).\n\n")
    fig = a.out.with_name(f"detection_{Path(a.set_dir).name}.png")
    S = write(a.set_dir, judges, a.out, fig, title=a.title, preamble=pre)
    for name, s in S.items():
        for label, v, bar, ok, margin, text in targets(s):
            print(f"{name}: {'PASS' if ok else 'FAIL'} {label}: {_pct(v)} (bar {_pct(bar)}, margin "
                  f"{100 * margin:+.1f} pts; {text})")
    print(f"wrote {a.out} and {fig}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
