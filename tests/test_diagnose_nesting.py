"""The choice between a general cause and its special case (``NESTS``): the special case is
named unless the general one explains the validation data better by min_gain, and the two
rules (force._general_case, force._special_case) never both fire on one pair."""
import numpy as np
import pytest

from hunting.diagnose import force
from hunting.diagnose.force import Explanation


class _Lib:
    """The two methods the swap rules use, with a validation RMS per set of names."""

    def __init__(self, rms: dict):
        self.rms = rms
        self.variants = {"offset": [{}], "asymmetry": [{}], "viscous": [{}], "level": [{}], "stribeck": [{}]}

    def best_variants(self, names):
        return Explanation(tuple((n, 0) for n in names), np.zeros(0), 0.0, 0.0)

    def validation_rms(self, e):
        return self.rms[frozenset(e.names)]


def _current(*names):
    return Explanation(tuple((n, 0) for n in names), np.zeros(0), 0.0, 0.0)


@pytest.mark.parametrize("general, special", [("asymmetry", "viscous"), ("stribeck", "level")])
@pytest.mark.parametrize("rms_general, rms_special, expect", [
    (1.00, 1.02, "special"),      # the general case is not 5 % better: the special case is named
    (0.90, 1.00, "general"),      # 10 % better: the extra freedom is real
    (0.95, 1.00, "special"),      # exactly min_gain better is not "better by min_gain": the boundary
    (0.94, 1.00, "general"),
])
def test_a_general_cause_gives_way_to_its_special_case_unless_needed(general, special, rms_general, rms_special,
                                                                     expect):
    lib = _Lib({frozenset({"offset", general}): rms_general, frozenset({"offset", special}): rms_special})
    cur_g, cur_s = _current("offset", general), _current("offset", special)
    to_special = force._special_case(lib, {}, cur_g, rms_general, 0.05, set())
    to_general = force._general_case(lib, {}, cur_s, rms_special, 0.05, set())
    if expect == "special":
        assert to_special is not None and to_special[0] == general and special in to_special[1].names
        assert to_general is None
    else:
        assert to_special is None
        assert to_general is not None and to_general[0] == special and general in to_general[1].names
    # a cause dropped for good is not brought back
    assert force._special_case(lib, {}, cur_g, rms_general, 0.05, {special}) is None
