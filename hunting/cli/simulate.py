"""``hunting simulate``: one trajectory of a preset, its status, JSON and figure."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .advice import tell
from .boundary import (UsageError, add_result_arguments, finite_float, nonnegative_int, positive_float, positive_int,
                       result_files, state_spec)
from .systems import add_system_arguments, resolve_system

NAME = "simulate"
HELP = "simulate a preset or a model"
MAX_SAMPLES = 20_000        # trajectory points written by default (a MAX_STEPS run has 1e6 steps)


def add_arguments(p) -> None:
    add_system_arguments(p)
    p.add_argument("--x0", type=state_spec, metavar="X1,X2,...",
                   help="initial state by position (0.1,0,0; missing entries are 0) or by name (x1=0.1,x3=0)")
    p.add_argument("--t", type=positive_float, default=30.0, help="end time [s] (default 30)")
    p.add_argument("--method", default="dop853", choices=("dop853", "dp5", "rk45", "radau"),
                   help="integration method (radau for stiff LuGre loops; rk45 is dp5)")
    p.add_argument("--rtol", type=positive_float, default=1e-10, help="relative tolerance (default 1e-10)")
    p.add_argument("--atol", type=positive_float, default=1e-12, help="absolute tolerance (default 1e-12)")
    p.add_argument("--max-steps", dest="max_steps", type=positive_int, default=1_000_000, metavar="N",
                   help="bound on integration steps (default 1e6)")
    p.add_argument("--max-events", dest="max_events", type=positive_int, default=100_000, metavar="N",
                   help="bound on mode switches (default 1e5)")
    p.add_argument("--growth", type=finite_float, default=1e6, metavar="FACTOR",
                   help="end with status DIVERGED when some |x_i| exceeds FACTOR * max(|x0|, 1) "
                        "(default 1e6; 0: no check)")
    p.add_argument("--max-samples", dest="max_samples", type=nonnegative_int, default=MAX_SAMPLES, metavar="N",
                   help=f"at most N trajectory points in --json and --plot, evenly chosen among the steps "
                        f"(first and last kept, at least 2; events are all kept; default {MAX_SAMPLES}; 0: every step)")
    add_result_arguments(p, "trajectory and events", "time responses and phase portrait")


files = result_files


def kernels(args) -> tuple[str, ...]:
    """The integration kernels this command runs (compiled ahead on a fresh install)."""
    return ("lean",) if args.method == "dop853" else ("full",)


def thinned(m: int, max_samples: int):
    """Indices of at most ``max_samples`` of ``m`` points, evenly spread, first and last kept;
    None when all are kept (``max_samples`` 0 or >= m)."""
    if max_samples == 0 or m <= max_samples:
        return None
    return np.unique(np.linspace(0, m - 1, max(max_samples, 2)).round().astype(int))


def run(args, results) -> int:
    from ..integrate import simulate
    from ..plotting import plot_trajectory
    if args.growth != 0 and args.growth <= 1:            # before a model file is compiled
        raise UsageError(f"--growth {args.growth:g} is not allowed: a factor > 1, or 0 for no check")
    choice = resolve_system(args)
    system = choice.system
    if args.x0:
        x0 = args.x0.vector(list(system.state_names))
    else:
        x0 = choice.model.state() if choice.model is not None else np.zeros(system.n_states)
    tr = simulate(system, x0, (0.0, args.t), method=args.method, rtol=args.rtol, atol=args.atol,
                  max_steps=args.max_steps, max_events=args.max_events, growth=args.growth or None)
    print(tell(args, tr.summary()))
    print(f"events: {len(tr.events)}; final state {np.array2string(tr.x_final, precision=6)}")
    n_points = len(tr.t)
    keep = thinned(n_points, args.max_samples)
    if keep is not None:
        print(f"note: --json/--plot hold {len(keep)} of the {len(tr.t)} points (--max-samples {args.max_samples}; "
              "0: every step)")
        tr = replace(tr, t=tr.t[keep], x=tr.x[keep], mode=tr.mode[keep])
    if args.json:
        results.write_json(args.json, {
            "preset": args.preset, "model": getattr(args, "model", None), "set": choice.overrides, "warnings": list(choice.warnings),
            "status": tr.status.name, "message": tr.message, "points_simulated": n_points,
            "t": tr.t.tolist(), "x": tr.x.tolist(), "mode": tr.mode.tolist(),
            "events": {"t": tr.events.t.tolist(), "x": tr.events.x_after.tolist(),
                       "mode_from": tr.events.mode_from.tolist(), "mode_to": tr.events.mode_to.tolist()}})
    if args.plot:
        stick = system.modes_of_kind("stick")
        plot_trajectory(tr, title=choice.label, stick_modes=stick, units=system.units, path=args.plot)
    return 0 if tr.success else 1
