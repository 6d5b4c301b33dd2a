"""Model files in YAML take every number a user writes: PyYAML reads YAML 1.1, where 1e5, 1.0e5
and -2E-3 are strings; the loader reads them as YAML 1.2 floats (float(), never eval)."""
import pytest

from hunting.describe.api import read_description
from hunting.describe.description import validate

CANUDAS = """\
name: canudas95
parameters: {{m: 1.0, kp: {kp}, ki: 4, kv: 6.0, xr: 1.0, Fc: 1.0, Fs: 1.5, vs: {vs},
             s0: {s0}, s1: 316.2, s2: {s2}}}
states: {{x: {x0}, v: 0.0, I: 0.0}}
signals:
  e: xr - x
  u: kp*e + ki*I - kv*v
equations: {{x: v, v: (u - F)/m, I: e}}
friction: {{force: F, velocity: v, model: lugre, level: "Fc + (Fs - Fc)*exp(-(w/vs)**2)",
           sigma0: s0, sigma1: s1, viscous: s2*w}}
"""


@pytest.mark.parametrize("text, value", [("1e5", 1e5), ("1.0e5", 1e5), ("1.0e+5", 1e5), ("100000", 1e5),
                                         ("1E5", 1e5), ("-2E-3", -2e-3), (".5", 0.5), ("5.", 5.0),
                                         ("+3", 3.0), ("1_000.5", 1000.5)])
def test_yaml_numbers_in_every_spelling(tmp_path, text, value):
    f = tmp_path / "m.yaml"
    f.write_text(CANUDAS.format(kp=3, vs="1e-3", s0=text, s2="4E-1", x0=text))
    desc = read_description(f)
    assert desc["parameters"]["s0"] == pytest.approx(value) and desc["parameters"]["vs"] == 1e-3
    assert desc["parameters"]["s2"] == pytest.approx(0.4) and desc["parameters"]["ki"] == 4
    spec = validate(desc)                   # was: "s0 = '1.0e5' is not allowed: ... a finite number"
    assert spec is not None


def test_yaml_keeps_strings_and_expressions(tmp_path):
    f = tmp_path / "m.yaml"
    f.write_text("a: '1e5'\nb: e5\nc: 1e\nd: Fs - 10*q\ne: 100\n")
    assert read_description(f) == {"a": "1e5", "b": "e5", "c": "1e", "d": "Fs - 10*q", "e": 100}


def test_a_directory_is_named_as_one(tmp_path):
    from hunting.errors import SystemDefinitionError
    with pytest.raises(SystemDefinitionError, match="is a directory"):
        read_description(tmp_path)
