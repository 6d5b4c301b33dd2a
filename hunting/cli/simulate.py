"""``hunting simulate``: one trajectory of a preset, its status, JSON and figure."""
from __future__ import annotations

import numpy as np

from .boundary import Output, positive_float, state_spec
from .systems import add_system_arguments, resolve_system

NAME = "simulate"
HELP = "simulate a preset"


def add_arguments(p) -> None:
    add_system_arguments(p)
    p.add_argument("--x0", type=state_spec, metavar="X1,X2,...",
                   help="initial state by position (0.1,0,0; missing entries are 0) or by name (x1=0.1,x3=0)")
    p.add_argument("--t", type=positive_float, default=30.0, help="end time [s] (default 30)")
    p.add_argument("--method", default="dop853", choices=("dop853", "dp5", "radau"),
                   help="integration method (radau for stiff LuGre loops)")
    p.add_argument("--json", metavar="FILE", help="trajectory and events as JSON ('-': standard output)")
    p.add_argument("--plot", metavar="FILE", help="time responses and phase portrait (png, pdf, svg, ...)")


def files(args):
    return [Output("--json", args.json, stdout=True), Output("--plot", args.plot, "figure")], []


def run(args, results) -> int:
    from ..integrate import simulate
    from ..plotting import plot_trajectory
    choice = resolve_system(args)
    loop = choice.loop
    x0 = args.x0.vector(list(loop.system.state_names)) if args.x0 else np.zeros(loop.n_states)
    tr = simulate(loop.system, x0, (0.0, args.t), method=args.method)
    print(tr.summary())
    print(f"events: {len(tr.events)}; final state {np.array2string(tr.x_final, precision=6)}")
    if args.json:
        results.write_json(args.json, {
            "preset": args.preset, "set": choice.overrides, "warnings": list(choice.warnings),
            "status": tr.status.name, "message": tr.message,
            "t": tr.t.tolist(), "x": tr.x.tolist(), "mode": tr.mode.tolist(),
            "events": {"t": tr.events.t.tolist(), "x": tr.events.x_after.tolist(),
                       "mode_from": tr.events.mode_from.tolist(), "mode_to": tr.events.mode_to.tolist()}})
    if args.plot:
        stick = [loop.stick_mode] if loop.stick_mode is not None else []
        plot_trajectory(tr, title=choice.label, stick_modes=stick, units=loop.system.units, path=args.plot)
    return 0 if tr.success else 1
