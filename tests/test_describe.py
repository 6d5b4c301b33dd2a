"""Model descriptions compiled into systems: the API, presets from descriptions against the
hand-written kernels."""
import pathlib

import numpy as np
import pytest

import hunting

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture(scope="session", autouse=True)
def model_cache(tmp_path_factory):
    """Compiled models go to one tmp dir per test session (compiled once, reused by every test)."""
    import os
    d = tmp_path_factory.mktemp("model_cache")
    old = os.environ.get("HUNTING_CACHE_DIR")
    os.environ["HUNTING_CACHE_DIR"] = str(d)
    yield d
    if old is None:
        os.environ.pop("HUNTING_CACHE_DIR", None)
    else:
        os.environ["HUNTING_CACHE_DIR"] = old


def test_api_names_layout_and_state():
    m = hunting.load_model(EXAMPLES / "belt.json")
    assert m.state_names == ("q", "v")
    assert m.param_names == ("m", "k", "Fc", "Fs", "vs", "vb")
    assert m.layout.param("vb") == 5 and m.param_index("k") == 1
    assert m.mode_names == ("slip+", "slip-", "stick")
    (c,) = m.contacts
    assert (c.slip_pos_modes, c.slip_neg_modes, c.stick_modes, c.surface_state) == ((0,), (1,), (2,), 1)
    np.testing.assert_array_equal(m.state(q=0.2), [0.2, 0.0])
    m2 = m.with_params(k=3.0)
    assert m2.system.param("k") == 3.0 and m.system.param("k") == 2.0
    assert m2.system.vector_field is m.system.vector_field          # nothing recompiled
    assert m2.description["parameters"]["k"] == 3.0


@pytest.mark.parametrize("name, x0, method", [("table9.1", [0.1, 0.0, 0.0], "dop853"),
                                              ("table8.1-lugre", [-1.0, 0.0, 0.0, 0.0], "radau")])
def test_presets_from_descriptions_match_hand_written(name, x0, method):
    m = hunting.model(name)
    loop = hunting.preset(name)
    te = np.linspace(0, 20, 201)
    kw = dict(method=method, rtol=1e-10, atol=1e-12, t_eval=te)
    a = hunting.simulate(m.system, x0, (0, 20), **kw)
    b = hunting.simulate(loop.system, x0, (0, 20), **kw)
    assert a.success and b.success
    assert np.abs(a.x - b.x).max() < 1e-8
