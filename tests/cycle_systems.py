"""Hand-written systems for the cycle-search tests (written the way a user adds one).

The block on a moving belt of issue 19's example: m q'' = -k q - F, relative velocity
w = v - vb, slip F = sgn(w) (Fc + (Fs - Fc) exp(-|w| / vs)), stick (w = 0, v = vb) while the
force that holds it, F = -k q, stays in [-Fs, Fs]. States (q, v); p = [m, k, Fc, Fs, vs, vb].
"""
import math

import numba
import numpy as np

from hunting import GUARD_SIG, MODE_SIG, RESET_SIG, VF_SIG, Mode, PiecewiseSystem

SLIP_POS, SLIP_NEG, STICK = 0, 1, 2
BELT = dict(m=1.0, k=2.0, Fc=0.3, Fs=0.5, vs=0.05, vb=0.1)


@numba.njit(VF_SIG, cache=True, error_model="numpy", _nrt=False)
def belt_vf(mode, t, x, p, out):
    if mode == STICK:
        out[0] = p[5]
        out[1] = 0.0
        return
    s = 1.0 if mode == SLIP_POS else -1.0
    w = x[1] - p[5]
    F = s * (p[2] + (p[3] - p[2]) * math.exp(-s * w / p[4]))
    out[0] = x[1]
    out[1] = (-p[1] * x[0] - F) / p[0]


@numba.njit(GUARD_SIG, cache=True, error_model="numpy", _nrt=False)
def belt_guards(mode, t, x, p, out):
    if mode == STICK:
        F = -p[1] * x[0]                 # the force that keeps w' = 0
        out[0] = p[3] - F                # leaves forward (w > 0)
        out[1] = p[3] + F                # leaves backward (w < 0)
    else:
        w = x[1] - p[5]
        out[0] = w if mode == SLIP_POS else -w
        out[1] = 1.0


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def _at_rest(x, p):
    F = -p[1] * x[0]
    if F > p[3]:
        return SLIP_POS
    if F < -p[3]:
        return SLIP_NEG
    return STICK


@numba.njit(RESET_SIG, cache=True, error_model="numpy", _nrt=False)
def belt_reset(mode, guard, t, x, p, x_out):
    x_out[0] = x[0]
    x_out[1] = x[1]
    if mode == STICK:
        return SLIP_POS if guard == 0 else SLIP_NEG
    x_out[1] = p[5]
    return _at_rest(x_out, p)


@numba.njit(MODE_SIG, cache=True, error_model="numpy", _nrt=False)
def belt_mode(t, x, p):
    w = x[1] - p[5]
    if w > 0:
        return SLIP_POS
    if w < 0:
        return SLIP_NEG
    return _at_rest(x, p)


def belt_system(**kw):
    v = {**BELT, **kw}
    return PiecewiseSystem(
        name="belt", state_names=("q", "v"),
        modes=(Mode("slip+"), Mode("slip-"), Mode("stick", "stick", 1)),
        guard_names=("w = 0 / break-away forward", "break-away backward"),
        param_names=tuple(BELT), params=np.array([v[k] for k in BELT]),
        vector_field=belt_vf, guards=belt_guards, transition=belt_reset, mode_of=belt_mode)


def belt_reference_cycle(m=1.0, k=2.0, Fc=0.3, Fs=0.5, vs=0.05, vb=0.1):
    """The belt's stick-slip cycle with scipy's solve_ivp (independent of hunting): from the
    break-away state (q = Fs/k, v = vb) slip backwards (w < 0) until w = 0 again (an event
    located by solve_ivp), then stick at the belt's speed until -k q reaches -Fs again.

    Returns dict(period, slip, stick, q_min, q_max, v_min, v_max)."""
    from scipy.integrate import solve_ivp

    def rhs(t, y):
        w = y[1] - vb
        F = -(Fc + (Fs - Fc) * math.exp(w / vs))          # slip with w < 0
        return [y[1], (-k * y[0] - F) / m]

    def w_zero(t, y):
        # armed after the first microsecond: the start is on w = 0 itself (solve_ivp would
        # otherwise report the start as the event for some vb)
        return y[1] - vb if t > 1e-6 else -1.0
    w_zero.terminal, w_zero.direction = True, 1.0
    q_b = Fs / k
    # leave the break-away state (w = 0) before the event is armed
    sol = solve_ivp(rhs, (0.0, 100.0), [q_b, vb], method="DOP853", rtol=1e-12, atol=1e-14,
                    events=w_zero, first_step=1e-8)
    t_slip = float(sol.t_events[0][0])
    q_entry = float(sol.y_events[0][0][0])
    t_stick = (q_b - q_entry) / vb
    # extremes: where q' = v or v' vanishes inside the slip phase (events located by solve_ivp)
    def v_zero(t, y):
        return y[1]

    def a_zero(t, y):
        return rhs(t, y)[1]
    ext = solve_ivp(rhs, (0.0, t_slip), [q_b, vb], method="DOP853", rtol=1e-12, atol=1e-14,
                    events=(v_zero, a_zero), first_step=1e-8)
    qs = np.concatenate([[q_b, q_entry], ext.y_events[0][:, 0]])
    vs_ = np.concatenate([[vb], ext.y_events[1][:, 1]])
    return dict(period=t_slip + t_stick, slip=t_slip, stick=t_stick, q_min=float(qs.min()), q_max=float(qs.max()),
                v_min=float(vs_.min()), v_max=float(vs_.max()))


# ---------------------------------------------------------------- a family of cycles
# the Hopf normal form (x, y) with a third state that never moves: every z carries a cycle, so
# no cycle is isolated and the shooting Jacobian is singular (a zero row for z)
@numba.njit(VF_SIG, cache=True, error_model="numpy", _nrt=False)
def family_vf(mode, t, x, p, out):
    r2 = x[0] * x[0] + x[1] * x[1]
    out[0] = x[0] - 2.0 * x[1] - x[0] * r2
    out[1] = 2.0 * x[0] + x[1] - x[1] * r2
    out[2] = 0.0


@numba.njit(GUARD_SIG, cache=True, error_model="numpy", _nrt=False)
def family_guards(mode, t, x, p, out):
    out[0] = 1.0


@numba.njit(RESET_SIG, cache=True, error_model="numpy", _nrt=False)
def family_reset(mode, guard, t, x, p, x_out):
    for i in range(x.size):
        x_out[i] = x[i]
    return mode


@numba.njit(MODE_SIG, cache=True, error_model="numpy", _nrt=False)
def family_mode(t, x, p):
    return 0


def family_system():
    return PiecewiseSystem(name="family", state_names=("x", "y", "z"), modes=("smooth",), guard_names=("none",),
                           param_names=(), params=np.zeros(1), vector_field=family_vf, guards=family_guards,
                           transition=family_reset, mode_of=family_mode)


# ---------------------------------------------------------------- the same as descriptions
BELT_DESCRIPTION = {
    "name": "belt", "parameters": dict(BELT), "states": ["q", "v"], "signals": {"u": "-k*q"},
    "equations": {"q": "v", "v": "(u - F)/m"},
    "friction": {"force": "F", "velocity": "v - vb", "model": "switch",
                 "slip": "sign(w)*(Fc + (Fs - Fc)*exp(-abs(w)/vs))", "stick": "Fs"}}

# the PID + LuGre loop of Canudas de Wit et al. (1995), in the position q with set point qd
PID_LUGRE_DESCRIPTION = {
    "name": "pid-lugre",
    "parameters": {"m": 1.0, "kp": 3.0, "kd": 6.0, "ki": 4.0, "qd": 1.0, "Fc": 1.0, "Fs": 1.5, "vs": 0.001,
                   "sigma0": 1e5, "sigma1": 316.22776601683796, "sigma2": 0.4},
    "states": ["q", "v", "ie"], "signals": {"e": "q - qd", "u": "-(kp*e + kd*v + ki*ie)"},
    "equations": {"q": "v", "v": "(u - F)/m", "ie": "e"},
    "friction": {"force": "F", "velocity": "v", "model": "lugre", "level": "Fc + (Fs - Fc)*exp(-(w/vs)**2)",
                 "sigma0": "sigma0", "sigma1": "sigma1", "viscous": "sigma2*w"}}


# ---------------------------------------------------------------- masses on belts and drives
# (the review's models; their cycles are checked against belt_masses_reference below)
TWO_CONTACT_DESCRIPTION = {
    "name": "two-contacts",
    "parameters": {"m1": 1.0, "m2": 1.0, "k1": 2.0, "k12": 1.0, "vb": 0.1, "Fc": 0.3, "Fs": 0.5, "vs": 0.05,
                   "Fc2": 0.2, "Fs2": 0.4},
    "states": ["q1", "v1", "q2", "v2"], "signals": {"f12": "k12*(q2 - q1)"},
    "equations": {"q1": "v1", "v1": "(-k1*q1 + f12 - F1)/m1", "q2": "v2", "v2": "(-f12 - F2)/m2"},
    "friction": [{"name": "belt1", "force": "F1", "velocity": "v1 - vb", "model": "switch",
                  "slip": "sign(w)*(Fc + (Fs - Fc)*exp(-abs(w)/vs))", "stick": "Fs"},
                 {"name": "belt2", "force": "F2", "velocity": "v2 - vb", "model": "switch",
                  "slip": "sign(w)*(Fc2 + (Fs2 - Fc2)/(1 + (w/vs)**2))", "stick": ["Fs2", "Fs2"]}]}

# a block dragged by a drive at speed vd through a spring to a second mass on a spring; the
# drive is written as a state relative to it (an autonomous system)
TWO_DOF_DESCRIPTION = {
    "name": "two-dof",
    "parameters": {"m1": 1.0, "m2": 0.5, "k12": 5.0, "k2": 1.0, "c12": 0.05, "vd": 0.1, "Fc": 1.0, "Fs": 1.5,
                   "vs": 0.05},
    "states": ["q1", "v1", "q2", "v2"],
    "signals": {"f12": "k12*(q2 - q1) + c12*(v2 - v1)", "fd": "-k2*q2"},
    "equations": {"q1": "v1", "v1": "(f12 - F)/m1", "q2": "v2", "v2": "(fd - f12)/m2"},
    "friction": {"force": "F", "velocity": "v1 - vd", "model": "switch",
                 "slip": "sign(w)*(Fc + (Fs - Fc)*exp(-abs(w)/vs))", "stick": "Fs"}}


def two_contact_forces(p):
    """(masses, other forces G(q, v) per mass, slip laws F(w) for w > 0, stick bounds, belt
    speeds) of TWO_CONTACT_DESCRIPTION, written out by hand."""
    def G(q, v):
        f12 = p["k12"] * (q[1] - q[0])
        return np.array([-p["k1"] * q[0] + f12, -f12])
    laws = (lambda w: p["Fc"] + (p["Fs"] - p["Fc"]) * math.exp(-abs(w) / p["vs"]),
            lambda w: p["Fc2"] + (p["Fs2"] - p["Fc2"]) / (1.0 + (w / p["vs"]) ** 2))
    return (p["m1"], p["m2"]), G, laws, (p["Fs"], p["Fs2"]), (p["vb"], p["vb"])


def two_dof_forces(p):
    """The same for TWO_DOF_DESCRIPTION (no contact on mass 2: bound None)."""
    def G(q, v):
        f12 = p["k12"] * (q[1] - q[0]) + p["c12"] * (v[1] - v[0])
        return np.array([f12, -p["k2"] * q[1] - f12])
    laws = (lambda w: p["Fc"] + (p["Fs"] - p["Fc"]) * math.exp(-abs(w) / p["vs"]), None)
    return (p["m1"], p["m2"]), G, laws, (p["Fs"], None), (p["vd"], 0.0)


def _to_qv(x):
    """(q1, v1, q2, v2, ...) -> (q1, q2, ..., v1, v2, ...)."""
    x = np.asarray(x, dtype=float)
    return np.concatenate([x[0::2], x[1::2]])


def _from_qv(z):
    N = len(z) // 2
    x = np.empty(2 * N)
    x[0::2], x[1::2] = z[:N], z[N:]
    return x


def belt_masses_run(forces, x0, t_end, *, stuck=None, rtol=1e-12, atol=1e-14, max_step=0.02, max_events=2000):
    """Masses on belts with Switch contacts, event-driven with scipy's solve_ivp (independent
    of hunting): mass i slips with m_i v_i' = G_i(q, v) - s_i F_i(|w_i|), w_i = v_i - vb_i,
    s_i = sign(w_i), or sticks (v_i = vb_i) while |G_i| <= its bound. Events: w_i = 0 (stick
    when |G_i| is inside the bound, else the slip reverses), |G_i| = bound (slip the way G_i
    pushes). ``max_step`` keeps short excursions of the stick force beyond its bound visible.
    States are (q1, v1, q2, v2, ...) as in the descriptions.

    Returns a list of events (t, contact, "stick" or "slip", state after) and the final state."""
    from scipy.integrate import solve_ivp
    ms, G, laws, bounds, vb = forces
    N = len(ms)
    y = _to_qv(x0)
    stuck = list(stuck) if stuck is not None else [False] * N
    sgn = [0.0] * N
    for i in range(N):
        w = y[N + i] - vb[i]
        if bounds[i] is not None and not stuck[i]:
            sgn[i] = 1.0 if w > 0 else -1.0
    t = 0.0
    log = []

    def rhs(_, z):
        q, v = z[:N], z[N:]
        g = G(q, v)
        dv = np.empty(N)
        for i in range(N):
            if stuck[i]:
                dv[i] = 0.0
            else:
                fr = sgn[i] * laws[i](v[i] - vb[i]) if bounds[i] is not None else 0.0
                dv[i] = (g[i] - fr) / ms[i]
        return np.concatenate([v, dv])

    for _ in range(max_events):
        if t >= t_end:
            break
        evs = []
        for i in range(N):
            if bounds[i] is None:
                continue
            if stuck[i]:
                def e(_, z, i=i):
                    return abs(G(z[:N], z[N:])[i]) - bounds[i]
                e.direction = 1.0
            else:
                def e(_, z, i=i):
                    return z[N + i] - vb[i]
                e.direction = -sgn[i]
            e.terminal = True
            evs.append((i, e))
        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=rtol, atol=atol, max_step=max_step,
                        events=[e for _, e in evs])
        if sol.status != 1:
            y = sol.y[:, -1]
            t = t_end
            break
        k = next(j for j, te in enumerate(sol.t_events) if len(te))
        i = evs[k][0]
        t = float(sol.t_events[k][0])
        y = sol.y_events[k][0].copy()
        g = G(y[:N], y[N:])
        if stuck[i]:
            stuck[i] = False
            sgn[i] = 1.0 if g[i] > 0 else -1.0
            log.append((t, i, "slip", _from_qv(y)))
        else:
            y[N + i] = vb[i]
            if abs(g[i]) <= bounds[i]:
                stuck[i] = True
                log.append((t, i, "stick", _from_qv(y)))
            else:
                sgn[i] = -sgn[i]
    return log, _from_qv(y)


def belt_masses_cycle(forces, x0, *, t_run, contact=0, periods_max=4, tol=1e-7):
    """The cycle a belt_masses_run from x0 settles on within t_run: period (between stick
    entries of ``contact`` whose states agree, fewest apart), the entry state, and the stick
    phases of every contact within that period as (contact, duration), in order."""
    log, _ = belt_masses_run(forces, x0, t_run)
    entries = [(t, y) for t, i, kind, y in log if i == contact and kind == "stick"]
    last_t, last_y = entries[-1]
    for p in range(1, min(periods_max, len(entries) - 1) + 1):
        t_p, y_p = entries[-1 - p]
        if np.max(np.abs(last_y - y_p)) < tol:
            break
    else:
        raise AssertionError(f"the reference run did not settle: {[(t, y.tolist()) for t, y in entries[-3:]]}")
    sticks, open_ = [], {}
    for t, i, kind, y in log:
        if kind == "stick":
            open_[i] = t
        elif i in open_:
            a = open_.pop(i)
            if t_p - 1e-9 <= a < last_t - 1e-9:
                sticks.append((i, t - a))
    return last_t - t_p, last_y, sticks


def belt_masses_multipliers(forces, y_entry, T, *, contact=0, h=1e-6):
    """Nontrivial Floquet multipliers of the cycle through the stick entry y_entry (contact
    ``contact`` just stuck; states (q1, v1, ...)): the return map to its entry nearest to T
    later, differentiated by central differences over the coordinates free on that section
    (positions, and velocities of the contacts that slip there); eigenvalues by decreasing
    modulus."""
    ms, G, laws, bounds, vb = forces
    N = len(ms)
    z = _to_qv(y_entry)
    g0 = G(z[:N], z[N:])
    stuck0 = [bounds[i] is not None and (i == contact or (abs(z[N + i] - vb[i]) < 1e-12 and abs(g0[i]) <= bounds[i]))
              for i in range(N)]
    free = [2 * i for i in range(N)] + [2 * i + 1 for i in range(N) if not stuck0[i]]

    def P(y):
        log, _ = belt_masses_run(forces, y, 1.5 * T, stuck=stuck0)
        ent = [(abs(t - T), x) for t, i, kind, x in log if i == contact and kind == "stick"]
        return min(ent, key=lambda e: e[0])[1]
    J = np.empty((len(free), len(free)))
    for c, j in enumerate(free):
        yp, ym = np.array(y_entry, dtype=float), np.array(y_entry, dtype=float)
        yp[j] += h
        ym[j] -= h
        J[:, c] = (P(yp)[free] - P(ym)[free]) / (2 * h)
    lam = np.linalg.eigvals(J)
    return lam[np.argsort(-np.abs(lam))]


def loopshaped_reference(path, K: float, *, t_run: float = 3.0, method: str = "Radau", rtol: float = 1e-9):
    """The cycle of examples/loopshaped.yaml at gain K with scipy only: the controller of the
    file's transfer function multiplied out and realized by scipy.signal.tf2ss, the delay by
    python-control's Pade approximation, the mass with its Switch contact event-driven with
    solve_ivp (stick: v = 0 while |cm u| <= Fs). Started like the model (q = q0, the rest 0).

    Returns dict(period, stick_q (|q| in stick, the stick error), stick, slip) of the last
    period (two stick phases of opposite sign)."""
    import control
    import yaml
    from scipy.integrate import solve_ivp
    from scipy.signal import tf2ss
    d = yaml.safe_load(open(path))
    p = dict(d["parameters"], K=K)
    num = p["K"] * p["wlp"] ** 2 * np.polymul([p["tau_i"], 1.0], [p["tau_z"], 1.0])
    den = np.polymul(np.polymul([p["tau_i"], 0.0], [p["tau_p"], 1.0]), [1.0, 2 * p["blp"] * p["wlp"], p["wlp"] ** 2])
    A1, B1, C1, D1 = tf2ss(num, den)
    order = next(b["order"] for b in d["blocks"] if "delay" in b)
    A2, B2, C2, D2 = tf2ss(*control.pade(p["Td"], order))
    n1, n2 = A1.shape[0], A2.shape[0]
    m, cm, Fc, Fs, vs, b = p["m"], p["cm"], p["Fc"], p["Fs"], p["vs"], p["b"]

    def ctrl(y):
        q, xc, xd = y[0], y[2:2 + n1], y[2 + n1:]
        uc = float((C1 @ xc)[0] + D1[0, 0] * (-q))
        u = float((C2 @ xd)[0] + D2[0, 0] * uc)
        return q, xc, xd, uc, u

    state = {"stick": False, "s": 1.0}

    def rhs(_, y):
        q, xc, xd, uc, u = ctrl(y)
        v = y[1]
        dxc = A1 @ xc + B1[:, 0] * (-q)
        dxd = A2 @ xd + B2[:, 0] * uc
        if state["stick"]:
            return np.concatenate([[0.0, 0.0], dxc, dxd])
        F = state["s"] * (Fc + (Fs - Fc) * math.exp(-(v / vs) ** 2)) + b * v
        return np.concatenate([[v, (cm * u - F) / m], dxc, dxd])

    def v_zero(_, y):
        return y[1]

    def release(_, y):
        return abs(cm * ctrl(y)[4]) - Fs
    release.direction, release.terminal, v_zero.terminal = 1.0, True, True
    y = np.zeros(2 + n1 + n2)
    y[0] = d["states"]["q"]
    state["s"] = 1.0 if cm * ctrl(y)[4] > 0 else -1.0
    t, log = 0.0, []
    while t < t_run:
        v_zero.direction = -state["s"]
        ev = release if state["stick"] else v_zero
        sol = solve_ivp(rhs, (t, t_run), y, method=method, rtol=rtol, atol=1e-3 * rtol, events=ev)
        if sol.status != 1:
            break
        t, y = float(sol.t_events[0][0]), sol.y_events[0][0].copy()
        u = ctrl(y)[4]
        if state["stick"]:
            state["stick"], state["s"] = False, (1.0 if u > 0 else -1.0)
            log.append((t, "slip", y[0]))
        else:
            y[1] = 0.0
            if abs(cm * u) <= Fs:
                state["stick"] = True
                log.append((t, "stick", y[0]))
            else:
                state["s"] = -state["s"]
    sticks = [k for k, e in enumerate(log) if e[1] == "stick"]
    a, c = sticks[-3], sticks[-1]                    # two stick entries apart: one period
    return dict(period=log[c][0] - log[a][0], stick_q=abs(log[c][2]), stick=log[a + 1][0] - log[a][0],
                slip=log[a + 2][0] - log[a + 1][0])


def pid_switch_reference(p, d_guess: float):
    """The symmetric hunting cycle of a PID servo with Switch friction (test_cycle_eventmap.
    PID_SWITCH's equations, e = q - qd) with solve_ivp: P2(d), the stick error two stick phases
    after the stick phase with error d (slip phases event-driven, stick phases in closed form),
    its fixed point near d_guess by the secant method, its slope there by central differences,
    and the period (between the first and third stick entries from the fixed point).

    Returns dict(d, slope, period, P2)."""
    from scipy.integrate import solve_ivp
    P, D, I, m, Fc, Fs, vs, b = (p[k] for k in ("P", "D", "I", "m", "Fc", "Fs", "vs", "b"))

    def u(x):
        return -P * (x[0] + D * x[1] + I * x[2])

    def slip(_, x, s):
        w = x[1]
        return [x[1], (u(x) - s * (Fc + (Fs - Fc) * math.exp(-(w / vs) ** 2)) - b * w) / m, x[0]]

    def run(x, t, sticks_wanted, stuck):
        ds, ts = [], []
        while len(ds) < sticks_wanted:
            if stuck:
                # in stick e and v are frozen, the integral drifts at rate e: |u| reaches Fs in
                # closed form (u is affine in the integral)
                target = (math.copysign(Fs, -x[0]) / -P - x[0]) / I       # xi where u = sign * Fs
                if x[0] == 0:
                    raise AssertionError("at rest on the equilibrium set")
                dt = (target - x[2]) / x[0]
                x = np.array([x[0], 0.0, target])
                t += dt
                stuck = False
            s = 1.0 if u(x) > 0 else -1.0
            ev = lambda _, y, s: y[1]                      # noqa: E731
            ev.terminal, ev.direction = True, -s
            sol = solve_ivp(slip, (t, t + 1e3), x, args=(s,), events=ev, rtol=1e-12, atol=1e-14,
                            first_step=1e-9)
            t, x = float(sol.t_events[0][0]), sol.y_events[0][0].copy()
            x[1] = 0.0
            if abs(u(x)) <= Fs:
                stuck = True
                ds.append(x[0])
                ts.append(t)
        return np.array(ds), np.array(ts)

    def P2(d):
        return run(np.array([d, 0.0, 0.0]), 0.0, 2, True)[0][-1]
    d1, d2 = d_guess, 1.01 * d_guess
    g1, g2 = P2(d1) - d1, P2(d2) - d2
    for _ in range(30):
        if g2 == g1 or abs(d2 - d1) < 1e-14 * abs(d2):
            break
        d1, g1, d2 = d2, g2, d2 - g2 * (d2 - d1) / (g2 - g1)
        g2 = P2(d2) - d2
    h = 1e-6 * abs(d2)
    _, ts = run(np.array([d2, 0.0, 0.0]), 0.0, 3, True)
    return dict(d=d2, slope=(P2(d2 + h) - P2(d2 - h)) / (2 * h), period=ts[2] - ts[0], P2=P2)
