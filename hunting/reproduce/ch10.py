"""Chapter 10: the linear motor (LiMMS), as a virtual experiment.

The machine is the virtual LiMMS of :mod:`hunting.experiment` (LuGre presliding, synthetic
cogging, 1 um encoder, noise, a 5 kHz controller). The thesis' identification (section 10.3) runs
on its signals; the identified Switch and LuGre models are analysed as in section 10.4 and
compared with the "measured" behaviour of the virtual machine. Figs. 10.4-10.12.

Reference values: the true motor is built from the thesis' identified values (Table 10.2,
sigma0, sigma1, m), so identified parameters are printed beside them. Behaviour that depends on
the cogging table (which the thesis gives only as a figure) is compared with the thesis' numbers
with tolerances that say so."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import analysis as A
from .. import simulate
from ..eventmap import MapOptions, attractors, evaluate_map, event_map
from ..experiment import VirtualMotor
from ..experiment import limms as X
from ..experiment.motor import F_QD, Q_D, SLOPE_QD
from ..models import preset
from ..models import servo as S
from ..plotting import _plt, plot_attractor_diagram, plot_event_map, plot_frf, save, thesis_marks
from .checks import Ledger

K_VALUES = np.arange(10.0, 60.01, 2.0)
D_RANGE = 0.015
MAP_OPT = MapOptions(rtol=1e-10, max_events=5000, max_steps=10_000_000)


def _identification(L: Ledger, motor: VirtualMotor, out: Path, results: dict):
    print("Section 10.3 -- identification of the virtual LiMMS (true values = thesis' identified values)")
    idl = X.identify(motor)
    tol = {"m [kg]": 0.02, "Fs": 0.05, "Fc": 0.05, "vs": 0.10, "b ": 0.05, "sigma0": 0.15, "sigma1": 0.15}
    rows = []
    for name, val, sd, true in idl.table(motor):
        rel = next(v for k, v in tol.items() if name.startswith(k.strip()))
        L.number(f"identified {name} (+- {sd:.3g})", val, true, rel * abs(true))
        rows.append(dict(name=name, identified=val, sigma=sd, true=true))
    results["identified"] = rows
    L.fact("sigma0 inside the thesis' spread across positions [0.5e6, 2e6] N/m",
           bool(0.5e6 <= idl.presliding.values["sigma0"] <= 2e6), True)
    qg = np.arange(-0.48, -0.05, 1e-4)
    Ft = motor.cogging_force(qg)[0]
    rms_err = float(np.sqrt(np.mean((idl.cogging(qg) - Ft) ** 2)))
    rel = rms_err / float(np.sqrt(np.mean(Ft ** 2)))
    print(f"  cogging table: rms error {rms_err:.3f} N = {rel:.1%} of the rms amplitude")
    L.fact("cogging table rms error below 8 % of its rms amplitude", bool(rel < 0.08), True)
    F_qd = float(idl.cogging(np.array([Q_D]))[0])
    a_qd = float(idl.cogging.slope(np.array([Q_D]), dq=2e-4)[0])
    L.number("identified F_cog(q_d)", F_qd, F_QD, 1.0, "N")
    L.number("identified dF_cog/dq(q_d)", a_qd, SLOPE_QD, 0.15 * abs(SLOPE_QD), "N/m")
    results["cogging"] = dict(rms_error=rms_err, F_qd=F_qd, slope_qd=a_qd, q_star=idl.q_star)

    r = idl.records
    g = 1.0 / idl.mass.values["m_over_cm"]
    P = r["P"].band(1.0, 1000.0)
    fig = plot_frf([(P.f, P.H, "reconstructed P = (1/S - 1)/C", "-"),
                    (P.f, g / (2j * np.pi * P.f) ** 2, f"double integrator, m/cm = {1 / g:.4f} kg V/N", "--")],
                   title="Fig. 10.4: LiMMS FRF from the closed-loop sensitivity (fit 30-140 Hz)", unit="m/V")
    L.on_figure(fig.axes[0], [("m [kg]", "identified m [kg]", ".4g")], loc="lower left")
    save(fig, out / "fig10_4.png")
    plt = _plt()
    rec_c, rv, cruise = r["cogging"]
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7.5, 6.0), sharex=True)
    for sgn, col, lab in ((1, "C0", "positive velocity"), (-1, "C3", "negative velocity")):
        sel = cruise & (np.sign(rv) == sgn)
        a1.plot(rec_c.y[sel], motor.cm * rec_c.uc[sel], ",", color=col, label=lab)
    a1.set_ylabel("cm u [N]")
    a1.legend(fontsize=8, markerscale=20)
    a1.set_title("Fig. 10.5: a) control effort at 0.05 m/s, b) cogging table", fontsize=10)
    a2.plot(qg, Ft, "-", color="0.6", lw=2.5, label="true (virtual motor)")
    a2.plot(qg, idl.cogging(qg), "-", color="k", lw=0.8, label="identified table")
    a2.axvline(Q_D, color="C2", lw=0.8, ls=":", label="q_d")
    thesis_marks(a2, Q_D, F_QD, label=f"thesis: F_cog(q_d) = {F_QD} N")
    dq = np.array([-0.003, 0.003])
    a2.plot(Q_D + dq, F_QD + SLOPE_QD * dq, "--", color="C3", lw=1.2, label=f"thesis: slope {SLOPE_QD:.5g} N/m")
    L.on_figure(a2, [("F_cog(q_d) [N]", "identified F_cog(q_d)", ".4g"),
                     ("dF_cog/dq [N/m]", "identified dF_cog/dq(q_d)", ".4g")], loc="upper right", room=0.45)
    a2.set_xlabel("q [m]")
    a2.set_ylabel("F_cog [N]")
    a2.legend(fontsize=8)
    for a in (a1, a2):
        a.grid(alpha=0.3)
    fig.tight_layout()
    save(fig, out / "fig10_5.png")

    v, F = r["friction_map"]
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.plot(v, F, "o", mfc="w", mec="k", label="measured (mean cm u at constant velocity)")
    vv = np.linspace(1e-4, 0.2, 400)
    cur = idl.curve
    ax.plot(vv, cur.positive.level(vv) + cur.positive.b * vv, "-", color="C0", label="fit, per direction")
    ax.plot(-vv, -(cur.negative.level(vv) + cur.negative.b * vv), "-", color="C0")
    ax.plot(vv, motor.positive.level(vv) + motor.positive.b * vv, "--", color="C3", lw=1.0,
            label="thesis, Table 10.2 (the virtual motor's curve)")
    ax.plot(-vv, -(motor.negative.level(vv) + motor.negative.b * vv), "--", color="C3", lw=1.0)
    L.on_figure(ax, [(f"{p} ({sgn})", f"identified {p} ({sgn}) ", ".4g") for sgn in "+-" for p in ("Fs", "Fc", "vs", "b")],
                loc="lower right")
    ax.set_xscale("symlog", linthresh=1e-3)
    ax.set_xlabel("v [m/s]")
    ax.set_ylabel("F [N]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Fig. 10.6: velocity-friction map and Stribeck + viscous fit", fontsize=10)
    fig.tight_layout()
    save(fig, out / "fig10_6.png")

    H = r["presliding_frf"].band(1.0, 250.0)
    P = r["P"].band(10.0, 1000.0)
    pv = idl.presliding.values
    s = 2j * np.pi * H.f
    fig = plot_frf([(H.f, H.H, f"presliding FRF at q* = {idl.q_star:.4f} m", "-"),
                    (H.f, pv["b0"] / (s ** 2 + pv["a1"] * s + pv["a0"]),
                     f"2nd order: sigma0 + alpha = {pv['a0'] * idl.m:.3g} N/m", "--"),
                    (P.f, P.H, "sliding (Fig. 10.4)", ":")],
                   title="Fig. 10.7: presliding FRF below the static friction and its fit", unit="m/V")
    L.on_figure(fig.axes[0], [("sigma0 [N/m]", "identified sigma0 [N/m]", ".3g"),
                              ("sigma1 [N s/m]", "identified sigma1 [N s/m]", ".3g")], loc="lower left")
    save(fig, out / "fig10_7.png")
    return idl


def _equilibrium(L: Ledger, idl, results: dict):
    print("Section 10.4.2 -- the equilibrium set")
    K_thesis = A.critical_value(lambda K: preset("limms-switch", K=K), 1.0, 200.0)
    L.number("K above which the equilibrium set is stable (sufficient, thesis values)", K_thesis, 50.3389, 1e-4, "V/m")
    K_id = A.critical_value(lambda K: idl.loop(K), 1.0, 200.0)
    L.number("same condition for the identified model (its m, b, alpha)", K_id, 50.3389, 5.0, "V/m")
    loop10 = idl.loop(10.0)
    Fs_p, Fs_n = idl.curve.positive.Fs, idl.curve.negative.Fs
    F_qd = float(idl.cogging(np.array([Q_D]))[0])
    kk = 2 * np.pi * 10.0 * idl.cm
    bounds = ((-Fs_n - F_qd) / kk, (Fs_p - F_qd) / kk)
    print(f"  equilibrium set at K = 10: e3 in [{bounds[0]:.5g}, {bounds[1]:.5g}] m s "
          f"(shifted by the cogging force {F_qd:.3f} N at q_d)")

    # LuGre: generalized Jacobian over q in [0, 1] and |beta| <= Fs / sigma0
    def worst(K):
        lp = idl.loop(K, "lugre")
        re = []
        for bf in np.linspace(-1, 1, 9):
            for q in np.linspace(0, 1, 11):
                ev = A.lugre_equilibrium_eigenvalues(lp, bf, q)
                ev = ev[np.argsort(np.abs(ev))][1:]           # drop the zero eigenvalue
                re.append(np.max(ev.real))
        return max(re)
    from scipy.optimize import brentq
    K_lugre = brentq(worst, 20.0, 120.0, xtol=1e-8)
    L.number("LuGre generalized Jacobian: all non-zero eigenvalues stable from K", K_lugre, 50.3389, 5.0, "V/m")
    L.fact("LuGre and Switch conditions coincide (identified model, within 0.01 V/m)",
           bool(abs(K_lugre - K_id) < 0.01), True)
    ev10 = A.lugre_equilibrium_eigenvalues(idl.loop(10.0, "lugre"), 0.0, 0.5)
    slow = float(sorted(ev10, key=abs)[1].real)
    results["equilibrium"] = dict(K_sufficient_thesis_values=K_thesis, K_sufficient_identified=K_id,
                                  K_lugre=K_lugre, e3_bounds_K10=bounds,
                                  lugre_eigenvalues_K10=[[float(e.real), float(e.imag)] for e in ev10])
    print(f"  LuGre at K = 10, beta = 0: eigenvalues {np.round(ev10, 4)}; the slow one {slow:.3g} 1/s "
          f"(time constant {-1 / slow:.0f} s: presliding drift against the integral action, Fig. 10.9)")
    return loop10


def _time_responses(L: Ledger, motor: VirtualMotor, idl, out: Path, results: dict):
    print("Fig. 10.8 / 10.9 -- time responses at K = 10 V/m")
    K, d0, T = 10.0, 0.01, 15.0
    rec = X.regulator_experiment(motor, K, d0, T, hold=False)
    plt = _plt()
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.5))
    e = rec.y - Q_D
    for j, model in enumerate(("switch", "lugre")):
        lp = idl.loop(K, model)
        x0 = lp.state(d0)
        tr = simulate(lp.system, x0, (0.0, T), t_eval=rec.t, rtol=1e-9, atol=1e-12,
                      method="radau" if model == "lugre" else "dop853", throw=True)
        c = lp.controller
        Fm = -idl.cm * (c.kp * tr.x[:, 0] + c.kd * tr.x[:, 1] + c.ki * tr.x[:, 2])
        ax = axes[0, j]
        ax.plot(rec.t, e * 1e3, "-", color="k", lw=1.0, label="virtual LiMMS")
        ax.plot(tr.t, tr.x[:, 0] * 1e3, "--", color="C3", lw=1.0, label=f"identified model ({model})")
        ax.set_ylabel("e1 [mm]")
        ax.legend(fontsize=8)
        ax.set_title(f"Fig. 10.8{'ac'[j]}: K = 10 V/m, {model} model", fontsize=10)
        ax = axes[1, j]
        ax.plot(rec.t, motor.cm * rec.uc, "-", color="k", lw=1.0)
        ax.plot(tr.t, Fm, "--", color="C3", lw=1.0)
        ax.set_ylabel("cm u_c [N]")
        ax.set_xlabel("t [s]")
        for a in axes[:, j]:
            a.grid(alpha=0.3)
    fig.tight_layout()
    save(fig, out / "fig10_8.png")
    m_att = X.measured_attractor(motor, K, d0)
    results["K10_measured"] = m_att.as_dict()

    # Fig. 10.9: starts inside the presliding range near the equilibrium set
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7.5, 5.5), sharex=True)
    finals, rest = [], []
    for d0s, col in ((15e-6, "C0"), (-10e-6, "C3")):
        r9 = X.regulator_experiment(motor, K, d0s, 30.0)
        e9 = r9.y - Q_D
        a1.plot(r9.t, e9 * 1e6, color=col, lw=0.8, label=f"e1(0) = {d0s * 1e6:.0f} um")
        a2.plot(r9.t, motor.cm * r9.uc, color=col, lw=0.8)
        finals.append(float(motor.cm * np.mean(r9.uc[-5000:])))
        rest.append(bool(np.max(np.abs(e9)) < 50e-6))
    a1.set_ylabel("e1 [um]")
    a1.legend(fontsize=8)
    a2.set_ylabel("cm u_c [N]")
    a2.set_xlabel("t [s]")
    a1.set_title("Fig. 10.9: virtual LiMMS near the equilibrium set, K = 10 V/m (presliding only)", fontsize=10)
    for a in (a1, a2):
        a.grid(alpha=0.3)
    fig.tight_layout()
    save(fig, out / "fig10_9.png")
    L.fact("virtual LiMMS started near the equilibrium set stays in presliding (both starts, 30 s)", all(rest), True)
    L.fact("and the control effort stays non-zero and different for the two starts",
           bool(abs(finals[0] - finals[1]) > 0.5 and min(abs(f) for f in finals) > 0.1), True)
    results["fig10_9_final_forces"] = finals


def _event_maps(L: Ledger, motor: VirtualMotor, idl, out: Path, results: dict):
    print("Figs. 10.10 / 10.11 -- events and event maps at K = 10 V/m (identified Switch model)")
    loop = idl.loop(10.0)
    grid = np.linspace(-D_RANGE, D_RANGE, 501)
    atts = attractors(loop, np.linspace(-D_RANGE, D_RANGE, 24), options=MAP_OPT)
    cyc = [a for a in atts if a.kind == "cycle"]
    main = max(cyc, key=lambda a: a.basin) if cyc else None
    results["K10_model_attractors"] = [a.as_dict() for a in atts]
    L.number("stick phases per period of the model's main cycle at K = 10", main.period if main else 0, 6, 0)
    if main is not None:
        L.fact("it is stable (|dP^k/dd| < 1)", bool(abs(main.multiplier) < 1), True)
        print(f"  stick errors [mm]: {np.round(main.d * 1e3, 3)}; multiplier {main.multiplier:.3g}; "
              f"reached from {main.basin} of 24 starts")
    em1 = event_map(loop, grid, 1, derivative=False, options=MAP_OPT)
    print("  experimental event map: 60 points on the virtual machine")
    gx, dx = X.experimental_event_map(motor, 10.0, np.linspace(-D_RANGE, D_RANGE, 60))
    model_at = np.interp(gx, grid, em1.image)
    close = np.abs(dx - model_at) < 1e-3
    results["experimental_map"] = dict(d=gx.tolist(), d_next=dx.tolist(), model=model_at.tolist())
    frac = float(np.mean(close[np.isfinite(dx)]))
    print(f"  {frac:.0%} of the experimental points lie within 1 mm of the model's map")
    L.fact("model and virtual machine maps correspond (> 60 % of the points within 1 mm)", bool(frac > 0.6), True)
    plt = _plt()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 5.4))
    plot_event_map(em1, cobweb_from=float(main.d[0]) if main else None, cobweb_steps=main.period if main else 0,
                   ax=a1, title="Fig. 10.11a: P for the identified Switch model, K = 10 V/m")
    a1.plot(gx, dx, "o", mfc="w", mec="C2", ms=5, label="virtual LiMMS (experimental)")
    a1.legend(fontsize=7, loc="upper left")
    if main is not None:
        k = main.period
        emk = event_map(loop, grid, k, derivative=False, options=MAP_OPT)
        plot_event_map(emk, ax=a2, title=f"Fig. 10.11b: P^{k}; its contracting fixed points are the cycle")
        for d in main.d:
            a2.axvline(d, color="C3", ls="--", lw=0.8)
    L.on_figure(a1, [("stick phases per period", "stick phases per period of the model's main cycle at K = 10", ".0f")])
    fig.tight_layout()
    save(fig, out / "fig10_11.png")

    if main is not None:                                # Fig. 10.10: the cycle in time, events numbered
        xb, mode = loop.breakaway_state(np.array([main.d[0]]))
        per = evaluate_map(loop, [main.d[0]], main.period, MAP_OPT)
        T = float(per.slip_time[0] + per.stick_time[0]) + 0.5
        tr = simulate(loop.system, xb[0], (0.0, T), mode0=int(mode[0]), rtol=1e-10, atol=1e-13, throw=True)
        fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
        names = ["e1 [m]", "e2 [m/s]", "e3 [m s]"]
        ev = tr.events
        slips = ev.t[ev.mode_from == S.STICK]
        roman = ["I", "II", "III", "IV", "V", "VI", "VII", "VIII", "IX", "X", "XI", "XII"]
        for i, ax in enumerate(axes):
            ax.plot(tr.t, tr.x[:, i], "k", lw=1.0)
            ax.set_ylabel(names[i])
            ax.grid(alpha=0.3)
            for j, ts in enumerate([0.0] + list(slips)):
                ax.axvline(ts, color="0.5", ls="--", lw=0.7)
                if i == 0 and j < len(roman):
                    ax.text(ts, ax.get_ylim()[1] * 0.85, roman[j], fontsize=8)
        axes[0].set_title(f"Fig. 10.10: the model's {main.period}-stick-phase cycle at K = 10 V/m "
                          "(dashed: start of each slip phase)", fontsize=10)
        axes[-1].set_xlabel("t [s]")
        fig.tight_layout()
        save(fig, out / "fig10_10.png")


def _diagrams(L: Ledger, motor: VirtualMotor, idl, out: Path, results: dict, K_values):
    print(f"Fig. 10.12 -- bifurcation diagrams over K = {K_values[0]:g} ... {K_values[-1]:g} V/m")
    measured = X.measured_diagram(motor, K_values)
    model = [attractors(idl.loop(float(K)), np.linspace(-D_RANGE, D_RANGE, 12), options=MAP_OPT) for K in K_values]
    results["diagram_measured"] = [m.as_dict() for m in measured]
    results["diagram_model"] = [dict(K=float(K), attractors=[a.as_dict() for a in atts])
                                for K, atts in zip(K_values, model)]

    class _M:                                           # measured attractors drawn like the model's
        def __init__(self, m):
            self.kind = "equilibrium" if m.at_rest else ("cycle" if m.period else "irregular")
            self.d = m.stick_errors
    plt = _plt()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 4.8), sharey=True)
    plot_attractor_diagram(K_values, [[_M(m)] for m in measured], ax=a1, unit="mm", scale=1e3, param="K [V/m]",
                           title="Fig. 10.12a: virtual LiMMS (simulated measurement)")
    plot_attractor_diagram(K_values, model, ax=a2, unit="mm", scale=1e3, param="K [V/m]",
                           title="Fig. 10.12b: identified Switch model (event maps)")

    def gone(kinds):
        """Midway between the last gain with hunting and the next gain of the grid."""
        idx = [i for i, ks in enumerate(kinds) if "cycle" in ks or "irregular" in ks]
        if not idx or idx[-1] == len(kinds) - 1:
            return float("nan")
        return 0.5 * (K_values[idx[-1]] + K_values[idx[-1] + 1])
    kinds_model = [{a.kind for a in atts} for atts in model]
    kinds_meas = [{_M(m).kind} for m in measured]
    K_gone_model = gone(kinds_model)
    K_gone_meas = gone(kinds_meas)
    eq_model = [K for K, ks in zip(K_values, kinds_model) if "equilibrium" in ks]
    print("  the thesis' model numbers depend on its cogging table (a figure only): tolerances 5 V/m")
    L.number("model: hunting cycles gone above K", K_gone_model, 54.0, 5.0, "V/m")
    L.number("model: equilibrium set attracts from K", min(eq_model) if eq_model else np.nan, 50.0, 5.0, "V/m")
    two = [K for K, atts in zip(K_values, model) if 40 <= K <= 50]
    only2 = all(sorted(a.period for a in atts if a.kind == "cycle") == [2] for K, atts in zip(K_values, model)
                if K in two and not any(a.kind == "equilibrium" for a in atts))
    L.fact("model: K in [40, 50]: one stable cycle, two stick phases", only2, True)
    n10 = next((max(a.period for a in atts if a.kind == "cycle") for K, atts in zip(K_values, model) if K == 10.0), 0)
    n_hi = [max((a.period for a in atts if a.kind == "cycle"), default=0) for K, atts in zip(K_values, model) if K >= 40]
    L.fact("model: fewer stick phases per period as K grows (K = 10 vs K >= 40)", bool(n10 > max(n_hi)), True)
    L.number("virtual LiMMS: hunting gone above K (thesis' machine: about 42)", K_gone_meas, 42.0, 8.0, "V/m")
    a1.axvline(42.0, color="C3", ls="--", lw=1.0, label="thesis' machine: hunting gone above about 42")
    a2.axvline(54.0, color="C3", ls="--", lw=1.0, label="thesis' model: cycles gone above about 54")
    a2.axvline(50.0, color="C3", ls=":", lw=1.0, label="thesis' model: equilibrium set attracts from about 50")
    for a in (a1, a2):
        a.legend(fontsize=7, loc="upper right")
    L.on_figure(a1, [("hunting gone above K", "virtual LiMMS: hunting gone above K", ".3g")], loc="lower right")
    L.on_figure(a2, [("cycles gone above K", "model: hunting cycles gone above K", ".3g"),
                     ("eq. set attracts from K", "model: equilibrium set attracts from K", ".3g")], loc="lower right")
    fig.tight_layout()
    save(fig, out / "fig10_12.png")
    results["K_gone"] = dict(model=K_gone_model, measured=K_gone_meas)


def run(out: Path, quick: bool = False) -> int:
    """Reproduce chapter 10 into ``out``. quick: a coarse K grid for the diagrams (tests)."""
    out.mkdir(parents=True, exist_ok=True)
    L = Ledger("Chapter 10")
    results: dict = {}
    motor = VirtualMotor()
    idl = _identification(L, motor, out, results)
    _equilibrium(L, idl, results)
    _time_responses(L, motor, idl, out, results)
    _event_maps(L, motor, idl, out, results)
    K_values = np.array([10.0, 30.0, 44.0, 48.0, 50.0, 52.0, 54.0, 56.0, 58.0]) if quick else K_VALUES
    _diagrams(L, motor, idl, out, results, K_values)
    L.save(out / "ch10.json", results)
    return L.finish(out)
