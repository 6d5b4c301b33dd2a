"""Loading measured data, as properties: whatever a CSV file holds, ``load`` returns a valid
measurement or raises SystemDefinitionError naming the file (never another exception), and what
``save_csv`` writes reads back."""
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hunting.diagnose import Measurement, load, save_csv
from hunting.errors import SystemDefinitionError

SETTINGS = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])

finite = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)
# tokens a careless export produces: numbers, blanks, text, NaN, stray quotes and separators
token = st.one_of(finite.map(repr), st.sampled_from(["", " ", "nan", "inf", "-", "1e", "1,5", '"3"', '"', "abc",
                                                     "0x10", "1_000", "\t2", "\x00", "1e400", "—"]))
row = st.lists(token, min_size=0, max_size=5).map(",".join)
header = st.lists(st.sampled_from(["t", "q", "u", "time", "qm", "vir", "q_ref", "x", "", "t "]),
                  min_size=0, max_size=5).map(",".join)


def _check(path):
    try:
        meas = load(path)
    except SystemDefinitionError as e:
        assert str(path.name) in str(e) or str(path) in str(e)
        assert "\n" not in str(e).strip()
        return None
    assert meas.n >= 2 and np.all(np.diff(meas.t) > 0)
    for k in ("t", "q", "u"):
        assert np.all(np.isfinite(getattr(meas, k)))
    return meas


@SETTINGS
@given(header, st.lists(row, max_size=80))
def test_any_csv_text_loads_or_is_named(tmp_path, head, rows):
    path = tmp_path / "data.csv"
    path.write_text("\n".join([head, *rows]) + "\n", encoding="utf-8")
    _check(path)


@SETTINGS
@given(st.binary(max_size=400))
def test_any_bytes_load_or_are_named(tmp_path, blob):
    path = tmp_path / "data.csv"
    path.write_bytes(b"t,q,u\n" + blob)
    _check(path)


@SETTINGS
@given(st.integers(50, 400), st.floats(1e-4, 1e-2), st.lists(finite, min_size=3, max_size=3),
       st.booleans())
def test_what_save_csv_writes_reads_back(tmp_path, n, dt, scales, with_ref):
    rng = np.random.default_rng(n)
    t = np.arange(n) * dt
    q, u, r = (s * rng.standard_normal(n) for s in scales)
    meas = Measurement(t=t, q=q, u=u, q_ref=r if with_ref else None, name="m")
    path = tmp_path / "m.csv"
    save_csv(meas, path)
    back = _check(path)
    assert back is not None
    for k in ("t", "q", "u") + (("q_ref",) if with_ref else ()):
        np.testing.assert_allclose(getattr(back, k), getattr(meas, k), rtol=1e-9, atol=1e-300)
    assert (back.q_ref is None) == (not with_ref)


@pytest.mark.parametrize("content, words", [
    (b"t,q,u\n0,0,0\n\xff\xfe,1,2\n", "UTF-8"),
    (b"t,q,u\n0,0\x00,0\n", "line 2: .* is not a number"),
])
def test_undecodable_files_are_named(tmp_path, content, words):
    path = tmp_path / "bad.csv"
    path.write_bytes(content)
    with pytest.raises(SystemDefinitionError, match=words):
        load(path)
