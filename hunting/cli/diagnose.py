"""``hunting diagnose``: measured data against a nominal model (causes, extension, gain)."""
from __future__ import annotations

from ..errors import HuntingError
from .boundary import Input, Output

NAME = "diagnose"
HELP = "measured data against the model: causes, extension, gain"


def add_arguments(p) -> None:
    p.add_argument("data", help="CSV (header t,q,u[,q_ref,f_ext]), .npz or .mat")
    p.add_argument("--model", required=True, help="MODEL.json (see hunting.diagnose.model)")
    p.add_argument("--validate", help="validation data (default: the last 40 %% of DATA)")
    p.add_argument("--names", help="column names in the files, e.g. q=qm,u=vir")
    p.add_argument("--drop", action="append", help="leave this column out (e.g. f_ext)")
    p.add_argument("--json", metavar="FILE", help="the diagnosis as JSON ('-': standard output)")
    p.add_argument("--report", metavar="DIR", help="directory for index.html, residual.png, diagnosis.json")


def files(args):
    outputs = [Output("--json", args.json, stdout=True), Output("--report", args.report, "dir")]
    inputs = [Input("DATA", args.data), Input("--model", args.model), Input("--validate", args.validate)]
    return outputs, inputs


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


def run(args, results) -> int:
    from ..diagnose import NominalModel, diagnose, load
    from ..diagnose.report import write_report
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
        results.write_json(args.json, dg.as_dict(), indent=2, default=float)   # the format of report.write_json
    if args.report:
        print(f"report: {write_report(dg, args.report)}")
    return 0
