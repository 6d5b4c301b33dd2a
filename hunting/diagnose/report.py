"""Diagnosis reports: JSON (the contract of ``hunting diagnose``), figures and a small HTML page."""
from __future__ import annotations

import html
import json
from pathlib import Path

import numpy as np

from ..plotting import _plt, cobweb_path, save
from .select import Diagnosis


def _pm(sigma) -> str:
    return "" if sigma is None or not np.isfinite(sigma) else f" ± {sigma:.2g}"


def write_json(dg: Diagnosis, path) -> None:
    Path(path).write_text(json.dumps(dg.as_dict(), indent=2, default=float))


def residual_figure(dg: Diagnosis, path) -> None:
    """Validation force residual of the nominal and the extended model against velocity,
    position and time (the evidence: structure against v or q names the cause)."""
    plt = _plt()
    kv = dg.kin_val
    fig, axes = plt.subplots(3, 1, figsize=(8, 9))
    for r, col, lab in ((dg.r_val_nominal, "C3", f"nominal (RMS {dg.nominal:.3g} N)"),
                        (dg.r_val_extended, "C0", f"extended (RMS {dg.extended:.3g} N)")):
        axes[0].plot(kv.v, r, ".", ms=1.0, color=col, label=lab)
        axes[1].plot(kv.q, r, ".", ms=1.0, color=col)
        axes[2].plot(kv.t, r, "-", lw=0.5, color=col)
    axes[0].set_xlabel("v [m/s]")
    axes[1].set_xlabel("q [m]")
    axes[2].set_xlabel("t [s]")
    for a in axes:
        a.set_ylabel("force residual [N]")
        a.grid(alpha=0.3)
    axes[0].legend(markerscale=8, fontsize=8)
    names = ", ".join(c.name for c in dg.causes) or "none"
    axes[0].set_title(f"validation force residual; causes found: {names}", fontsize=10)
    fig.tight_layout()
    save(fig, path)


def behaviour_figure(dg: Diagnosis, validate, path) -> None:
    """Validation run: the measured position error and the re-simulated nominal and extended
    loops (top), and each simulation's deviation from the measurement (bottom)."""
    plt = _plt()
    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    axes[0].plot(validate.t, validate.q - validate.q_ref, "k-", lw=1.0, label="measured")
    for style, lab in (("C3--", "nominal"), ("C0-", "extended")):
        sim = dg.simulations[lab]
        n = sim.q.size
        axes[0].plot(sim.t, sim.q - validate.q_ref[:n], style, lw=0.8, label=lab)
        axes[1].plot(sim.t, sim.q - validate.q[:n], style, lw=0.8,
                     label=f"{lab} (RMS {dg.behaviour[lab]['position_rms']:.3g} m)")
    axes[0].set_ylabel("q - q_ref [m]")
    axes[1].set_ylabel("simulated - measured q [m]")
    axes[1].set_xlabel("t [s]")
    for a in axes:
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    axes[0].set_title("behaviour on the validation data: re-simulated closed loop", fontsize=10)
    fig.tight_layout()
    save(fig, path)


def event_map_figure(dg: Diagnosis, path) -> None:
    """The measured event map of the validation run (stick error d_n against the next, d_{n+1},
    under a constant reference) with the cobweb of its last stretch, beside the re-simulated
    nominal and extended loops' maps; the diagonal (fixed points: one-sided cycles or rest) and
    the anti-diagonal (symmetric two-stick cycles)."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.0, 6.6))
    b = dg.behaviour
    every = [np.asarray(b[k]["event_map"], float).reshape(-1, 2) for k in ("measured", "nominal", "extended")]
    lim = max([float(np.max(np.abs(p))) for p in every if p.size] + [1e-12]) * 1.08
    ax.plot([-lim, lim], [-lim, lim], "-", color="0.4", lw=0.8, label="diagonal")
    ax.plot([-lim, lim], [lim, -lim], ":", color="0.4", lw=0.8, label="anti-diagonal")
    meas = every[0]
    if meas.shape[0]:
        # cobweb through the measured sequence's last (at most 12) steps: the pairs chain (d_{n+1}
        # of one is d_n of the next) as long as they are consecutive
        chain = [meas[-1]]
        for pt in meas[-2::-1]:
            if pt[1] != chain[-1][0] or len(chain) == 12:
                break
            chain.append(pt)
        xs = [c[0] for c in chain[::-1]] + [chain[0][1]]
        ax.plot(*cobweb_path(xs), "-", color="k", lw=0.6, alpha=0.6, label="cobweb (measured, last steps)")
    for pts, style, lab in zip(every, ("ko", "C3x", "C0+"), ("measured", "nominal", "extended")):
        c = b[lab]["map_contraction"]
        note = "" if c is None else f", |d$_{{n+1}}$|/|d$_n$| = {c:.3g}"
        ax.plot(pts[:, 0], pts[:, 1], style, ms=8 if lab == "measured" else 6, mfc="none" if lab == "measured" else None,
                label=f"{lab} ({pts.shape[0]} pairs{note})")
    ax.axhline(0, color="0.85", lw=0.6)
    ax.axvline(0, color="0.85", lw=0.6)
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_xlabel("stick error d$_n$ [m]")
    ax.set_ylabel("next stick error d$_{n+1}$ [m]")
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2)
    ax.set_title("event map of the validation run: measured and re-simulated", fontsize=10)
    fig.tight_layout()
    save(fig, path)


def write_report(dg: Diagnosis, directory) -> Path:
    """JSON, the figures (force residual; behaviour and event map when the view exists) and index.html in
    ``directory``; returns the HTML path."""
    d = Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    write_json(dg, d / "diagnosis.json")
    imgs = []
    if dg.nominal is not None:
        residual_figure(dg, d / "residual.png")
        imgs.append("residual.png")
    if dg.behaviour is not None:
        behaviour_figure(dg, dg.validation, d / "behaviour.png")
        imgs.append("behaviour.png")
        if any(dg.behaviour[k]["event_map"] for k in ("measured", "nominal", "extended")):
            event_map_figure(dg, d / "event_map.png")
            imgs.append("event_map.png")
    gains = "".join(f"<tr><td>{html.escape(g['metric'])}</td><td>{g['nominal']}</td><td>{g['extended']}</td></tr>"
                    for g in dg.gains())
    notes = "".join(f"<li>{html.escape(n)}</li>" for n in dg.notes)
    rows = "".join(
        f"<tr><td>{i + 1}</td><td>{html.escape(c.name)}</td><td>{c.score:.3g}</td><td>{c.p_value:.2g}</td>"
        f"<td>{html.escape(', '.join(f'{k} = {v:.4g}' + _pm(c.sigma.get(k)) for k, v in c.parameters.items()))}</td>"
        f"<td>{html.escape(c.gain['metric'])}: {c.gain['nominal']:.4g} → {c.gain['extended']:.4g}</td></tr>"
        for i, c in enumerate(dg.causes))
    rej = "".join(f"<li>{html.escape(r['name'])}: " + html.escape(
        r.get("reason") or f"p = {r.get('p_value', float('nan')):.2g}, validation gain = "
        f"{r.get('validation_gain') if r.get('validation_gain') is None else format(r['validation_gain'], '.2%')}")
        + "</li>" for r in dg.rejected)
    alt = "".join(f"<li>{html.escape(a['name'])}: {html.escape(str(a['parameters']))} (absorbed by "
                  f"{html.escape(', '.join(a['absorbed_by']))})</li>" for a in dg.alternatives)
    page = f"""<!doctype html><html><head><meta charset="utf-8"><title>hunting diagnosis</title></head><body>
<h1>Diagnosis</h1>
<table border="1" cellpadding="4"><tr><th>validation metric</th><th>nominal</th><th>extended</th></tr>{gains}</table>
{'<ul>' + notes + '</ul>' if notes else ''}
<p>Criterion: {html.escape(dg.criterion)}.</p>
<table border="1" cellpadding="4"><tr><th>rank</th><th>cause</th><th>score</th><th>p</th><th>parameters</th>
<th>validation metric: nominal → extended</th></tr>{rows}</table>
{'<h2>Alternatives</h2><ul>' + alt + '</ul>' if alt else ''}
{'<h2>Not reported (why)</h2><ul>' + rej + '</ul>' if rej else ''}
{''.join(f'<img src="{i}" width="720"><br>' for i in imgs)}</body></html>"""
    (d / "index.html").write_text(page)
    return d / "index.html"
