"""The choice between a general cause and its special case (``NESTS``): the special case is
named where it explains the validation data within min_gain of the general one, the general one
where it explains them better by min_gain and by SWAP_SHARE of the nominal model's validation
residual; the two rules (force._general_case, force._special_case) never both fire on one pair;
between them (both at the noise) the fitting data's BIC of the two sets decides, and the special
case wins only where its set holds on the validation data."""
import numpy as np
import pytest

from hunting.diagnose import force
from hunting.diagnose.force import Explanation


class _Lib:
    """The two methods the swap rules use, with a validation RMS per set of names."""

    def __init__(self, rms: dict, bic: dict | None = None):
        self.rms, self.bic = rms, bic or {}
        self.variants = {"offset": [{}], "asymmetry": [{}], "viscous": [{}], "level": [{}], "stribeck": [{}],
                         "level_asymmetry": [{}], "mass": [{}]}

    def best_variants(self, names):
        return Explanation(tuple((n, 0) for n in names), np.zeros(0), self.bic.get(frozenset(names), 0.0), 0.0)

    def validation_rms(self, e):
        return self.rms.get(frozenset(e.names), 1e9)     # a set not given explains nothing


def _current(*names, bic: float = 0.0):
    return Explanation(tuple((n, 0) for n in names), np.zeros(0), bic, 0.0)


def _diagnosed(family: str, index: int):
    """(Diagnosis, truth) of a blind dataset, diagnosed without the behaviour view."""
    from blind_records import blind_record

    from hunting.diagnose import diagnose
    fit, val, model, truth = blind_record(family, index)
    return diagnose(fit, model, val, behaviour=False), truth


@pytest.mark.parametrize("general, special", [("asymmetry", "viscous"), ("stribeck", "level")])
@pytest.mark.parametrize("rms_general, rms_special, rms0, expect", [
    (1.00, 1.02, 2.0, "special"),      # the general case is not 5 % better: the special case is named
    (0.90, 1.00, 2.0, "general"),      # 10 % better: the extra freedom is real
    (0.95, 1.00, 2.0, "special"),      # exactly min_gain better is not "better by min_gain": the boundary
    (0.94, 1.00, 2.0, "general"),
    # both explain nearly all of a nominal residual of 10: 0.1 better is 1 % of it (SWAP_SHARE 2 %),
    # noise: no swap either way (reporting16 d0592: an asymmetry for a viscous change, 1.0 % of it)
    (0.90, 1.00, 10.0, "neither"),
    (0.79, 1.00, 10.0, "general"),
    (0.96, 1.00, 10.0, "special"),
])
def test_a_general_cause_gives_way_to_its_special_case_unless_needed(general, special, rms_general, rms_special,
                                                                     rms0, expect):
    # the fitting data prefer the general case by BIC: at the noise, its choice stands
    lib = _Lib({frozenset({"offset", general}): rms_general, frozenset({"offset", special}): rms_special},
               {frozenset({"offset", general}): -10.0, frozenset({"offset", special}): 0.0})
    cur_g, cur_s = _current("offset", general, bic=-10.0), _current("offset", special)
    to_special = force._special_case(lib, {}, cur_g, rms_general, rms0, 0.05, set())
    to_general = force._general_case(lib, {}, cur_s, rms_special, rms0, 0.05, set())
    if expect == "neither":
        assert to_special is None and to_general is None
    elif expect == "special":
        assert to_special is not None and to_special[0] == general and special in to_special[1].names
        assert to_general is None
    else:
        assert to_special is None
        assert to_general is not None and to_general[0] == special and general in to_general[1].names
    # a cause dropped for good is not brought back
    assert force._special_case(lib, {}, cur_g, rms_general, rms0, 0.05, {special}) is None


@pytest.mark.parametrize("bic_general, holds, expect", [(-10.0, True, None), (+1.9, True, "special"),
                                                         (+1.9, False, None), (0.0, True, "special")])
def test_at_the_noise_the_fitting_data_decide_between_a_cause_and_its_special_case(bic_general, holds, expect):
    """reporting33 d0341: a level change of 21.9 % named as levels scaled apart by 1.2188 and 1.2192;
    on the validation data the general case is 12 % better on what is left, 0.05 % of the nominal
    residual (both explain 99.6 %), and it stood as what the search's pruning left of a larger set.
    There the fitting data's BIC between the two sets decides; the special case is named only where
    its set holds on the validation data (``holds``)."""
    lib = _Lib({frozenset({"level_asymmetry"}): 0.00581, frozenset({"level"}): 0.00664},
               {frozenset({"level_asymmetry"}): bic_general, frozenset({"level"}): 0.0})
    cur = _current("level_asymmetry", bic=bic_general)
    out = force._special_case(lib, {}, cur, 0.00581, 1.67, 0.05, set(), lambda alt: holds)
    if expect is None:
        assert out is None
    else:
        assert out[0] == "level_asymmetry" and out[1].names == ("level",) and "BIC" in out[2]


@pytest.mark.parametrize("rms_stribeck, rms_apart, expect", [(0.80, 0.90, "stribeck"), (0.90, 0.80, "level_asymmetry"),
                                                              (0.97, 0.99, None)])
def test_of_two_general_causes_the_better_one_replaces_the_special_case(rms_stribeck, rms_apart, expect):
    """``level`` is the special case of ``stribeck`` and of ``level_asymmetry``: the one that explains
    the validation data best takes its place, where it is better by min_gain."""
    lib = _Lib({frozenset({"mass", "level"}): 1.0, frozenset({"mass", "stribeck"}): rms_stribeck,
                frozenset({"mass", "level_asymmetry"}): rms_apart})
    out = force._general_case(lib, {}, _current("mass", "level"), 1.0, 2.0, 0.05, set())
    if expect is None:
        assert out is None
    else:
        assert out[0] == "level" and set(out[1].names) == {"mass", expect} and out[2].startswith(expect)


@pytest.mark.parametrize("rms_apart, expect", [(1.00, "offset"), (0.90, None)])
def test_levels_scaled_apart_give_way_to_an_offset_that_explains_the_data_as_well(rms_apart, expect):
    """An offset is nearly a special case of ``level_asymmetry`` (above the Stribeck velocity): the
    independent generator's seed-4 d0049, an offset named as levels scaled apart with the same
    validation residual, is named an offset; factors apart that are better by min_gain stay."""
    lib = _Lib({frozenset({"mass", "level_asymmetry"}): rms_apart, frozenset({"mass", "level"}): 1.5,
                frozenset({"mass", "offset"}): 1.0})
    out = force._special_case(lib, {}, _current("mass", "level_asymmetry", bic=-10.0), rms_apart, 2.0, 0.05, set())
    if expect is None:
        assert out is None
    else:
        assert out[0] == "level_asymmetry" and set(out[1].names) == {"mass", expect}


def test_a_swap_at_the_noise_floor_keeps_the_selected_special_case():
    """reporting16 d0592: a cogging beside a viscous change of 7.0 N s/m. With both, the residual
    left is near the noise; an asymmetry in the viscous change's place was 5 % better on that
    remainder, 1.0 % of the nominal residual, and replaced it (the viscous change was missed).
    Under SWAP_SHARE the viscous change stays, within 3 %, beside the cogging."""
    d, truth = _diagnosed("reporting16", 592)
    assert sorted(c.name for c in d.causes) == ["cogging", "viscous"], [(c.name, c.parameters) for c in d.causes]
    b = next(e["params"]["b"] for e in truth["effects"] if e["cause"] == "viscous")
    assert next(c for c in d.causes if c.name == "viscous").parameters["b"] == pytest.approx(b, rel=0.03)


def test_a_level_change_alike_in_both_directions_is_named_a_level_change():
    """reporting33 d0341 end to end: the Coulomb and static levels scaled by 1.2179 in both
    directions, a nearly noise-free record; named ``level`` (was ``level_asymmetry`` with scales
    1.2188 and 1.2192), its scale within 0.5 %. The general cause is the report's same-family
    alternative: given way to its special case, or (since the fifty-second session's cogging pitch
    candidates, the search's best explanation holds the level itself) not in the best
    explanation at all."""
    d, truth = _diagnosed("reporting33", 341)
    assert [c.name for c in d.causes] == ["level"], [(c.name, c.parameters) for c in d.causes]
    assert d.causes[0].parameters["scale"] == pytest.approx(truth["effects"][0]["params"]["scale"], rel=0.005)
    assert any(a["name"] == "level_asymmetry" and a.get("replaces") == "level" for a in d.alternatives), d.alternatives
    row = next(r for r in d.rejected if r["name"] == "level_asymmetry")
    assert "special case level" in row["reason"] or row["reason"].startswith("not in the best explanation"), row


@pytest.mark.parametrize("names, words", [
    (("delay",), "the fitted extension is not physical: delay < 0"),
    (("delay", "mass"), "the fitted extension is not physical beside mass: delay < 0")])
def test_an_unphysical_member_is_said_beside_the_others_only_where_there_are_others(names, words):
    """The reason read 'not physical beside : delay ...' for a set of one (reporting31/32)."""
    bad = {n: Explanation(tuple((m, 0) for m in n), np.zeros(0), 0.0, 0.0,
                          unphysical={"delay": "delay < 0"} if "delay" in n else {})
           for n in (names, tuple(m for m in names if m != "delay"))}
    rejected = []
    left = force._physical_subset(_Lib({}), bad, names, rejected)
    assert left.names == tuple(m for m in names if m != "delay")
    assert rejected[0]["reason"] == words
