"""``hunting continue``: the hunting branch in one parameter (shooting + pseudo-arclength)."""
from __future__ import annotations

from ..errors import SystemDefinitionError
from .boundary import UsageError, add_result_arguments, finite_float, positive_float, result_files, state_spec
from .systems import add_system_arguments, resolve_system

NAME = "continue"
HELP = "follow the hunting branch in one parameter (shooting + arclength)"


def add_arguments(p) -> None:
    add_system_arguments(p)
    p.add_argument("--param", required=True, help="the parameter to vary (a preset parameter, e.g. K or P, or a "
                   "model parameter)")
    p.add_argument("--from", dest="start", type=finite_float, required=True, metavar="A",
                   help="start value of the parameter")
    p.add_argument("--to", dest="end", type=finite_float, required=True, metavar="B",
                   help="end value of the parameter (different from A)")
    p.add_argument("--back-to", dest="back_to", type=finite_float, default=None, metavar="C",
                   help="after a fold, follow the branch back until the parameter reaches this value")
    p.add_argument("--x0", type=state_spec, metavar="NAME=V,...",
                   help="where the cycle search at A starts, by name (q=0.2) or position; unnamed states start at 0 "
                        "(default: the event map where there is one, else the model's initial values)")
    p.add_argument("--period-guess", dest="period_guess", type=positive_float, metavar="T",
                   help="a period guess [s] at A: shoot from --x0 first (reaches unstable cycles)")
    add_result_arguments(p, "the branch", "bifurcation diagram and multipliers")


files = result_files


def run(args, results) -> int:
    from ..continuation import follow
    from ..plotting import plot_branch
    if args.start == args.end:
        raise UsageError(f"--from {args.start:g} --to {args.end:g}: the range is empty "
                         "(allowed: two different finite values)")
    if any(name == args.param for name, _ in args.set):
        raise UsageError(f"--param {args.param}: {args.param} is also given in --set (allowed: remove it there)")
    try:                                # the parameter's name and both ends of the range
        choice = resolve_system(args, **{args.param: args.start})
        resolve_system(args, warn=False, **{args.param: args.end})
    except SystemDefinitionError as e:
        raise UsageError(f"--param {args.param} --from {args.start:g} --to {args.end:g}: {e}") from None
    x0 = args.x0.vector(list(choice.system.state_names)) if args.x0 else None
    br = follow(choice.source, args.param, args.start, args.end, params=choice.params, x0=x0,
                period_guess=args.period_guess, stop_at=args.back_to if args.back_to is not None else args.start)
    print(f"{len(br.mu)} points, {br.message}")
    for s in br.special:
        print(f"{s.kind:<16} {args.param} = {s.param:.8g}  (interval width {s.precision:.2g})")
    if args.json:
        results.write_json(args.json, br.as_dict(), indent=1)
    if args.plot:
        plot_branch(br, title=f"{choice.preset or choice.model.name}: hunting branch in {args.param}", path=args.plot)
    return 0 if br.status.ok or len(br.mu) else 1
