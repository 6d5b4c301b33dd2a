"""From a checked description to the symbolic hybrid system (sympy).

Steps: linear blocks become states (controllable canonical form; a delay its Pade rational
first); signals are substituted into the equations; every friction contact contributes modes
(Switch: slip+, slip-, stick; LuGre: w >= 0, w < 0) and the modes of the system are their
product; per mode the contact forces are replaced by their laws with the direction taken from
the mode (``sign(w)`` -> +1 or -1, ``abs(w)`` -> +w or -w: the field is the smooth extension of
the mode beyond its guards), the forces of sticking contacts are solved from dw/dt = 0 (linear
in the forces), and the Jacobians d f/d x and d f/d p are taken by differentiation.

Everything the code generator needs comes out as a :class:`Symbolic`; nothing here knows about
numba.
"""
from __future__ import annotations

from dataclasses import dataclass
from math import factorial

from ..errors import SystemDefinitionError
from .description import SLIP_VARIABLE, TF_VARIABLE, BlockSpec, Spec
from .expressions import TIME, to_sympy

# parts of a contact's mode
SLIP_POS, SLIP_NEG, STICK = 0, 1, 2
PART_NAMES = {"switch": ("slip+", "slip-", "stick"), "lugre": ("slip+", "slip-")}


@dataclass
class Symbolic:
    """The symbolic system: names, modes and per-mode expressions (sympy objects).

    t, x, p : time, state and parameter symbols; modes : tuple of part tuples (one part index per
    contact); vf, guards : per mode lists of n / n_guards expressions; jac, pjac : per mode
    sympy Matrix (n, n) and (n, n_params); stick_force : per mode {contact: F*}; wdot : per mode
    {contact: dw/dt} for LuGre contacts; signals : per mode list of the output values
    (``signal_names``); contact helpers (per contact): w, surface (state index), dwdx (d w / d
    x_surface), orient (-d(dw/dt)/dF: > 0 when the force opposes w), lo, hi (stick bound
    magnitudes, Switch only); block_leads: (block output, leading denominator coefficient) per
    linear block (a parameter value that makes it 0 leaves the block undefined)."""

    state_names: tuple
    param_names: tuple
    t: object
    x: tuple
    p: tuple
    contacts: tuple
    strides: tuple
    modes: tuple
    mode_names: tuple
    guard_names: tuple
    vf: list
    guards: list
    jac: list
    pjac: list
    stick_force: list
    wdot: list
    signal_names: tuple
    signals: list
    w: list
    surface: list
    dwdx: list
    orient: list
    lo: list
    hi: list
    bristle_states: dict
    block_leads: tuple = ()

    @property
    def n_guards(self) -> int:
        return max(1, 2 * len(self.contacts))


def _pade(order: int, T):
    """Coefficients (ascending powers of s) of the [order/order] Pade approximant of exp(-s T):
    c_k (-s T)^k over c_k (s T)^k, c_k = (2n - k)! n! / ((2n)! k! (n - k)!), exact rationals."""
    import sympy as sp
    n = order
    c = [sp.Rational(factorial(2 * n - k) * factorial(n), factorial(2 * n) * factorial(k) * factorial(n - k))
         for k in range(n + 1)]
    return [c[k] * (-T) ** k for k in range(n + 1)], [c[k] * T ** k for k in range(n + 1)]


def _block_coefficients(b: BlockSpec, psym: dict):
    """(num, den) coefficient lists of a block in ascending powers of s (sympy expressions)."""
    import sympy as sp
    where = f"blocks[{b.output!r}]"
    if b.delay is not None:
        return _pade(b.order, to_sympy(b.delay, psym))
    if b.tf is not None:
        s = sp.Symbol(TF_VARIABLE)
        h = sp.together(to_sympy(b.tf, {**psym, TF_VARIABLE: s}))
        if h.has(sp.zoo, sp.oo, -sp.oo, sp.nan):      # 1/(0*s), 1/(s - s): sympy's 1/0 is zoo
            raise SystemDefinitionError(f"{where}.tf = {b.tf.text!r}: the denominator is zero (the transfer "
                                        "function is not defined)")
        num, den = sp.fraction(h)
        try:
            pn, pd = sp.Poly(sp.expand(num), s), sp.Poly(sp.expand(den), s)
        except sp.PolynomialError:
            raise SystemDefinitionError(f"{where}.tf = {b.tf.text!r} is not a rational function of s") from None
        if pd.is_zero:
            raise SystemDefinitionError(f"{where}.tf = {b.tf.text!r}: the denominator is zero (the transfer "
                                        "function is not defined)")
        return pn.all_coeffs()[::-1], pd.all_coeffs()[::-1]
    num = [to_sympy(e, psym) for e in b.num][::-1]
    den = [to_sympy(e, psym) for e in b.den][::-1]
    return num, den


def _realize(b: BlockSpec, psym: dict):
    """Controllable canonical form of a block: (A rows as lambdas of the states, ...). Returns
    (a, c, D, lead): normalized denominator coefficients a_0..a_{n-1}, output coefficients
    c_0..c_{n-1}, feed-through D and the leading denominator coefficient (it divides the others), for xi' = [xi_2, ..., xi_n, u - sum a_i xi_{i+1}], y = sum c_i xi_{i+1} + D u."""
    import sympy as sp
    where = f"blocks[{b.output!r}]"
    num, den = _block_coefficients(b, psym)
    while len(den) > 1 and den[-1] == 0:
        den = den[:-1]
    while len(num) > 1 and num[-1] == 0:
        num = num[:-1]
    n = len(den) - 1
    if den[-1] == 0:
        raise SystemDefinitionError(f"{where}: the denominator is zero")
    if len(num) - 1 > n:
        raise SystemDefinitionError(
            f"{where}: the transfer function is improper (numerator degree {len(num) - 1} > denominator degree "
            f"{n}): it would differentiate its input; add a low-pass (e.g. divide by (1 + s/wlp)) or write the "
            "derivative with a state")
    lead = den[-1]
    a = [sp.together(d / lead) if d != 0 else sp.Integer(0) for d in den[:-1]]
    bn = list(num) + [sp.Integer(0)] * (n + 1 - len(num))
    bn = [v / lead for v in bn]
    D = bn[n]
    c = [bn[i] - D * a[i] for i in range(n)]
    return a, c, D, lead


def directional(expr, wsym, s: int, w_value):
    """``expr`` (a law in w) with the direction s = +1 / -1 taken from the mode: sign(w) -> s,
    abs(w) -> s w, then w -> w_value."""
    import sympy as sp
    wp = sp.Symbol("_wpos", positive=True)
    return expr.subs(wsym, s * wp).subs(wp, s * w_value)


def _clean(e):
    """Tidy a derivative: w**b/w -> w**(b - 1) (0/0 at w = 0 otherwise)."""
    import sympy as sp
    if e == 0 or not e.has(sp.Pow):
        return e
    return sp.powsimp(e)


def build(spec: Spec) -> Symbolic:
    """The symbolic system of a checked description (raises SystemDefinitionError for what only
    algebra can find: improper blocks, algebraic loops, forces not linear in the stick
    condition, a force that does not act on its contact's velocity)."""
    import sympy as sp
    from sympy.solvers.solveset import NonlinearError

    t = sp.Symbol("t", real=True)
    pnames = tuple(spec.parameters)
    p = tuple(sp.Symbol(f"p_{j}", real=True) for j in range(len(pnames)))
    psym = dict(zip(pnames, p))

    # blocks -> state names
    realized, leads = [], []
    for b in spec.blocks:
        a, c, D, lead = _realize(b, psym)
        realized.append((a, c, D))
        leads.append((b.output, lead))
    bristles = {c.state: c for c in spec.contacts if c.model == "lugre"}
    names = list(spec.states) + list(bristles)
    block_states = []
    taken = set(names) | set(pnames) | set(spec.signals) | {b.output for b in spec.blocks} | set(spec.forces)
    for b, (a, _, _) in zip(spec.blocks, realized):
        bs = [f"{b.output}_{i + 1}" for i in range(len(a))]
        clash = [v for v in bs if v in taken]
        if clash:
            raise SystemDefinitionError(f"blocks[{b.output!r}]: its states would be named {bs} but {clash} "
                                        "are already used: rename the block output")
        taken |= set(bs)
        block_states.append(bs)
        names += bs
    x = tuple(sp.Symbol(f"x_{i}", real=True) for i in range(len(names)))
    xsym = dict(zip(names, x))
    F = {c.force: sp.Symbol(f"F_{i}", real=True) for i, c in enumerate(spec.contacts)}
    base = {**psym, **xsym, **F, TIME: t}

    # signals and block outputs, resolved recursively (an algebraic loop is an error)
    blocks = {b.output: (b, r, bs) for b, r, bs in zip(spec.blocks, realized, block_states)}
    resolved: dict = {}

    def resolve(name, stack=()):
        if name in resolved:
            return resolved[name]
        if name in stack:
            cyc = list(stack[stack.index(name):]) + [name]
            raise SystemDefinitionError(f"signals form a cycle: {' -> '.join(cyc)} (an algebraic loop through a "
                                        "block's direct feed-through: make the block strictly proper)")
        if name in spec.signals:
            e = spec.signals[name]
            v = to_sympy(e, env(e.names, stack + (name,)))
        else:
            b, (a, c, D), bs = blocks[name]
            v = sum((ci * xsym[si] for ci, si in zip(c, bs)), sp.Integer(0))
            if D != 0:
                v = v + D * block_input(b, stack + (name,))
        resolved[name] = v
        return v

    def env(used, stack=()):
        out = {}
        for n in used:
            if n in base:
                out[n] = base[n]
            elif n in spec.signals or n in blocks:
                out[n] = resolve(n, stack)
        return out

    def block_input(b, stack=()):
        return to_sympy(b.input, env(b.input.names, stack))

    wsym = sp.Symbol(SLIP_VARIABLE, real=True)

    def law(e):
        return to_sympy(e, {**env(e.names - {SLIP_VARIABLE}), SLIP_VARIABLE: wsym})

    f_user = [to_sympy(spec.equations[s], env(spec.equations[s].names)) for s in spec.states]
    f_blocks = []
    for b, (a, c, D), bs in zip(spec.blocks, realized, block_states):
        if not bs:
            continue
        u = block_input(b)
        for i in range(len(bs) - 1):
            f_blocks.append(xsym[bs[i + 1]])
        f_blocks.append(u - sum((ai * xsym[si] for ai, si in zip(a, bs)), sp.Integer(0)))

    # contacts
    contacts = spec.contacts
    w, surface, dwdx, orient, lo, hi = [], [], [], [], [], []
    raw = f_user + [sp.Integer(0)] * len(bristles) + f_blocks     # bristle rates are per mode
    for ci, c in enumerate(contacts):
        wc = to_sympy(c.velocity, env(c.velocity.names))
        cand = [(k, sp.diff(wc, x[k])) for k in range(len(x))]
        cand = [(k, d) for k, d in cand if d != 0]
        if not cand:
            raise SystemDefinitionError(f"friction[{c.name!r}].velocity = {c.velocity.text!r} depends on no state")
        # the stick entry moves this state onto w = 0: one the velocity is linear in, and not
        # the surface state of an earlier contact (a second contact must not undo the first)
        used = set(surface)
        k, d = next(((k, d) for k, d in cand if not d.has(x[k]) and k not in used),
                    next(((k, d) for k, d in cand if not d.has(x[k])), cand[0]))
        w.append(wc)
        surface.append(k)
        dwdx.append(d)
        wdot_raw = sp.diff(wc, t) + sum((sp.diff(wc, x[j]) * raw[j] for j in range(len(x))), sp.Integer(0))
        b_c = -sp.diff(wdot_raw, F[c.force])
        if c.model == "switch" and b_c == 0:
            raise SystemDefinitionError(f"friction[{c.name!r}]: the force {c.force!r} does not act on the "
                                        f"contact's velocity {c.velocity.text!r} (d(dw/dt)/d{c.force} = 0): "
                                        "use the force in the equation of the state the velocity depends on")
        orient.append(b_c)
        if c.model == "switch":
            lo.append(to_sympy(c.stick[0], env(c.stick[0].names)))
            hi.append(to_sympy(c.stick[1], env(c.stick[1].names)))
        else:
            lo.append(None)
            hi.append(None)

    # modes: product of the contacts' parts, contact 0 fastest
    nparts = [3 if c.model == "switch" else 2 for c in contacts]
    strides, s_ = [], 1
    for k in nparts:
        strides.append(s_)
        s_ *= k
    n_modes = s_
    modes = []
    for m in range(n_modes):
        modes.append(tuple((m // strides[i]) % nparts[i] for i in range(len(contacts))))
    if len(contacts) == 1:
        mode_names = tuple(PART_NAMES[contacts[0].model][pt[0]] for pt in modes)
    elif not contacts:
        mode_names = ("smooth",)
        modes = [()]
    else:
        mode_names = tuple(",".join(f"{c.name}:{PART_NAMES[c.model][q]}" for c, q in zip(contacts, pt)) for pt in modes)
    if len(contacts) == 1:
        c0 = contacts[0].name
        guard_names = (f"{c0}: velocity zero / break-away +", f"{c0}: break-away -") \
            if contacts[0].model == "switch" else (f"{c0}: velocity zero", f"{c0}: unused")
    else:
        guard_names = tuple(g for c in contacts for g in (
            (f"{c.name}: velocity zero / break-away +", f"{c.name}: break-away -") if c.model == "switch"
            else (f"{c.name}: velocity zero", f"{c.name}: unused")))
    if not contacts:
        guard_names = ("unused",)

    n_user = len(spec.states)
    bristle_index = {c.state: n_user + i for i, c in enumerate(bristles.values())}
    out_names = tuple(spec.signals) + tuple(b.output for b in spec.blocks) + tuple(c.force for c in contacts)
    sig_raw = [resolve(k) for k in spec.signals] + [resolve(b.output) for b in spec.blocks]

    vf, guards, jac, pjac, stick_force, wdot, signals = [], [], [], [], [], [], []
    X, P = sp.Matrix(x), sp.Matrix(p)
    for pt in modes:
        subs = {}
        zrates = {}
        for ci, c in enumerate(contacts):
            part = pt[ci]
            if c.model == "switch" and part == STICK:
                continue
            s = 1 if part == SLIP_POS else -1
            if c.model == "switch":
                subs[F[c.force]] = directional(law(c.slip), wsym, s, w[ci])
            else:
                g = directional(law(c.level), wsym, s, w[ci])
                s0 = directional(law(c.sigma0), wsym, s, w[ci])
                s1 = directional(law(c.sigma1), wsym, s, w[ci])
                visc = directional(law(c.viscous), wsym, s, w[ci])
                z = xsym[c.state]
                zdot = w[ci] - s0 * (s * w[ci]) * z / g
                subs[F[c.force]] = s0 * z + s1 * zdot + visc
                zrates[c.state] = zdot
        # the laws may use signals, which never use forces: one substitution pass suffices
        f = [e.subs(subs) for e in raw]
        # abs(w) and sign(w) of a slipping contact's velocity anywhere in the equations (an
        # observer copying the bristle model, say) take the mode's side too: no kink inside a mode
        kinks = {}
        for ci, c in enumerate(contacts):
            if not (c.model == "switch" and pt[ci] == STICK):
                sgn = 1 if pt[ci] == SLIP_POS else -1
                kinks[sp.Abs(w[ci])] = sgn * w[ci]
                kinks[sp.sign(w[ci])] = sp.Integer(sgn)
        if kinks:
            f = [e.xreplace(kinks) for e in f]
        for name, zd in zrates.items():
            f[bristle_index[name]] = zd
        sticking = [ci for ci, c in enumerate(contacts) if c.model == "switch" and pt[ci] == STICK]
        fstar = {}
        if sticking:
            eqs = [sp.diff(w[ci], t) + sum((sp.diff(w[ci], x[j]) * f[j] for j in range(len(x))), sp.Integer(0))
                   for ci in sticking]
            unknowns = [F[contacts[ci].force] for ci in sticking]
            try:
                A, rhs = sp.linear_eq_to_matrix(eqs, unknowns)
            except NonlinearError:
                raise SystemDefinitionError(
                    f"stick of {[contacts[ci].name for ci in sticking]}: the condition dw/dt = 0 is not linear in the "
                    f"friction forces {[contacts[ci].force for ci in sticking]}: write the forces linearly "
                    "in the equations (as in m v' = ... - F)") from None
            if len(sticking) == 1:
                sol = [rhs[0] / A[0, 0]]
            else:
                if sp.simplify(A.det()) == 0:
                    raise SystemDefinitionError(
                        f"stick of {[contacts[ci].name for ci in sticking]} together: the forces are not determined "
                        "by the stick conditions (the contacts constrain the same motion)")
                sol = list(A.LUsolve(rhs))
            for ci, v in zip(sticking, sol):
                fstar[ci] = v
            fs = {F[contacts[ci].force]: fstar[ci] for ci in sticking}
            f = [e.subs(fs) for e in f]
        else:
            fs = {}
        vf.append(f)
        g = []
        for ci, c in enumerate(contacts):
            part = pt[ci]
            if c.model == "switch" and part == STICK:
                g += [hi[ci] - fstar[ci], fstar[ci] + lo[ci]]
            elif part == SLIP_POS:
                g += [w[ci], sp.Integer(1)]
            else:
                g += [-w[ci], sp.Integer(1)]
        if not contacts:
            g = [sp.Integer(1)]
        guards.append(g)
        stick_force.append(fstar)
        wd = {}
        for ci, c in enumerate(contacts):
            if c.model == "lugre":
                wd[ci] = sp.diff(w[ci], t) + sum((sp.diff(w[ci], x[j]) * f[j] for j in range(len(x))), sp.Integer(0))
        wdot.append(wd)
        allsubs = {**subs, **fs}
        signals.append([e.subs(allsubs).xreplace(kinks) for e in sig_raw]
                       + [F[c.force].subs(allsubs).xreplace(kinks) for c in contacts])
        fv = sp.Matrix(f)
        jac.append(fv.jacobian(X).applyfunc(_clean))
        pjac.append(fv.jacobian(P).applyfunc(_clean) if p else sp.zeros(len(x), 0))

    return Symbolic(tuple(names), pnames, t, x, p, contacts, tuple(strides), tuple(modes), tuple(mode_names),
                    tuple(guard_names), vf, guards, jac, pjac, stick_force, wdot, out_names, signals, w, surface,
                    dwdx, orient, lo, hi, bristle_index, tuple(leads))
