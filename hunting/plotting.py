"""matplotlib figures (imported lazily so that the engine does not need a display)."""
from __future__ import annotations

import numpy as np


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def save(fig, path) -> None:
    """Save a figure (atomically: a temporary file, then a rename) and release it (reproducers
    make dozens of figures)."""
    from pathlib import Path

    import matplotlib

    from ._atomic import atomic_path
    fmt = Path(path).suffix[1:].lower() or matplotlib.rcParams["savefig.format"]
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=130, format=fmt)
    finally:
        _plt().close(fig)


def _axes(ax, figsize):
    """(fig, ax, own): a new figure when ax is None (own = True), else the axes' figure."""
    if ax is None:
        fig, ax = _plt().subplots(figsize=figsize)
        return fig, ax, True
    return ax.figure, ax, False


def _finish(fig, ax, own: bool, title: str, path) -> None:
    """Common tail of the single-axes plots: title, layout and saving when the figure is ours."""
    if title:
        ax.set_title(title, fontsize=10)
    if own:
        fig.tight_layout()
        if path is not None:
            save(fig, path)


THESIS_STYLE = dict(marker="x", color="C3", ms=9, mew=2.0, ls="none", zorder=6)


def thesis_marks(ax, x, y, *, label: str = "thesis") -> None:
    """The thesis' values as red crosses (one legend entry), beside ours."""
    ax.plot(np.atleast_1d(x), np.atleast_1d(y), label=label, **THESIS_STYLE)


def thesis_table(ax, rows, *, loc: str = "lower right", title: str = "", room: float = 0.0) -> None:
    """A small table in the axes: for each row (label, thesis, ours, format) the thesis value
    beside ours ("hunting"), so a figure carries the check it illustrates. ``room``: widen the
    y range by this fraction on the table's side so that it does not cover the data."""
    if room > 0:
        lo, hi = ax.get_ylim()
        span = hi - lo
        ax.set_ylim((lo - room * span, hi) if loc.startswith("lower") else (lo, hi + room * span))
    cells = [(label, thesis if isinstance(thesis, str) else format(thesis, fmt),
              ours if isinstance(ours, str) else format(ours, fmt)) for label, thesis, ours, fmt in rows]
    w0 = max(len(c[0]) for c in cells)
    w1 = max(6, *(len(c[1]) for c in cells)) + 2
    w2 = max(7, *(len(c[2]) for c in cells)) + 2
    lines = [f"{'':<{w0}}{'thesis':>{w1}}{'hunting':>{w2}}"] + [f"{a:<{w0}}{b:>{w1}}{c:>{w2}}" for a, b, c in cells]
    text = (title + "\n" if title else "") + "\n".join(lines)
    pos = {"lower right": (0.98, 0.03, "right", "bottom"), "upper right": (0.98, 0.97, "right", "top"),
           "lower left": (0.02, 0.03, "left", "bottom"), "upper left": (0.02, 0.97, "left", "top"),
           "center right": (0.98, 0.5, "right", "center")}[loc]
    ax.text(pos[0], pos[1], text, transform=ax.transAxes, ha=pos[2], va=pos[3], family="monospace", fontsize=7,
            bbox=dict(boxstyle="round", fc="white", ec="0.6", alpha=0.9), zorder=10)


def plot_trajectory(traj, *, title: str = "", stick_modes=(), units: dict | None = None, path=None):
    """Time responses of every state and a phase portrait (x1, x2, x3 in 3-D).

    Stick phases (modes in ``stick_modes``) are shaded (with a legend entry); event states are
    marked with circles. Returns the figure; saves it when ``path`` is given."""
    plt = _plt()
    units = units or {}
    n = traj.x.shape[1]
    fig = plt.figure(figsize=(11, 2.2 * max(n, 3)))
    gs = fig.add_gridspec(n, 2, width_ratios=[1.4, 1])
    intervals = traj.stick_intervals(list(stick_modes)) if len(stick_modes) else np.empty((0, 2))
    for i in range(n):
        ax = fig.add_subplot(gs[i, 0])
        ax.plot(traj.t, traj.x[:, i], lw=1.0, color="C0")
        for j, (a, b) in enumerate(intervals):
            ax.axvspan(a, b, color="0.85", lw=0, label="stick phase" if j == 0 else None)
        if i == 0 and len(intervals):
            ax.legend(fontsize=8, loc="best")
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
        save(fig, path)
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
    _finish(fig, ax, True, title, path)
    return fig


def cobweb_path(xs) -> tuple[list, list]:
    """The cobweb of the iterates xs = (d_0, d_1, ...) of a map: from (d_0, 0) up to the map at
    (d_0, d_1), across to the diagonal at (d_1, d_1), up to (d_1, d_2), ... Returns (px, py)."""
    px, py = [xs[0]], [0.0]
    for a, b in zip(xs[:-1], xs[1:]):
        px += [a, b]
        py += [b, b]
    return px, py


def plot_event_map(em, *, cobweb_from=None, cobweb_steps: int = 6, fixed=(), title: str = "", ax=None,
                   path=None, unit: str = "m"):
    """P^k(d) against d with the diagonal; optional cobweb from ``cobweb_from`` (iterating the
    true map) and fixed points (stable filled, unstable open)."""
    fig, ax, own = _axes(ax, (5.6, 5.0))
    k = em.iterate
    lab = "P(d)" if k == 1 else f"P$^{k}$(d)"
    ax.plot(em.grid, em.image, ".", ms=2.0 if em.grid.size > 200 else 5.0, color="C0", label=lab)
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
        ax.plot(*cobweb_path(xs), "-", color="C3", lw=0.9, label="cobweb")
        ax.plot(xs[:-1], xs[1:], "o", color="C3", ms=4)
    labelled = set()
    for f in fixed:
        for d in ([f.d] if f.kind == "equilibrium" else [f.d, -f.d] if em.loop.odd and em.grid.min() < 0 else [f.d]):
            key = "stable" if f.stable else "unstable"
            ax.plot(d, d, "o", ms=7, mfc="k" if f.stable else "w", mec="k", zorder=5,
                    label=None if key in labelled else f"{key} fixed point")
            labelled.add(key)
    ax.set_xlabel(f"d$^n$ [{unit}]")
    ax.set_ylabel(f"d$^{{n+{k}}}$ [{unit}]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    _finish(fig, ax, own, title, path)
    return fig


def plot_map_diagram(diagram, *, title: str = "", ax=None, path=None, unit: str = "m"):
    """Bifurcation diagram from event maps: cycle stick errors against the parameter, stable
    solid and unstable dashed; the equilibrium set (d = 0) solid where stable, dashed where not;
    folds and stability changes marked."""
    fig, ax, own = _axes(ax, (6.0, 4.2))
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
    _finish(fig, ax, own, title, path)
    return fig


def plot_branch(branch, *, axes=None, title: str = "", path=None, unit: str | None = None, equilibrium_stable=None):
    """Bifurcation diagram of a branch of periodic orbits (amplitude max |x| of the first state
    against the parameter; stable solid, unstable dashed; folds, grazing points and multiplier
    crossings marked) above its Floquet multipliers (real parts; the trivial one dotted).

    ``unit``: the first state's unit (default: the branch's ``units``; none when unknown).
    ``equilibrium_stable``: optional (mu, stable) arrays to draw the equilibrium set x = 0."""
    plt = _plt()
    if axes is None:
        fig, axes = plt.subplots(2, 1, figsize=(7.0, 7.0), sharex=True, gridspec_kw=dict(height_ratios=[3, 2]))
    else:
        fig = axes[0].figure
    ax, axm = axes
    mu, amp, st = branch.mu, branch.amplitude, branch.stable
    x1 = branch.state_names[0] if branch.state_names else "x1"
    if unit is None:
        unit = (getattr(branch, "units", None) or {}).get(x1)
    start = 0
    for i in range(1, len(mu) + 1):
        if i == len(mu) or st[i] != st[start]:
            sl = slice(start, min(i + 1, len(mu)))
            ax.plot(mu[sl], amp[sl], "-" if st[start] else "--", color="k", lw=1.5 if st[start] else 1.1)
            start = i
    if equilibrium_stable is not None:
        emu, est = equilibrium_stable
        ax.plot(emu, np.zeros_like(emu), "-" if np.all(est) else "--", color="C0", lw=2.0,
                label=f"equilibrium set ({x1} = 0)")
    styles = {"fold": ("s", "C3", "cyclic fold"), "grazing": ("D", "C2", "grazing (event sequence changes)"),
              "period_doubling": ("v", "C4", "period doubling"), "torus": ("^", "C1", "torus"),
              "multiplier_+1": (None, None, None)}
    shown = set()
    for s_ in branch.special:
        marker, color, what = styles.get(s_.kind, ("o", "C5", s_.kind))
        if marker is None or not len(mu):
            continue
        i0 = min(max(s_.index, 0), len(mu) - 1)
        i1 = min(i0 + 1, len(mu) - 1)
        frac = (s_.param - mu[i0]) / (mu[i1] - mu[i0]) if mu[i1] != mu[i0] else 0.0
        a = float(amp[i0] + min(max(frac, 0.0), 1.0) * (amp[i1] - amp[i0]))
        label = (f"{what} {branch.param} = {s_.param:.4g}" if s_.kind == "fold"
                 else (what if s_.kind not in shown else None))
        ax.plot(s_.param, a, marker, color=color, ms=7, mfc="w" if s_.kind == "grazing" else color, mew=1.5,
                label=label, zorder=5)
        shown.add(s_.kind)
    ax.plot([], [], "-", color="k", label="stable cycles")
    ax.plot([], [], "--", color="k", label="unstable cycles")
    folds = [s_ for s_ in branch.special if s_.kind == "fold"]
    if folds:   # magnified view of the fold, where the unstable branch starts
        k0 = folds[0].param
        sel = np.abs(mu - k0) < 0.03 * abs(k0) + 1e-12
        if sel.sum() > 3:
            ins = ax.inset_axes([0.45, 0.22, 0.5, 0.4])
            start = 0
            idx = np.flatnonzero(sel)
            m2, a2, s2 = mu[idx], amp[idx], st[idx]
            for i in range(1, len(m2) + 1):
                if i == len(m2) or s2[i] != s2[start]:
                    sl = slice(start, min(i + 1, len(m2)))
                    ins.plot(m2[sl], a2[sl], "-" if s2[start] else "--", color="k", lw=1.2)
                    start = i
            ins.plot(k0, amp[min(folds[0].index + 1, len(mu) - 1)], "s", color="C3", ms=5)
            ins.tick_params(labelsize=7)
            ins.grid(alpha=0.3)
            ins.set_title("near the fold", fontsize=7)
    ax.set_ylabel(f"max |{x1}|" + (f" [{unit}]" if unit else ""))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    lam = branch.multipliers
    for j in range(lam.shape[1]):
        axm.plot(mu, lam[:, j].real, ":" if j == 0 else "-", lw=1.0, label=f"lambda{j + 1}")
    axm.axhline(1.0, color="0.5", lw=0.6)
    axm.set_ylim(-0.5, 3.0)
    pu = (getattr(branch, "units", None) or {}).get(branch.param)
    axm.set_xlabel(branch.param + (f" [{pu}]" if pu else ""))
    axm.set_ylabel("Floquet multipliers (real)")
    axm.grid(alpha=0.3)
    axm.legend(fontsize=8, ncol=4)
    _finish(fig, ax, True, title, path)
    return fig


def plot_cycles(system, orbits, labels, *, title: str = "", path=None, eq_bounds=None):
    """Periodic orbits in (x1, x2, x3), with the equilibrium set segment on the x3 axis."""
    from .integrate.simulate import simulate
    plt = _plt()
    fig = plt.figure(figsize=(6.5, 5.5))
    ax = fig.add_subplot(projection="3d")
    for po, lab, style in zip(orbits, labels, ("-", "--", ":")):
        tr = simulate(system.with_param_array(po.params), po.x0, (0.0, po.period),
                      t_eval=np.linspace(0.0, po.period, 3001), rtol=1e-10, atol=1e-13)
        ax.plot(tr.x[:, 0], tr.x[:, 1], tr.x[:, 2], style, color="k", lw=1.0, label=lab)
    if eq_bounds is not None:
        ax.plot([0, 0], [0, 0], list(eq_bounds), "-", color="C0", lw=3, label="equilibrium set")
    ax.set_xlabel("x1")
    ax.set_ylabel("x2")
    ax.set_zlabel("x3")
    ax.legend(fontsize=8)
    _finish(fig, ax, True, title, path)
    return fig


def plot_frf(curves, *, title: str = "", path=None, unit: str = ""):
    """Bode plot of FRFs: curves is a list of (f [Hz], H complex, label, style) tuples."""
    plt = _plt()
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(6.4, 5.6), sharex=True)
    for f, H, label, style in curves:
        a1.loglog(f, np.abs(H), style, lw=1.1, ms=2, label=label)
        ph = np.degrees(np.angle(H))
        a2.semilogx(f, np.where(ph > 1e-9, ph - 360.0, ph), style, lw=1.1, ms=2)   # in (-360, 0]
    a1.set_ylabel(f"|H| [{unit}]" if unit else "|H|")
    a2.set_ylabel("phase [deg]")
    a2.set_yticks([-360, -270, -180, -90, 0])
    a2.set_xlabel("f [Hz]")
    for a in (a1, a2):
        a.grid(alpha=0.3, which="both")
    a1.legend(fontsize=8)
    _finish(fig, a1, True, title, path)
    return fig


def plot_attractor_diagram(values, attractors_per_value, *, param: str = "K", title: str = "", ax=None,
                           path=None, unit: str = "m", scale: float = 1.0):
    """Stick errors of the attracting cycles against the parameter (one dot per stick phase of a
    period, as in thesis Fig. 10.12); squares at 0 where the equilibrium set attracts. Entries of
    ``attractors_per_value`` are lists of objects with ``kind`` ("cycle", "equilibrium",
    "irregular") and ``d`` (stick errors)."""
    fig, ax, own = _axes(ax, (6.4, 4.4))
    labelled = set()
    for v, atts in zip(values, attractors_per_value):
        for a in atts:
            if a.kind == "equilibrium":
                lab = "equilibrium set attracts" if "eq" not in labelled else None
                labelled.add("eq")
                ax.plot(v, 0.0, "s", mfc="w", mec="C0", ms=6, label=lab)
            else:
                irr = a.kind == "irregular"
                key = "irr" if irr else "cyc"
                lab = (("irregular (no period <= 64)" if irr else "stable cycle: stick errors")
                       if key not in labelled else None)
                labelled.add(key)
                d = np.asarray(a.d) * scale
                ax.plot(np.full(d.size, v), d, ".", color="0.6" if irr else "k", ms=2 if irr else 4, label=lab)
    ax.set_xlabel(param)
    ax.set_ylabel(f"stick error [{unit}]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    _finish(fig, ax, own, title, path)
    return fig


#: per contact: (shading of its stick phases, colour of its stick segments in the portrait)
_CONTACT_COLORS = (("0.82", "C3"), ("#f6c48f", "#d46a00"), ("#b5dcb0", "#2a8a2a"), ("#cdbde6", "#6a3fa0"))


def _label(name: str, units: dict) -> str:
    """``name [unit]`` when the unit is known, else the bare name (no unit beats a wrong one)."""
    u = units.get(name)
    return f"{name} [{u}]" if u else name


def cycle_panels(result, system, model=None, *, block_states: bool = False) -> list:
    """What :func:`plot_cycle` draws, in order: (name, kind, index) with kind "state" (index
    into the state vector) or "signal" (a model's signal name). For a compiled model: its
    mechanical states (the description's and the LuGre bristle states), then its block outputs
    and friction forces; the block realizations' internal states only with ``block_states``
    (they are an implementation of the blocks, often of size 1e-10). Otherwise every state."""
    names = list(result.state_names)
    if model is None or not hasattr(model, "signals"):
        return [(k, "state", i) for i, k in enumerate(names)]
    d = model.description
    own = list(d.get("states", {})) + [names[c.bristle_state] for c in model.contacts if c.bristle_state is not None]
    panels = [(k, "state", names.index(k)) for k in names if k in own]
    sig = set(getattr(model, "signal_names", ()))
    panels += [(b["output"], "signal", None) for b in d.get("blocks", []) if b["output"] in sig]
    panels += [(c.force, "signal", None) for c in model.contacts if c.force in sig]
    if block_states:
        panels += [(k, "state", i) for i, k in enumerate(names) if k not in own]
    return panels


def _portrait_pair(result, panels, model) -> tuple:
    """((name, index), (name, index)) of the phase portrait's axes."""
    names = list(result.state_names)
    shown = [(name, i) for name, kind, i in panels if kind == "state"] or [(k, i) for i, k in enumerate(names)]
    if model is not None and hasattr(model, "description"):
        eqs = model.description.get("equations", {})
        pairs = [(k, e) for k, e in eqs.items() if e in names and k in names and k != e]
        first = [c.surface_state for c in getattr(model, "contacts", ())][:1]
        pairs.sort(key=lambda kv: names.index(kv[1]) not in first)
        if pairs:
            a, b = pairs[0]
            return (a, names.index(a)), (b, names.index(b))
    if len(shown) < 2:
        return shown[0], shown[0]
    rng = np.array([result.maximum[k] - result.minimum[k] for k, _ in shown])
    size = np.maximum(np.array([max(abs(result.maximum[k]), abs(result.minimum[k])) for k, _ in shown]), 1e-300)
    rel = rng / size
    order = [k for k in range(len(shown)) if rel[k] >= 0.5 * rel.max()] + \
            [k for k in range(len(shown)) if rel[k] < 0.5 * rel.max()]
    return shown[order[0]], shown[order[1]]


def plot_cycle(result, system, *, periods: int = 2, units: dict | None = None, title: str = "", path=None,
               model=None, block_states: bool = False):
    """A periodic orbit (a :class:`hunting.continuation.CycleResult`): each state (and, for a
    compiled model, each block output and friction force) over ``periods`` periods from its
    x0 with the stick phases of every contact shaded (one band per contact when there are
    several), and a phase portrait of one period with each contact's stick segments drawn in
    its own colour.

    Parameters
    ----------
    result : CycleResult
    system : PiecewiseSystem the result belongs to (at the result's parameters)
    periods : int
    units : mapping name -> unit text, optional
        Added to the system's own (``system.units``, a model description's ``units``); names
        without a unit are labelled without one.
    model : compiled model, optional
        Gives the panels (:func:`cycle_panels`) and signal values.
    block_states : bool
        Also draw the block realizations' internal states.

    Returns the figure; saves it when ``path`` is given."""
    from .integrate.simulate import simulate
    plt = _plt()
    units = {**dict(getattr(system, "units", {}) or {}), **dict(units or {})}
    T = float(result.period)
    tr = simulate(system, result.x0_array, (0.0, periods * T), mode0=result.mode0,
                  t_eval=np.linspace(0.0, periods * T, 2000 * periods + 1), rtol=1e-10, atol=1e-13)
    panels = cycle_panels(result, system, model, block_states=block_states)
    values = {}
    if any(kind == "signal" for _, kind, _ in panels):
        sig = [model.signals(x, t, int(m)) for t, x, m in zip(tr.t, tr.x, tr.mode)]
        for name, kind, _ in panels:
            if kind == "signal":
                values[name] = np.array([s_[name] for s_ in sig])
    for name, kind, i in panels:
        if kind == "state":
            values[name] = tr.x[:, i]
    contacts = list(dict.fromkeys(p.contact for p in result.phases))
    nc = len(contacts)
    colors = {c: _CONTACT_COLORS[k % len(_CONTACT_COLORS)] for k, c in enumerate(contacts)}
    if model is None and "t" not in units and getattr(system, "units", None):
        units["t"] = "s"                              # the presets' time unit
    n = len(panels)
    fig = plt.figure(figsize=(11, 1.9 * max(n, 3) + 0.8))
    gs = fig.add_gridspec(n, 2, width_ratios=[1.5, 1])
    for r, (name, kind, _) in enumerate(panels):
        ax = fig.add_subplot(gs[r, 0])
        labelled = set()
        for p in result.phases:
            if p.kind != "stick":
                continue
            band = contacts.index(p.contact)
            lo_y, hi_y = (band / nc, (band + 1) / nc) if nc > 1 else (0.0, 1.0)
            for k in range(-1, periods):
                a = p.start + k * T                        # a phase may wrap the period
                lo, hi = max(a, 0.0), min(a + p.duration, periods * T)
                if hi > lo:
                    lab = None
                    if r == 0 and p.contact not in labelled:
                        where = ("lower band", "upper band")[band] if nc == 2 else f"band {band + 1} from below"
                        lab = "stick" if nc == 1 else f"{p.contact} sticks ({where})"
                        labelled.add(p.contact)
                    ax.axvspan(lo, hi, ymin=lo_y, ymax=hi_y, color=colors[p.contact][0], lw=0, label=lab)
        ax.plot(tr.t, values[name], lw=1.0, color="C0")
        for k in range(1, periods):
            ax.axvline(k * T, color="0.4", lw=0.6, ls="--", label="period" if (r == 0 and k == 1) else None)
        ax.set_ylabel(_label(name, units))
        ax.set_xlim(0.0, periods * T)
        ax.grid(alpha=0.3)
        if r == 0:
            ax.legend(loc="upper right", fontsize=8, framealpha=0.9)
        if r == n - 1:
            ax.set_xlabel(_label("t from x0", {"t from x0": units.get("t")}))
    # phase portrait: a position and its velocity (x' = v in the model's equations, the
    # velocity of the first contact preferred), else the two shown states that move most
    # relative to their size
    (ni, i), (nj, j) = _portrait_pair(result, panels, model)
    ax = fig.add_subplot(gs[:, 1])
    one = tr.t <= T
    ax.plot(tr.x[one, i], tr.x[one, j], lw=1.0, color="C0", label="slip" if nc == 1 else "orbit")
    # contacts whose surface state is on an axis are drawn last (on top) and thinnest
    surf = {c.name: c.surface_state for c in getattr(model, "contacts", ())}
    ranked = sorted(range(nc), key=lambda k: surf.get(contacts[k]) in (i, j))
    for rank, k in enumerate(ranked):
        c = contacts[k]
        st = np.zeros(tr.t.size, dtype=bool)
        for p in result.phases:
            if p.kind == "stick" and p.contact == c:
                st |= ((tr.t - p.start) % T) <= p.duration
        st &= one
        if np.any(st):
            lab = "stick" if nc == 1 else f"{c} sticks"
            xs, ys = np.where(st, tr.x[:, i], np.nan)[one], np.where(st, tr.x[:, j], np.nan)[one]
            ax.plot(xs, ys, lw=2.0 + 2.5 * (nc - 1 - rank), color=colors[c][1], solid_capstyle="butt", label=lab)
            # a stick phase that is a point in this plane (both states frozen) still shows
            edges = np.flatnonzero(np.diff(np.concatenate([[0], st.astype(int), [0]])))
            ax.plot(tr.x[edges[::2], i], tr.x[edges[::2], j], "o", color=colors[c][1], ms=6 + 2 * (nc - 1 - rank))
    ax.plot([result.x0[ni]], [result.x0[nj]], "o", color="k", ms=5, label="x0")
    ax.set_xlabel(_label(ni, units))
    ax.set_ylabel(_label(nj, units))
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    lam = list(result.multipliers)
    if lam:
        lam.pop(int(np.argmin(np.abs(np.array(lam) - 1.0))))        # the trivial multiplier
    tu = f" {units['t']}" if units.get("t") else ""
    fig.suptitle(title or f"{result.label}: {'stable' if result.stable else 'unstable'} cycle, period {T:.6g}{tu}"
                 + (f", largest |lambda| besides 1: {max(np.abs(lam)):.3g}" if lam else ""), fontsize=10)
    fig.tight_layout(rect=(0.0, 0.0, 1.0, 0.97))
    if path is not None:
        save(fig, path)
    return fig
