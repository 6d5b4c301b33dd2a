"""Stick-exit maps for any system with one sticking contact whose break-away states form a
one-parameter family: :class:`StickFamily`, which the event-map engine takes like a ServoLoop.

In a stick mode the contact's surface state holds w = 0. The event map needs the break-away
state as a function of one number, the stick error d. That holds when, in stick, exactly one
other state is frozen (it is d, like the position error of a servo) and exactly one evolves
(the drift, like the PID's integral): the break-away state at d is the drift value at which a
stick guard reaches zero while the stick flow pushes it through. The structure is read from
the compiled functions by probing (no symbolic form needed), so a PID servo written as
equations, or by hand, qualifies; a belt-driven block (its stick phases all end at one state),
a LuGre contact (no stick mode) or several contacts get a clear error.

d is measured from d0, the frozen value at which the drift stops (the stick phase never ends:
the equilibrium set), so d = 0 is the equilibrium set as for the thesis' loops.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import SystemDefinitionError
from ..integrate._batch import B_T_FIRST_EVENT, run_batch
from ..system import PiecewiseSystem

_N_PROBES = 6


# what to do when a system's stick states cannot be mapped in one dimension (also rewritten
# into command-line words by hunting.cli.advice)
NOT_A_FAMILY_ADVICE = ("a 1-D stick-exit map needs exactly one frozen state (the stick error) and one that drifts "
                       "(e.g. a PID servo's position error and integral). Use find_cycle instead")


def _call(fn, mode, x, p, size):
    out = np.empty(size)
    fn(int(mode), 0.0, np.ascontiguousarray(x, dtype=np.float64), p, out)
    return out


@dataclass(frozen=True)
class StickFamily:
    """A system's stick phases as a one-parameter family (what the event-map engine needs).

    Attributes
    ----------
    system : PiecewiseSystem
    name : str
    stick_mode : int
        The stick mode's index.
    surface_state, d_state, drift_state : int
        Indices of the state held on w = 0, the frozen one (d) and the drifting one.
    surface_value : float
        x[surface_state] on w = 0.
    d0 : float
        x[d_state] at which the drift stops (d = x[d_state] - d0).
    odd : bool
        The system's symmetry flag (P(-d) = -P(d) is used when True).

    Examples
    --------
    The chapter-9 loop written as a model description (``hunting.model("table9.1")``) or the
    hand-written preset both qualify:

    >>> from hunting import preset
    >>> from hunting.eventmap import stick_family
    >>> fam = stick_family(preset("table9.1").system)
    >>> fam.system.state_names[fam.d_state], fam.system.state_names[fam.drift_state], fam.d0
    ('x1', 'x3', 0.0)
    """

    system: PiecewiseSystem = field(repr=False)
    name: str
    stick_mode: int
    surface_state: int
    d_state: int
    drift_state: int
    surface_value: float = 0.0
    d0: float = 0.0
    odd: bool = False
    constant_drift: bool = True
    _scale: np.ndarray = field(default=None, repr=False)

    def require_stick_map(self) -> None:
        """Checked when the family was built (see :func:`stick_family`)."""

    def _base(self) -> np.ndarray:
        x = np.zeros(self.system.n_states)
        x[self.surface_state] = self.surface_value
        return x

    def _guards(self, x) -> np.ndarray:
        return _call(self.system.guards, self.stick_mode, x, self.system.params, self.system.n_guards)

    def _drift(self, x) -> float:
        return float(_call(self.system.vector_field, self.stick_mode, x, self.system.params,
                           self.system.n_states)[self.drift_state])

    def _breakaway(self, d: float):
        """(state, slip mode) at the end of the stick phase with error d; (state, stick) for the
        equilibrium set (no drift)."""
        sys_ = self.system
        x = self._base()
        x[self.d_state] = self.d0 + d
        if d == 0 or self._drift(x) == 0:
            return x, self.stick_mode
        e_scale = float(self._scale[self.drift_state])
        fire = sys_.directions[self.stick_mode]
        best = None
        for i in range(sys_.n_guards):
            # secant on g_i(e) from e = 0, e_scale (exact in one step for guards affine in e)
            a, b = 0.0, e_scale
            xa, xb = x.copy(), x.copy()
            xa[self.drift_state], xb[self.drift_state] = a, b
            ga, gb = self._guards(xa)[i], self._guards(xb)[i]
            tol = 1e-13 * (abs(ga) + abs(gb) + 1.0)
            for _ in range(60):
                if gb == ga:
                    break
                c = b - gb * (b - a) / (gb - ga)
                if not math.isfinite(c):
                    break
                xc = x.copy()
                xc[self.drift_state] = c
                gc = self._guards(xc)[i]
                a, ga, b, gb = b, gb, c, gc
                if abs(gc) <= tol or abs(b - a) <= 1e-15 * (abs(b) + e_scale):
                    break
            xr = x.copy()
            xr[self.drift_state] = b
            g = self._guards(xr)
            if not abs(g[i]) <= 1e4 * tol:
                continue
            # the stick flow must push g_i through zero in its firing direction, the other
            # guards must be inside (the state is a stick state just before)
            h = 1e-7 * e_scale
            xp, xm = xr.copy(), xr.copy()
            drift = self._drift(xr)
            xp[self.drift_state] += h * np.sign(drift)
            xm[self.drift_state] -= h * np.sign(drift)
            rate = (self._guards(xp)[i] - self._guards(xm)[i])
            ok_dir = (rate < 0) if fire[i] == -1 else ((rate > 0) if fire[i] == 1 else rate != 0)
            inside = all(g[j] * (-fire[j] if fire[j] else 1) >= -1e-9 * (abs(g[j]) + 1.0)
                         for j in range(sys_.n_guards) if j != i)
            if ok_dir and inside:
                best = (i, xr)
                break
        if best is None:
            raise SystemDefinitionError(f"{self.name}: no break-away state for the stick error d = {d!r}: no stick "
                                        f"guard reaches zero along {sys_.state_names[self.drift_state]} with the stick "
                                        f"flow pushing it through")
        i, xr = best
        out = np.empty(sys_.n_states)
        mode = int(sys_.transition(int(self.stick_mode), int(i), 0.0, xr, sys_.params, out))
        return xr, mode

    def force_scale(self) -> float:
        """The stick error whose stick force alone (drift state at 0) reaches a bound of the
        stick set: the smallest |d| > 0 at which a stick guard vanishes (for a PID servo
        Fs / kp, the scale of its event map); 1.0 when no guard vanishes along d.

        Examples
        --------
        >>> from hunting import preset
        >>> from hunting.eventmap import stick_family
        >>> round(stick_family(preset("table9.1").system).force_scale(), 12)
        0.4
        """
        sys_ = self.system
        best = math.inf
        for i in range(sys_.n_guards):
            def g(d, i=i):
                x = self._base()
                x[self.d_state] = self.d0 + d
                return self._guards(x)[i]
            for sign in (1.0, -1.0):
                a, b = 0.0, sign * float(self._scale[self.d_state])
                ga, gb = g(a), g(b)
                for _ in range(60):
                    if gb == ga or not math.isfinite(gb):
                        break
                    c = b - gb * (b - a) / (gb - ga)
                    a, ga, b, gb = b, gb, c, g(c)
                    if abs(gb) <= 1e-13 * (abs(ga) + 1.0) or abs(b - a) <= 1e-15 * (abs(b) + 1.0):
                        break
                if math.isfinite(b) and abs(g(b)) <= 1e-9 * (abs(g(0.0)) + 1.0) and b * sign > 0:
                    best = min(best, abs(b))
        return float(best) if math.isfinite(best) else 1.0

    def stick_error(self, X) -> np.ndarray:
        """d of states X (m, n): x[d_state] - d0."""
        return np.atleast_2d(X)[:, self.d_state] - self.d0

    def breakaway_state(self, d) -> tuple[np.ndarray, np.ndarray]:
        """States (m, n) at the end of the stick phases with errors d (m,), and the modes that
        follow (the stick mode for d = 0: the equilibrium set never breaks away)."""
        d = np.atleast_1d(np.asarray(d, dtype=float))
        X = np.empty((d.size, self.system.n_states))
        modes = np.empty(d.size, dtype=np.int64)
        for k, dk in enumerate(d):
            X[k], modes[k] = self._breakaway(float(dk))
        return X, modes

    def stick_duration(self, X_entry) -> np.ndarray:
        """Duration of the stick phases entered at X_entry (m, n), until break-away (inf at d = 0)."""
        X_entry = np.atleast_2d(np.asarray(X_entry, dtype=float))
        d = X_entry[:, self.d_state] - self.d0
        out = np.full(d.size, np.inf)
        run = d != 0
        if not np.any(run):
            return out
        if self.constant_drift:
            Xb, _ = self.breakaway_state(d[run])
            rates = np.array([self._drift(x) for x in Xb])
            out[run] = (Xb[:, self.drift_state] - X_entry[run, self.drift_state]) / rates
            return out
        Xs = X_entry[run].copy()
        _, _, st, _, fo = run_batch(self.system, Xs, self.stick_mode, t_max=1e12, atol=1e-13, rtol=1e-12,
                                    max_events=1, stop_mode=-1)
        out[run] = fo[:, B_T_FIRST_EVENT]
        return out


def _model_parts(obj):
    """(system, contacts or None) of a compiled model or a PiecewiseSystem."""
    sys_ = getattr(obj, "system", None)
    if isinstance(sys_, PiecewiseSystem) and not isinstance(obj, PiecewiseSystem):
        return sys_, getattr(obj, "contacts", None), obj
    if isinstance(obj, PiecewiseSystem):
        return obj, None, None
    raise SystemDefinitionError(f"system = {obj!r} is not allowed: give a ServoLoop, a compiled model "
                                f"(hunting.model(...)) or a PiecewiseSystem")


def stick_family(obj, *, d_state: str | None = None, seed: int = 0) -> StickFamily:
    """The stick phases of a system with one sticking contact as a :class:`StickFamily`.

    Parameters
    ----------
    obj : compiled model or PiecewiseSystem
    d_state : str, optional
        Name of the frozen state to use as d when several are frozen in stick.
    seed : int
        Seed of the random probe states.

    Raises
    ------
    SystemDefinitionError
        Naming what is missing: no stick mode or several contacts; a time-dependent system; stick
        states that are not a one-parameter family (which states evolve and which are frozen).
    """
    sys_, contacts, model = _model_parts(obj)
    name = sys_.name
    if contacts is not None:
        kinds = [getattr(c, "model", "?") for c in contacts]
        if len(contacts) != 1 or kinds[0] != "switch":
            raise SystemDefinitionError(f"{name}: a 1-D stick-exit map needs one Switch friction contact; this model "
                                        f"has {len(contacts)} contact(s) ({', '.join(kinds) or 'none'})")
        stick = list(contacts[0].stick_modes)
    else:
        stick = sys_.modes_of_kind("stick")
    if len(stick) != 1:
        raise SystemDefinitionError(f"{name}: a 1-D stick-exit map needs exactly one stick mode (a Switch friction "
                                    f"contact); modes are {[m.name + ' (' + m.kind + ')' for m in sys_.modes]}")
    sm = stick[0]
    surface = sys_.modes[sm].surface_state if contacts is None else int(contacts[0].surface_state)
    if not 0 <= surface < sys_.n_states:
        raise SystemDefinitionError(f"{name}: the stick mode {sys_.modes[sm].name!r} declares no surface state "
                                    f"(Mode(..., 'stick', surface_state))")
    n = sys_.n_states
    p = sys_.params
    rng = np.random.default_rng(seed)
    probes = rng.normal(size=(_N_PROBES, n))
    # surface value: w = 0 (a compiled model knows w; hand-written stick modes are taken at 0)
    surface_value = 0.0
    if model is not None and hasattr(model, "relative_velocity"):
        x = probes[0].copy()
        x[surface] = 0.0
        w0 = model.relative_velocity(x, 0.0, 0)
        x[surface] = 1.0
        w1 = model.relative_velocity(x, 0.0, 0)
        if w1 == w0:
            raise SystemDefinitionError(f"{name}: the relative velocity does not depend on the surface state")
        surface_value = -w0 / (w1 - w0)
    probes[:, surface] = surface_value
    F = np.array([_call(sys_.vector_field, sm, x, p, n) for x in probes])
    # time invariance: the same field and guards at another time
    if sys_.time_dependent_mode(probes[:2], [sm], guards=True, params=p) is not None:
        raise SystemDefinitionError(f"{name}: event maps need a time-invariant system (its stick mode "
                                    f"changes with t)")
    others = [i for i in range(n) if i != surface]
    frozen = [i for i in others if np.all(F[:, i] == 0.0)]
    moving = [i for i in others if i not in frozen]
    names = sys_.state_names
    if d_state is not None:
        if d_state not in names or names.index(d_state) not in frozen:
            raise SystemDefinitionError(f"d_state = {d_state!r} is not a state frozen in stick: frozen are "
                                        f"{[names[i] for i in frozen]}")
        frozen = [names.index(d_state)]
    if len(frozen) != 1 or len(moving) != 1:
        evolve, stay = [names[i] for i in moving], [names[i] for i in frozen]
        if not frozen and len(moving) <= 1:
            what = (f"every stick phase ends at the same state (only {evolve or 'no state'} drifts and nothing "
                    "stays frozen to tell the phases apart)")
        else:
            what = (f"in stick {len(evolve)} state(s) evolve ({', '.join(evolve) or 'none'}) and {len(stay)} stay "
                    f"frozen ({', '.join(stay) or 'none'})")
        raise SystemDefinitionError(f"{name}: the stick states are not a one-parameter family: {what}; "
                                    f"{NOT_A_FAMILY_ADVICE}")
    di, ei = frozen[0], moving[0]
    # d0: the frozen value at which the drift stops (the drift is probed at two values of d)
    x = probes[0].copy()
    x[di] = 0.0
    r0 = _call(sys_.vector_field, sm, x, p, n)[ei]
    x[di] = 1.0
    r1 = _call(sys_.vector_field, sm, x, p, n)[ei]
    if r1 == r0:
        raise SystemDefinitionError(f"{name}: the drift of {names[ei]} in stick does not depend on {names[di]}: "
                                    f"no stick error to map")
    d0 = -r0 / (r1 - r0) + 0.0          # + 0.0: no negative zero
    x[di] = d0 + 0.7
    x2 = x.copy()
    x2[ei] += 1.0
    constant = bool(_call(sys_.vector_field, sm, x, p, n)[ei] == _call(sys_.vector_field, sm, x2, p, n)[ei])
    scale = np.maximum(np.abs(probes).max(axis=0), 1.0)
    return StickFamily(sys_, name, sm, surface, di, ei, float(surface_value), float(d0), bool(sys_.odd and d0 == 0),
                       constant, scale)


def as_stick_map(obj):
    """What the event-map engine takes: a ServoLoop (or a StickFamily) as it is, a preset name as
    its loop, a compiled model or PiecewiseSystem as its :func:`stick_family`."""
    from ..models.loop import ServoLoop
    if isinstance(obj, (ServoLoop, StickFamily)):
        return obj
    if isinstance(obj, str):
        from ..models.presets import preset
        return preset(obj)
    return stick_family(obj)
