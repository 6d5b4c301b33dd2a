"""``hunting eventmap``: the stick-to-stick map P^k on a grid and its fixed points."""
from __future__ import annotations

from .boundary import Output, grid, positive_int
from .systems import add_system_arguments, resolve_system

NAME = "eventmap"
HELP = "stick-to-stick event map and its fixed points"


def add_arguments(p) -> None:
    add_system_arguments(p)
    p.add_argument("--grid", required=True, type=grid, metavar="START:STOP:N",
                   help="stick errors d: N points from START to STOP (e.g. 0:0.5:501)")
    p.add_argument("--iterate", type=positive_int, default=1, metavar="K",
                   help="stick phases per map application (P^K; default 1)")
    p.add_argument("--json", metavar="FILE", help="map, statuses and fixed points as JSON ('-': standard output)")
    p.add_argument("--plot", metavar="FILE", help="the map with its fixed points (png, pdf, svg, ...)")


def files(args):
    return [Output("--json", args.json, stdout=True), Output("--plot", args.plot, "figure")], []


def run(args, results) -> int:
    from ..errors import Status
    from ..eventmap import event_map, fixed_points
    from ..plotting import plot_event_map
    choice = resolve_system(args)
    loop = choice.loop
    loop.require_stick_map()
    em = event_map(loop, args.grid, args.iterate, derivative=False)
    fps = fixed_points(loop, args.grid, args.iterate, emap=em)
    for f in fps:
        print(f"{f.kind:<12} d = {f.d:+.10f}  stick phases {f.iterate}  slope {f.slope:+.6g}  "
              f"{'stable' if f.stable else 'unstable'}")
    if args.json:
        results.write_json(args.json, {
            "preset": args.preset, "set": choice.overrides, "iterate": args.iterate,
            "warnings": list(choice.warnings), "grid": em.grid.tolist(),
            "image": [None if not ok else float(v) for v, ok in zip(em.image, em.ok)],
            "status": [Status(int(s)).name for s in em.status],
            "fixed_points": [dict(d=f.d, iterate=f.iterate, slope=f.slope, stable=bool(f.stable), kind=f.kind,
                                  orbit=[float(o) for o in f.orbit]) for f in fps]}, indent=1)
    if args.plot:
        plot_event_map(em, fixed=fps, title=f"{choice.label}: P^{args.iterate}", path=args.plot)
    return 0
