"""``hunting continue``: the hunting branch in one parameter (shooting + pseudo-arclength)."""
from __future__ import annotations

from ..errors import SystemDefinitionError
from .boundary import Output, UsageError, finite_float
from .systems import add_system_arguments, resolve_system

NAME = "continue"
HELP = "follow the hunting branch in one parameter (shooting + arclength)"


def add_arguments(p) -> None:
    add_system_arguments(p)
    p.add_argument("--param", required=True, help="the parameter to vary (a preset parameter, e.g. K or P)")
    p.add_argument("--from", dest="start", type=finite_float, required=True, metavar="A",
                   help="start value of the parameter")
    p.add_argument("--to", dest="end", type=finite_float, required=True, metavar="B",
                   help="end value of the parameter (different from A)")
    p.add_argument("--back-to", dest="back_to", type=finite_float, default=None, metavar="C",
                   help="after a fold, follow the branch back until the parameter reaches this value")
    p.add_argument("--json", metavar="FILE", help="the branch as JSON ('-': standard output)")
    p.add_argument("--plot", metavar="FILE", help="bifurcation diagram and multipliers (png, pdf, svg, ...)")


def files(args):
    return [Output("--json", args.json, stdout=True), Output("--plot", args.plot, "figure")], []


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
    br = follow(choice.preset, args.param, args.start, args.end, overrides=choice.overrides,
                stop_at=args.back_to if args.back_to is not None else args.start)
    print(f"{len(br.mu)} points, {br.message}")
    for s in br.special:
        print(f"{s.kind:<16} {args.param} = {s.param:.8g}  (interval width {s.precision:.2g})")
    if args.json:
        results.write_json(args.json, br.as_dict(), indent=1)
    if args.plot:
        plot_branch(br, title=f"{choice.preset}: hunting branch in {args.param}", path=args.plot)
    return 0
