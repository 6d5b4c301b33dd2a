"""``hunting eventmap``: the stick-to-stick map P^k on a grid and its fixed points."""
from __future__ import annotations

import sys
from collections import Counter

import numpy as np

from .advice import tell
from .boundary import add_result_arguments, grid, positive_int, result_files
from .systems import add_system_arguments, resolve_system

NAME = "eventmap"
HELP = "stick-to-stick event map and its fixed points"


def add_arguments(p) -> None:
    add_system_arguments(p)
    p.add_argument("--grid", required=True, type=grid, metavar="START:STOP:N",
                   help="stick errors d: N points from START to STOP (e.g. 0:0.5:501)")
    p.add_argument("--iterate", type=positive_int, default=1, metavar="K",
                   help="stick phases per map application (P^K; default 1)")
    add_result_arguments(p, "map, statuses and fixed points", "the map with its fixed points")


files = result_files


def kernels(args) -> tuple[str, ...]:
    """The integration kernels this command runs (compiled ahead on a fresh install)."""
    return ("lean",)


def run(args, results) -> int:
    from ..errors import Status
    from ..eventmap import check_resolution, event_map, stick_family
    from ..plotting import plot_event_map
    choice = resolve_system(args)
    if choice.model is not None:
        loop = stick_family(choice.model)   # one Switch contact whose stick states form a 1-parameter family
    else:
        loop = choice.loop
        loop.require_stick_map()
    em = event_map(loop, args.grid, args.iterate, derivative=False)
    res = check_resolution(em)          # its fixed points with the slope at d = 0 computed once; logs its warnings
    for f in res.fixed:
        note = "  (not bracketed by the grid: found by refining)" if f in res.unbracketed else ""
        print(f"{f.kind:<12} d = {f.d:+.10f}  stick phases {f.iterate}  slope {_slope_words(f)}  "
              f"{'stable' if f.stable else 'unstable'}{note}")
    if args.json:
        results.write_json(args.json, {
            "preset": args.preset, "model": getattr(args, "model", None), "set": choice.overrides,
            "iterate": args.iterate, "warnings": list(choice.warnings) + list(res.warnings),
            "suggested_grid": res.suggestion_text() or None, "grid": em.grid.tolist(),
            "image": [None if not ok else float(v) for v, ok in zip(em.image, em.ok)],
            "status": [Status(int(s)).name for s in em.status],
            "fixed_points": [f.as_dict() | {"bracketed_by_grid": f not in res.unbracketed} for f in res.fixed],
            "jumps": res.jumps}, indent=1, default=float)
    defined = int(np.count_nonzero(em.ok))
    if defined < 2:                     # one point (d = 0, say) is not a map: nothing was learnt
        failed = Counter(Status(int(s)).name for s, ok in zip(em.status, em.ok) if not ok)
        why = ", ".join(f"{name} at {k}" for name, k in failed.most_common())
        print(tell(args, f"hunting: no map: P^{args.iterate} is defined at {defined} of {len(em.grid)} grid points "
                         f"({why}): lower --iterate, or choose a grid where the motion reaches a stick phase "
                         f"{args.iterate} times"), file=sys.stderr)
        return 1
    if args.plot:
        plot_event_map(em, fixed=res.fixed, title=f"{choice.label}: P^{args.iterate}", path=args.plot)
    return 0


def _slope_words(f) -> str:
    """The fixed point's slope as printed: a number, or what the map does at the origin when it
    has no finite slope there (a probe ratio P(delta)/delta is not a slope)."""
    behaviour = f.origin.behaviour if f.origin is not None else "linear"
    if behaviour == "discontinuous":
        return "unbounded (the map jumps at d = 0)"
    if behaviour == "steep" and not np.isfinite(f.slope):
        return "unbounded (slip grows away from d = 0)"
    if behaviour == "steep":
        return f"unbounded (P(d)/d still growing, {f.slope:+.3g} at the smallest probe)"
    if behaviour == "undefined":
        return "undefined (a probe near d = 0 failed)"
    return f"{f.slope:+.6g}"
