"""The hunting command: every bad input is one line and an exit code, results are never lost.

Most cases call ``main(argv)`` in this process (fast); a few run the console entry point in a
subprocess (broken pipe, no traceback on a real stderr)."""
import json
import os
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import hunting
from hunting._atomic import atomic_path
from hunting.cli import main
from hunting.cli import boundary as B

ROOT = Path(__file__).resolve().parents[1]


def run_main(capsys, argv):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert lines[0].startswith("hunting: error: ") and "Traceback" not in err, err
    return lines[0]


@pytest.fixture
def files(tmp_path):
    """A data file, a model file and a plain file to misuse as a directory."""
    (tmp_path / "data.csv").write_text("t,q,u\n0,0,0\n0.001,0,0\n")
    (tmp_path / "model.json").write_text("{}")
    (tmp_path / "plain").write_text("x")
    return tmp_path


# (argv with {tmp} for the temporary directory, text the one-line message must contain)
BAD = [
    # simulate: initial state
    ("simulate table9.1 --x0 a,b,c", "--x0"),
    ("simulate table9.1 --x0 0.1,,0", "entry 2 is empty"),
    ("simulate table9.1 --x0 1,2,3,4,5", "has 5 entries"),
    ("simulate table9.1 --x0 x1=0.1,x9=2", "'x9' is not a state"),
    ("simulate table9.1 --x0 x1=0.1,0", "mixes positions and names"),
    ("simulate table9.1 --x0 nan,0,0", "not finite"),
    ("simulate table9.1 --x0 inf", "not finite"),
    ("simulate table9.1 --x0 x1=1,x1=2", "given twice"),
    # simulate: outputs
    ("simulate table9.1 --json /nonexistent/dir/out.json", "'/nonexistent/dir' does not exist"),
    ("simulate table9.1 --plot /nonexistent/x.png", "'/nonexistent' does not exist"),
    ("simulate table9.1 --json {tmp}/same.out --plot {tmp}/same.out", "not a figure format"),
    ("simulate table9.1 --json {tmp}/same.png --plot {tmp}/same.png", "same path as --json"),
    ("simulate table9.1 --plot {tmp}/fig.xyz", "'.xyz' is not a figure format"),
    ("simulate table9.1 --plot -", "standard output is not allowed"),
    ("simulate table9.1 --json {tmp}", "is a directory"),
    ("simulate table9.1 --json {tmp}/plain/out.json", "is not a directory"),
    # simulate: numbers and names
    ("simulate table9.1 --t -1", "argument --t"),
    ("simulate table9.1 --t 0", "argument --t"),
    ("simulate table9.1 --t nan", "argument --t"),
    ("simulate table9.1 --t abc", "argument --t"),
    ("simulate table9.1 --method euler", "invalid choice: 'euler'"),
    ("simulate table9.1 --set P", "'P' is not NAME=VALUE"),
    ("simulate table9.1 --set =3", "is not NAME=VALUE"),
    ("simulate table9.1 --set P=20,D=2", "one per option, e.g. --set P=20 --set D=2"),
    ("simulate table9.1 --set P=abc", "--set P=abc: P = 'abc' is not a number"),
    ("simulate table9.1 --set m=-1", "mass = -1.0 is not allowed"),
    ("simulate table9.1 --set Q=1", "'Q' is not a parameter"),
    ("simulate table9.1 --set P=1 --set P=2", "P is already set"),
    ("simulate table9.1 --set D=-1", "D = -1.0 is not allowed"),
    ("simulate table9.1 --set model=foo", "model = 'foo' is not allowed"),
    ("simulate nope", "PRESET 'nope' is not known"),
    ("simulate table9.1 --foo", "unrecognized arguments: --foo"),
    # eventmap
    ("eventmap table9.1 --grid 0:0.5", "--grid"),
    ("eventmap table9.1 --grid 0:1:1", "2 <= N"),
    ("eventmap table9.1 --grid 1:0:10", "START < STOP"),
    ("eventmap table9.1 --grid a:b:c", "is not START:STOP:N"),
    ("eventmap table9.1 --grid 0:nan:5", "--grid"),
    ("eventmap table9.1 --grid 0:1:2000000", "N <= 1000001"),
    ("eventmap table9.1 --grid 0:1:5 --iterate 0", "argument --iterate"),
    ("eventmap table9.1 --grid 0:1:5 --iterate 1.5", "argument --iterate"),
    ("eventmap table8.1-lugre --grid 0:1:3", "event maps need the exact Switch model"),
    ("eventmap table9.1", "--grid"),
    ("eventmap table9.1 --grid 0:1:5 --json /nonexistent/m.json", "does not exist"),
    # continue
    ("continue table9.1 --param P --from 0.6 --to 0.6", "the range is empty"),
    ("continue table9.1 --param P --from nan --to 1", "argument --from"),
    ("continue table9.1 --param P --from 1 --to inf", "argument --to"),
    ("continue table9.1 --param Q --from 1 --to 2", "--param Q"),
    ("continue table9.1 --param P --from 10 --to 12 --set P=3", "also given in --set"),
    ("continue table9.1 --param D --from -1 --to 1", "D = -1.0 is not allowed"),
    ("continue table9.1 --param P --from 10 --to 12 --plot /nonexistent/b.png", "does not exist"),
    ("continue table9.1 --param P --from 10 --to 12 --json /nonexistent/b.json", "does not exist"),
    # reproduce and demo
    ("reproduce ch7", "invalid choice: 'ch7'"),
    ("reproduce ch9 --out /proc/nope", "--out '/proc/nope'"),
    ("reproduce ch9 --out {tmp}/plain", "is not a directory"),
    ("demo --out /proc/nope", "--out '/proc/nope'"),
    # diagnose (the boundary only: paths before computing)
    ("diagnose {tmp}/nope.csv --model {tmp}/model.json", "DATA '{tmp}/nope.csv' does not exist"),
    ("diagnose {tmp}/data.csv --model {tmp}/nope.json", "--model '{tmp}/nope.json' does not exist"),
    ("diagnose {tmp}/data.csv --model {tmp}/model.json --json {tmp}/data.csv", "same path as DATA"),
    ("diagnose {tmp}/data.csv --model {tmp}/model.json --report /proc/nope", "--report '/proc/nope'"),
    ("diagnose {tmp}/data.csv --model {tmp}/model.json --validate {tmp}", "--validate"),
    ("diagnose {tmp}/data.csv --model {tmp}/model.json --json /nonexistent/d.json", "does not exist"),
    # the command itself
    ("", "required: COMMAND"),
    ("frobnicate", "invalid choice: 'frobnicate'"),
]


@pytest.mark.parametrize("argv, expected", BAD, ids=[a or "<none>" for a, _ in BAD])
def test_bad_input_is_one_line_and_exit_2(capsys, files, argv, expected):
    argv = argv.format(tmp=files).split()
    code, out, err = run_main(capsys, argv)
    line = one_line_error(err)
    assert code == 2, line
    assert expected.format(tmp=files) in line


def test_diagnose_failures_inside_the_command_are_one_line(capsys, files):
    """--drop u and a ragged CSV (the diagnosis' own messages may change; the boundary keeps
    them to one line without a traceback)."""
    (files / "model.json").write_text(json.dumps({"plant": {"mass": 95.0, "motor_constant": 35.15},
                                                  "friction": {"law": "coulomb-viscous", "Fc": 20.0, "b": 200.0}}))
    (files / "ragged.csv").write_text("t,q,u\n0,0,0\n0.001,0\n0.002,0,0,5\n")
    for argv in (f"diagnose {files}/data.csv --model {files}/model.json --drop u",
                 f"diagnose {files}/ragged.csv --model {files}/model.json"):
        code, _, err = run_main(capsys, argv.split())
        assert code in (1, 2) and one_line_error(err)


def test_diagnose_bad_inputs_name_what_is_wrong(capsys, files):
    """Exit 2 and the diagnosis' own words: a dropped required column, a ragged row, and model
    descriptions (the equations format of simulate --model) that have no nominal-model reading (a
    moving belt; a loop-shaped controller): the part that cannot be read is named (the YAML one
    once said "Expecting value: line 1 column 1"). tests/test_diagnose_description.py has more."""
    (files / "model.json").write_text(json.dumps({"plant": {"mass": 95.0, "motor_constant": 35.15},
                                                  "friction": {"law": "coulomb-viscous", "Fc": 20.0, "b": 200.0}}))
    (files / "ragged.csv").write_text("t,q,u\n0,0,0\n0.001,0\n0.002,0,0,5\n")
    cases = [(f"diagnose {files}/data.csv --model {files}/model.json --drop u", "column 'u' cannot be left out"),
             (f"diagnose {files}/ragged.csv --model {files}/model.json", "line 3 has 2 fields, the header has 3"),
             (f"diagnose {files}/data.csv --model {ROOT}/examples/belt.json", "'v - vb' is not a velocity state"),
             (f"diagnose {files}/data.csv --model {ROOT}/examples/loopshaped.yaml", "is not a PID"),
             (f"diagnose {files}/data.csv --model {files}/data.csv", "is not JSON")]
    for argv, expected in cases:
        code, _, err = run_main(capsys, argv.split())
        line = one_line_error(err)
        assert code == 2 and expected in line, (argv, code, line)
        if "examples/" in argv:
            assert "Expecting value" not in line and line.startswith("hunting: error: model description ")


def test_at_least_forty_bad_inputs_are_covered():
    assert len(BAD) >= 40


def test_outputs_are_checked_before_computing(monkeypatch, capsys, tmp_path):
    import hunting.integrate
    import hunting.reproduce.ch9

    def computed(*a, **k):
        raise AssertionError("computed before checking the outputs")
    monkeypatch.setattr(hunting.integrate, "simulate", computed)
    monkeypatch.setattr(hunting.reproduce.ch9, "run", computed)
    for argv in (["simulate", "table9.1", "--json", "/nonexistent/dir/out.json"],
                 ["simulate", "table9.1", "--plot", str(tmp_path / "p.png"), "--json", str(tmp_path / "p.png")],
                 ["reproduce", "ch9", "--out", "/proc/nope"]):
        code, _, err = run_main(capsys, argv)
        assert code == 2 and "AssertionError" not in err


def test_simulate_writes_json_and_plot(tmp_path):
    js, png = tmp_path / "t.json", tmp_path / "t.png"
    assert main(["simulate", "table9.1", "--x0", "0.1,0,0", "--t", "3", "--json", str(js), "--plot", str(png)]) == 0
    data = json.loads(js.read_text())
    assert data["status"] == "SUCCESS" and abs(data["events"]["x"][1][0] + 0.1222757) < 1e-6
    assert png.stat().st_size > 10000
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []      # no temporary files left
    assert stat.S_IMODE(js.stat().st_mode) == 0o666 & ~_umask()


def _umask():
    old = os.umask(0)
    os.umask(old)
    return old


def test_x0_by_name_equals_x0_by_position(capsys, tmp_path):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    assert main(["simulate", "table9.1", "--x0", "x1=0.1,x3=0", "--t", "1", "--json", str(a)]) == 0
    assert main(["simulate", "table9.1", "--x0", "0.1", "--t", "1", "--json", str(b)]) == 0
    assert json.loads(a.read_text())["x"] == json.loads(b.read_text())["x"]


def test_json_dash_is_stdout_and_the_summary_goes_to_stderr(capsys, tmp_path):
    code, out, err = run_main(capsys, ["simulate", "table9.1", "--x0", "0.1", "--t", "1", "--json", "-"])
    assert code == 0 and json.loads(out)["status"] == "SUCCESS"
    assert "SUCCESS" in err and not (tmp_path / "-").exists() and not Path("-").exists()


def test_atomic_write_keeps_the_old_file_when_writing_fails(tmp_path):
    target = tmp_path / "r.json"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("disk full")
    assert target.read_text() == "old" and sorted(p.name for p in tmp_path.iterdir()) == ["r.json"]


def test_numerical_failure_is_exit_1_and_one_line(monkeypatch, capsys):
    import hunting.cli.simulate as cmd

    def fails(args, results):
        raise hunting.ConvergenceError("table9.1: the step bound was reached: raise max_steps")
    monkeypatch.setattr(cmd, "run", fails)
    code, _, err = run_main(capsys, ["simulate", "table9.1"])
    assert code == 1 and "step bound" in one_line_error(err)


def test_unexpected_error_is_one_line_with_a_debug_hint_and_debug_shows_the_traceback(monkeypatch, capsys):
    import hunting.cli.simulate as cmd

    def bug(args, results):
        raise TypeError("unsupported operand")
    monkeypatch.setattr(cmd, "run", bug)
    code, _, err = run_main(capsys, ["simulate", "table9.1"])
    assert code == 1 and "--debug" in one_line_error(err) and "TypeError" in err
    for argv in (["--debug", "simulate", "table9.1"], ["simulate", "table9.1", "--debug"]):
        code, _, err = run_main(capsys, argv)
        assert code == 1 and "Traceback" in err and "unsupported operand" in err


def test_debug_shows_the_traceback_of_a_bad_value(capsys):
    code, _, err = run_main(capsys, ["simulate", "table9.1", "--set", "m=-1", "--debug"])
    assert code == 2 and "Traceback" in err and "mass = -1.0 is not allowed" in err


def _subprocess(args, **kw):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-m", "hunting.cli", *args], capture_output=True, text=True,
                          env=env, **kw)


def test_console_entry_point_runs_and_a_bad_value_has_no_traceback():
    r = _subprocess(["models"])
    assert r.returncode == 0 and "table9.1" in r.stdout
    r = _subprocess(["simulate", "table9.1", "--x0", "a,b,c"])
    assert r.returncode == 2 and one_line_error(r.stderr)


def test_broken_pipe_ends_quietly():
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    p = subprocess.Popen([sys.executable, "-m", "hunting.cli", "models"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, env=env)
    p.stdout.close()                     # like `hunting models | head -0`
    err = p.stderr.read().decode()
    assert p.wait() == 141 and err == ""


def test_models_lists_presets_with_units(capsys):
    assert main(["models"]) == 0
    out = capsys.readouterr().out
    for name in ("table9.1", "table8.1-switch", "table8.1-lugre", "limms-switch", "limms-lugre"):
        assert name in out
    assert "Fs" in out and "[N m]" in out and "[m/s]" in out


# ---------------------------------------------------------------- argument parsing, as properties
finite = st.floats(allow_nan=False, allow_infinity=False, width=64)


@given(st.lists(finite, min_size=1, max_size=6))
def test_state_spec_reads_back_what_repr_writes(values):
    spec = B.state_spec(",".join(repr(v) for v in values))
    assert spec.values == tuple(values) and spec.names == ()


@given(st.text(max_size=30))
@settings(max_examples=300)
def test_argument_types_accept_or_explain_any_text(text):
    for parse in (B.state_spec, B.grid, B.finite_float, B.positive_float, B.positive_int, B.name_value):
        try:
            parse(text)
        except B.argparse.ArgumentTypeError as e:
            assert repr(text) in str(e) or text in str(e)


@given(finite, st.floats(1e-6, 1e6), st.integers(2, 1000))
def test_grid_is_linspace(a, width, n):
    text = f"{a!r}:{a + width!r}:{n}"
    if not a + width > a:
        return
    assert np.array_equal(B.grid(text), np.linspace(a, a + width, n))


# ---------------------------------------------------------------- status, not success
def test_unstable_gains_end_with_diverged_not_success():
    lp = hunting.preset("table9.1", P=-5)
    tr = hunting.simulate(lp.system, [0.1, 0.0, 0.0], (0.0, 30.0))
    assert tr.status == hunting.Status.DIVERGED and not tr.success
    assert 1e6 < np.max(np.abs(tr.x_final)) < 1e7 and tr.t_final < 5      # ends at the first point beyond
    assert np.max(np.abs(tr.x[:-1])) <= 1e6 and "controller gains" in tr.message
    free = hunting.simulate(lp.system, [0.1, 0.0, 0.0], (0.0, 30.0), growth=None)
    assert free.status == hunting.Status.SUCCESS and np.max(np.abs(free.x_final)) > 1e70
    sparse = hunting.simulate(lp.system, [0.1, 0.0, 0.0], (0.0, 30.0), t_eval=np.linspace(0, 30, 7))
    assert sparse.status == hunting.Status.DIVERGED and sparse.t[-1] == 5.0
    with pytest.raises(hunting.ConvergenceError, match="DIVERGED|grew by orders of magnitude"):
        hunting.simulate(lp.system, [0.1, 0.0, 0.0], (0.0, 30.0), throw=True)


def test_bounds_end_the_run_at_the_first_point_beyond_them():
    lp = hunting.preset("table9.1")
    tr = hunting.simulate(lp.system, [0.1, 0.0, 0.0], (0.0, 30.0), bounds=[0.2, np.inf, np.inf])
    assert tr.status == hunting.Status.OUT_OF_BOUNDS and "x1" in tr.message
    assert abs(tr.x[-1, 0]) > 0.2 and np.all(np.abs(tr.x[:-1, 0]) <= 0.2)
    assert tr.events.t.size == 0 or tr.events.t[-1] <= tr.t_final
    full = hunting.simulate(lp.system, [0.1, 0.0, 0.0], (0.0, 30.0))
    assert full.success and np.allclose(full.x[: tr.x.shape[0] - 1], tr.x[:-1])


def test_simulate_names_a_bad_x0_and_bad_limits():
    sy = hunting.preset("table9.1").system
    for x0 in ("abc", [1, "a", 2], {"a": 1}):
        with pytest.raises(hunting.SystemDefinitionError, match=r"x0 = .* is not allowed: x0 must be 3 finite numbers"):
            hunting.simulate(sy, x0, (0, 1))
    for kw, text in ((dict(growth=0.5), "growth = 0.5"), (dict(bounds=-1), "bounds = -1"),
                     (dict(bounds=[1, 2]), "bounds = \\[1, 2\\]")):
        with pytest.raises(hunting.SystemDefinitionError, match=text):
            hunting.simulate(sy, [0.1, 0, 0], (0, 1), **kw)


def test_cli_warns_up_front_and_exits_1_on_divergence(capsys):
    code, out, err = run_main(capsys, ["simulate", "table9.1", "--set", "P=-5", "--x0", "0.1,0,0"])
    assert code == 1 and out.startswith("DIVERGED") and "SUCCESS" not in out
    assert "warning: the linear loop without friction is unstable" in err
    code, out, err = run_main(capsys, ["simulate", "table9.1", "--x0", "0.1,0,0", "--t", "2"])
    assert code == 0 and "warning" not in err


# ---------------------------------------------------------------- values that start with a minus sign
@pytest.mark.parametrize("argv, dest, expected", [
    ("simulate table9.1 --x0 -0.1,0,0", "x0", (-0.1, 0.0, 0.0)),
    ("simulate table9.1 --x0 -1e-1", "x0", (-0.1,)),
    ("simulate table9.1 --x0 -.1,-2E-3", "x0", (-0.1, -2e-3)),
    ("simulate table9.1 --x0 x1=-0.1,x3=-1", "x0", (-0.1, -1.0)),
    ("cycle table9.1 --x0 -0.1,0,0", "x0", (-0.1, 0.0, 0.0)),
    ("eventmap table9.1 --grid -0.5:0.5:11", "grid", -0.5),
    ("continue table9.1 --param P --from -1e-3 --to -2.5E2 --back-to -7", "start", -1e-3),
    ("continue table9.1 --param P --from 1 --to -2.5E2", "end", -250.0),
    ("continue table9.1 --param P --from 1 --to 2 --back-to -.5", "back_to", -0.5),
    ("simulate table9.1 --growth -1", "growth", -1.0),
    ("simulate table9.1 --set P=-5", "set", [("P", "-5")]),
])
def test_values_may_start_with_a_minus_sign(argv, dest, expected):
    args = hunting.cli.build_parser().parse_args(argv.split())
    got = getattr(args, dest)
    if dest == "x0":
        got = got.values
    elif dest == "grid":
        got = got[0]
    assert got == expected


@pytest.mark.parametrize("argv, expected", [
    ("cycle table9.1 --period-guess -1", "argument --period-guess: '-1' is not allowed: a finite number > 0"),
    ("simulate table9.1 --t -1e3", "argument --t: '-1e3' is not allowed"),
    ("simulate table9.1 --t -inf", "argument --t: '-inf' is not allowed"),
    ("simulate table9.1 --json -o.json", "--json: expected one argument (to give a value that starts with '-', "
                                         "write --json=-...)"),
])
def test_a_negative_value_where_none_is_allowed_names_the_option(capsys, argv, expected):
    code, _, err = run_main(capsys, argv.split())
    assert code == 2 and expected in one_line_error(err)


def test_simulate_from_a_negative_start(capsys):
    code, out, _ = run_main(capsys, ["simulate", "table9.1", "--x0", "-0.1,0,0", "--t", "3"])
    assert code == 0 and out.startswith("SUCCESS")


def test_pgf_without_tex_is_refused_before_computing(monkeypatch, capsys, tmp_path):
    """`--plot f.pgf` needs the TeX program of matplotlib's pgf backend (was: a RuntimeError after
    the computation, the figure lost)."""
    import shutil

    import hunting.integrate

    def computed(*a, **k):
        raise AssertionError("computed before checking the outputs")
    monkeypatch.setattr(hunting.integrate, "simulate", computed)
    monkeypatch.setattr(shutil, "which", lambda name: None)
    code, _, err = run_main(capsys, ["simulate", "table9.1", "--plot", str(tmp_path / "f.pgf")])
    line = one_line_error(err)
    assert code == 2 and "writing .pgf needs the TeX program 'xelatex'" in line and ".png" in line


def test_diagnose_help_says_everything_the_controller_is_used_for(capsys):
    """Review (newcomer): the help said the controller was needed only for the behaviour view
    and the saturation/quantization/presliding causes; the noise-fed causes are also checked
    along the nominal loop's noise-free re-simulation, which runs the controller."""
    from hunting.diagnose.causes import CAUSES
    assert main(["diagnose", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "Needed for the behaviour view and for the saturation" not in text
    assert "noise-free re-simulation" in text and "gives the measured u" in text
    fed = [n for n, mod in CAUSES.items() if getattr(mod, "NOISE_FED", False)]
    at = text.index("noise-fed causes")
    assert fed and all(n in text[at:at + 200] for n in fed), fed


def test_eventmap_says_the_slope_is_unbounded_where_the_map_jumps(capsys):
    """beta = inf (the discontinuous curve): P jumps at d = 0, so the equilibrium has no finite
    slope; the probe ratio P(delta)/delta (1.93e6 at the smallest probe) was printed as one."""
    code, out, _ = run_main(capsys, ["eventmap", "table9.1", "--set", "beta=inf", "--grid", "0:0.5:11"])
    line = next(ln for ln in out.splitlines() if ln.startswith("equilibrium"))
    assert code == 0 and "slope unbounded (the map jumps at d = 0)" in line and "unstable" in line
    code, out, _ = run_main(capsys, ["eventmap", "table9.1", "--grid", "0:0.5:11"])
    line = next(ln for ln in out.splitlines() if ln.startswith("equilibrium"))
    assert "slope -0.925624" in line and "stable" in line
