"""``hunting diagnose``: measured data against a nominal model (causes, extension, gain)."""
from __future__ import annotations

import argparse
import sys

from ..errors import HuntingError
from .boundary import Input, Output

NAME = "diagnose"
HELP = "measured data against the model: causes, extension, gain"
DATA_HELP = """\
DATA and --validate: CSV with a header row, .npz or .mat, one row per sample at a fixed interval:
  t [s], q [m or rad], u (controller output, what cm multiplies), optional q_ref (reference),
  f_ext [N] (known force on the load), u_inj (a known signal inside u, e.g. test pulses).
  Other names map with --names (e.g. q=qm,u=vir); the EMPS benchmark's are known (qm, vir, qg,
  pulses_N as u_inj). Without --validate the last 40 % of DATA is the validation data.

Example (the EMPS benchmark, its files from nonlinearbenchmark.org):
  hunting diagnose DATA_EMPS.mat --validate DATA_EMPS_PULSES.mat --model examples/emps/model.json
"""


def add_arguments(p) -> None:
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.epilog = DATA_HELP
    format_help = p.format_help

    def with_schema() -> str:
        # the schema text lives beside its parser in hunting.diagnose.model, whose import loads
        # the models' numba functions (3 s of compilation on a fresh install, 1 s from the
        # cache): read it only when this help is shown, not for every command's parser
        from ..diagnose.model import SCHEMA_HELP
        p.epilog = DATA_HELP + "\n" + SCHEMA_HELP
        return format_help()

    p.format_help = with_schema
    p.add_argument("data", help="measured data (CSV, .npz or .mat; columns below)")
    p.add_argument("--model", required=True, help="the nominal model: its JSON, or a model description (the "
                   "equations format of simulate --model, JSON or YAML); both below")
    p.add_argument("--validate", help="validation data (default: the last 40 %% of DATA)")
    p.add_argument("--names", help="column names in the files, e.g. q=qm,u=vir")
    p.add_argument("--drop", action="append", help="leave this optional column out (e.g. u_inj)")
    p.add_argument("--json", metavar="FILE", help="the diagnosis as JSON ('-': standard output)")
    p.add_argument("--report", metavar="DIR", help="directory for index.html, figures, diagnosis.json")


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
    from tqdm import tqdm

    from ..diagnose import NominalModel, diagnose, load
    from ..diagnose.report import format_terminal, write_report
    names = _parse_names(args.names, args.drop)
    model = NominalModel.from_json(args.model)
    fit = load(args.data, names)
    val = load(args.validate, names) if args.validate else None
    if val is not None:
        from ..diagnose.data import same_record
        from ..diagnose.guards import SAME_DATA_NOTE
        if same_record(fit, val):
            print(f"warning: {SAME_DATA_NOTE.format(args.validate)}", file=sys.stderr)
    bar = tqdm(total=1, desc="diagnose", file=sys.stderr, disable=not sys.stderr.isatty(), leave=False,
               bar_format="{desc}: {n}/{total} {bar} {elapsed}")

    def progress(stage, done, total):
        bar.total = total
        bar.n = done
        bar.set_description(f"diagnose: {stage}")
        bar.refresh()
    try:
        dg = diagnose(fit, model, val, progress=progress)
    finally:
        bar.close()
    print(format_terminal(dg))
    if args.json:
        results.write_json(args.json, dg.as_dict(), indent=2, default=float)   # the format of report.write_json
    if args.report:
        print(f"report: {write_report(dg, args.report)}")
    return 0
