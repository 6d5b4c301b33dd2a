"""Chapter 8: PID + LuGre versus PID + Switch friction (Table 8.1), bifurcation diagrams in the
controller gain K by shooting and pseudo-arclength continuation (Figs. 8.2-8.6)."""
from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from .. import analysis as A
from .. import simulate
from ..continuation import OrbitStatus, follow, shoot
from ..continuation.cycle import find_cycle
from ..continuation.shooting import guess_from_stick_error
from ..eventmap import fixed_points
from ..models import preset
from ..plotting import _plt, save, plot_branch, plot_cycles, plot_trajectory
from .checks import Ledger

TABLE_8_1 = dict(m=0.026, cm=16.0, Fs=0.53, Fc=0.44, vs=0.02, b=0.1, sigma0=2.2e4, sigma1=7.58, eta=1e-6, alpha=10.0)


def _nearest(branch, mu, stable):
    idx = [i for i in range(len(branch.mu)) if branch.stable[i] == stable]
    return min(idx, key=lambda i: abs(branch.mu[i] - mu))


def _orbit_at(name, branch, mu, stable):
    """Shoot at parameter mu from the branch, interpolating between the two points of the
    wanted stability that bracket mu (or starting from the nearest one)."""
    idx = [i for i in range(len(branch.mu)) if branch.stable[i] == stable]
    lp = preset(name, K=mu)
    for a, b in zip(idx[:-1], idx[1:]):
        if b == a + 1 and (branch.mu[a] - mu) * (branch.mu[b] - mu) <= 0:
            w = (mu - branch.mu[a]) / (branch.mu[b] - branch.mu[a]) if branch.mu[b] != branch.mu[a] else 0.0
            x0 = branch.x0[a] + w * (branch.x0[b] - branch.x0[a])
            T = branch.period[a] + w * (branch.period[b] - branch.period[a])
            return shoot(lp.system, x0, T)
    i = _nearest(branch, mu, stable)
    return shoot(lp.system, branch.x0[i], branch.period[i])


def _thesis_fold(L: Ledger, ax, ax_table, short: str, fold_thesis: float) -> None:
    """The thesis' fold as a red dashed line beside ours, and the fold check as a table on
    ``ax_table`` (the multipliers' panel, where it covers nothing)."""
    ax.axvline(fold_thesis, color="C3", ls="--", lw=1.0, label=f"thesis: cyclic fold K = {fold_thesis}")
    for inset in ax.child_axes:             # the magnified view of the fold: above the line, with its own
        inset.set_zorder(10)
        inset.patch.set_facecolor("white")
        inset.axvline(fold_thesis, color="C3", ls="--", lw=1.0)
    ax.legend(fontsize=8, loc="upper left")
    items = [("fold K", f"{short}: fold K (within 0.5 %)", ".4f")] if any(
        r["check"] == f"{short}: fold K (within 0.5 %)" for r in L.rows) else []
    L.on_figure(ax_table, items + [("one cyclic fold", f"{short}: one cyclic fold", "")], loc="upper right")


def run(out: Path) -> int:
    out.mkdir(parents=True, exist_ok=True)
    L = Ledger("Chapter 8")
    results: dict = {}
    t_start = time.perf_counter()

    print("Table 8.1 -- parameters")
    lg = preset("table8.1-lugre")
    vals = dict(m=lg.plant.mass, cm=lg.plant.motor_constant, Fs=lg.friction.curve.positive.Fs,
                Fc=lg.friction.curve.positive.Fc, vs=lg.friction.curve.positive.vs, b=lg.friction.sigma2,
                sigma0=lg.friction.sigma0, sigma1=lg.friction.sigma1)
    sw = preset("table8.1-switch")
    vals.update(eta=sw.friction.eta, alpha=sw.friction.alpha)
    for k, v in TABLE_8_1.items():
        L.number(f"Table 8.1 {k}", vals[k], v, 1e-12 * max(1.0, abs(v)))
    tau = 1 / (2 * math.pi)
    kmin = lg.plant.mass / (lg.plant.motor_constant * tau * (tau + tau))
    L.number("linear stability without friction: K > J/(cm tau_d (tau_d + tau_i))", kmin, 0.0321, 5e-5)

    print("Section 8.4.1 -- LuGre equilibrium set, generalized Jacobian (1-q) J- + q J+")
    worst = -np.inf
    for K in (0.05, 0.3, 0.62, 1.0):
        lp = preset("table8.1-lugre", K=K)
        for bf in (-1.0, -0.5, 0.0, 0.5, 1.0):
            for q in np.linspace(0.0, 1.0, 11):
                ev = A.lugre_equilibrium_eigenvalues(lp, bf, q)
                ev = ev[np.argsort(np.abs(ev))]
                worst = max(worst, float(np.max(ev[1:].real)))
                zero = abs(ev[0])
    L.fact("one zero eigenvalue, three in the open left half plane (K > 0.0321)", bool(worst < 0 and zero < 1e-9), True)
    L.fact("sufficient condition sigma2 / J > pi", bool(lg.friction.sigma2 / lg.plant.mass > math.pi), True)

    print("Fig. 8.2 -- regulator task theta_d = 1 rad, K = 0.04: both loops hunt")
    amps, figs = {}, {}
    for name, method in (("table8.1-switch", "dop853"), ("table8.1-lugre", "dop853")):
        lp = preset(name, K=0.04)
        tr = simulate(lp.system, lp.state(x1=-1.0), (0.0, 100.0), method=method, rtol=1e-9, atol=1e-12, throw=True)
        amps[name] = float(np.max(np.abs(tr.x[tr.t > 70, 0])))
        figs[name] = plot_trajectory(tr, title=f"Fig. 8.2: {name}, K = 0.04", units=lp.system.units,
                                     stick_modes=[lp.stick_mode] if lp.stick_mode is not None else [])
    L.number("hunting amplitude ratio Switch / LuGre at K = 0.04", amps["table8.1-switch"] / amps["table8.1-lugre"], 1.0, 0.05)
    for name, fig in figs.items():
        L.on_figure(fig.axes[0], [("amplitude Switch/LuGre", "hunting amplitude ratio Switch / LuGre at K = 0.04",
                                   ".3f")], loc="lower right", room=0.4,
                    title=f"hunting cycle, amplitude {amps[name]:.4g} rad (t > 70 s)")
        save(fig, out / f"fig8_2_{name.split('-')[1]}.png")

    branches = {}
    for name, fold_thesis, k_unstable in (("table8.1-lugre", 0.620, 0.615), ("table8.1-switch", 0.647, 0.634)):
        short = name.split("-")[1]
        print(f"Fig. 8.{3 if short == 'lugre' else 5} -- {short} branch from K = 0.05 through the fold")
        t0 = time.perf_counter()
        br = follow(name, "K", 0.05, 1.0, stop_at=k_unstable)
        dt = time.perf_counter() - t0
        branches[short] = br
        results[f"branch {short}"] = br.as_dict()
        folds = [s for s in br.special if s.kind == "fold"]
        print(f"    {len(br.mu)} points in {dt:.1f} s; {br.message}")
        L.fact(f"{short}: one cyclic fold", len(folds), 1)
        if folds:
            f = folds[0]
            L.number(f"{short}: fold K (within 0.5 %)", f.param, fold_thesis, 0.005 * fold_thesis)
            cross = [s for s in br.special if s.kind == "multiplier_+1"]
            L.fact(f"{short}: lambda2 passes +1 at the fold", bool(cross and abs(cross[0].param - f.param) < 1e-3), True)
        lam = br.multipliers
        n = lam.shape[1]
        triv = np.abs(lam[:, 0] - 1) / np.maximum(1.0, np.abs(lam[:, 1]))
        print(f"    max |lambda1 - 1| / max(1, |lambda2|) = {np.max(triv):.1e}")
        # 1e-4: next to a grazing point (an event almost tangent) the saltation matrix divides by
        # a small n . f, which amplifies the event-time error (4.7e-5 at K = 0.58, LuGre), and the
        # branch's multipliers are only as accurate as its corrector (2.0e-4 at K = 0.573 with
        # numba 0.68 / numpy 2.4; a tighter newton_tol shrinks such errors tenfold): points above
        # it are checked again by shooting on the orbit itself
        again = np.flatnonzero(triv >= 1e-4)
        for i in again:
            c = find_cycle(name, x0=br.x0[i], period_guess=float(br.period[i]), params={"K": float(br.mu[i])})
            if c.status == OrbitStatus.SUCCESS:
                lam_i = np.asarray(c.multipliers, dtype=complex)
                lam_i = lam_i[np.argsort(np.abs(lam_i - 1))]
                big = np.max(np.abs(lam_i[1:])) if lam_i.size > 1 else 1.0
                triv[i] = abs(lam_i[0] - 1) / max(1.0, big)
        if again.size:
            print(f"    {again.size} point(s) re-checked by shooting: max |lambda1 - 1| / max(1, |lambda2|) = "
                  f"{np.max(triv):.1e}")
        L.fact(f"{short}: {n} multipliers, trivial one = 1", bool(np.max(triv) < 1e-4), True)
        small = np.abs(lam[:, 2:])
        L.fact(f"{short}: {'two multipliers near' if n == 4 else 'one multiplier equal to'} zero",
               bool(np.max(small) < (0.05 if n == 4 else 1e-8)), True)
        L.fact(f"{short}: all multipliers real", bool(np.max(np.abs(lam.imag)) < 1e-6), True)
        L.fact(f"{short}: stable below the fold, unstable after it",
               bool(br.stable[: folds[0].index + 1].all() and not br.stable[folds[0].index + 2:].any()) if folds else False, True)
        reached = float(br.mu[-1])
        L.fact(f"{short}: unstable branch followed down to K = {k_unstable}", bool(reached <= k_unstable + 1e-6), True)
        po_s = _orbit_at(name, br, k_unstable, True)
        po_u = _orbit_at(name, br, k_unstable, False)
        L.fact(f"{short}: stable and unstable cycles at K = {k_unstable}", (po_s.success and po_s.stable,
                                                                          po_u.success and not po_u.stable), (True, True))
        results[f"cycles {short} K={k_unstable}"] = dict(
            stable=dict(period=po_s.period, amplitude=po_s.amplitude, multipliers=[float(abs(v)) for v in po_s.multipliers]),
            unstable=dict(period=po_u.period, amplitude=po_u.amplitude, multipliers=[float(abs(v)) for v in po_u.multipliers]))
        lp = preset(name, K=k_unstable)
        if short == "lugre":     # Fig. 8.5 is drawn below, with the event-map circles added
            fig = plot_branch(br, title="Fig. 8.3: lugre loop, hunting branch in K",
                              equilibrium_stable=(np.array([0.0321, 1.0]), np.array([True, True])))
            _thesis_fold(L, fig.axes[0], fig.axes[1], short, fold_thesis)
            save(fig, out / "fig8_3.png")
        plot_cycles(lp.system, [po_s, po_u], [f"stable, K = {k_unstable}", f"unstable, K = {k_unstable}"],
                    title=f"Fig. 8.{4 if short == 'lugre' else 6}: {short} cycles at K = {k_unstable}",
                    eq_bounds=preset("table8.1-switch", K=k_unstable).equilibrium_set(),
                    path=out / f"fig8_{4 if short == 'lugre' else 6}.png")

    print("Switch loop: unstable cycles from the event map (Fig. 8.5 circles), shooting where it is conditioned")
    rows = []
    for K in (0.2, 0.3, 0.5, 0.6, 0.62, 0.634):
        lp = preset("table8.1-switch", K=K)
        un = [f for f in fixed_points(lp, np.linspace(0.0, 0.01, 2001), 2) if f.kind == "cycle" and not f.stable]
        if not un:
            print(f"    K = {K}: no unstable fixed point bracketed on the grid")
            continue
        row = dict(K=K, d=un[0].d, slope=un[0].slope)
        print(f"    K = {K}: unstable cycle d* = {un[0].d:.7f}, slope of P^2 = {un[0].slope:.4g}")
        if un[0].slope < 1e6:       # single shooting is limited by the multiplier's size
            x0, T = guess_from_stick_error(lp, un[0].d)
            po = shoot(lp.system, x0, T)
            row.update(amplitude=po.amplitude, multiplier=float(max(abs(po.multipliers[1:]))))
            L.fact(f"K = {K}: shooting converges on the unstable cycle", (po.success, po.stable), (True, False))
            L.number(f"K = {K}: amplitude (shooting) / stick error (event map)", po.amplitude / un[0].d, 1.0, 1e-6)
            L.number(f"K = {K}: lambda2 (shooting) / slope of P^2 (event map)", row["multiplier"] / un[0].slope,
                     1.0, 1e-3)
        rows.append(row)
    results["switch unstable cycles"] = rows
    fig = _plt().figure(figsize=(7, 7))
    ax = fig.add_subplot(2, 1, 1)
    ax2 = fig.add_subplot(2, 1, 2, sharex=ax)
    plot_branch(branches["switch"], axes=(ax, ax2), title="Fig. 8.5: switch loop, hunting branch in K "
                "(circles: unstable cycles from the event map)",
                equilibrium_stable=(np.array([0.0321, 1.0]), np.array([True, True])))
    ax.plot([r["K"] for r in rows], [r["d"] for r in rows], "o", mfc="w", mec="k", ms=6,
            label="unstable cycles (event map)")
    _thesis_fold(L, ax, ax2, "switch", 0.647)
    save(fig, out / "fig8_5.png")

    L.save(out / "ch8.json", extra=dict(results=results, seconds=time.perf_counter() - t_start))
    return L.finish(out)
