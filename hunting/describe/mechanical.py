"""Physical parameters read off a model description: one mechanical degree of freedom with one
friction contact, the motor constant, a Stribeck (or LuGre) friction law and a PID controller.

The description says ``m v' = cm u - F - b v - offset - F_cog(q)`` in whatever algebra the user wrote;
this module reads the numbers back from the description's own symbolic form (the parsed
expressions and the linear blocks, through sympy; no text is re-parsed or evaluated) and checks
each reading numerically. What cannot be read exactly is a :class:`~hunting.errors.SystemDefinitionError`
naming the key and what is allowed, never an approximation:

- the plant: the contact's velocity is a state ``v`` (no moving belt), one state ``q`` has
  ``q' = v``, and the equation of ``v`` is affine in the friction force ``F``, the drive ``u``
  and ``v`` with constant coefficients: ``m = -1 / (dv'/dF)``, ``cm = m dv'/du``, a viscous term
  ``b = -m dv'/dv`` (added to the friction law's), a constant rest (``offset = -m rest``) and
  sines and cosines of ``w q + phi`` (cogging ``F_cog(q)``, harmonics of the smallest ``w``);
- the friction law: a ``switch`` slip force equal, per direction, to ``Fc + (Fs - Fc)
  exp(-(|w|/vs)^beta) + b |w|`` (read off and compared on a dense velocity grid: relative error
  below :data:`LAW_TOLERANCE`) with a stick bound equal to ``Fs``; or ``lugre`` with constant
  sigma0 and sigma1, a Stribeck ``level`` and a linear ``viscous`` term;
- the controller: the drive ``u`` (a signal or block output, optionally limited as
  ``min(max(.., -S), S)``) is a linear time-invariant function
  of q, v and controller states whose transfer function from q is a PID ``-(kp + ki/s + kd s /
  (tau_f s + 1))`` (checked on a frequency grid to :data:`CONTROLLER_TOLERANCE`), the reference
  entering through one name (a parameter or a signal of t) either as the error ``q - r`` in every
  term (derivative on the error) or in the P and I terms only (derivative on the measurement).

Used by ``hunting diagnose --model DESCRIPTION`` (:func:`hunting.diagnose.model.nominal_from_description`);
nothing here knows about diagnosis.
"""
from __future__ import annotations

import ast
import math
from dataclasses import dataclass

import numpy as np

from ..errors import SystemDefinitionError
from ..models.friction import DirectionalCurve, StribeckCurve
from ..models.plant import Cogging
from .description import SLIP_VARIABLE, ContactSpec, Spec, validate
from .expressions import TIME, to_sympy

#: largest relative deviation of a friction law from the Stribeck form read off it
LAW_TOLERANCE = 1e-9
#: largest relative deviation of the controller's frequency response from the PID read off it
CONTROLLER_TOLERANCE = 1e-9
#: the drive's name when several signals enter the velocity equation (diagnose's data column)
DRIVE = "u"
_SPEEDS = np.geomspace(1e-9, 1e3, 2001)        # [velocity units] the grid laws are compared on
_FREQUENCIES = np.geomspace(1e-3, 1e5, 161)     # [rad/s] the grid controllers are compared on


@dataclass(frozen=True)
class PIDReading:
    """A PID controller read off a description: u = -(kp e + ki int e + kd D), e = q - r, where
    D = s/(tau_f s + 1) applied to e (derivative_on "error") or to q ("measurement").

    kp [u/m], ki [u/(m s)], kd [u s/m], tau_f [s] (0: no filter); reference : the name through
    which r enters (a parameter or a signal of t), or None when the description regulates q to 0
    (then the description does not say where the derivative acts and "error" is reported);
    saturation : the bound S of u = min(max(PID, -S), S) (inf: none)."""

    kp: float
    ki: float
    kd: float
    tau_f: float = 0.0
    derivative_on: str = "error"
    reference: str | None = None
    saturation: float = math.inf


@dataclass(frozen=True)
class MechanicalParameters:
    """One mechanical degree of freedom with one friction contact, read off a description.

    position, velocity : the state names of q and v = q'; mass [kg]; drive : the name of the
    signal, block output or parameter u that the motor constant multiplies; cm [N per unit of u];
    offset [N] : constant force in m v' = cm u - F(v) - offset; law : "switch" or "lugre"; curve :
    the friction's :class:`DirectionalCurve` (viscous terms of the equation included in its b);
    sigma0 [N/m], sigma1 [N s/m] : LuGre's (None for switch); controller : a :class:`PIDReading`
    when the drive is a signal, None when it is a parameter (an open loop); cogging : F_cog(q) as a
    harmonic :class:`Cogging` (m v' = cm u - F - offset - F_cog), or None."""

    position: str
    velocity: str
    mass: float
    drive: str
    cm: float
    offset: float
    law: str
    curve: DirectionalCurve
    sigma0: float | None = None
    sigma1: float | None = None
    controller: PIDReading | None = None
    cogging: Cogging | None = None


def mechanical_parameters(description, **overrides) -> MechanicalParameters:
    """Read the plant, friction law and controller off a model description.

    Parameters
    ----------
    description : dict or Spec
        A model description (the format of :func:`hunting.model`), or a checked :class:`Spec`.
    **overrides : float
        Parameter values replacing the description's defaults.

    Returns
    -------
    MechanicalParameters

    Raises
    ------
    SystemDefinitionError
        When a part has no exact reading in the form above: the message names the key
        (``friction.slip``, ``equations['v']``, ``signals['u']``, ...), says why and what is allowed.

    Examples
    --------
    >>> d = {"parameters": {"m": 2.0, "Fc": 1.0, "b": 0.5, "kp": 40.0, "kd": 9.0, "r": 0.0},
    ...      "states": ["q", "v"], "signals": {"u": "-kp*(q - r) - kd*v"},
    ...      "equations": {"q": "v", "v": "(u - F)/m"},
    ...      "friction": {"force": "F", "velocity": "v", "model": "switch",
    ...                   "slip": "sign(w)*Fc + b*w", "stick": "Fc"}}
    >>> p = mechanical_parameters(d)
    >>> p.mass, p.cm, p.curve.positive.Fc, p.curve.positive.b
    (2.0, 1.0, 1.0, 0.5)
    >>> p.controller.kp, p.controller.kd, p.controller.derivative_on, p.controller.reference
    (40.0, 9.0, 'measurement', 'r')
    """
    import sympy as sp

    spec = description if isinstance(description, Spec) else validate(description)
    unknown = sorted(set(overrides) - set(spec.parameters))
    if unknown:
        raise SystemDefinitionError(f"parameters {unknown} are not in the description (its parameters: "
                                    f"{list(spec.parameters)})")
    values = {**spec.parameters, **{k: float(v) for k, v in overrides.items()}}
    return _Reader(spec, values, sp).read()


class _Reader:
    """The steps of :func:`mechanical_parameters` over one checked description."""

    def __init__(self, spec: Spec, values: dict, sp):
        self.spec, self.values, self.sp = spec, values, sp
        self.t = sp.Symbol(TIME, real=True)
        self.psym = {k: sp.Symbol(k, real=True) for k in spec.parameters}
        self.pval = {self.psym[k]: sp.Float(v) for k, v in values.items()}
        self.xsym = {s: sp.Symbol(s, real=True) for s in spec.states}
        for c in spec.contacts:
            if c.model == "lugre":
                self.xsym[c.state] = sp.Symbol(c.state, real=True)
        self.fsym = {c.force: sp.Symbol(c.force, real=True) for c in spec.contacts}
        # linear blocks as states (the compiler's controllable canonical form)
        from .symbolic import _realize
        self.blocks = {}
        for b in spec.blocks:
            a, c, D, _ = _realize(b, self.psym)
            names = [f"{b.output}_{i + 1}" for i in range(len(a))]
            for n in names:
                self.xsym[n] = sp.Symbol(n, real=True)
            self.blocks[b.output] = (b, a, c, D, names)
        self.keep: set = set()          # names kept as symbols while resolving

    # ------------------------------------------------------------------ expressions
    def symbol(self, name):
        return self.sp.Symbol(name, real=True)

    def resolve(self, name, stack=()):
        """The expression of a signal or block output in states, parameters, forces and t."""
        if name in self.keep:
            return self.symbol(name)
        if name in stack:                       # validate() and the compiler catch loops first
            raise SystemDefinitionError(f"signals form a cycle through {name!r}")
        if name in self.spec.signals:
            return self.expr(self.spec.signals[name], stack + (name,))
        b, a, c, D, names = self.blocks[name]
        y = sum((ci * self.xsym[n] for ci, n in zip(c, names)), self.sp.Integer(0))
        if D != 0:
            y = y + D * self.expr(b.input, stack + (name,))
        return y

    def expr(self, e, stack=()):
        env = {}
        for n in e.names:
            if n in self.keep:
                env[n] = self.symbol(n)
            elif n in self.psym:
                env[n] = self.psym[n]
            elif n in self.xsym:
                env[n] = self.xsym[n]
            elif n in self.fsym:
                env[n] = self.fsym[n]
            elif n == TIME:
                env[n] = self.t
            elif n in self.spec.signals or n in self.blocks:
                env[n] = self.resolve(n, stack)
        return to_sympy(e, env)

    def rates(self) -> dict:
        """Every state's right-hand side (bristle states excluded), signals resolved."""
        out = {s: self.expr(self.spec.equations[s]) for s in self.spec.states}
        for b, a, _, _, names in self.blocks.values():
            for i in range(len(names) - 1):
                out[names[i]] = self.xsym[names[i + 1]]
            if names:
                out[names[-1]] = self.expr(b.input) - sum((ai * self.xsym[n] for ai, n in zip(a, names)),
                                                          self.sp.Integer(0))
        return out

    def number(self, e) -> float:
        return float(self.sp.sympify(e).subs(self.pval))

    def exact(self, e) -> float:
        """The value of a constant expression computed at 50 digits (m from -1/(-1/m) is m)."""
        return float(self.sp.sympify(e).evalf(50, subs=self.pval))

    def is_constant(self, e) -> bool:
        return not (self.sp.sympify(e).free_symbols - set(self.psym.values()))

    # ------------------------------------------------------------------ steps
    def read(self) -> MechanicalParameters:
        spec = self.spec
        if len(spec.contacts) != 1:
            raise SystemDefinitionError(
                f"friction has {len(spec.contacts)} contacts: a diagnosable model has exactly one friction contact "
                "on one mechanical degree of freedom")
        c = spec.contacts[0]
        tree = c.velocity.tree
        if not (isinstance(tree, ast.Name) and tree.id in spec.states):
            raise SystemDefinitionError(
                f"friction[{c.name!r}].velocity = {c.velocity.text!r} is not a velocity state: the friction must act "
                "on the measured velocity q' itself (allowed: the name of the state v with q' = v; no moving belt "
                "or drive speed)")
        v = tree.id
        rates = self.rates()
        vs = self.xsym[v]
        qs = [s for s in spec.states if s != v and self.sp.simplify(rates[s] - vs) == 0]
        if len(qs) != 1:
            raise SystemDefinitionError(
                f"equations: {'no state has' if not qs else f'the states {qs} all have'} the equation d/dt = {v}: a "
                f"diagnosable model has one position state q with q' = {v} (the contact's velocity)")
        q = qs[0]
        for s, e in rates.items():
            if s not in (v, q) and e.has(self.fsym[c.force]):
                raise SystemDefinitionError(
                    f"equations[{s!r}] uses the friction force {c.force!r}: a diagnosable model has one mechanical "
                    f"degree of freedom (q, {v}); a second mass or a flexible load has no reading")
        drive = self.drive(v)
        mass, cm, b_extra, offset, cog = self.plant(q, v, c, drive)
        law, curve, s0, s1 = self.friction(c, b_extra)
        ctrl = None
        if drive not in spec.parameters:
            ctrl = self.controller(drive, q, v, c)
        return MechanicalParameters(q, v, mass, drive, cm, offset, law, curve, s0, s1, ctrl, cog)

    def drive(self, v) -> str | None:
        """The name the motor constant multiplies: 'u' when a signal, block output or parameter
        of that name enters the velocity equation, else its only signal or block output."""
        spec = self.spec
        eq = spec.equations[v]
        outputs = set(spec.signals) | set(self.blocks)
        if DRIVE in outputs | set(spec.parameters):
            self.keep = {DRIVE}
            if self.expr(eq).has(self.symbol(DRIVE)):
                self.keep = set()
                return DRIVE
            self.keep = set()
        direct = sorted(eq.names & outputs)
        if len(direct) == 1:
            return direct[0]
        if len(direct) > 1:
            raise SystemDefinitionError(
                f"equations[{v!r}] = {eq.text!r} uses the signals {direct}: call the controller output that drives "
                f"the plant {DRIVE!r} (the data's u column)")
        return None

    def plant(self, q, v, c: ContactSpec, drive):
        sp = self.sp
        self.keep = {drive} if drive is not None else set()
        e = self.expr(self.spec.equations[v])
        self.keep = set()
        F, V = self.fsym[c.force], self.xsym[v]
        U = self.symbol(drive) if drive is not None else sp.Symbol("_no_drive")
        if drive in self.psym:
            e = e.subs(self.psym[drive], U)
        where = f"equations[{v!r}] = {self.spec.equations[v].text!r}"
        coef, dsym = {}, {}
        for name, sym in ((c.force, F), (drive or "u", U), (v, V)):
            d = sp.diff(e, sym)
            if not self.is_constant(d):
                raise SystemDefinitionError(
                    f"{where} is not affine in {name!r} with a constant coefficient (its coefficient uses "
                    f"{sorted(map(str, d.free_symbols - set(self.psym.values())))}): allowed m {v}' = cm u - "
                    f"{c.force} - b {v} - offset with constant m, cm, b, offset")
            coef[name], dsym[name] = self.number(d), d
        rest = sp.expand(e - sp.diff(e, F) * F - sp.diff(e, U) * U - sp.diff(e, V) * V)
        aF = coef[c.force]
        if not aF < 0:
            raise SystemDefinitionError(
                f"{where}: d{v}'/d{c.force} = {aF:g} must be negative (the friction force opposes the motion: "
                f"m {v}' = ... - {c.force})")
        harmonic, rest = self.cogging(rest, q, where, -1 / dsym[c.force])
        if not self.is_constant(rest):
            used = sorted(map(str, rest.free_symbols - set(self.psym.values())))
            raise SystemDefinitionError(
                f"{where} has a term in {used} beside the drive, the friction force and {v}: allowed m {v}' = cm u - "
                f"{c.force} - b {v} - offset - F_cog({q}), F_cog a sum of sin and cos of 2 pi k {q} / pitch + phase "
                "(time-dependent, state-feedback and other position-dependent forces have no reading: write a "
                "controller as the signal u)")
        mass = self.exact(-1 / dsym[c.force])
        if drive is None:
            raise SystemDefinitionError(
                f"{where} has no drive: the controller output u (the data's u column) must enter it, as a signal, "
                "block output or parameter named 'u'")
        cm = self.exact(-dsym[drive] / dsym[c.force])
        if not cm > 0:
            raise SystemDefinitionError(
                f"{where}: the motor constant (m d{v}'/d{drive}) is {cm:g}; it must be > 0 (flip the sign of "
                f"{drive!r} and of its controller)")
        cog = None if harmonic is None else Cogging.harmonic(*harmonic)
        return mass, cm, self.exact(dsym[v] / dsym[c.force]) + 0.0, self.exact(rest / dsym[c.force]) + 0.0, cog

    def cogging(self, rest, q, where, mass):
        """(harmonic, constant): the force -mass * (the part of ``rest``, a sympy expression, that
        is a sum of c sin(w q + phi) and c cos(w q + phi) with constant c, w, phi) as (pitch, cos,
        sin) coefficients [N] of the harmonics k = 1, 2, .. of the smallest w (None when there is
        none), and what is left of ``rest``. ``mass`` is a sympy expression (the coefficients are
        computed at 50 digits); the harmonics are checked against ``rest`` on a grid of q."""
        sp = self.sp
        Q = self.xsym[q]
        atoms = [a for a in rest.atoms(sp.sin, sp.cos) if a.has(Q)]
        if not atoms:
            return None, rest
        terms = []                                      # (omega, phase, coefficient, is_sin)
        A = [sp.Dummy() for _ in atoms]
        lin = rest.xreplace(dict(zip(atoms, A)))
        for atom, a in zip(atoms, A):
            arg = atom.args[0]
            w, coef = sp.diff(arg, Q), sp.diff(lin, a)
            if not (self.is_constant(w) and self.is_constant(coef) and not (arg - w * Q).has(Q)):
                return None, rest                       # not a harmonic: the caller names the term
            terms.append((self.number(w), self.number(arg - w * Q), self.exact(-mass * coef), atom.func == sp.sin, w))
        left = lin.xreplace({a: 0 for a in A})
        if left.has(Q):
            return None, rest
        w0 = min(abs(t[0]) for t in terms)
        n = 0
        for w, *_ in terms:
            k = abs(w) / w0
            if abs(k - round(k)) > 1e-9 or round(k) > 64:
                raise SystemDefinitionError(
                    f"{where}: the position-dependent force has frequencies {sorted({abs(t[0]) for t in terms})} "
                    f"rad per unit of {q}, not harmonics of one pitch (allowed: F_cog a sum of sin and cos of 2 pi k "
                    f"{q} / pitch + phase, k = 1, 2, ..)")
            n = max(n, round(k))
        cos, sin = [0.0] * n, [0.0] * n
        for w, phi, c, is_sin, _ in terms:
            k, sg = round(abs(w) / w0) - 1, (1.0 if w > 0 else -1.0)
            if is_sin:      # c sin(w q + phi) = c cos(phi) sin(w q) + c sin(phi) cos(w q)
                sin[k] += c * math.cos(phi) * sg
                cos[k] += c * math.sin(phi)
            else:           # c cos(w q + phi) = c cos(phi) cos(w q) - c sin(phi) sin(w q)
                cos[k] += c * math.cos(phi)
                sin[k] -= c * math.sin(phi) * sg
        pitch = self.exact(2 * sp.pi / sp.Abs(min(terms, key=lambda t: abs(t[0]))[4]))
        qs = np.linspace(-2 * pitch, 2 * pitch, 4001)
        f = sp.lambdify(Q, (-mass * (rest - left)).subs(self.pval), "numpy")
        got = np.asarray(f(qs), dtype=float) * np.ones_like(qs)
        mine = Cogging.harmonic(pitch, cos, sin)(qs)
        scale = max(float(np.max(np.abs(got))), 1e-300)
        if float(np.max(np.abs(got - mine))) > 1e-9 * scale:
            raise SystemDefinitionError(f"{where}: the position-dependent force is not read exactly as harmonics "
                                        f"(deviation {np.max(np.abs(got - mine)) / scale:.3g} of its size)")
        return (pitch, cos, sin), left

    # ------------------------------------------------------------------ friction
    def law(self, e, c: ContactSpec):
        """A law of the contact as a sympy expression of w and the parameters (symbols)."""
        env = {n: self.psym[n] for n in e.names if n in self.psym}
        env[SLIP_VARIABLE] = self.sp.Symbol(SLIP_VARIABLE, real=True)
        extra = sorted(e.names - set(env) - {"pi"})
        if extra:
            raise SystemDefinitionError(
                f"friction[{c.name!r}]: {e.text!r} uses {extra}: a diagnosable friction law uses only w and "
                "parameters")
        return to_sympy(e, env)

    def directional(self, expr, s: int, odd: bool = True):
        """(e, x): the law at w = s x as a sympy expression of the speed x = |w| > 0, times s when
        it is odd (a force; a LuGre level g(w) is a magnitude)."""
        from .symbolic import directional
        w = self.sp.Symbol(SLIP_VARIABLE, real=True)
        x = self.sp.Symbol("x", positive=True)
        return (s if odd else 1) * directional(expr, w, s, s * x), x

    def friction(self, c: ContactSpec, b_extra: float):
        sides = ((1, "positive"), (-1, "negative"))
        if c.model == "switch":
            slip = self.law(c.slip, c)
            curves = {}
            for k, (s, side) in zip((1, 0), sides):
                stick = self.number(self.expr(c.stick[k]))
                curves[s] = _stribeck(*self.directional(slip, s), self.pval, f"friction[{c.name!r}].slip", side, stick,
                                      f"friction[{c.name!r}].stick" + ("" if c.stick[0] is c.stick[1] else f"[{k}]"))
            law, s0, s1 = "switch", None, None
        else:
            level, visc = self.law(c.level, c), self.law(c.viscous, c)
            curves = {}
            for s, side in sides:
                g = _stribeck(*self.directional(level, s, odd=False), self.pval, f"friction[{c.name!r}].level", side, None, None)
                e, x = self.directional(visc, s)
                bv = _viscous(e.subs(self.pval), x, f"friction[{c.name!r}].viscous", side)
                curves[s] = StribeckCurve(g.Fc, g.Fs, g.vs, g.beta, bv)
            s0, s1 = (self.constant_law(c, k) for k in ("sigma0", "sigma1"))
            law = "lugre"
        pos, neg = (StribeckCurve(cv.Fc, cv.Fs, cv.vs, cv.beta, cv.b + b_extra) for cv in (curves[1], curves[-1]))
        return law, DirectionalCurve(pos, neg if neg != pos else pos), s0, s1

    def constant_law(self, c, key) -> float:
        e = getattr(c, key)
        val = self.law(e, c).subs(self.pval)
        if val.free_symbols:
            raise SystemDefinitionError(f"friction[{c.name!r}].{key} = {e.text!r} depends on w: a diagnosable LuGre "
                                        f"contact has a constant {key} (a parameter)")
        return float(val)

    # ------------------------------------------------------------------ controller
    def controller(self, drive, q, v, c: ContactSpec) -> PIDReading:
        sp = self.sp
        spec = self.spec
        where = f"{'signals' if drive in spec.signals else 'blocks'}[{drive!r}]"
        # signals of t and parameters only stay names: candidates for the reference
        self.keep, self.time_signals = set(), {}
        for k in spec.signals:
            e = self.resolve(k)
            if e.has(self.t) and not (e.free_symbols - {self.t} - set(self.psym.values())):
                self.keep.add(k)
                self.time_signals[k] = e
        u, saturation = self.saturation(self.resolve(drive), where)
        rates = self.rates()
        self.keep = set()
        cstates = [s for s in list(spec.states) + [n for *_, names in self.blocks.values() for n in names]
                   if s not in (q, v)]
        friction = [(c.force, self.fsym[c.force])] + ([(c.state, self.xsym[c.state])] if c.state else [])
        for s, e in [(drive, u)] + [(s, rates[s]) for s in cstates]:
            bad = [n for n, sym in friction if e.has(sym)]
            if bad:
                what = "the controller output" if s == drive else f"the controller state {s!r}"
                raise SystemDefinitionError(f"{where}: {what} uses {bad}: a diagnosable controller is a PID of the "
                                            "measured position (no friction compensation or observer)")
        X = [self.xsym[q], self.xsym[v]] + [self.xsym[s] for s in cstates]
        rows = [u] + [rates[s] for s in cstates]
        J = sp.Matrix(rows).jacobian(sp.Matrix(X))
        for i in range(len(rows)):
            for j in range(len(X)):
                if not self.is_constant(J[i, j]):
                    raise SystemDefinitionError(
                        f"{where}: the controller is not linear in {X[j]} with a constant gain "
                        f"({'its output' if i == 0 else 'the rate of ' + cstates[i - 1]} has d/d{X[j]} = {J[i, j]}): "
                        "allowed a PID u = -(kp e + ki int e + kd de/dt), e = q - r, as signals or transfer-function "
                        "blocks (saturation, deadzone and gain scheduling have no reading)")
        Jn = np.array([[self.number(J[i, j]) for j in range(len(X))] for i in range(len(rows))], dtype=float)
        exo = [sp.expand(r - sum((J[i, j] * X[j] for j in range(len(X))), sp.Integer(0))) for i, r in enumerate(rows)]
        lin = _Linear(Jn[1:, 2:], Jn[1:, 0], Jn[1:, 1], Jn[0, 2:], Jn[0, 0], Jn[0, 1])
        s_grid = 1j * _FREQUENCIES
        h = lin.from_q(s_grid)
        gains, fit, dev = _fit_pid(h, s_grid, lin.poles())
        if dev > CONTROLLER_TOLERANCE:
            err = np.abs(h - fit) / np.maximum(np.abs(h), 1e-300)
            k = int(np.argmax(err))
            raise SystemDefinitionError(
                f"{where}: the controller from q to {drive!r} is not a PID -(kp + ki/s + kd s/(tau_f s + 1)) (largest "
                f"relative deviation {err[k]:.3g} at {_FREQUENCIES[k]:.3g} rad/s; "
                f"{'controller states ' + str(cstates) if cstates else 'no controller state'}): allowed P, I and "
                "D terms with one first-order derivative filter at most; lead-lag, low-pass and delay blocks have "
                "no reading")
        gains = _polish(J.subs(self.pval).evalf(50), gains)
        ref, on = self.reference(exo, where, lin, s_grid, h, gains)
        return PIDReading(*gains, on, ref, saturation)

    def saturation(self, u, where):
        """(inner, bound): u = min(max(inner, -S), S) (either nesting) gives (inner, S) with S a
        constant > 0; any other u gives (u, inf)."""
        sp = self.sp
        for outer, inner_f, sign in ((sp.Min, sp.Max, 1), (sp.Max, sp.Min, -1)):
            if u.func is outer and len(u.args) == 2:
                const = [a for a in u.args if self.is_constant(a)]
                nested = [a for a in u.args if a.func is inner_f and len(a.args) == 2]
                if len(const) == 1 and len(nested) == 1:
                    lo = [a for a in nested[0].args if self.is_constant(a)]
                    rest = [a for a in nested[0].args if not self.is_constant(a)]
                    if len(lo) == 1 and len(rest) == 1:
                        hi_v, lo_v = sign * self.exact(const[0]), -sign * self.exact(lo[0])
                        if not (hi_v > 0 and hi_v == lo_v):
                            raise SystemDefinitionError(
                                f"{where}: the controller output is limited to [{-lo_v:g}, {hi_v:g}]: allowed a "
                                "symmetric saturation min(max(u, -S), S) with S > 0")
                        return rest[0], hi_v
        return u, math.inf

    def reference(self, exo, where, lin, s_grid, h, gains):
        """(name, derivative_on) of the reference: the terms without states must be linear in one
        name r whose transfer r -> u is that of the error (-H) or of the P and I terms only."""
        sp = self.sp
        if all(sp.simplify(e) == 0 for e in exo):
            return None, "error"
        kp, ki, kd, _ = gains
        names = set().union(*(e.free_symbols for e in exo)) - {self.t}
        scale = np.maximum(np.abs(h), 1e-300)
        found = []
        for r in sorted(str(n) for n in names):
            R = self.psym.get(r, self.symbol(r))
            coef = [sp.diff(e, R) for e in exo]
            if not all(self.is_constant(k) and not k.has(R) for k in coef):
                continue
            # a signal r(t) may also enter through its derivative r'(t) (written out, e.g. kd*(v - r'))
            dr = sp.diff(self.time_signals[r], self.t) if r in self.time_signals else sp.Integer(0)
            rest = [sp.simplify((e - k * R).subs(self.pval)) for e, k in zip(exo, coef)]
            kd_r = [sp.simplify(x / dr) if dr != 0 else sp.Integer(0) for x in rest]
            if any(x != 0 and (dr == 0 or not self.is_constant(y) or y.has(self.t)) for x, y in zip(rest, kd_r)):
                continue
            k = np.array([self.number(k) for k in coef])
            k1 = np.array([self.number(y) for y in kd_r])
            g = lin.from_input(s_grid, k[1:] + 0j, k[0]) + s_grid * lin.from_input(s_grid, k1[1:] + 0j, k1[0])
            if np.max(np.abs(g + h) / scale) < CONTROLLER_TOLERANCE:
                found.append((r, "error"))
            elif np.max(np.abs(g - (kp + ki / s_grid)) / scale) < CONTROLLER_TOLERANCE:
                found.append((r, "measurement" if kd else "error"))
        if len(found) != 1:
            texts = sorted({str(e) for e in exo if e != 0})
            raise SystemDefinitionError(
                f"{where}: the terms without states, {texts}, are not one reference r entering as the error q - r"
                f"{f' (candidates {[f[0] for f in found]})' if len(found) > 1 else ''}: allowed u = -(kp (q - r) + "
                "ki int (q - r) + kd D) with D the derivative of q - r or of q and r one parameter or a signal of t "
                "(no feedforward or constant force in u)")
        return found[0]


def _polish(J, gains) -> tuple:
    """The gains (kp, ki, kd, tau_f) of a verified PID fit solved again at 50 digits from the
    controller's Jacobian J (sympy, rows u then controller-state rates; columns q, v, controller
    states), so that each rounds to the double the description's arithmetic gives."""
    import mpmath
    with mpmath.workdps(50):
        M = mpmath.matrix([[mpmath.mpf(str(J[i, j])) for j in range(J.cols)] for i in range(J.rows)])
        n = J.rows - 1
        A = M[1:, 2:] if n else None
        tau = mpmath.mpf(0)
        if gains[3]:
            lam = [e for e in mpmath.eig(A)[0]]
            lam = min(lam, key=lambda e: abs(e + 1 / mpmath.mpf(gains[3])))
            tau = -1 / mpmath.re(lam)

        def H(s):
            y = M[0, 0] + M[0, 1] * s
            if n:
                b = mpmath.matrix([M[1 + i, 0] + M[1 + i, 1] * s for i in range(n)])
                y += (M[0, 2:] * mpmath.lu_solve(s * mpmath.eye(n) - A, b))[0]
            return y
        cols = [k for k in range(3) if gains[k]]
        rows, rhs = [], []
        for w in (mpmath.mpf("0.7"), mpmath.mpf("3.1")):
            s = mpmath.mpc(0, w)
            basis = (1, 1 / s, s / (tau * s + 1))
            h = -H(s)
            for part in (mpmath.re, mpmath.im):
                rows.append([part(basis[k]) for k in cols])
                rhs.append(part(h))
        out = [0.0, 0.0, 0.0]
        if cols:
            R, y = mpmath.matrix(rows), mpmath.matrix(rhs)
            sol = mpmath.lu_solve(R.T * R, R.T * y)          # normal equations: exact data, 50 digits
            for k, v in zip(cols, sol):
                out[k] = float(v)
        return (*out, float(tau) if gains[2] else 0.0)


@dataclass(frozen=True)
class _Linear:
    """A linear controller x' = A x + Bq q + Bv v, u = C x + Dq q + Dv v (arrays), whose transfer
    functions from q (with v = s q) and from an input entering the rates through E and the
    output through F are evaluated on a grid of s."""

    A: np.ndarray
    Bq: np.ndarray
    Bv: np.ndarray
    C: np.ndarray
    Dq: float
    Dv: float

    def poles(self) -> np.ndarray:
        return np.linalg.eigvals(self.A) if self.A.size else np.zeros(0)

    def _through(self, s, b) -> complex:
        n = len(self.C)
        return self.C @ np.linalg.solve(s * np.eye(n) - self.A, b) if n else 0.0

    def from_q(self, s_grid) -> np.ndarray:
        """u per q at each s (v = s q)."""
        return np.array([self._through(s, self.Bq + self.Bv * s) + self.Dq + self.Dv * s for s in s_grid])

    def from_input(self, s_grid, E, F) -> np.ndarray:
        """u per r at each s for the input vectors E (states) and F (output)."""
        return np.array([self._through(s, E) + F for s in s_grid])


# ---------------------------------------------------------------------- readings
def _limit(e, x, point) -> float | None:
    """A finite limit of the sympy expression e(x) as x -> point (None when sympy finds none)."""
    import sympy as sp
    try:
        v = sp.limit(e, x, point, "+") if point == 0 else sp.limit(e, x, point)
    except (NotImplementedError, ValueError, TypeError, sp.PoleError):
        return None
    return float(v) if v.is_number and v.is_finite and v.is_real else None


def _stribeck(e_sym, x, values, where, side, stick, stick_where) -> StribeckCurve:
    """The StribeckCurve whose level plus viscous term is e(x) (a sympy expression of the speed
    x = |w| > 0 in one direction and the parameters, whose ``values`` are {symbol: Float}), read
    off its limits and checked on a dense speed grid; stick : the stick bound that must equal Fs
    (None: not checked). vs is solved at 50 digits so that it rounds to the value written."""
    import sympy as sp
    e = e_sym.subs(values)
    h = sp.lambdify(x, e, "numpy")
    xs = _SPEEDS
    with np.errstate(all="ignore"):
        y = np.asarray(h(xs), dtype=float) * np.ones_like(xs)
    if not np.all(np.isfinite(y)):
        bad = xs[~np.isfinite(y)][0]
        raise SystemDefinitionError(f"{where}: the {side}-direction force is not finite at |w| = {bad:.3g}")
    b = _limit(e / x, x, sp.oo)
    Fc = None if b is None else _limit(e - b * x, x, sp.oo)
    Fs = _limit(e, x, 0)
    if b is None or Fc is None or Fs is None:
        raise SystemDefinitionError(
            f"{where}: the {side}-direction force has no finite Coulomb level (limit of F - b |w| for |w| -> oo) or "
            "break-away level (limit for w -> 0): allowed Fc + (Fs - Fc) exp(-(|w|/vs)^beta) + b |w|")
    vs, beta = 1.0, 2.0
    drop = Fs - Fc
    stribeck = abs(drop) > 1e-12 * max(abs(Fs), abs(Fc), 1e-300)
    if stribeck:
        with np.errstate(all="ignore"):
            d = (y - b * xs - Fc) / drop                # exp(-(x/vs)^beta) if of the Stribeck form
        ok = (d > 0.05) & (d < 0.95)
        if ok.sum() >= 2:
            # two speeds where the dip is well conditioned, the law evaluated there at 50 digits:
            # beta = log(L_a / L_b) / log(x_a / x_b), vs = x_a / L_a^(1/beta), L = -log(d)
            i = np.flatnonzero(ok)
            ka, kb = i[np.argmin(np.abs(d[i] - 0.7))], i[np.argmin(np.abs(d[i] - 0.3))]
            L = []
            for k in (ka, kb):
                xk = sp.Float(float(xs[k]), 50)             # the double's exact value, 50 digits
                dk = (e_sym.subs(x, xk).evalf(50, subs=values) - sp.Float(b, 50) * xk - sp.Float(Fc, 50)) / \
                    (sp.Float(Fs, 50) - sp.Float(Fc, 50))
                L.append(-sp.log(dk))
            if ka != kb:
                xa, xb = sp.Float(float(xs[ka]), 50), sp.Float(float(xs[kb]), 50)
                beta_hp = (sp.log(L[0] / L[1]) / sp.log(xa / xb)).evalf(50)
                beta = float(beta_hp)
                vs = float((xa / L[0] ** (1 / beta_hp)).evalf(50))
    fit = Fc + (Fs - Fc) * np.exp(-(xs / vs) ** beta) + b * xs
    err = np.abs(fit - y) / np.maximum(np.abs(y), 1e-300)
    k = int(np.argmax(err))
    if err[k] > LAW_TOLERANCE:
        raise SystemDefinitionError(
            f"{where}: the {side}-direction force is not of the Stribeck form Fc + (Fs - Fc) exp(-(|w|/vs)^beta) "
            f"+ b |w| (largest relative deviation {err[k]:.3g} at |w| = {xs[k]:.3g} from Fc = {Fc:.6g}, Fs = "
            f"{Fs:.6g}, vs = {vs:.6g}, beta = {beta:.6g}, b = {b:.6g}); rational and other laws have no reading")
    if stick is not None and abs(stick - Fs) > LAW_TOLERANCE * max(abs(Fs), 1e-300):
        raise SystemDefinitionError(
            f"{stick_where}: the {side}-direction stick bound is {stick:.6g}, not the slip force at w -> 0 "
            f"(Fs = {Fs:.6g}): allowed a stick bound equal to the break-away level of the slip law")
    if Fc < 0 or Fs < Fc:
        raise SystemDefinitionError(
            f"{where}: the {side}-direction levels Fc = {Fc:.6g}, Fs = {Fs:.6g} are not allowed (0 <= Fc <= Fs)")
    return StribeckCurve(Fc, Fs, vs, beta, b) if stribeck else StribeckCurve(Fc, Fc, 1.0, 2.0, b)


def _viscous(e, x, where, side) -> float:
    """b of a viscous term e(x) = b x (one direction: a sympy expression of the speed x > 0)."""
    import sympy as sp
    slope = sp.diff(e, x)
    if slope.free_symbols or sp.simplify(e - slope * x) != 0:
        raise SystemDefinitionError(f"{where}: the {side}-direction viscous force {e} (x = |w|) is not b |w| with "
                                    "a constant b: allowed a linear viscous term such as b*w")
    return float(slope)


def _fit_pid(h, s, poles):
    """((kp, ki, kd, tau_f), fit, deviation): the PID -(kp + ki/s + kd s/(tau_f s + 1)) closest to
    the response h at the points s (least squares, relative), with tau_f = 0 or -1/p for a real
    negative controller pole p; fit : its response; deviation : the largest relative difference."""
    taus = [0.0] + [-1.0 / p.real for p in poles if abs(p.imag) <= 1e-12 * abs(p) and p.real < 0]
    scale = np.maximum(np.abs(h), 1e-300)
    best = None
    for tau in taus:
        M = np.column_stack([np.ones_like(s), 1.0 / s, s / (tau * s + 1.0)]) / scale[:, None]
        y = -h / scale
        g, *_ = np.linalg.lstsq(np.vstack([M.real, M.imag]), np.concatenate([y.real, y.imag]), rcond=None)
        g = np.where(np.abs(M * g[None, :]).max(axis=0) < 1e-12, 0.0, g)    # a term below rounding is none
        fit = -(g[0] + g[1] / s + g[2] * s / (tau * s + 1.0))
        dev = float(np.max(np.abs(fit - h) / scale))
        gains = (float(g[0]), float(g[1]), float(g[2]), float(tau) if g[2] else 0.0)
        if best is None or dev < best[2]:
            best = (gains, fit, dev)
    return best
