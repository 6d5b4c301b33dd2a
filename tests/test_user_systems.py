"""The user path: systems defined outside the package run on the same compiled kernels."""
import math

import numba
import numpy as np
import pytest
from scipy.optimize import brentq

import hunting
from hunting.integrate import _kernel
from user_systems import (ABOVE, BELOW, SLIDE, STICK, ball_system, filippov_system, spring_force,
                          two_mass_system)


def test_filippov_sliding_exit_and_crossing_match_closed_form():
    sys_ = filippov_system()
    tr = hunting.simulate(sys_, [0.0, 0.0], (0.0, 6.0), rtol=1e-12, atol=1e-14)
    ev = tr.events
    assert tr.mode[0] == SLIDE
    # sliding ends when 2 sin s = 1 (s = t): t = pi/6, leaving tangentially upwards
    assert ev.mode_from[0] == SLIDE and ev.mode_to[0] == ABOVE
    assert abs(ev.t[0] - math.pi / 6) < 1e-12
    # above: y(s) = -(s - pi/6) + 2 (cos(pi/6) - cos s); returns to 0 at s*
    y = lambda s: -(s - math.pi / 6) + 2 * (math.cos(math.pi / 6) - math.cos(s))  # noqa: E731
    s_star = brentq(y, math.pi, 4.5, xtol=1e-15)
    assert abs(ev.t[1] - s_star) < 1e-10
    assert ev.mode_to[1] == BELOW            # 2 sin s* < -1: both fields point down, it crosses
    # on the sliding segment y stays on the surface (to rounding of the convex combination)
    assert np.all(np.abs(tr.x[tr.mode == SLIDE, 0]) < 1e-15)


def test_two_mass_system_stick_slip():
    sys_ = two_mass_system()
    tr = hunting.simulate(sys_, [0.0, 0.0, 0.0, 0.0], (0.0, 10.0), rtol=1e-11, atol=1e-13)
    assert tr.success
    ev = tr.events
    brk = np.flatnonzero(ev.mode_from == STICK)
    ent = np.flatnonzero(ev.mode_to == STICK)
    assert len(brk) >= 3 and len(ent) >= 3
    p = sys_.params
    for k in brk:          # break-away exactly at the static level
        assert abs(abs(spring_force(ev.t[k], ev.x_before[k], p)) - 1.5) < 1e-9
    for k in ent:          # stick entered with the force inside the stick set
        assert ev.x_after[k, 1] == 0.0 and abs(spring_force(ev.t[k], ev.x_after[k], p)) <= 1.5
    # during each stick phase mass 1 does not move at all
    for a, b in tr.stick_intervals([STICK]):
        sel = (tr.t >= a) & (tr.t <= b) & (tr.mode == STICK)
        assert np.ptp(tr.x[sel, 0]) == 0.0 and np.all(tr.x[sel, 1] == 0.0)


def test_new_systems_reuse_the_compiled_kernel():
    # the lean kernel (DOP853) and the full one (Radau here) each compile once, for every system
    kernels = [_kernel.compiled("lean"), _kernel.compiled("full")]
    hunting.simulate(ball_system(e=0.9), [1.0, 0.0], (0.0, 1.0))
    hunting.simulate(two_mass_system(), [0.0] * 4, (0.0, 1.0))
    hunting.simulate(hunting.preset("table8.1-lugre").system, [-1, 0, 0, 0], (0.0, 1.0), method="radau")
    hunting.simulate(two_mass_system(), [0.0] * 4, (0.0, 1.0), method="radau")
    assert [len(k.overloads) for k in kernels] == [1, 1]


def test_zeno_is_detected_and_reported():
    sys_ = ball_system(e=0.5)
    tr = hunting.simulate(sys_, [1.0, 0.0], (0.0, 10.0))
    assert tr.status == hunting.Status.ZENO and "Zeno" in tr.message
    # accumulation time of the bounces: t* = sqrt(2 h/g) (1 + e) / (1 - e); the run stops
    # shortly after, once bounces stay below the guard tolerance (chattering on the floor)
    t_star = math.sqrt(2 / 9.81) * 1.5 / 0.5
    assert abs(tr.t_final - t_star) < 1e-4
    assert len(tr.events) < 200


def test_protocol_violations_are_named():
    @numba.njit(cache=False)
    def vf(mode, t, x, p, out):
        out[:] = 0.0

    sys_ = ball_system()
    with pytest.raises(hunting.SystemDefinitionError, match=r"vf = .* is not a numba function|compiled for"):
        hunting.PiecewiseSystem(name="bad", state_names=("a",), modes=("m",), guard_names=("g",),
                                param_names=(), params=np.zeros(1), vector_field=vf, guards=sys_.guards,
                                transition=sys_.transition, mode_of=sys_.mode_of)
    with pytest.raises(hunting.SystemDefinitionError, match=r"directions has shape \(1, 3\)"):
        hunting.PiecewiseSystem(name="bad", state_names=("h", "v"), modes=("m",), guard_names=("g",),
                                param_names=(), params=np.zeros(2), vector_field=sys_.vector_field,
                                guards=sys_.guards, transition=sys_.transition, mode_of=sys_.mode_of,
                                directions=np.zeros((1, 3)))


def test_memoized_function_addresses_match_numba():
    from numba.experimental import function_type as ft

    from hunting import _fastcall
    from hunting.system import GUARD_SIG, VF_SIG
    for sys_ in (ball_system(), two_mass_system(), hunting.preset("table9.1").system):
        for fn, sig in ((sys_.vector_field, VF_SIG), (sys_.guards, GUARD_SIG)):
            assert ft._get_wrapper_address(fn, sig) == _fastcall._orig_wrapper(fn, sig)
            assert ft._get_jit_address(fn, sig) == _fastcall._orig_jit(fn, sig)


@pytest.mark.parametrize("vectorize, unroll", [(False, False), (True, False), (False, True)])
def test_compile_for_without_loop_passes_restores_numba_settings(vectorize, unroll):
    """A kernel's compile without LLVM's loop vectorizer or unroller leaves numba's settings as
    they were for everything compiled afterwards."""
    import numba.core.codegen as codegen
    from hunting.system import VF_SIG, compile_for

    @numba.njit
    def vf(mode, t, x, p, out):
        for i in range(x.size):
            out[i] = -x[i]

    before = (numba.config.LOOP_VECTORIZE, getattr(codegen, "create_pass_builder", None))
    compile_for(vf, VF_SIG, vectorize=vectorize, unroll=unroll)
    assert (numba.config.LOOP_VECTORIZE, getattr(codegen, "create_pass_builder", None)) == before
    out = np.empty(3)
    vf(0, 0.0, np.arange(3.0), np.empty(0), out)
    np.testing.assert_array_equal(out, -np.arange(3.0))
