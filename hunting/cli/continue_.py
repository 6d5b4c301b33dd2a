"""``hunting continue``: the hunting branch in one parameter (shooting + pseudo-arclength).

Exit code 0 when the branch reaches ``--to``, or turns at a fold and is followed back to
``--back-to`` (a branch that ends in a fold does not reach ``--to``: that is its answer);
1 when it stops anywhere else (point or step limit, a failed corrector, no cycle at
``--from``), with where it stopped and why.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import SystemDefinitionError
from .advice import tell
from .boundary import UsageError, add_result_arguments, finite_float, positive_float, positive_int, result_files, \
    state_spec
from .systems import add_system_arguments, names_lugre, resolve_system

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
                   help="after a fold, follow the branch back until the parameter reaches C (between A and B; "
                        "default A)")
    p.add_argument("--x0", type=state_spec, metavar="NAME=V,...",
                   help="where the cycle search at A starts, by name (q=0.2) or position; unnamed states start at 0 "
                        "(default: the event map where there is one, else the model's initial values)")
    p.add_argument("--period-guess", dest="period_guess", type=positive_float, metavar="T",
                   help="a period guess [s] at A: shoot from --x0 first (reaches unstable cycles)")
    p.add_argument("--max-points", dest="max_points", type=positive_int, default=400, metavar="N",
                   help="bound on the branch points (default 400)")
    p.add_argument("--ds-max", dest="ds_max", type=positive_float, default=0.3, metavar="S",
                   help="largest step along the branch, scaled arclength (default 0.3)")
    p.add_argument("--ds-min", dest="ds_min", type=positive_float, default=1e-6, metavar="S",
                   help="smallest step before the corrector gives up (default 1e-6)")
    add_result_arguments(p, "the branch", "bifurcation diagram and multipliers")


files = result_files


def kernels(args) -> tuple[str, ...]:
    """The kernels this command runs, compiled ahead on a fresh install while this process
    compiles the system: the flows' variational kernel (which also runs the start's simulation
    until the lean kernel, compiled last, is cached:
    :func:`hunting.integrate._kernel.plain_kind`), and the full one for a LuGre contact, whose
    branch's sensitivities run Radau."""
    return ("variational", "full", "lean") if names_lugre(args) else ("variational", "lean")


@dataclass(frozen=True)
class Outcome:
    """How a branch ended, for the user: exit code, one line, and whether it reached --to."""

    code: int
    line: str
    reached_end: bool


def outcome(br, param: str, start: float, end: float, back_to: float | None) -> Outcome:
    """Judge a Branch against what was asked (--from A --to B [--back-to C]) from its points,
    not only its status: SUCCESS with the last point short of B is not "reached"."""
    if len(br.mu) == 0:
        return Outcome(1, f"no branch: {br.message}", False)
    direction = 1.0 if end > start else -1.0
    mus = [float(m) for m in br.mu]
    last = mus[-1]
    folds = [s for s in br.special if s.kind == "fold"]
    reached = any((m - end) * direction >= 0 for m in mus)
    if reached:
        past = "" if abs(last - end) <= 1e-12 * max(1.0, abs(end)) else f" (last point {param} = {last:.6g})"
        return Outcome(0, f"reached --to {end:g}{past}", True)
    back = start if back_to is None else back_to
    at_folds = ", ".join(f"{s.param:.6g}" for s in folds)
    if br.status.ok and len(folds) % 2 == 1 and (last - back) * direction <= 0:
        return Outcome(0, f"the branch turns at the fold at {param} = {at_folds} and does not reach --to {end:g}; "
                          f"followed back to {param} = {last:.6g} (--back-to {back:g})", False)
    creep = _creep(mus, param, start, end) if not br.status.ok else None
    if creep:
        return Outcome(1, f"stopped at {param} = {last:.6g}, short of --to {end:g} ({br.status.name}): {creep}", False)
    why = br.message if not br.status.ok else (
        f"the continuation ended after {len(folds)} fold(s)" + (f" (at {param} = {at_folds})" if folds else "")
        + f", neither at --to {end:g} nor back at {back:g}: check the folds (a singular parameter value nearby?)")
    status = "" if br.status.ok else f" ({br.status.name})"
    return Outcome(1, f"stopped at {param} = {last:.6g}, short of --to {end:g}{status}: {why}", False)


def _creep(mus: list, param: str, start: float, end: float, min_points: int = 40) -> str | None:
    """Why a branch that ran into a point or step limit will not get further: over the second half
    of its points it moved always towards --to but covered less than 1 % of what the first half
    covered (the m -> 0 branch of a belt model: steps of 1e-7 after 400 points). The family
    approaches a limit it does not pass (a singular value such as a mass of 0); more points
    would only crawl on. None when the branch does not creep."""
    if len(mus) < min_points:
        return None
    sign = 1.0 if end > start else -1.0
    half = len(mus) // 2
    tail = mus[half - 1:]
    steps = [(b - a) * sign for a, b in zip(tail, tail[1:])]
    if min(steps) <= 0 or sum(steps) > 1e-2 * abs(mus[half - 1] - mus[0]):
        return None
    last = tail[-1]
    towards_zero = last * end <= 0 and abs(last) <= 1e-2 * abs(end - start)
    limit = (f"{param} = 0, where the model may be singular (a mass or a time constant of 0)" if towards_zero
             else "a limit it does not pass (a singular parameter value nearby?)")
    return (f"the branch creeps towards {limit}: its last {len(steps)} points moved {param} by {sum(steps):.2g} in "
            f"all (the last step {steps[-1]:.2g}), and more points will not pass it. Give --to a value on this side "
            f"(e.g. --to {last:.3g}){', and start on the other side with --from' if towards_zero else ''}")


def _check_range(args) -> None:
    if args.start == args.end:
        raise UsageError(f"--from {args.start:g} --to {args.end:g}: the range is empty "
                         "(allowed: two different finite values)")
    if args.back_to is not None and not min(args.start, args.end) <= args.back_to <= max(args.start, args.end):
        raise UsageError(f"--back-to {args.back_to:g} is outside --from {args.start:g} --to {args.end:g} "
                         "(allowed: a value between them; the branch is followed only inside the range)")
    if args.ds_min > args.ds_max:
        raise UsageError(f"--ds-min {args.ds_min:g} --ds-max {args.ds_max:g}: allowed: --ds-min <= --ds-max")
    if any(name == args.param for name, _ in args.set):
        raise UsageError(f"--param {args.param}: {args.param} is also given in --set (allowed: remove it there)")


def run(args, results) -> int:
    from ..continuation import ContinuationOptions, follow
    from ..plotting import plot_branch
    _check_range(args)
    try:                                # the parameter's name and both ends of the range
        choice = resolve_system(args, **{args.param: args.start})
        resolve_system(args, warn=False, **{args.param: args.end})
    except SystemDefinitionError as e:
        raise UsageError(f"--param {args.param} --from {args.start:g} --to {args.end:g}: {e}") from None
    if args.start * args.end < 0 or 0.0 in (args.start, args.end):
        print(tell(args, f"note: the range of {args.param} includes 0; a model may be singular there "
                         "(e.g. a mass or a time constant)"))
    ds = min(max(ContinuationOptions.ds, args.ds_min), args.ds_max)     # the default first step, within the bounds
    options = ContinuationOptions(ds=ds, ds_min=args.ds_min, ds_max=args.ds_max, max_points=args.max_points)
    x0 = args.x0.vector(list(choice.system.state_names)) if args.x0 else None
    br = follow(choice.source, args.param, args.start, args.end, params=choice.params, options=options, x0=x0,
                period_guess=args.period_guess, stop_at=args.back_to if args.back_to is not None else args.start)
    end = outcome(br, args.param, args.start, args.end, args.back_to)
    print(f"{len(br.mu)} points: {tell(args, end.line)}")
    def same_place(a, b) -> bool:       # two estimates of one point, each within its bracket
        return abs(a.param - b.param) <= 2 * (a.precision + b.precision) + 1e-6 * abs(a.param)

    folds = [s for s in br.special if s.kind == "fold"]
    crossings = [s for s in br.special if s.kind == "multiplier_+1"]
    for s in br.special:
        if s.kind == "multiplier_+1" and any(same_place(s, f) for f in folds):
            continue                     # the fold's own multiplier crossing: said on the fold's line
        crossing = s.kind == "fold" and any(same_place(s, c) for c in crossings)
        print(f"{s.kind:<16} {args.param} = {s.param:.8g}  (interval width {s.precision:.2g})"
              + ("  a multiplier passes +1 here" if crossing else ""))
    if args.json:
        out = br.as_dict()
        out.update(requested={"from": args.start, "to": args.end, "back_to": args.back_to},
                   reached_end=end.reached_end, outcome=end.line)
        results.write_json(args.json, out, indent=1)
    if args.plot and len(br.mu):
        plot_branch(br, title=f"{choice.preset or choice.model.name}: hunting branch in {args.param}", path=args.plot)
    elif args.plot:
        print(f"no figure: the branch has no points (--plot {args.plot} not written)")
    return end.code
