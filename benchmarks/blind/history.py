"""The held-out verdicts side by side: has the diagnosis's rate on data it never saw moved?

Every session drew a new reporting set before its changes and judged its stop code on it
(``RESULTS_reporting<k>.md``, written by :mod:`benchmarks.blind.report`). This reads the headline
judge of each (the first hunting column of its targets table) and asks whether the rates change
from verdict to verdict: per target the counts, the pooled rate with a Wilson 95 % interval, the
trend per verdict (a binomial logistic fit of the rate on the verdict's number, its slope's
95 % interval) and a chi-square test of one common rate across the verdicts.

    python -m benchmarks.blind.history [--first 20] [--figure docs/figures/diagnose_blind_history.png
        --plateau 20]

Prints markdown."""
from __future__ import annotations

import argparse
import math
import re
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
ROWS = {"named_first": "moderate single effects named first", "both_found": "two moderate effects both found",
        "false_alarm": "false alarms, overall", "params": "found causes' parameters within 10 %"}
_COUNT = re.compile(r"\((\d+)/(\d+)")


def verdicts(first: int = 2) -> list[dict]:
    """[{set, k, label, <target>: (hits, n)}] of the RESULTS_reporting<k>.md files with k >= first,
    in order of k (the headline judge: the first column after ``bar`` of the targets table)."""
    out = []
    for p in HERE.glob("RESULTS_reporting*.md"):
        m = re.fullmatch(r"RESULTS_reporting(\d+)\.md", p.name)
        if not m or int(m.group(1)) < first:
            continue
        lines = p.read_text().splitlines()
        head = next((ln for ln in lines if ln.startswith("| target | bar |")), None)
        if head is None:
            continue
        row = dict(set=f"reporting{m.group(1)}", k=int(m.group(1)), label=head.split("|")[3].strip())
        for key, text in ROWS.items():
            ln = next((ln for ln in lines if ln.startswith(f"| {text} |")), None)
            c = _COUNT.search(ln.split("|")[3]) if ln else None
            if c:
                row[key] = (int(c.group(1)), int(c.group(2)))
        out.append(row)
    return sorted(out, key=lambda r: r["k"])


def wilson(k: int, n: int, level: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a binomial rate k/n at confidence ``level`` (scipy's binomtest)."""
    from scipy.stats import binomtest
    if n == 0:
        return (math.nan, math.nan)
    ci = binomtest(int(k), int(n)).proportion_ci(confidence_level=level, method="wilson")
    return (float(ci.low), float(ci.high))


def trend(x: np.ndarray, k: np.ndarray, n: np.ndarray) -> tuple[float, float]:
    """(slope, standard error) of logit(rate) = a + slope x for binomial counts k of n (Newton
    iterations on the log-likelihood, at most 50)."""
    X = np.column_stack([np.ones_like(x, dtype=float), x.astype(float)])
    beta = np.zeros(2)
    p0 = np.clip(k.sum() / n.sum(), 1e-6, 1 - 1e-6)
    beta[0] = math.log(p0 / (1 - p0))
    for _ in range(50):
        p = 1 / (1 + np.exp(-X @ beta))
        W = n * p * (1 - p)
        H = X.T @ (X * W[:, None])
        step = np.linalg.solve(H, X.T @ (k - n * p))
        beta += step
        if np.max(np.abs(step)) < 1e-10:
            break
    p = 1 / (1 + np.exp(-X @ beta))
    cov = np.linalg.inv(X.T @ (X * (n * p * (1 - p))[:, None]))
    return float(beta[1]), float(math.sqrt(cov[1, 1]))


def homogeneity(k: np.ndarray, n: np.ndarray) -> tuple[float, int, float]:
    """(chi-square, degrees of freedom, p) of the hypothesis that every verdict has the pooled rate
    (scipy's test of the 2 x verdicts contingency table, no continuity correction)."""
    from scipy.stats import chi2_contingency
    r = chi2_contingency(np.array([k, n - k], float), correction=False)
    return float(r.statistic), int(r.dof), float(r.pvalue)


def markdown(rows: list[dict]) -> str:
    lines = ["| set | judge | named first | pairs both found | false alarms | parameters within 10 % |",
             "|---|---|---|---|---|---|"]

    def cell(r, key):
        if key not in r:
            return "-"
        a, b = r[key]
        return f"{100 * a / b:.1f} % ({a}/{b})" if b else "-"
    for r in rows:
        lines.append(f"| {r['set']} | {r['label']} | " + " | ".join(cell(r, key) for key in ROWS) + " |")
    lines += ["", "| target | pooled (Wilson 95 %) | trend per verdict, logit slope (95 %) | one rate for all: "
                  "chi-square, dof, p |", "|---|---|---|---|"]
    for key, text in ROWS.items():
        sel = [r for r in rows if key in r and r[key][1] > 0]
        if len(sel) < 3:
            continue
        x = np.array([r["k"] for r in sel])
        k = np.array([r[key][0] for r in sel], float)
        n = np.array([r[key][1] for r in sel], float)
        lo, hi = wilson(int(k.sum()), int(n.sum()))
        s, se = trend(x, k, n)
        x2, dof, p = homogeneity(k, n)
        lines.append(f"| {text} | {100 * k.sum() / n.sum():.1f} % ({int(k.sum())}/{int(n.sum())}; {100 * lo:.1f}-"
                     f"{100 * hi:.1f}) | {s:+.4f} ({s - 1.96 * se:+.4f} to {s + 1.96 * se:+.4f}) | {x2:.1f}, {dof}, "
                     f"{p:.2f} |")
    return "\n".join(lines) + "\n"


def figure(rows: list[dict], path: Path, plateau: int | None = None) -> None:
    """Named first and pairs both found per verdict with Wilson intervals, the pooled rate of every
    verdict and, from set ``plateau`` on, of those verdicts alone, and the targets."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, key, bar, title, low in ((axes[0], "named_first", 0.95, "moderate single effects named first", 60),
                                     (axes[1], "both_found", 0.90, "two moderate effects both found", 0)):
        sel = [r for r in rows if key in r and r[key][1] > 0]
        x = np.array([r["k"] for r in sel])
        k = np.array([r[key][0] for r in sel])
        n = np.array([r[key][1] for r in sel])
        ci = np.array([wilson(int(a), int(b)) for a, b in zip(k, n)])
        rate = k / n
        ax.errorbar(x, 100 * rate, yerr=100 * np.abs(ci.T - rate), fmt="o", ms=4, capsize=2, label="held-out verdict")
        pooled = k.sum() / n.sum()
        ax.axhline(100 * pooled, color="C2", lw=1.0, ls=":",
                   label=f"pooled, all {n.size} verdicts: {100 * pooled:.1f} %")
        if plateau is not None and np.any(x >= plateau):
            late = x >= plateau
            pl = k[late].sum() / n[late].sum()
            ax.plot([plateau, x.max()], [100 * pl, 100 * pl], color="C2", lw=2.0,
                    label=f"pooled from reporting{plateau}: {100 * pl:.1f} %")
        ax.axhline(100 * bar, color="C3", ls="--", lw=1.2, label=f"target {100 * bar:.0f} %")
        ax.set_xlabel("reporting set (one per session, drawn before its changes)")
        ax.set_ylabel("rate [%]")
        ax.set_title(title, fontsize=10)
        ax.set_ylim(low, 101)
        ax.legend(fontsize=8, loc="lower right")
        ax.grid(alpha=0.3)
    fig.suptitle("hunting diagnose on blind sets it never saw: Wilson 95 % intervals", fontsize=11)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--first", type=int, default=2, help="the first reporting set read (default 2)")
    ap.add_argument("--figure", type=Path, default=None)
    ap.add_argument("--plateau", type=int, default=None, help="also draw the pooled rate from this set on")
    a = ap.parse_args(argv)
    rows = verdicts(a.first)
    print(markdown(rows), end="")
    if a.figure is not None:
        figure(rows, a.figure, a.plateau)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
