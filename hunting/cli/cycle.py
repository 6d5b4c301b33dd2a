"""``hunting cycle``: a periodic orbit (hunting limit cycle) by simulation and shooting.

Prints the period, the Floquet multipliers, each state's range over the orbit and the stick
and slip phases; ``--json`` writes period, x0 and min/max by state name, multipliers as
[re, im] (largest modulus first), phases [{kind, duration}] and stable. No cycle (the motion
comes to rest, escapes, or does not recur) is a numerical failure: exit 1 with the reason,
and the JSON (when asked) carries the status and the message.
"""
from __future__ import annotations

import sys

from .advice import tell
from .boundary import UsageError, add_result_arguments, positive_float, result_files, state_spec
from .systems import add_system_arguments, resolve_system

NAME = "cycle"
HELP = "find a periodic orbit (hunting cycle): period, multipliers, stick phases"


def add_arguments(p) -> None:
    add_system_arguments(p)
    p.add_argument("--x0", type=state_spec, metavar="NAME=V,...",
                   help="where to start, by name (x1=-1) or position (-1,0,0); unnamed states start at 0 "
                        "(default: a preset's event map, a model's initial values)")
    p.add_argument("--period-guess", dest="period_guess", type=positive_float, metavar="T",
                   help="a period guess [s]: shoot from --x0 first (reaches unstable cycles), "
                        "and scale the transient by it")
    p.add_argument("--which", choices=("stable", "unstable"), default="stable",
                   help="without --x0: the stable (default) or unstable cycle of the event map (presets, and "
                        "models with one Switch contact whose stick phases form a one-parameter family)")
    p.add_argument("--t-max", dest="t_max", type=positive_float, default=None, metavar="T",
                   help="bound on the simulated transient before shooting [s] (default 2000 period guesses, "
                        "else 1e4)")
    p.add_argument("--d-max", dest="d_max", type=positive_float, default=None, metavar="D",
                   help="for a preset or a model with an event map: the largest stick error its event map is "
                        "searched on (default: the whole range the map reaches)")
    add_result_arguments(p, "the orbit", "the orbit with its stick phases shaded")


files = result_files


def kernels(args) -> tuple[str, ...]:
    """The kernels this command runs, compiled ahead on a fresh install while this process
    compiles the system: the flows' variational kernel first, which also runs the transient
    simulation until the lean kernel, compiled next, is cached
    (:func:`hunting.integrate._kernel.plain_kind`)."""
    return ("variational", "lean")


def run(args, results) -> int:
    from ..continuation import StartOptions, find_cycle
    from ..plotting import cycle_panels, plot_cycle
    if args.which == "unstable" and args.x0 and args.period_guess is None:     # before compiling a model
        raise UsageError("--which unstable needs no --x0 (the event map of a preset or of a model with one "
                         "Switch contact), or --x0 with --period-guess (shooting from there): a simulation never "
                         "settles on an unstable cycle")
    choice = resolve_system(args)
    x0 = args.x0.vector(list(choice.system.state_names)) if args.x0 else None
    start = StartOptions(t_max=args.t_max) if args.t_max is not None else None
    res = find_cycle(choice.source, x0, args.period_guess, choice.params, which=args.which, d_max=args.d_max,
                     start=start)
    if res.success:
        states = [name for name, kind, _ in cycle_panels(res, choice.system, choice.model) if kind == "state"]
        print(tell(args, res.summary(states)))
    if args.json:
        out = res.as_dict()
        out.update(preset=choice.preset, model=getattr(args, "model", None), set=choice.overrides)
        results.write_json(args.json, out, indent=1)
    if not res.success:
        print(f"hunting: no cycle ({res.status.name}): {' '.join(tell(args, res.message).split())}", file=sys.stderr)
        return 1
    if args.plot:
        sys_ = choice.system if res.orbit is None or res.orbit.params is None else \
            choice.system.with_param_array(res.orbit.params)
        plot_cycle(res, sys_, model=choice.model, path=args.plot)
    return 0
