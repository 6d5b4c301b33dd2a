"""matplotlib figures (imported lazily so that the engine does not need a display)."""
from __future__ import annotations

import numpy as np


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def plot_trajectory(traj, *, title: str = "", stick_modes=(), units: dict | None = None, path=None):
    """Time responses of every state and a phase portrait (x1, x2, x3 in 3-D).

    Stick phases (modes in ``stick_modes``) are shaded; event states are marked with circles.
    Returns the figure; saves it when ``path`` is given."""
    plt = _plt()
    units = units or {}
    n = traj.x.shape[1]
    fig = plt.figure(figsize=(11, 2.2 * max(n, 3)))
    gs = fig.add_gridspec(n, 2, width_ratios=[1.4, 1])
    intervals = traj.stick_intervals(list(stick_modes)) if len(stick_modes) else np.empty((0, 2))
    for i in range(n):
        ax = fig.add_subplot(gs[i, 0])
        ax.plot(traj.t, traj.x[:, i], lw=1.0, color="C0")
        for a, b in intervals:
            ax.axvspan(a, b, color="0.85", lw=0)
        name = traj.state_names[i] if traj.state_names else f"x{i + 1}"
        ax.set_ylabel(f"{name} [{units.get(name, '-')}]")
        ax.grid(alpha=0.3)
        if i == n - 1:
            ax.set_xlabel("t [s]")
    ax3 = fig.add_subplot(gs[:, 1], projection="3d" if n >= 3 else None)
    if n >= 3:
        ax3.plot(traj.x[:, 0], traj.x[:, 1], traj.x[:, 2], lw=0.8, color="C0")
        ev = traj.events
        if len(ev):
            ax3.scatter(ev.x_after[:, 0], ev.x_after[:, 1], ev.x_after[:, 2], s=12, facecolors="none",
                        edgecolors="C3", label="events")
            ax3.legend(loc="upper left", fontsize=8)
        ax3.set_xlabel("x1")
        ax3.set_ylabel("x2")
        ax3.set_zlabel("x3")
    else:
        ax3.plot(traj.x[:, 0], traj.x[:, 1], lw=0.8)
        ax3.set_xlabel("x1")
        ax3.set_ylabel("x2")
    ax3.set_title("phase portrait", fontsize=10)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    if path is not None:
        fig.savefig(path, dpi=120)
    return fig


def plot_hysteresis(force, displacement, *, title: str = "", path=None, units=("N", "m")):
    """Force against displacement (presliding hysteresis, thesis Fig. 4.2a)."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    ax.plot(displacement, force, lw=1.0)
    ax.plot(displacement[:1], force[:1], "ko", ms=4, label="start")
    ax.set_xlabel(f"displacement [{units[1]}]")
    ax.set_ylabel(f"applied force [{units[0]}]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title)
    fig.tight_layout()
    if path is not None:
        fig.savefig(path, dpi=120)
    return fig


def plot_event_map(em, *, cobweb_from=None, cobweb_steps: int = 6, fixed=(), title: str = "", ax=None,
                   path=None, unit: str = "m"):
    """P^k(d) against d with the diagonal; optional cobweb from ``cobweb_from`` (iterating the
    true map) and fixed points (stable filled, unstable open)."""
    plt = _plt()
    own = ax is None
    if own:
        fig, ax = plt.subplots(figsize=(5.6, 5.0))
    else:
        fig = ax.figure
    k = em.iterate
    lab = "P(d)" if k == 1 else f"P$^{k}$(d)"
    ax.plot(em.grid, em.image, ".", ms=2.0, color="C0", label=lab)
    lo, hi = float(np.nanmin(em.grid)), float(np.nanmax(em.grid))
    ax.plot([lo, hi], [lo, hi], "-", color="0.4", lw=0.8, label="diagonal")
    ax.axhline(0, color="0.8", lw=0.6)
    ax.axvline(0, color="0.8", lw=0.6)
    if cobweb_from is not None:
        from .eventmap.engine import evaluate_map
        xs = [float(cobweb_from)]
        for _ in range(cobweb_steps):
            mv = evaluate_map(em.loop, [xs[-1]], k, em.options)
            if not mv.ok[0]:
                break
            xs.append(float(mv.image[0]))
        px, py = [xs[0]], [0.0]
        for a, b in zip(xs[:-1], xs[1:]):
            px += [a, b]
            py += [b, b]
        ax.plot(px, py, "-", color="C3", lw=0.9, label="cobweb")
        ax.plot(xs[:-1], xs[1:], "o", color="C3", ms=4)
    for f in fixed:
        for d in ([f.d] if f.kind == "equilibrium" else [f.d, -f.d] if em.loop.odd and em.grid.min() < 0 else [f.d]):
            ax.plot(d, d, "o", ms=7, mfc="k" if f.stable else "w", mec="k", zorder=5)
    ax.set_xlabel(f"d$^n$ [{unit}]")
    ax.set_ylabel(f"d$^{{n+{k}}}$ [{unit}]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    if title:
        ax.set_title(title, fontsize=10)
    if own:
        fig.tight_layout()
        if path is not None:
            fig.savefig(path, dpi=130)
    return fig


def plot_map_diagram(diagram, *, title: str = "", ax=None, path=None, unit: str = "m"):
    """Bifurcation diagram from event maps: cycle stick errors against the parameter, stable
    solid and unstable dashed; the equilibrium set (d = 0) solid where stable, dashed where not;
    folds and stability changes marked."""
    plt = _plt()
    own = ax is None
    if own:
        fig, ax = plt.subplots(figsize=(6.0, 4.2))
    else:
        fig = ax.figure
    v = diagram.values
    # cycles: connect points branch by branch (sorted by d within each parameter value)
    branches: dict = {}
    for i, fps in enumerate(diagram.fixed):
        cyc = sorted([f for f in fps if f.kind == "cycle"], key=lambda f: f.d)
        for j, f in enumerate(cyc):
            key = (f.stable, j if f.stable else -1 - j)
            branches.setdefault(key, []).append((v[i], f.d))
    for sp in diagram.special:          # close the pair of branches at each fold
        if sp.kind == "fold":
            for key in ((True, 0), (False, -1)):
                if key in branches:
                    branches[key].append((sp.param, sp.data.get("d", 0.0)))
    for (stable, _), pts in branches.items():
        pts = np.array(sorted(pts))
        ax.plot(pts[:, 0], pts[:, 1], "-" if stable else "--", color="k", lw=1.4 if stable else 1.1,
                marker="o" if stable else None, ms=3)
    eq = diagram.equilibrium_stable()
    for i in range(v.size - 1):
        ax.plot(v[i:i + 2], [0, 0], "-" if (eq[i] and eq[i + 1]) else "--", color="C0", lw=2.0 if eq[i] else 1.2)
    for s in diagram.special:
        if s.kind == "fold":
            ax.plot(s.param, s.data.get("d", 0.0), "s", color="C3", ms=7, label=f"fold {diagram.param} = {s.param:.4g}")
        else:
            ax.plot(s.param, 0.0, "D", color="C2", ms=7, label=f"equilibrium set stable from {s.param:.4g}")
    ax.plot([], [], "-", color="k", label="stable cycle")
    ax.plot([], [], "--", color="k", label="unstable cycle")
    ax.plot([], [], "-", color="C0", lw=2.0, label="equilibrium set (dashed: unstable)")
    ax.set_xlabel(diagram.param)
    ax.set_ylabel(f"stick error d* [{unit}]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    if title:
        ax.set_title(title, fontsize=10)
    if own:
        fig.tight_layout()
        if path is not None:
            fig.savefig(path, dpi=130)
    return fig
