"""``hunting simulate``: one trajectory of a preset, its status, JSON and figure."""
from __future__ import annotations

import numpy as np

from .boundary import UsageError, add_result_arguments, finite_float, positive_float, result_files, state_spec
from .systems import add_system_arguments, resolve_system

NAME = "simulate"
HELP = "simulate a preset or a model"


def add_arguments(p) -> None:
    add_system_arguments(p)
    p.add_argument("--x0", type=state_spec, metavar="X1,X2,...",
                   help="initial state by position (0.1,0,0; missing entries are 0) or by name (x1=0.1,x3=0)")
    p.add_argument("--t", type=positive_float, default=30.0, help="end time [s] (default 30)")
    p.add_argument("--method", default="dop853", choices=("dop853", "dp5", "radau"),
                   help="integration method (radau for stiff LuGre loops)")
    p.add_argument("--growth", type=finite_float, default=1e6, metavar="FACTOR",
                   help="end with status DIVERGED when some |x_i| exceeds FACTOR * max(|x0|, 1) "
                        "(default 1e6; 0: no check)")
    add_result_arguments(p, "trajectory and events", "time responses and phase portrait")


files = result_files


def run(args, results) -> int:
    from ..integrate import simulate
    from ..plotting import plot_trajectory
    choice = resolve_system(args)
    system = choice.system
    if args.x0:
        x0 = args.x0.vector(list(system.state_names))
    else:
        x0 = choice.model.state() if choice.model is not None else np.zeros(system.n_states)
    if args.growth != 0 and args.growth <= 1:
        raise UsageError(f"--growth {args.growth:g} is not allowed: a factor > 1, or 0 for no check")
    tr = simulate(system, x0, (0.0, args.t), method=args.method, growth=args.growth or None)
    print(tr.summary())
    print(f"events: {len(tr.events)}; final state {np.array2string(tr.x_final, precision=6)}")
    if args.json:
        results.write_json(args.json, {
            "preset": args.preset, "model": getattr(args, "model", None), "set": choice.overrides, "warnings": list(choice.warnings),
            "status": tr.status.name, "message": tr.message,
            "t": tr.t.tolist(), "x": tr.x.tolist(), "mode": tr.mode.tolist(),
            "events": {"t": tr.events.t.tolist(), "x": tr.events.x_after.tolist(),
                       "mode_from": tr.events.mode_from.tolist(), "mode_to": tr.events.mode_to.tolist()}})
    if args.plot:
        stick = system.modes_of_kind("stick")
        plot_trajectory(tr, title=choice.label, stick_modes=stick, units=system.units, path=args.plot)
    return 0 if tr.success else 1
