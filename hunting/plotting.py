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
