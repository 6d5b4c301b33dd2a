"""`hunting cycle` and `--model FILE` on simulate, eventmap and continue."""
import json
from pathlib import Path

import pytest

from hunting.cli import main
from cycle_systems import BELT_DESCRIPTION, belt_reference_cycle
from test_cycle_eventmap import PID_SWITCH

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "belt.json"


@pytest.fixture()
def belt_file(tmp_path):
    p = tmp_path / "belt.json"
    p.write_text(json.dumps(BELT_DESCRIPTION))
    return p


def test_cycle_json_contract_and_figure(tmp_path):
    js, png = tmp_path / "c.json", tmp_path / "c.png"
    assert main(["cycle", "table9.1", "--json", str(js), "--plot", str(png)]) == 0
    d = json.loads(js.read_text())
    assert d["status"] == "SUCCESS" and d["stable"] is True
    assert set(d["x0"]) == set(d["min"]) == set(d["max"]) == {"x1", "x2", "x3"}
    assert d["max"]["x1"] == pytest.approx(0.2523, abs=1e-4)                  # Table 9.2
    mods = [abs(complex(*z)) for z in d["multipliers"]]
    assert len(d["multipliers"][0]) == 2 and mods == sorted(mods, reverse=True)
    assert [p["kind"] for p in d["phases"]].count("stick") == 2
    assert sum(p["duration"] for p in d["phases"]) == pytest.approx(d["period"], rel=1e-12)
    assert png.stat().st_size > 10_000


def test_cycle_of_a_model_file_matches_solve_ivp(tmp_path, belt_file):
    js = tmp_path / "b.json"
    assert main(["cycle", "--model", str(belt_file), "--x0", "q=0.2", "--json", str(js)]) == 0
    d = json.loads(js.read_text())
    ref = belt_reference_cycle()
    assert d["period"] == pytest.approx(ref["period"], rel=1e-9)
    assert {p["kind"]: p["duration"] for p in d["phases"]}["stick"] == pytest.approx(ref["stick"], rel=1e-8)
    assert d["model"] == str(belt_file)
    # a parameter of the model by name
    assert main(["cycle", "--model", str(belt_file), "--set", "vb=0.12", "--json", str(js)]) == 0
    assert json.loads(js.read_text())["period"] == pytest.approx(belt_reference_cycle(vb=0.12)["period"], rel=1e-9)


def test_no_cycle_is_a_numerical_failure_with_its_reason(tmp_path, capsys):
    js = tmp_path / "e.json"
    assert main(["cycle", "table9.1", "--x0", "x3=0.01", "--json", str(js)]) == 1
    err = capsys.readouterr().err
    assert "no cycle (EQUILIBRIUM)" in err and "Traceback" not in err
    assert json.loads(js.read_text())["status"] == "EQUILIBRIUM"


@pytest.mark.parametrize("argv,message", [
    (["cycle"], "no system"),
    (["cycle", "table9.1", "--model", str(EXAMPLE)], "give one of them"),
    (["cycle", "--model", "/nonexistent/m.json"], "does not exist"),
    (["cycle", "table9.1", "--x0", "q=1"], "'q' is not a state"),
    (["cycle", "table9.1", "--period-guess", "-1"], "--period-guess"),
    (["cycle", "table9.1", "--x0", "x1=0.3", "--which", "unstable"], "--which unstable"),
    (["continue", "table9.1", "--param", "P", "--from", "10", "--to", "10"], "--from 10 --to 10"),
])
def test_bad_cycle_arguments(argv, message, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_bad_model_arguments(belt_file, capsys):
    assert main(["cycle", "--model", str(belt_file), "--set", "nope=1"]) == 2
    assert "'nope' is not a parameter" in capsys.readouterr().err
    assert main(["eventmap", "--model", str(belt_file), "--grid", "0:0.4:11"]) == 2
    assert "not a one-parameter family" in capsys.readouterr().err


def test_model_files_reach_simulate_eventmap_and_continue(tmp_path, belt_file):
    pid = tmp_path / "pid.json"
    pid.write_text(json.dumps(PID_SWITCH))
    js = tmp_path / "m.json"
    assert main(["eventmap", "--model", str(pid), "--grid", "0:0.4:201", "--iterate", "2", "--json", str(js)]) == 0
    fps = json.loads(js.read_text())["fixed_points"]
    assert [round(f["d"], 4) for f in fps if f["kind"] == "cycle"] == [0.0034, 0.2523]
    assert main(["simulate", "--model", str(belt_file), "--t", "12", "--json", str(js)]) == 0
    assert json.loads(js.read_text())["status"] == "SUCCESS"
    assert main(["continue", "--model", str(belt_file), "--param", "vb", "--from", "0.1", "--to", "0.12",
                 "--json", str(js)]) == 0
    pts = json.loads(js.read_text())["points"]
    assert len(pts) >= 2 and pts[-1]["param"] >= 0.12
    assert pts[-1]["period"] == pytest.approx(belt_reference_cycle(vb=pts[-1]["param"])["period"], rel=1e-7)


def test_continue_starts_on_the_cycle_wherever_the_map_has_it(tmp_path):
    """Issue 18: `continue table9.1 --param P --from 10 --to 12` (the cycle is at d = 0.2523)."""
    js = tmp_path / "p.json"
    assert main(["continue", "table9.1", "--param", "P", "--from", "10", "--to", "12", "--json", str(js)]) == 0
    pts = json.loads(js.read_text())["points"]
    assert pts[0]["amplitude"] == pytest.approx(0.2523, abs=1e-4) and pts[-1]["param"] >= 12


def test_continue_towards_a_singular_parameter_value_says_it_creeps():
    """Finding 11: the belt model's branch in m from 1 to -1 crawls towards m = 0 (steps of 1e-7
    after 400 points, 5e-10 after 3000); the stop names that limit instead of 'raise
    --max-points'. A branch with even steps that runs out of points is not called creeping."""
    import numpy as np

    from hunting.cli.continue_ import outcome
    from hunting.continuation import Branch
    from hunting.continuation.status import OrbitStatus

    def branch(mus):
        m = len(mus)
        return Branch("m", np.array(mus), np.ones(m), np.ones(m), np.ones((m, 2), complex), np.ones(m, bool),
                      np.zeros((m, 2)), [], [], OrbitStatus.POINT_LIMIT, "max_points = 400 reached")
    crawl = list(1.0 / (1.0 + np.arange(400.0)) ** 2)                # 1 -> 6e-6, steps shrinking
    o = outcome(branch(crawl), "m", 1.0, -1.0, None)
    assert o.code == 1 and "creeps towards m = 0" in o.line and "--to 6.25e-06" in o.line, o.line
    even = list(np.linspace(1.0, 0.5, 400))
    o = outcome(branch(even), "m", 1.0, -1.0, None)
    assert o.code == 1 and "creeps" not in o.line and "max_points = 400 reached" in o.line, o.line
    away = list(1.0 + 1.0 / (1.0 + np.arange(400.0)) ** 2)          # creeping towards 1, not 0
    o = outcome(branch(away), "m", 2.0, 0.5, None)
    assert "creeps towards a limit it does not pass" in o.line and "m = 0" not in o.line, o.line


# PID x lead x 2nd-order low-pass and a Pade delay (as Eq. 5.4 of the thesis) around a Stribeck
# contact; at K = 10 it hunts with T = 4.6477, q in +-0.15824 (cross-checked by simulation)
LOOPSHAPED_HUNT = """
name: loopshape-hunt
parameters:
  m: 1.0
  K: 10.0
  ti: 0.5
  tz: 0.2
  tp: 0.02
  wlp: 200.0
  zlp: 0.7
  Td: 0.002
  Fc: 2.0
  Fs: 4.0
  vs: 0.1
  b: 0.5
states: {q: 0.05, v: 0.0}
signals:
  e: q
blocks:
  - output: uc
    input: -e
    tf: K*(ti*s + 1)/(ti*s)*(tz*s + 1)/(tp*s + 1)*wlp**2/(s**2 + 2*zlp*wlp*s + wlp**2)
  - {output: u, input: uc, delay: Td, order: 3}
equations:
  q: v
  v: (u - F)/m
friction:
  force: F
  velocity: v
  model: switch
  slip: sign(w)*(Fc + (Fs - Fc)*exp(-(w/vs)**2)) + b*w
  stick: Fs
"""


def test_cycle_summary_lists_the_mechanical_states_not_block_realizations(tmp_path, capsys):
    path = tmp_path / "ls.yaml"
    path.write_text(LOOPSHAPED_HUNT)
    code = main(["cycle", "--model", str(path)])
    out = capsys.readouterr().out
    assert code == 0, out
    ranges = out.splitlines()[2]
    assert ranges.lstrip().startswith("q in [") and " v in [" in ranges
    assert "internal block states" in ranges and "u_1" not in ranges


def test_continue_says_the_fold_and_its_multiplier_crossing_once(capsys):
    """The fold's lambda2 = +1 crossing is one point, printed on the fold's line (it used to
    be a second line, 'multiplier_+1', at a slightly different estimate)."""
    assert main(["continue", "table8.1-lugre", "--param", "K", "--from", "0.6", "--to", "0.7"]) == 0
    lines = capsys.readouterr().out.splitlines()
    fold = [s for s in lines if s.startswith("fold")]
    assert len(fold) == 1 and "K = 0.620296" in fold[0] and "a multiplier passes +1 here" in fold[0]
    assert not any(s.startswith("multiplier_+1") for s in lines)
