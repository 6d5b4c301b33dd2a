"""The ``hunting`` command.

    hunting models                      presets and their parameters with units
    hunting simulate PRESET [--set NAME=VALUE ...] [--x0 X1,X2,X3] [--t T] [--json F] [--plot F]
    hunting eventmap PRESET [--set NAME=VALUE ...] --grid START:STOP:N [--iterate K]
                     [--json FILE] [--plot FILE]
    hunting continue PRESET [--set NAME=VALUE ...] --param NAME --from A --to B [--back-to C]
                     [--json FILE] [--plot FILE]
    hunting reproduce ch8|ch9|ch10 [--out DIR]   a thesis chapter: tables and figures, checked
    hunting demo [--out DIR]            short simulations of chapters 4, 8 and 9, checked
    hunting diagnose DATA --model MODEL.json [--validate DATA2] [--json FILE] [--report DIR]
                     [--names KEY=COLUMN,...] [--drop COLUMN]   measured data against the model
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from .errors import HuntingError


def _parse_sets(items) -> dict:
    out = {}
    for it in items or []:
        if "=" not in it:
            raise HuntingError(f"--set {it!r} is not NAME=VALUE")
        k, v = it.split("=", 1)
        out[k.strip()] = v.strip()
    return out


def _cmd_models(args) -> int:
    from .models.presets import describe_presets
    print(describe_presets())
    return 0


def _cmd_simulate(args) -> int:
    from . import simulate
    from .models import preset
    from .plotting import plot_trajectory
    loop = preset(args.preset, **_parse_sets(args.set))
    x0 = np.zeros(loop.n_states)
    if args.x0:
        vals = [float(v) for v in args.x0.split(",")]
        x0[: len(vals)] = vals
    tr = simulate(loop.system, x0, (0.0, args.t), method=args.method)
    print(tr.summary())
    stick = [loop.stick_mode] if loop.stick_mode is not None else []
    print(f"events: {len(tr.events)}; final state {np.array2string(tr.x_final, precision=6)}")
    if args.json:
        Path(args.json).write_text(json.dumps({
            "preset": args.preset, "status": tr.status.name, "message": tr.message,
            "t": tr.t.tolist(), "x": tr.x.tolist(), "mode": tr.mode.tolist(),
            "events": {"t": tr.events.t.tolist(), "x": tr.events.x_after.tolist(),
                       "mode_from": tr.events.mode_from.tolist(), "mode_to": tr.events.mode_to.tolist()}}))
    if args.plot:
        plot_trajectory(tr, title=loop.name, stick_modes=stick, units=loop.system.units, path=args.plot)
    return 0 if tr.success else 1


def _parse_grid(text: str) -> np.ndarray:
    try:
        a, b, n = text.split(":")
        a, b, n = float(a), float(b), int(n)
    except ValueError:
        raise HuntingError(f"--grid {text!r} is not START:STOP:N (e.g. 0:0.5:501)") from None
    if n < 2 or not (np.isfinite(a) and np.isfinite(b)) or b <= a:
        raise HuntingError(f"--grid {text!r} is not allowed: need START < STOP and N >= 2")
    return np.linspace(a, b, n)


def _cmd_eventmap(args) -> int:
    from .eventmap import event_map, fixed_points
    from .models import preset
    from .plotting import plot_event_map
    loop = preset(args.preset, **_parse_sets(args.set))
    grid = _parse_grid(args.grid)
    em = event_map(loop, grid, args.iterate, derivative=False)
    fps = fixed_points(loop, grid, args.iterate, emap=em)
    for f in fps:
        print(f"{f.kind:<12} d = {f.d:+.10f}  stick phases {f.iterate}  slope {f.slope:+.6g}  "
              f"{'stable' if f.stable else 'unstable'}")
    if args.json:
        from .errors import Status
        Path(args.json).write_text(json.dumps({
            "preset": args.preset, "set": _parse_sets(args.set), "iterate": args.iterate,
            "grid": em.grid.tolist(),
            "image": [None if not ok else float(v) for v, ok in zip(em.image, em.ok)],
            "status": [Status(int(s)).name for s in em.status],
            "fixed_points": [dict(d=f.d, iterate=f.iterate, slope=f.slope, stable=bool(f.stable), kind=f.kind,
                                  orbit=[float(o) for o in f.orbit]) for f in fps]}, indent=1))
    if args.plot:
        plot_event_map(em, fixed=fps, title=f"{loop.name}: P^{args.iterate}", path=args.plot)
    return 0


def _cmd_continue(args) -> int:
    from .continuation import follow
    from .plotting import plot_branch
    sets = _parse_sets(args.set)
    if args.param in sets:
        raise HuntingError(f"--param {args.param} is also given in --set: remove it there")
    br = follow(args.preset, args.param, args.start, args.end, params=sets,
                stop_at=args.back_to if args.back_to is not None else args.start)
    print(f"{len(br.mu)} points, {br.message}")
    for s in br.special:
        print(f"{s.kind:<16} {args.param} = {s.param:.8g}  (interval width {s.precision:.2g})")
    if args.json:
        Path(args.json).write_text(json.dumps(br.as_dict(), indent=1))
    if args.plot:
        plot_branch(br, title=f"{args.preset}: hunting branch in {args.param}", path=args.plot)
    return 0


def _cmd_reproduce(args) -> int:
    import importlib
    chapters = {"ch8": "hunting.reproduce.ch8", "ch9": "hunting.reproduce.ch9", "ch10": "hunting.reproduce.ch10"}
    if args.chapter not in chapters:
        raise HuntingError(f"chapter {args.chapter!r} is not available: choose from {sorted(chapters)}")
    mod = importlib.import_module(chapters[args.chapter])
    return mod.run(Path(args.out or f"out/{args.chapter}"))


def _parse_names(text, drop) -> dict | None:
    names = {}
    for item in (text.split(",") if text else []):
        if "=" not in item:
            raise HuntingError(f"--names {item!r} is not KEY=COLUMN")
        k, v = item.split("=", 1)
        names[k.strip()] = v.strip()
    for d in drop or []:
        names[d] = None
    return names or None


def _cmd_diagnose(args) -> int:
    from .diagnose import NominalModel, diagnose, load
    from .diagnose.report import write_json, write_report
    names = _parse_names(args.names, args.drop)
    fit = load(args.data, names)
    val = load(args.validate, names) if args.validate else None
    model = NominalModel.from_json(args.model)
    dg = diagnose(fit, model, val)
    for g in dg.gains():
        print(f"validation {g['metric']}: nominal {g['nominal']} -> extended {g['extended']}")
    for note in dg.notes:
        print(f"note: {note}")
    print(f"criterion: {dg.criterion}")
    if not dg.causes:
        print("no cause found: the nominal model explains the data within the criterion")
    for i, c in enumerate(dg.causes):
        pars = ", ".join(f"{k} = {v:.5g}" + ("" if c.sigma.get(k) is None else f" +- {c.sigma[k]:.2g}")
                         for k, v in c.parameters.items())
        print(f"  {i + 1}. {c.name:<10} score {c.score:.3g}  p {c.p_value:.2g}  {pars}")
    for a in dg.alternatives:
        print(f"     (also explains the data alone: {a['name']} {a['parameters']}; absorbed by {a['absorbed_by']})")
    if args.json:
        write_json(dg, args.json)
    if args.report:
        print(f"report: {write_report(dg, args.report)}")
    return 0


def _cmd_demo(args) -> int:
    from .demo import run_demo
    return run_demo(Path(args.out))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="hunting", description=__doc__.split("\n")[0] or "hunting")
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("models", help="list presets with parameters and units")
    sp = sub.add_parser("simulate", help="simulate a preset")
    sp.add_argument("preset")
    sp.add_argument("--set", action="append", metavar="NAME=VALUE")
    sp.add_argument("--x0", help="initial state, comma separated (missing entries are 0)")
    sp.add_argument("--t", type=float, default=30.0, help="end time [s]")
    sp.add_argument("--method", default="dop853")
    sp.add_argument("--json")
    sp.add_argument("--plot")
    ep = sub.add_parser("eventmap", help="stick-to-stick event map and its fixed points")
    ep.add_argument("preset")
    ep.add_argument("--set", action="append", metavar="NAME=VALUE")
    ep.add_argument("--grid", required=True, metavar="START:STOP:N")
    ep.add_argument("--iterate", type=int, default=1)
    ep.add_argument("--json")
    ep.add_argument("--plot")
    cp = sub.add_parser("continue", help="follow the hunting branch in one parameter (shooting + arclength)")
    cp.add_argument("preset")
    cp.add_argument("--set", action="append", metavar="NAME=VALUE")
    cp.add_argument("--param", required=True)
    cp.add_argument("--from", dest="start", type=float, required=True)
    cp.add_argument("--to", dest="end", type=float, required=True)
    cp.add_argument("--back-to", dest="back_to", type=float, default=None,
                    help="after a fold, follow the branch back until the parameter reaches this value")
    cp.add_argument("--json")
    cp.add_argument("--plot")
    rp = sub.add_parser("reproduce", help="reproduce a thesis chapter (tables, figures, checks)")
    rp.add_argument("chapter", help="ch8, ch9 or ch10")
    rp.add_argument("--out")
    dp = sub.add_parser("demo", help="hunting cycles of chapters 8 and 9, checked against the thesis")
    dp.add_argument("--out", default="out/demo")
    gp = sub.add_parser("diagnose", help="measured data against the model: causes, extension, gain")
    gp.add_argument("data", help="CSV (header t,q,u[,q_ref,f_ext]), .npz or .mat")
    gp.add_argument("--model", required=True, help="MODEL.json (see hunting.diagnose.model)")
    gp.add_argument("--validate", help="validation data (default: the last 40 %% of DATA)")
    gp.add_argument("--names", help="column names in the files, e.g. q=qm,u=vir")
    gp.add_argument("--drop", action="append", help="leave this column out (e.g. f_ext)")
    gp.add_argument("--json")
    gp.add_argument("--report", help="directory for index.html, residual.png, diagnosis.json")
    args = ap.parse_args(argv)
    try:
        return {"models": _cmd_models, "simulate": _cmd_simulate, "eventmap": _cmd_eventmap,
                "continue": _cmd_continue, "reproduce": _cmd_reproduce, "demo": _cmd_demo,
                "diagnose": _cmd_diagnose}[args.cmd](args)
    except HuntingError as e:
        print(f"hunting: error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
