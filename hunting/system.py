"""The piecewise-smooth system protocol.

A closed loop with friction is a hybrid system: in each *mode* a smooth vector field, *guards*
whose zero crossings end the mode, and a *transition* (reset) function that picks the next mode
and may change the state. All user functions are numba-compiled with the fixed signatures below
so that every kernel (integrator, sensitivity, event map) compiles once, takes them as
first-class function values and is cached on disk for every system and parameter value.

Signatures (``mode`` is the current mode index, ``t`` time, ``x`` state of shape (n,), ``p`` the
flat parameter array)::

    VF_SIG     void(mode, t, x, p, out)               out[:n]        = dx/dt in ``mode``
    GUARD_SIG  void(mode, t, x, p, out)               out[:n_guards] = guard values in ``mode``
    RESET_SIG  int64(mode, guard, t, x, p, x_out)     -> next mode (-1: stop); writes x_out[:n]
    MODE_SIG   int64(t, x, p)                          -> mode of a state (used at the start)
    JAC_SIG    void(mode, t, x, p, out)               out[:n, :n]    = d f / d x in ``mode``

Guard convention: while a mode is valid its guards stay away from zero; guard ``i`` *fires* when
it crosses zero in the direction ``directions[mode, i]`` (-1 falling, +1 rising, 0 either).
A guard the mode does not use returns a constant (e.g. 1.0). Vector fields should be the smooth
extension of the mode's field a little beyond its guards (for instance the sign of the velocity
taken from the mode, not from ``x``): events are then located on smooth interpolants.
"""
from __future__ import annotations

import copy
import warnings
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from typing import Mapping, Sequence

import llvmlite.binding as llvm
import numba
import numba.core.codegen as _numba_codegen
import numpy as np
from numba import types
from numba.core.errors import NumbaExperimentalFeatureWarning

from ._fastcall import install as _install_fastcall
from .errors import SystemDefinitionError

_install_fastcall()

_i8, _f8 = types.int64, types.float64
_vec = types.float64[::1]
_mat = types.float64[:, ::1]

VF_SIG = types.void(_i8, _f8, _vec, _vec, _vec)
GUARD_SIG = types.void(_i8, _f8, _vec, _vec, _vec)
RESET_SIG = _i8(_i8, _i8, _f8, _vec, _vec, _vec)
MODE_SIG = _i8(_f8, _vec, _vec)
JAC_SIG = types.void(_i8, _f8, _vec, _vec, _mat)

VF_TYPE = types.FunctionType(VF_SIG)
GUARD_TYPE = types.FunctionType(GUARD_SIG)
RESET_TYPE = types.FunctionType(RESET_SIG)
MODE_TYPE = types.FunctionType(MODE_SIG)
JAC_TYPE = types.FunctionType(JAC_SIG)

MODE_KINDS = ("smooth", "stick", "filippov")


def _pass_builder_without_unrolling(tm, opt=2, loop_vectorize=False, slp_vectorize=False):
    """numba.core.llvm_bindings.create_pass_builder with LLVM's loop unroller off."""
    pto = llvm.create_pipeline_tuning_options()
    pto.speed_level = opt
    pto.slp_vectorization = slp_vectorize
    pto.loop_vectorization = loop_vectorize
    pto.loop_unrolling = False
    return llvm.create_pass_builder(tm, pto)


@contextmanager
def _loop_passes(vectorize: bool, unroll: bool):
    """While compiling: LLVM pass pipelines without the loop vectorizer (``vectorize=False``)
    and without the loop unroller (``unroll=False``). numba reads LOOP_VECTORIZE each time it
    builds a pipeline; unrolling has no numba setting, so its pipeline factory is swapped (only
    when it has the expected name). Both are restored afterwards."""
    saved_vec = numba.config.LOOP_VECTORIZE
    saved_pb = getattr(_numba_codegen, "create_pass_builder", None)
    try:
        if not vectorize:
            numba.config.LOOP_VECTORIZE = False
        if not unroll and saved_pb is not None:
            _numba_codegen.create_pass_builder = _pass_builder_without_unrolling
        yield
    finally:
        numba.config.LOOP_VECTORIZE = saved_vec
        if saved_pb is not None:
            _numba_codegen.create_pass_builder = saved_pb


def compile_for(disp, sig, *, vectorize: bool = True, unroll: bool = True):
    """Compile numba dispatcher ``disp`` for signature ``sig`` unless it has an overload (numba
    loads it from its disk cache when there) and disable compilation for other types: arguments
    that do not match are an error instead of a silent new specialization. What
    ``numba.njit(sig)`` does at import, done on first use (so importing a module compiles
    nothing a command does not run). Returns ``disp``.

    ``vectorize=False`` and ``unroll=False`` compile it (and the functions it compiles in turn)
    without LLVM's loop vectorizer and loop unroller: for code whose loops run over a few states
    only, their vector and unrolled copies of every loop cost compile time and no run time."""
    if not disp.overloads:
        with _loop_passes(vectorize, unroll), warnings.catch_warnings():
            # compiling inside a caller's warning context (pytest's resets the filter that
            # hunting._fastcall installs at import)
            warnings.simplefilter("ignore", NumbaExperimentalFeatureWarning)
            disp.compile(sig)
        disp.disable_compile()
    return disp


@numba.njit(JAC_SIG, cache=True, error_model="numpy")
def no_jacobian(mode, t, x, p, out):  # pragma: no cover - placeholder passed when finite differences are used
    """Stand-in for systems without an analytic Jacobian (the kernels then use differences)."""
    out[:, :] = 0.0


def _require_finite(p: np.ndarray, names: tuple) -> None:
    """Raise naming every non-finite entry of a flat parameter array."""
    if not np.all(np.isfinite(p)):
        bad = [names[i] if i < len(names) else f"params[{i}]" for i in np.flatnonzero(~np.isfinite(p))]
        raise SystemDefinitionError(f"parameters {bad} are not finite")


@dataclass(frozen=True)
class Mode:
    """Description of one mode.

    kind: ``"smooth"`` (an ordinary vector field), ``"stick"`` (friction stick: motion of the
    sliding coordinate held at zero while the friction force stays in its stick set, which may
    be larger than the Filippov hull) or ``"filippov"`` (sliding with the Filippov convex
    combination). ``surface_state`` is the index of the state that is zero on the sliding
    surface (the relative velocity for friction), ``-1`` for smooth modes.
    """

    name: str
    kind: str = "smooth"
    surface_state: int = -1

    def __post_init__(self):
        if self.kind not in MODE_KINDS:
            raise SystemDefinitionError(f"mode kind = {self.kind!r} is not allowed: use one of {MODE_KINDS}")


# library functions that stand in a PiecewiseSystem before they are compiled (see compile_later)
_DEFERRED: dict[int, tuple] = {}


def compile_later(disp, sig):
    """Let dispatcher ``disp`` stand in a PiecewiseSystem uncompiled; a kernel's caller compiles
    it for ``sig`` when that kernel calls it (``kernel_jacobian``). Returns ``disp``."""
    _DEFERRED[id(disp)] = (disp, sig)
    return disp


def kernel_jacobian(system, used: bool = True) -> tuple:
    """The ``(jac, has_jac)`` arguments of a kernel call for ``system``. ``used=False`` (the lean
    kernel, which never calls the Jacobian) passes the placeholder, so a preset's Jacobian (~1.5 s
    of compile with the functions it calls) compiles only when a kernel that calls it runs."""
    if system.jacobian is None or not used:
        return no_jacobian, False
    return compile_for(system.jacobian, JAC_SIG), True


def _check_dispatcher(role: str, fn, sig) -> None:
    if fn is None:
        raise SystemDefinitionError(f"{role} is missing")
    deferred = _DEFERRED.get(id(fn))
    if deferred is not None and deferred[0] is fn and deferred[1] == sig:
        return
    sigs = getattr(fn, "signatures", None)
    if sigs is None:
        raise SystemDefinitionError(
            f"{role} = {fn!r} is not a numba function: decorate it with @numba.njit(hunting.{role.upper()}_SIG, cache=True, error_model='numpy')")
    if sig.args not in [tuple(s) for s in sigs]:
        raise SystemDefinitionError(
            f"{role} {getattr(fn, '__name__', fn)!r} was compiled for {sigs}, not for {sig}: "
            f"decorate it with an explicit signature, @numba.njit(hunting.system.<SIG>, cache=True, error_model='numpy')")


@dataclass(frozen=True)
class PiecewiseSystem:
    """A compiled piecewise-smooth system with its names.

    Parameters
    ----------
    name : str
        Short name used in messages and plots.
    state_names : sequence of str, length n
    modes : sequence of Mode, length n_modes
    guard_names : sequence of str, length n_guards (the same number of guards in every mode)
    param_names : sequence of str, length n_params (names of the leading entries of ``params``;
        ``params`` may carry a longer tail, e.g. a cogging table)
    params : float64 array (n_params_total,)
    vector_field, guards, transition, mode_of : numba dispatchers with VF_SIG, GUARD_SIG,
        RESET_SIG, MODE_SIG
    directions : int array (n_modes, n_guards), entries -1, 0 or +1 (default all -1: falling)
    jacobian : numba dispatcher with JAC_SIG, or None (finite differences are used)
    odd : bool
        True when f(-x) = -f(x) with the mirrored mode (see ``mirror_mode``); lets analyses
        exploit symmetry. Only set it when it is true.
    mirror_mode : int array (n_modes,), the mode of -x for a state in each mode (for odd systems)
    units : mapping name -> unit, for labels
    explain : Python callable ``(mode, t, x, p) -> str | None``, optional: names the model's
        expression that is not finite at a point (compiled models give one; ``simulate`` uses it
        when the vector field is not finite at the initial state)
    """

    name: str
    state_names: tuple
    modes: tuple
    guard_names: tuple
    param_names: tuple
    params: np.ndarray
    vector_field: object
    guards: object
    transition: object
    mode_of: object
    directions: np.ndarray | None = None
    jacobian: object | None = None
    odd: bool = False
    mirror_mode: np.ndarray | None = None
    units: Mapping[str, str] = field(default_factory=dict)
    explain: object | None = field(default=None, compare=False, repr=False)

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "state_names", tuple(self.state_names))
        set_(self, "modes", tuple(m if isinstance(m, Mode) else Mode(str(m)) for m in self.modes))
        set_(self, "guard_names", tuple(self.guard_names))
        set_(self, "param_names", tuple(self.param_names))
        if not self.state_names:
            raise SystemDefinitionError("state_names is empty: a system needs at least one state")
        if not self.modes:
            raise SystemDefinitionError("modes is empty: a system needs at least one mode")
        p = np.ascontiguousarray(self.params, dtype=np.float64)
        if p.ndim != 1:
            raise SystemDefinitionError(f"params has shape {p.shape}: it must be a flat array")
        if len(p) < len(self.param_names):
            raise SystemDefinitionError(
                f"params has {len(p)} entries but {len(self.param_names)} param_names")
        _require_finite(p, self.param_names)
        set_(self, "params", p)
        ng = max(1, len(self.guard_names))
        if self.directions is None:
            d = -np.ones((len(self.modes), ng), dtype=np.int64)
        else:
            d = np.ascontiguousarray(self.directions, dtype=np.int64)
        if d.shape != (len(self.modes), ng):
            raise SystemDefinitionError(
                f"directions has shape {d.shape}: it must be (n_modes, n_guards) = {(len(self.modes), ng)}")
        if not np.all(np.isin(d, (-1, 0, 1))):
            raise SystemDefinitionError("directions entries must be -1 (falling), 0 (either) or +1 (rising)")
        set_(self, "directions", d)
        if self.mirror_mode is not None:
            mm = np.asarray(self.mirror_mode, dtype=np.int64)
            if mm.shape != (len(self.modes),) or mm.min() < 0 or mm.max() >= len(self.modes):
                raise SystemDefinitionError(f"mirror_mode = {self.mirror_mode!r} must map each mode to a mode index")
            set_(self, "mirror_mode", mm)
        _check_dispatcher("vf", self.vector_field, VF_SIG)
        _check_dispatcher("guard", self.guards, GUARD_SIG)
        _check_dispatcher("reset", self.transition, RESET_SIG)
        _check_dispatcher("mode", self.mode_of, MODE_SIG)
        if self.jacobian is not None:
            _check_dispatcher("jac", self.jacobian, JAC_SIG)

    @property
    def n_states(self) -> int:
        return len(self.state_names)

    @property
    def n_modes(self) -> int:
        return len(self.modes)

    @property
    def n_guards(self) -> int:
        return max(1, len(self.guard_names))

    def mode_index(self, name: str) -> int:
        """Index of the mode called ``name``."""
        for i, m in enumerate(self.modes):
            if m.name == name:
                return i
        raise SystemDefinitionError(
            f"mode = {name!r} is not a mode of {self.name}: modes are {[m.name for m in self.modes]}")

    def modes_of_kind(self, kind: str) -> list[int]:
        return [i for i, m in enumerate(self.modes) if m.kind == kind]

    def param(self, name: str) -> float:
        """Value of a named parameter."""
        try:
            return float(self.params[self.param_names.index(name)])
        except ValueError:
            raise SystemDefinitionError(
                f"parameter {name!r} is not a parameter of {self.name}: parameters are {list(self.param_names)}") from None

    def with_params(self, values: Mapping[str, float] | None = None, /, **kw) -> "PiecewiseSystem":
        """Copy with named parameters replaced (the compiled functions are shared, nothing recompiles)."""
        new = np.array(self.params, dtype=np.float64)
        for k, v in {**(values or {}), **kw}.items():
            if k not in self.param_names:
                raise SystemDefinitionError(
                    f"parameter {k!r} is not a parameter of {self.name}: parameters are {list(self.param_names)}")
            new[self.param_names.index(k)] = float(v)
        return replace(self, params=new)

    def with_param_array(self, params: Sequence[float]) -> "PiecewiseSystem":
        """Copy with the whole flat parameter array replaced. Only the parameters are checked:
        the rest was validated when this system was built (continuation calls this at every
        flow, and re-validating the compiled functions cost ~0.1 ms each time)."""
        p = np.ascontiguousarray(params, dtype=np.float64)
        if p.shape != self.params.shape:
            raise SystemDefinitionError(f"params has shape {p.shape}: expected {self.params.shape}")
        _require_finite(p, self.param_names)
        new = copy.copy(self)
        object.__setattr__(new, "params", p)
        return new

    def evaluate(self, x, mode: int | None = None, t: float = 0.0) -> np.ndarray:
        """Vector field at one state (shape (n,)); mode from ``mode_of`` when not given."""
        x = self.check_state(x)
        if mode is None:
            mode = int(self.mode_of(float(t), x, self.params))
        out = np.empty(self.n_states)
        self.vector_field(int(mode), float(t), x, self.params, out)
        return out

    def guard_values(self, x, mode: int | None = None, t: float = 0.0) -> np.ndarray:
        x = self.check_state(x)
        if mode is None:
            mode = int(self.mode_of(float(t), x, self.params))
        out = np.empty(self.n_guards)
        self.guards(int(mode), float(t), x, self.params, out)
        return out

    def time_dependent_mode(self, states, modes=None, *, guards: bool = False, params=None) -> int | None:
        """The first mode whose vector field (and, with ``guards``, guard values) at one of
        ``states`` (each shape (n,)) differs between t = 0 and t = 1.2345 (rtol 1e-12), or None:
        a probe of time invariance. ``modes``: the mode indices to probe (default all);
        ``params``: the parameter array (default the system's)."""
        p = self.params if params is None else params
        checks = [(self.vector_field, self.n_states)] + ([(self.guards, self.n_guards)] if guards else [])
        for x in states:
            x = np.ascontiguousarray(x, dtype=float)
            for mode in (range(self.n_modes) if modes is None else modes):
                for fn, size in checks:
                    a, b = np.empty(size), np.empty(size)
                    fn(int(mode), 0.0, x, p, a)
                    fn(int(mode), 1.2345, x, p, b)
                    if not np.allclose(a, b, rtol=1e-12, atol=1e-300, equal_nan=True):
                        return int(mode)
        return None

    def initial_mode(self, x, t: float = 0.0) -> int:
        x = self.check_state(x)
        m = int(self.mode_of(float(t), x, self.params))
        if not 0 <= m < self.n_modes:
            raise SystemDefinitionError(f"mode_of returned {m} for x = {x}: not a mode index of {self.name}")
        return m

    def check_state(self, x, name: str = "x0") -> np.ndarray:
        """Return ``x`` as a contiguous float64 array of shape (n,), or raise naming the problem."""
        a = np.ascontiguousarray(np.asarray(x, dtype=np.float64).reshape(-1) if np.ndim(x) <= 1 else x,
                                 dtype=np.float64)
        if a.shape != (self.n_states,):
            raise SystemDefinitionError(
                f"{name} has shape {np.shape(x)}: {self.name} has {self.n_states} states {list(self.state_names)}")
        if not np.all(np.isfinite(a)):
            raise SystemDefinitionError(f"{name} = {a.tolist()} is not allowed: every entry must be finite")
        return a
