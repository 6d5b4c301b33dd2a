"""Chapter 9 (and the map-based part of chapter 11): PID + Switch friction, Table 9.1.

Tables 9.2-9.4, Figs. 9.4-9.8, 11.1 and 11.3; every thesis number printed beside ours."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import analysis as A
from .. import simulate
from ..eventmap import event_map, fixed_points, map_diagram
from ..models import preset
from ..models import servo as S
from ..plotting import _plt, plot_event_map, plot_map_diagram, plot_trajectory, save, thesis_marks
from .checks import Ledger

CURVES = {"beta=2": dict(beta=2.0), "beta=1": dict(beta=1.0), "beta=0.5": dict(beta=0.5),
          "discontinuous": dict(beta="inf")}
GRID = np.round(np.arange(0, 501) * 0.001, 12)      # the thesis' grid, Delta d = 0.001 on [0, 0.5]


def _cycles(fps):
    return [f for f in fps if f.kind == "cycle"]


def run(out: Path) -> int:
    out.mkdir(parents=True, exist_ok=True)
    L = Ledger("Chapter 9")
    results: dict = {}

    print("Fig. 9.4 / 9.5 -- Table 9.1 from x(0) = (0.1, 0, 0); event map P")
    loop = preset("table9.1")
    tr = simulate(loop.system, [0.1, 0.0, 0.0], (0.0, 12.0), throw=True)
    d_seq = tr.events.x_after[tr.events.entering(S.STICK), 0]
    L.number("P(0.1): first stick error", d_seq[0], -0.1223, 5e-5, "m")
    L.fact("stick-slip sequence diverges", bool(np.all(np.diff(np.abs(d_seq)) > 0)), True)
    fig = plot_trajectory(tr, title="Fig. 9.4: Table 9.1 loop from (0.1, 0, 0)", stick_modes=[S.STICK],
                          units=loop.system.units)
    t_first = tr.events.t[tr.events.entering(S.STICK)][0]
    ax = fig.axes[0]
    ax.plot(t_first, d_seq[0], "o", mfc="w", mec="C0", ms=8, label="hunting: first stick error")
    thesis_marks(ax, t_first, -0.1223, label="thesis: P(0.1) = -0.1223")
    ax.legend(fontsize=7, loc="upper left")
    L.on_figure(ax, [("P(0.1) [m]", "P(0.1): first stick error", ".5f")], loc="lower right", room=0.35)
    save(fig, out / "fig9_4.png")
    em1 = event_map(loop, np.linspace(-0.5, 0.5, 1001), 1, derivative=False)
    fig = plot_event_map(em1, cobweb_from=0.1, cobweb_steps=3, title="Fig. 9.5: event map P, cobweb from d = 0.1")
    thesis_marks(fig.axes[0], 0.1, -0.1223, label="thesis: P(0.1)")
    fig.axes[0].legend(fontsize=8, loc="upper left")
    L.on_figure(fig.axes[0], [("P(0.1) [m]", "P(0.1): first stick error", ".5f")])
    save(fig, out / "fig9_5.png")
    L.fact("P is odd: max |P(d) + P(-d)| < 1e-9", bool(np.nanmax(np.abs(em1.image + em1.image[::-1])) < 1e-9), True)

    print("Table 9.2 / Fig. 9.6 -- fixed points of P^2, beta = 2")
    em2 = event_map(loop, GRID, 2, derivative=False)
    fps = fixed_points(loop, GRID, 2, thesis_fits=True, emap=em2)
    results["table9.2"] = [f.as_dict() for f in fps]
    eq = next(f for f in fps if f.kind == "equilibrium")
    cyc = _cycles(fps)
    L.fact("equilibrium set d1* = 0 stable", eq.stable, True)
    L.number("slope of P^2 at the origin", eq.slope, 0.86, 0.01)
    L.fact("number of cycles", len(cyc), 2)
    if len(cyc) == 2:
        L.number("d2* (unstable cycle)", cyc[0].d, 0.0034, 1e-4, "m")
        L.fact("d2* unstable", not cyc[0].stable, True)
        L.number("slope of P^2 at d2*", cyc[0].slope, 1.25, 0.01)
        L.number("d3* (stable cycle)", cyc[1].d, 0.2523, 1e-4, "m")
        L.fact("d3* stable", cyc[1].stable, True)
        L.number("slope of P^2 at d3*", cyc[1].slope, 0.78, 0.01)
        for f in cyc:
            print(f"    thesis' local cubic fit: d = {f.fit_d:.6f} (true map {f.d:.10f}), slope {f.fit_slope:.4f}")
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(11, 5))
    plot_event_map(em2, fixed=fps, title="Fig. 9.6: P$^2$, beta = 2 (filled: stable)", ax=axes[0])
    thesis_marks(axes[0], [0.0, 0.0034, 0.2523], [0.0, 0.0034, 0.2523], label="thesis: d1*, d2*, d3*")
    axes[0].legend(fontsize=8, loc="upper left")
    if len(cyc) == 2:
        L.on_figure(axes[0], [("slope at d1* = 0", "slope of P^2 at the origin", ".4g"),
                              ("d2* [m]", "d2* (unstable cycle)", ".5g"), ("slope at d2*", "slope of P^2 at d2*", ".4g"),
                              ("d3* [m]", "d3* (stable cycle)", ".5g"), ("slope at d3*", "slope of P^2 at d3*", ".4g")])
    zoom = event_map(loop, np.linspace(0.0, 0.008, 161), 2, derivative=False)
    plot_event_map(zoom, fixed=[f for f in fps if f.d < 0.008], title="near the equilibrium set", ax=axes[1])
    thesis_marks(axes[1], [0.0, 0.0034], [0.0, 0.0034], label="thesis: d1*, d2*")
    axes[1].legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    save(fig, out / "fig9_6.png")

    print("Table 9.3 / Fig. 9.7 -- other damping curves")
    thesis93 = {"beta=1": 0.2314, "beta=0.5": 0.1786, "discontinuous": 0.1485}
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.8))
    results["table9.3"] = {}
    for ax, (name, dstar) in zip(axes, thesis93.items()):
        lp = preset("table9.1", **CURVES[name])
        em = event_map(lp, GRID, 2, derivative=False)
        f3 = fixed_points(lp, GRID, 2, emap=em)
        results["table9.3"][name] = [f.as_dict() for f in f3]
        e3 = next(f for f in f3 if f.kind == "equilibrium")
        c3 = _cycles(f3)
        L.fact(f"{name}: equilibrium set unstable", not e3.stable, True)
        L.fact(f"{name}: one cycle, stable", (len(c3), all(c.stable for c in c3)), (1, True))
        if c3:
            L.number(f"{name}: d2*", c3[0].d, dstar, 1e-4, "m")
        how = ("slope of the linearization" if e3.origin.method == "linearization" else
               f"P^2(delta)/delta at delta = {e3.origin.probes[0][-1]:.1e}")
        print(f"    origin: {e3.origin.behaviour}, {how}: {e3.slope:.3g}")
        plot_event_map(em, fixed=f3, title=f"Fig. 9.7: P$^2$, {name}", ax=ax)
        thesis_marks(ax, dstar, dstar, label=f"thesis: d2* = {dstar}")
        ax.legend(fontsize=8, loc="upper left")
        items = [("equilibrium set unstable", f"{name}: equilibrium set unstable", "")]
        if c3:
            items.append(("d2* [m]", f"{name}: d2*", ".5g"))
        L.on_figure(ax, items)
    fig.tight_layout()
    save(fig, out / "fig9_7.png")

    print("Fig. 9.8 -- bifurcation diagrams, P = 10 ... 31")
    Ps = np.arange(10, 32, dtype=float)
    fig, axes = plt.subplots(2, 2, figsize=(12, 8.5))
    diagrams = {}
    for ax, name in zip(axes.ravel(), CURVES):
        dg = map_diagram("table9.1", "P", Ps, overrides=CURVES[name])
        diagrams[name] = dg
        results[f"fig9.8 {name}"] = dg.as_dict()
        plot_map_diagram(dg, title=f"Fig. 9.8: {name}", ax=ax)
    fig98, axes98 = fig, dict(zip(CURVES, axes.ravel()))
    d2 = diagrams["beta=2"]
    L.fact("beta=2: equilibrium set stable for all P", bool(d2.equilibrium_stable().all()), True)
    last = int(Ps[np.flatnonzero(d2.n_cycles() > 0)[-1]])
    L.fact("beta=2: last P with cycles", last, 21)
    folds = [s for s in d2.special if s.kind == "fold"]
    if folds:
        print(f"    fold located at P = {folds[0].param:.5f} (interval width {folds[0].precision:.1e})")
        L.fact("beta=2: fold between P = 21 and 22", bool(21 < folds[0].param < 22), True)
    d1 = diagrams["beta=1"]
    st = d1.equilibrium_stable()
    L.fact("beta=1: equilibrium set unstable up to P = 26", bool(not st[Ps <= 26].any()), True)
    L.fact("beta=1: equilibrium set stable from P = 27", bool(st[Ps >= 27].all()), True)
    L.fact("beta=1: no cycle from P = 27 (shrunk into the set)", bool((d1.n_cycles()[Ps >= 27] == 0).all()), True)
    pcrit = A.critical_value(lambda P: preset("table9.1", beta=1.0, P=P), 10.0, 40.0)
    L.number("beta=1: sufficient bound P > (Fs-Fc)/(D vs) + m I/D - b/D", pcrit, 29.0, 1e-9)
    for name in ("beta=0.5", "discontinuous"):
        dg = diagrams[name]
        L.fact(f"{name}: equilibrium set unstable for all P", bool(not dg.equilibrium_stable().any()), True)
        cyc_ok = all(any(f.kind == "cycle" and f.stable for f in fps) for fps in dg.fixed)
        L.fact(f"{name}: a stable cycle for every P", cyc_ok, True)
    ax = axes98["beta=2"]
    ax.axvspan(21, 22, color="C3", alpha=0.12, lw=0, label="thesis: fold between P = 21 and 22")
    ax.legend(fontsize=7, loc="upper right")
    L.on_figure(ax, [("last P with cycles", "beta=2: last P with cycles", "")]
                + ([("fold in (21, 22)", "beta=2: fold between P = 21 and 22", "")] if folds else [])
                + [("eq. set stable", "beta=2: equilibrium set stable for all P", "")], loc="center right")
    ax = axes98["beta=1"]
    thesis_marks(ax, 27.0, 0.0, label="thesis: equilibrium set stable from P = 27")
    ax.legend(fontsize=7, loc="upper right")
    L.on_figure(ax, [("unstable to P = 26", "beta=1: equilibrium set unstable up to P = 26", ""),
                     ("stable from P = 27", "beta=1: equilibrium set stable from P = 27", ""),
                     ("bound P >", "beta=1: sufficient bound P > (Fs-Fc)/(D vs) + m I/D - b/D", ".4g")],
                loc="center right")
    for name in ("beta=0.5", "discontinuous"):
        L.on_figure(axes98[name], [("eq. set unstable", f"{name}: equilibrium set unstable for all P", ""),
                                   ("stable cycle", f"{name}: a stable cycle for every P", "")], loc="center right")
    fig98.tight_layout()
    save(fig98, out / "fig9_8.png")

    print("Table 9.4 -- classification")
    table94 = []
    for name, dg in diagrams.items():
        cond = A.stability_condition(preset("table9.1", **CURVES[name]))
        elim = bool((dg.n_cycles() == 0).any())
        row = dict(curve=name, equilibrium_set=("locally stable" if dg.equilibrium_stable().all() else
                                                "stable above P = %.4g" % next(s.param for s in dg.special
                                                                                if s.kind == "equilibrium_stability")
                                                if dg.equilibrium_stable().any() else "unstable"),
                   cycles=("stable + unstable pair, fold at P = %.4g" % next(s.param for s in dg.special if s.kind == "fold")
                           if any(s.kind == "fold" for s in dg.special) else
                           "one stable cycle" + (", shrinks into the set" if elim else " for every P")),
                   hunting_can_be_eliminated=elim, sufficient_condition=cond.text)
        table94.append(row)
        print(f"    {name:<14} equilibrium set: {row['equilibrium_set']:<24} cycles: {row['cycles']:<40} "
              f"eliminable: {elim}")
    results["table9.4"] = table94
    L.fact("Table 9.4: hunting can be eliminated (beta=2, beta=1, beta=0.5, discontinuous)",
           tuple(r["hunting_can_be_eliminated"] for r in table94), (True, True, False, False))

    print("Chapter 11 -- Coulomb friction only (Fc = Fs = 4 N): critical damping b*")
    bstar = A.critical_damping(lambda b: preset("table9.1", Fc=4.0, b=b))
    L.number("b* (slope of the linear map P^2 through 1)", bstar, -1.253, 5e-4, "N s/m")
    fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    for ax, b in zip(axes, (1.0, 0.0, round(bstar, 3))):
        lp = preset("table9.1", Fc=4.0, b=b)
        t = simulate(lp.system, [0.1, 0.0, 0.0], (0.0, 40.0), throw=True)
        ax.plot(t.t, t.x[:, 0], lw=1.0)
        ax.set_ylabel("x1 [m]")
        ax.set_title(f"b = {b:g} N s/m", fontsize=9)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("t [s]")
    L.on_figure(axes[-1], [("b* [N s/m]", "b* (slope of the linear map P^2 through 1)", ".4f")], room=0.4)
    fig.suptitle("Fig. 11.1: Coulomb friction only, decreasing viscous damping (last: b = b*)")
    fig.tight_layout()
    save(fig, out / "fig11_1.png")
    lin = A.coulomb_map_slope(preset("table9.1", Fc=4.0))
    hom = preset("table9.1", Fc=4.0)
    from ..eventmap import evaluate_map
    mv = evaluate_map(hom, [0.01, 0.1, 0.4], 2)
    L.fact("Coulomb only: P^2 is linear in d (homogeneous)", bool(np.allclose(mv.image / mv.d, lin, rtol=1e-8)), True)

    v = np.linspace(-1.0, 1.0, 4001)
    fig, axes = plt.subplots(2, 2, figsize=(10, 7))
    results["fig11.3"] = {}
    for ax, name in zip(axes.ravel(), CURVES):
        curve = preset("table9.1", **CURVES[name]).friction.curve.positive
        fnl = A.stribeck_block(curve, bstar, v)
        bad = A.nonpassive_intervals(curve, bstar, v)
        results["fig11.3"][name] = bad
        ax.plot(v, fnl, lw=1.0)
        for a, b in bad:
            ax.axvspan(a, b, color="C3", alpha=0.12, lw=0)
        ax.axhline(0, color="0.5", lw=0.6)
        ax.set_title(f"{name}: F_nl (shaded: not passive)", fontsize=9)
        ax.set_xlabel("x2 [m/s]")
        ax.set_ylabel("F_nl [N]")
        ax.grid(alpha=0.3)
    fig.suptitle(f"Fig. 11.3: Stribeck-related block F_nl = g sgn - Fs sgn + (b - b*) v, b* = {bstar:.4f} "
                 "(thesis -1.253)")
    fig.tight_layout()
    save(fig, out / "fig11_3.png")
    small = results["fig11.3"]["beta=2"]
    L.fact("beta=2: F_nl passive for small |v| (first non-passive |v| > 0)", bool(small and min(abs(small[-1][0]), abs(small[0][1])) > 0.005), True)

    L.save(out / "ch9.json", extra=dict(results=results))
    return L.finish(out)
