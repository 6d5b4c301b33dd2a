"""What the command line tells a user to do names options that command has.

Every advice text of the library (integrator statuses, orbit statuses) is rewritten for every
command, and checked: no Python argument names left, and every option it names exists in that
command's parser. Then the messages of real runs, and the exit code of `continue` when the
branch stops short of --to."""
import json
import re

import numpy as np
import pytest

import hunting
from hunting.cli import build_parser, main
from hunting.cli.advice import Command, for_cli, library_advice
from hunting.cli.continue_ import outcome
from hunting.continuation.status import OrbitStatus
from hunting.errors import status_message
from hunting.results import SpecialPoint

PARSER = build_parser()
COMMANDS = sorted(PARSER.commands)
API_WORDS = re.compile(r"period_guess|t_max|d_max|max_steps|max_events|max_points|ds_min|ds_max|t_span|"
                       r"method='radau'|simulate's growth|transition function|find_cycle|\(x0\)|\(x0,|\btol\b")
FLAG = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")
LIBRARY_ADVICE = sorted(set(library_advice()))


def _command(name, model_file=False):
    flags = frozenset(s for a in PARSER.commands[name]._actions for s in a.option_strings)
    return Command(name, flags, model_file)


@pytest.mark.parametrize("name", COMMANDS)
def test_every_library_advice_names_only_options_the_command_has(name):
    for model_file in (False, True):
        cmd = _command(name, model_file)
        for text in LIBRARY_ADVICE:
            said = for_cli(text, cmd)
            assert not API_WORDS.search(said), (name, said)
            elsewhere = re.sub(r"'hunting [^']*'", "", said)       # another command, quoted whole
            for flag in FLAG.findall(elsewhere):
                assert cmd.has(flag), (name, flag, said)


def test_the_reviewers_messages_in_cli_words():
    cycle, cont, sim = _command("cycle"), _command("continue"), _command("simulate", model_file=True)
    no_rec = ("returns did not repeat within t = 10000. The motion did not return periodically within the "
              "transient bound: start closer to the cycle (x0), give period_guess, or raise t_max")
    assert for_cli(no_rec, cycle).endswith("start closer to the cycle (--x0), give --period-guess or raise --t-max")
    assert "--max-points 400 reached" in for_cli(
        "max_points = 400 reached at vb = 8.49385: raise max_points or ds_max", cont)
    assert "raise --max-points or --ds-max" in for_cli("raise max_points or ds_max", cont)
    assert for_cli(status_message(hunting.Status.STEP_TOO_SMALL), sim).count("--method radau") == 1
    zeno = for_cli(status_message(hunting.Status.ZENO), sim)
    assert "model file's friction entries" in zeno and "transition function" not in zeno
    assert "'hunting cycle' instead" in for_cli("not a one-parameter family. Use find_cycle instead", cycle)


def test_an_advice_sentence_is_said_once():
    advice = OrbitStatus.SINGULAR_JACOBIAN.advice
    text = (f"returns to q2 = 0.0342 did not repeat; shooting from the returns gave SINGULAR_JACOBIAN: singular "
            f"shooting Jacobian at iteration 1: {advice}. {advice[0].upper()}{advice[1:]}")
    said = for_cli(text, _command("cycle"))
    assert said.lower().count("the shooting jacobian is singular: the orbit is not isolated") == 1
    assert said.startswith("returns to q2 = 0.0342 did not repeat") and "(--x0 with --period-guess)" in said


# ---------------------------------------------------------------- real runs
def test_cycle_failure_names_cli_options(capsys):
    code = main(["cycle", "table9.1", "--x0", "x3=0.01"])          # a start inside the stick set: rest
    err = capsys.readouterr().err
    assert code == 1 and "EQUILIBRIUM" in err and "(--x0)" in err and "(x0)" not in err


def test_simulate_step_bound_names_its_options(capsys, tmp_path):
    js = tmp_path / "s.json"
    code = main(["simulate", "table9.1", "--x0", "0.1", "--t", "30", "--max-steps", "100", "--max-samples", "20",
                 "--json", str(js)])
    out = capsys.readouterr().out
    assert code == 1 and out.startswith("MAX_STEPS") and "raise --max-steps or loosen --rtol/--atol" in out
    data = json.loads(js.read_text())
    assert len(data["t"]) == 20 and data["points_simulated"] > 50 and data["status"] == "MAX_STEPS"
    assert "hold 20 of the" in out


def test_rk45_is_offered(capsys):
    assert main(["simulate", "table9.1", "--x0", "0.1", "--t", "1", "--method", "rk45"]) == 0


TWODOF = {"name": "two-dof", "parameters": {"m1": 1.0, "m2": 0.5, "k12": 5.0, "k2": 1.0, "c12": 0.05, "vd": 0.1,
                                            "Fc": 1.0, "Fs": 1.5, "vs": 0.05},
          "states": ["q1", "v1", "q2", "v2"],
          "signals": {"f12": "k12*(q2 - q1) + c12*(v2 - v1)", "fd": "-k2*q2"},
          "equations": {"q1": "v1", "v1": "(f12 - F)/m1", "q2": "v2", "v2": "(fd - f12)/m2"},
          "friction": {"force": "F", "velocity": "v1 - vd", "model": "switch",
                       "slip": "sign(w)*(Fc + (Fs - Fc)*exp(-abs(w)/vs))", "stick": "Fs"}}


def test_eventmap_of_a_two_dof_model_gives_the_right_reason(capsys, tmp_path):
    """Mass 1 sticks to a moving drive, mass 2 keeps moving: three states evolve in stick, none
    stays frozen (was: "every stick phase ends at the same state")."""
    f = tmp_path / "twodof.json"
    f.write_text(json.dumps(TWODOF))
    code = main(["eventmap", "--model", str(f), "--grid", "0:1:11"])
    err = capsys.readouterr().err
    assert code == 2 and "3 state(s) evolve (q1, q2, v2) and 0 stay frozen" in err
    assert "ends at the same state" not in err and "'hunting cycle' instead" in err


# ---------------------------------------------------------------- continue: did the branch get there?
def _branch(mus, status=OrbitStatus.SUCCESS, message="reached the end of the parameter range", folds=()):
    m = len(mus)
    special = [SpecialPoint("fold", 0, f, (f, f), 0.0) for f in folds]
    return hunting.continuation.Branch("p", np.array(mus, float), np.ones(m), np.ones(m), np.ones((m, 2), complex),
                                       np.ones(m, bool), np.zeros((m, 2)), [], special, status, message)


@pytest.mark.parametrize("mus, status, folds, end, back_to, code, words", [
    ([0.1, 0.15, 0.2], OrbitStatus.SUCCESS, (), 0.2, None, 0, "reached --to 0.2"),
    ([0.1, 0.15, 0.2208], OrbitStatus.SUCCESS, (), 0.2, None, 0, "reached --to 0.2 (last point p = 0.2208)"),
    ([0.1, 0.05, -0.2], OrbitStatus.SUCCESS, (), -0.1, None, 0, "reached --to -0.1"),
    ([0.1, 0.102], OrbitStatus.STEP_LIMIT, (), 0.2, None, 1, "stopped at p = 0.102, short of --to 0.2 (STEP_LIMIT)"),
    ([0.1, 0.15], OrbitStatus.POINT_LIMIT, (), 0.2, None, 1, "short of --to 0.2 (POINT_LIMIT)"),
    ([0.1, 0.15, 0.18, 0.12, 0.1], OrbitStatus.SUCCESS, (0.181,), 0.2, None, 0, "turns at the fold at p = 0.181"),
    ([0.1, 0.15, 0.18, 0.12], OrbitStatus.SUCCESS, (0.181,), 0.2, 0.13, 0,
     "followed back to p = 0.12 (--back-to 0.13)"),
    ([0.1, 0.15, 0.18, 0.16], OrbitStatus.SUCCESS, (0.181,), 0.2, 0.13, 1, "neither at --to 0.2 nor back at 0.13"),
    # the reviewer's "folds" at m = 6e-9 on the way from 1 to -1: the run said SUCCESS
    ([1.0, 0.5, 6e-9, 5.8e-9, 2.9e-9], OrbitStatus.SUCCESS, (6.06e-9, 5.74e-9), -1.0, None, 1, "after 2 fold(s)"),
    ([], OrbitStatus.NO_START, (), 0.2, None, 1, "no branch"),
])
def test_continue_exit_code_follows_where_the_branch_ended(mus, status, folds, end, back_to, code, words):
    start = mus[0] if mus else 0.1
    o = outcome(_branch(mus, status, "why", folds), "p", start, end, back_to)
    assert o.code == code and words in o.line, o.line
    assert o.reached_end == (code == 0 and "reached" in words)


def test_continue_short_of_the_end_exits_1_with_where_and_why(capsys, monkeypatch):
    import hunting.continuation as C

    def short(*a, **k):
        return _branch([10.0, 10.5, 11.0], OrbitStatus.POINT_LIMIT,
                       "max_points = 3 reached at P = 11: raise max_points or ds_max")
    monkeypatch.setattr(C, "follow", short)
    code = main(["continue", "table9.1", "--param", "P", "--from", "10", "--to", "12", "--max-points", "3"])
    out = capsys.readouterr().out
    assert code == 1 and "stopped at P = 11, short of --to 12 (POINT_LIMIT)" in out
    assert "raise --max-points or --ds-max" in out and "max_points" not in out


@pytest.mark.parametrize("argv, message", [
    ("--from 0.1 --to 0.2 --back-to 5", "--back-to 5 is outside --from 0.1 --to 0.2"),
    ("--from 0.1 --to 0.2 --back-to 0.05", "--back-to 0.05 is outside"),
    ("--from 0.1 --to 0.2 --ds-min 0.5 --ds-max 0.1", "--ds-min <= --ds-max"),
    ("--from 0.1 --to 0.2 --max-points 0", "argument --max-points"),
])
def test_continue_range_options_are_checked(capsys, argv, message):
    code = main(["continue", "table9.1", "--param", "P", *argv.split()])
    err = capsys.readouterr().err
    assert code == 2 and message in err and err.count("\n") == 1


def test_eventmap_defined_nowhere_is_a_failure(capsys):
    """--iterate 1000: only d = 0 reaches its stick phases (was: exit 0 with a warning)."""
    code = main(["eventmap", "table9.1", "--grid", "0:0.5:11", "--iterate", "1000"])
    err = capsys.readouterr().err
    assert code == 1 and "no map: P^1000 is defined at 1 of 11 grid points (MAX_EVENTS at 10)" in err
    assert "lower --iterate" in err


@pytest.mark.parametrize("grid", ["abc", [0.1], [0.0, float("nan")], [[0.1, "x"]]])
def test_fixed_points_name_a_bad_grid(grid):
    """(was: a bare numpy ValueError for "abc", an empty list for one point)"""
    from hunting.eventmap import fixed_points
    with pytest.raises(hunting.SystemDefinitionError, match="grid = .* is not allowed: at least 2 finite"):
        fixed_points("table9.1", grid, 2)
