"""The own channel's choice between two readings of the same evidence
(:func:`hunting.diagnose.select._own_channel`, :func:`hunting.diagnose.select._replacing`): which
one is named beside the causes the force channel found, and the increments of a reading that
replaces one of them."""
from types import SimpleNamespace

import pytest

from hunting.diagnose.result import Cause
from hunting.diagnose.select import _own_channel, _replacing


def _verdict(velocity_fitted: bool) -> dict:
    """A dwell verdict whose growth test failed and whose break-away level holds: the dwell
    reading, and the static level (``instead``) at 1.19 N."""
    reading = dict(name="stribeck", evidence="static level", parameters={"Fc": 0.66, "Fs": 1.19, "vs": 2e-3, "vs_neg": 2e-3},
                   sigma={"Fs": 0.005}, increments={"Fs": 0.52}, metric="break-away force RMS error [N]",
                   nominal=0.5, extended=0.02, model="static model", velocity_fitted=velocity_fitted)
    level = dict(statistic=18.8, p_value=None, significant=True, evidence="every rest above Fs", rivals=("stribeck",),
                 parameters={"level": 0.0, "gain": 0.53, "time": 0.055}, sigma={"gain": 0.005},
                 metric="break-away force RMS error [N]", nominal=0.5, extended=0.03, model="dwell model", instead=reading)
    return dict(statistic=0.1, p_value=0.5, reason="the growth test fails", otherwise=level)


@pytest.mark.parametrize("found, velocity_fitted, named", [
    ([], False, "stribeck"),                 # nothing of the family found: the static level
    (["stribeck"], False, "dwell"),          # the sliding data fixed the curve's static level
    (["stribeck"], True, "stribeck"),        # ... unless its velocity was fitted there: it replaces the fit
    (["level"], True, "dwell"),              # a level change of another name stays, and so does dwell
])
def test_which_reading_is_named(found, velocity_fitted, named):
    mod = SimpleNamespace(NAME="dwell", judge=lambda *args: _verdict(velocity_fitted))
    cause, alternative, model = _own_channel(mod, None, None, None, None, "nominal", 1e-3, 0.05, False, None,
                                             found=lambda rivals: found)
    assert cause.name == named
    assert model == ("static model" if named == "stribeck" else "dwell model")
    assert (alternative or {}).get("name") == ("dwell" if named == "stribeck" else None)


def test_a_reading_that_replaces_a_found_cause_carries_its_increments():
    """The reading extended the model the found Stribeck fit had extended: its Fs increment was
    against that fit's Fs, and the replaced cause's increments turn it into one against the
    nominal model (Fs 0.60 N nominal, fitted 0.67, read 1.19)."""
    found = Cause("stribeck", 0.2, 1.0, 1e-5, {"Fc": 0.66, "Fs": 0.67, "vs": 6e-3, "vs_neg": 6e-3}, {}, {},
                  increments={"Fs": 0.07}, family="friction curve")
    other = Cause("viscous", 0.1, 1.0, 1e-5, {"b": 3.0}, {}, {}, increments={"b": 1.0}, family="velocity")
    reading = Cause("stribeck", 30.0, 18.8, None, {"Fc": 0.66, "Fs": 1.19, "vs": 2e-3, "vs_neg": 2e-3}, {}, {},
                    increments={"Fs": 0.52}, family="friction curve")
    out = _replacing([found, other], reading)
    assert [c.name for c in out] == ["viscous", "stribeck"]
    assert out[1].increments["Fs"] == pytest.approx(1.19 - 0.60)
    assert _replacing([other], reading)[-1].increments == {"Fs": 0.52}
