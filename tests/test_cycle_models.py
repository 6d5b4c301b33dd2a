"""Cycles and branches of models written as descriptions (issue 19, the review of main @ 4d67e6e)
against independent scipy solvers (tests/cycle_systems.py): the minimal period, sections on the
motion (not on states that are numerical noise), starts on a cycle, reasons for no cycle that
fit, the event-map start of a compiled model at its equilibrium, grazing points only where the
event sequence changes, branches that end on their end, figures labelled by the model."""
import json
from pathlib import Path

import numpy as np
import pytest

import hunting
from hunting import find_cycle, follow
from hunting.cli import main
from hunting.continuation import OrbitStatus, continue_orbit, resolve, shoot
from hunting.continuation.shooting import minimal_period
from cycle_systems import (BELT_DESCRIPTION, TWO_CONTACT_DESCRIPTION, TWO_DOF_DESCRIPTION, belt_masses_cycle,
                           belt_masses_multipliers, belt_reference_cycle, belt_system, loopshaped_reference,
                           pid_switch_reference, two_contact_forces, two_dof_forces)
from test_cycle_eventmap import PID_SWITCH
from user_systems import two_mass_system

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
ON_THE_CYCLE = dict(q1=0.699303, v1=0.11, q2=0.5516818, v2=-0.10518)     # a stick entry (review)


@pytest.fixture(scope="module")
def two_contact():
    return hunting.model(TWO_CONTACT_DESCRIPTION)


@pytest.fixture(scope="module")
def two_dof():
    return hunting.model(TWO_DOF_DESCRIPTION)


@pytest.fixture(scope="module")
def loopshaped():
    return hunting.load_model(EXAMPLES / "loopshaped.yaml")


def test_two_contacts_cycle_has_its_minimal_period(two_contact):
    """The review's finding 2: the search reported 27.08 (twice the period) with the squares of
    the multipliers. Against the event-driven solve_ivp: period, every stick phase, and the
    nontrivial multiplier from central differences of its return map."""
    r = find_cycle(two_contact)
    assert r.success and r.stable
    T, y, sticks = belt_masses_cycle(two_contact_forces(TWO_CONTACT_DESCRIPTION["parameters"]), r.x0_array,
                                     t_run=3.5 * r.period)
    assert r.period == pytest.approx(T, rel=1e-9) and r.period == pytest.approx(13.5404, abs=1e-4)
    ours = sorted((p.contact, round(p.duration, 7)) for p in r.phases if p.kind == "stick")
    ref = sorted((("belt1", "belt2")[i], round(d, 7)) for i, d in sticks)
    assert ours == ref
    lam = belt_masses_multipliers(two_contact_forces(TWO_CONTACT_DESCRIPTION["parameters"]), y, T)
    assert abs(r.multipliers[1]) == pytest.approx(abs(lam[0]), rel=1e-5)       # 0.7125, not 0.5077
    assert r.multipliers[1].real == pytest.approx(lam[0].real, rel=1e-5)
    # the phases in order along the period, whatever the contact
    starts = [p.start for p in r.phases]
    assert starts == sorted(starts) and {p.contact for p in r.phases} == {"belt1", "belt2"}
    # handed twice the period, shooting converges there too; minimal_period halves it
    po2 = shoot(two_contact.system, r.x0_array, 2 * r.period, section=r.orbit.section)
    assert po2.success and po2.period == pytest.approx(2 * r.period, rel=1e-9)
    assert minimal_period(two_contact.system, po2).period == pytest.approx(r.period, rel=1e-9)


@pytest.mark.parametrize("start", [ON_THE_CYCLE, None], ids=["on the cycle", "from rest"])
def test_two_dof_cycle_from_on_the_cycle_and_from_rest(two_dof, start):
    """Finding 4: started on the cycle (a stick entry of the independent solve), the search
    returned NO_RECURRENCE. The cycle has two stick phases, one ending in a 0.046 s slip that a
    flow stepping over the stick guard's short dip misses; against solve_ivp (events within
    steps of 0.02) and its return map's multipliers."""
    m = two_dof.with_params(vd=0.11)
    r = find_cycle(m, start)
    assert r.success and r.stable
    T, y, sticks = belt_masses_cycle(two_dof_forces(dict(TWO_DOF_DESCRIPTION["parameters"], vd=0.11)),
                                     r.x0_array, t_run=3.5 * r.period)
    assert r.period == pytest.approx(T, rel=1e-9)
    assert sorted(round(p.duration, 7) for p in r.phases if p.kind == "stick") == sorted(round(d, 7) for _, d in sticks)
    assert len(sticks) == 2
    lam = belt_masses_multipliers(two_dof_forces(dict(TWO_DOF_DESCRIPTION["parameters"], vd=0.11)), y, T)
    assert np.abs(r.multipliers[1:3]) == pytest.approx(np.abs(lam[:2]), rel=2e-3)


def test_loopshaped_example_sections_on_the_motion_and_its_rest_is_an_equilibrium(loopshaped):
    """Findings 4 and 5 on the shipped examples/loopshaped.yaml (8 states, 6 of them block
    realization states of size 1e-13 to 1e-7). At K = 100 it hunts: the search used to take
    its returns on a block state at the noise level (uc_1 = -4e-14) and failed after 97 s; the
    cycle agrees with solve_ivp on the transfer functions realized by scipy and
    python-control's Pade. At its own K = 900 it comes to rest within 3 s: EQUILIBRIUM, not
    NO_RECURRENCE after 640 s of simulation."""
    r = find_cycle(loopshaped, params={"K": 100.0})
    assert r.success and r.stable
    assert "entries into stick" in r.start                     # the returns are stick entries
    ref = loopshaped_reference(EXAMPLES / "loopshaped.yaml", 100.0)
    assert r.period == pytest.approx(ref["period"], rel=1e-8)
    assert r.maximum["q"] == pytest.approx(ref["stick_q"], rel=1e-7)
    dur = {p.kind: p.duration for p in r.phases}
    assert dur["stick"] == pytest.approx(ref["stick"], rel=1e-7) and dur["slip"] == pytest.approx(ref["slip"], rel=1e-7)
    rest = find_cycle(loopshaped)
    assert rest.status == OrbitStatus.EQUILIBRIUM and "came to rest by t = " in rest.message
    assert float(rest.message.split("came to rest by t = ")[1].split()[0]) < 10.0
    assert "did not return periodically" not in rest.message


def test_no_cycle_reasons_fit_the_system():
    """Finding 5: table 9.1 at P = 30, beta = 1 has no cycle and an attracting equilibrium set
    (its event map says so): EQUILIBRIUM from the map at once, not NO_RECURRENCE after a 1e4 s
    transient with advice to start closer. A time-forced system is refused with a clear error."""
    r = find_cycle("table9.1", params={"P": 30, "beta": 1})
    assert r.status == OrbitStatus.EQUILIBRIUM
    assert "attracts" in r.message and "start closer" not in r.message and "no cycle at these parameters" in r.message
    with pytest.raises(hunting.SystemDefinitionError, match="depends on the time t"):
        find_cycle(two_mass_system())
    # started in the stick set with a stick error whose integral needs 4e4 s to break away
    stuck = find_cycle("table9.1", {"x1": 1e-6})
    assert stuck.status == OrbitStatus.EQUILIBRIUM and "no stick guard is reached before t = 4e+04" in stuck.message
    # inside the small unstable cycle: stick errors shrink while the stick phases lengthen
    creep = find_cycle("table9.1", {"x1": 1e-3})
    assert creep.status == OrbitStatus.EQUILIBRIUM and "creeps onto a set of rest" in creep.message


def test_a_pid_servo_at_its_equilibrium_starts_from_its_event_map(tmp_path):
    """Finding 6: a PID servo written as equations whose initial state is its equilibrium
    (q = qd = 0) found no cycle (EQUILIBRIUM) and `continue` no branch. Its stick family's event
    map starts it, as for presets; against solve_ivp's fixed point of P^2, its slope (the
    multiplier) and the period. `continue --model` reaches the branch, also from --x0 with
    --period-guess."""
    m = hunting.model(PID_SWITCH).with_params(qd=0.0)
    r = find_cycle(m)
    assert r.success and r.stable and "event map of its stick phases" in r.start
    ref = pid_switch_reference(dict(PID_SWITCH["parameters"], qd=0.0), 0.25)
    assert r.maximum["q"] == pytest.approx(ref["d"], rel=1e-8)
    assert r.period == pytest.approx(ref["period"], rel=1e-8)
    assert abs(r.multipliers[1]) == pytest.approx(ref["slope"], rel=1e-4)
    pid = tmp_path / "pid.json"
    pid.write_text(json.dumps(dict(PID_SWITCH, parameters=dict(PID_SWITCH["parameters"], qd=0.0))))
    js = tmp_path / "b.json"
    for extra in ([], ["--x0", f"q={r.x0['q']},v={r.x0['v']},ie={r.x0['ie']}", "--period-guess", "2.4"]):
        assert main(["continue", "--model", str(pid), "--param", "P", "--from", "10", "--to", "10.5",
                     "--json", str(js)] + extra) == 0
        pts = json.loads(js.read_text())["points"]
        assert pts[0]["period"] == pytest.approx(r.period, rel=1e-8) and pts[-1]["param"] == 10.5


def test_readme_belt_branch_has_no_grazing_and_ends_on_its_end():
    """Finding 3: the README's follow(belt, "vb", 0.1, 0.2) reported 2 grazing points (6 for
    the rational law) although every orbit slips, then sticks; and it ended at 0.22. A
    branch started on a state inside the stick phase (where the mode at the start is
    ambiguous: Newton moves v off the belt speed) has no grazing point either."""
    m = hunting.load_model(EXAMPLES / "belt.json")
    br = follow(m, "vb", 0.1, 0.2)
    assert br.status == OrbitStatus.SUCCESS and br.special == []
    assert br.mu[-1] == pytest.approx(0.2, abs=1e-12)
    assert br.period[-1] == pytest.approx(belt_reference_cycle(vb=0.2)["period"], rel=1e-8)
    sys_ = belt_system()
    ref = belt_reference_cycle()
    po = shoot(sys_, [0.15, 0.1], ref["period"], section=0)             # q on the section, in stick
    assert po.success
    lens = resolve(sys_).lens("vb")
    br2 = continue_orbit(lens.system_at, po, 0.1, 0.15, param="vb", param_direction=lens.direction)
    assert br2.status == OrbitStatus.SUCCESS and [s.kind for s in br2.special] == []


def test_two_dof_branch_grazes_then_folds(two_dof):
    """A genuine change of the event sequence: on the 2-DOF branch in the drive speed a second
    stick phase appears (grazing of the stick bound) near vd = 0.109, and the branch folds at
    vd = 0.11432. Checked with solve_ivp: one stick phase per period before the grazing
    interval, two after; the branch's orbit just below the fold is a cycle of the reference."""
    br = follow(two_dof, "vd", 0.1, 0.12, stop_at=0.11)
    graze = [s for s in br.special if s.kind == "grazing"]
    folds = [s for s in br.special if s.kind == "fold"]
    assert graze and graze[0].data["events_before"] == 2 and graze[0].data["events_after"] == 4
    assert folds and folds[0].param == pytest.approx(0.11432, abs=1e-5)
    lo, hi = graze[0].interval
    p = TWO_DOF_DESCRIPTION["parameters"]
    for vd, n_sticks in ((lo - 1e-4, 1), (hi + 1e-4, 2)):
        i = int(np.argmin(np.abs(br.mu - vd)))
        _, _, sticks = belt_masses_cycle(two_dof_forces(dict(p, vd=float(br.mu[i]))), br.x0[i],
                                         t_run=3.5 * br.period[i])
        assert len(sticks) == n_sticks
    i = int(np.argmin(np.abs(br.mu - (folds[0].param - 2e-5))))
    T, _, _ = belt_masses_cycle(two_dof_forces(dict(p, vd=float(br.mu[i]))), br.x0[i], t_run=3.5 * br.period[i])
    assert T == pytest.approx(br.period[i], rel=1e-8)


def test_figures_show_the_model_with_its_units(loopshaped, two_contact):
    """Finding 15: panels of the mechanical states, block outputs and friction forces (block
    realization states only on request), labels by the model's names with the units of its
    description (none when not given: no "[rad]"), one stick band per contact."""
    from hunting.plotting import cycle_panels, plot_branch, plot_cycle
    belt = hunting.model(dict(BELT_DESCRIPTION, units={"q": "m", "v": "m/s", "F": "N", "t": "s", "vb": "m/s"}))
    r = find_cycle(belt, {"q": 0.2})
    fig = plot_cycle(r, belt.system, model=belt)
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert labels[:3] == ["q [m]", "v [m/s]", "F [N]"] and fig.axes[2].get_xlabel() == "t from x0 [s]"
    br = follow(belt, "vb", 0.1, 0.11)
    fig = plot_branch(br)
    assert fig.axes[0].get_ylabel() == "max |q| [m]" and fig.axes[1].get_xlabel() == "vb [m/s]"
    r = find_cycle(loopshaped, params={"K": 100.0})
    names = [p[0] for p in cycle_panels(r, loopshaped.system, loopshaped)]
    assert names == ["q", "v", "uc", "u", "F"]
    assert len(cycle_panels(r, loopshaped.system, loopshaped, block_states=True)) == 5 + 6
    r2 = find_cycle(two_contact)
    fig = plot_cycle(r2, two_contact.system, model=two_contact)
    assert "[" not in "".join(ax.get_ylabel() for ax in fig.axes)
    legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert "belt1 sticks (lower band)" in legend and "belt2 sticks (upper band)" in legend
    import matplotlib.pyplot as plt
    plt.close("all")
