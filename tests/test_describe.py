"""Model descriptions compiled into systems: the API, presets from descriptions against the
hand-written kernels."""
import json
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
    assert "contact friction (switch): force F, w = v - vb" in m.summary() and "k                = 2" in m.summary()


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


# ------------------------------------------------------------------ bad descriptions
BELT = {"parameters": {"m": 1.0, "k": 2.0, "Fc": 0.3, "Fs": 0.5, "vs": 0.05, "vb": 0.1},
        "states": ["q", "v"], "signals": {"u": "-k*q"},
        "equations": {"q": "v", "v": "(u - F)/m"},
        "friction": {"force": "F", "velocity": "v - vb", "model": "switch",
                     "slip": "sign(w)*(Fc + (Fs - Fc)*exp(-abs(w)/vs))", "stick": "Fs"}}


def _with(**changes):
    import copy
    d = copy.deepcopy(BELT)
    for path, value in changes.items():
        keys = path.split("__")
        tgt = d
        for k in keys[:-1]:
            tgt = tgt[k]
        if value is None:
            del tgt[keys[-1]]
        else:
            tgt[keys[-1]] = value
    return d


@pytest.mark.parametrize("desc, match", [
    (_with(equations__v="(u - F)/mass"), r"equations\['v'\] = '\(u - F\)/mass': unknown name 'mass'"),
    (_with(equations__v=None), r"state \['v'\] has no equation"),
    (_with(equations=None), "equations is missing"),
    (_with(equations__x="q"), r"equations for \['x'\] but they are not states"),
    (_with(signals={"u": "-k*q + y", "y": "2*u"}), r"signals form a cycle: u -> y -> u|signals form a cycle: y -> u -> y"),
    (_with(friction__velocity="vb"), r"velocity = 'vb' depends on no state"),
    (_with(friction__stick="-Fs"), r"stick = '-Fs' is -0.5 .*must be a finite number >= 0"),
    (_with(friction__stick=["Fs", "Fs - 1"]), r"stick\[1\]|stick = 'Fs - 1' is -0.5"),
    (_with(equations__v="(u - F)/m + __import__('os')"), r"the function '__import__' is not allowed .* at position 13"),
    (_with(equations__v="(u - F)/m if q else 0"), r"IfExp is not allowed .* at position 1"),
    (_with(equations__v="q.real"), r"Attribute is not allowed"),
    (_with(equations__v="(u - F)/m % 2"), r"the operator Mod is not allowed"),
    (_with(equations__v="exp(q, 2)"), r"exp\(\) takes 1 argument, got 2"),
    (_with(equations__v="(u - F/m"), r"not a valid expression"),
    (_with(equations__v="'text'"), r"the constant 'text' is not allowed"),
    (_with(friction__model="coulomb"), r"model = 'coulomb' is not allowed: use 'switch' or 'lugre'"),
    (_with(friction__stick=None), r"needs 'stick'"),
    (_with(friction__velocity="v - F"), r"velocity = 'v - F' uses \['F'\], which depend on friction forces"),
    (_with(parameters__k="two"), r"parameters\['k'\] = 'two' is not allowed"),
    (_with(parameters__t=1.0), r"parameters\['t'\] = 't' is reserved"),
    (_with(signals={"q": "k"}), r"signals\['q'\] = 'q' is already used as a state"),
    (_with(states=[]), "states is missing or empty"),
    (_with(extra=1), r"description keys \['extra'\] are not known"),
    (_with(friction__slip="sign(w)*Fc*z"), r"slip = 'sign\(w\)\*Fc\*z': unknown name 'z'"),
])
def test_bad_descriptions_get_clear_errors(desc, match):
    with pytest.raises(hunting.SystemDefinitionError, match=match):
        hunting.model(desc)


@pytest.mark.parametrize("desc, match", [
    (_with(blocks=[{"output": "y", "input": "q", "tf": "s**2/(s + 1)"}]), r"improper .*numerator degree 2 > denominator degree 1"),
    (_with(equations__v="(u - F**2)/m"), r"not linear in the friction forces"),
    (_with(equations__q="v - F", equations__v="u/m"), r"the force 'F' does not act on the contact's velocity"),
    (_with(signals={"u": "-k*q - y"}, blocks=[{"output": "y", "input": "u", "tf": "2/(s + 1) + 1"}]),
     r"signals form a cycle: .*algebraic loop"),
])
def test_errors_found_by_algebra(desc, match):
    with pytest.raises(hunting.SystemDefinitionError, match=match):
        hunting.model(desc)


def test_negative_stick_bound_when_parameters_change():
    m = hunting.model(BELT)
    with pytest.raises(hunting.SystemDefinitionError, match=r"stick = 'Fs' is -1.0 at the parameter values"):
        m.with_params(Fs=-1.0)
    with pytest.raises(hunting.SystemDefinitionError, match=r"parameter 'K' is not a parameter"):
        m.with_params(K=1.0)
    with pytest.raises(hunting.SystemDefinitionError, match=r"state 'x' is not a state"):
        m.state(x=1.0)


# ------------------------------------------------------------------ linear blocks
def _block_response(m, block_states, input_state, output, w):
    """H(jw) of a compiled block from its realization: A, B from the analytic Jacobian, C, D
    from the block output at unit states (the output is linear in them)."""
    n = m.n_states
    bi = [m.layout.state(s) for s in block_states]
    ui = m.layout.state(input_state)
    J = m.jacobian(np.zeros(n), mode=0)
    A, B = J[np.ix_(bi, bi)], J[bi, ui]
    C = np.array([m.signals(np.eye(n)[i], mode=0)[output] for i in bi])
    D = m.signals(np.eye(n)[ui], mode=0)[output]
    return np.array([C @ np.linalg.solve(1j * wk * np.eye(len(bi)) - A, B) + D for wk in w])


def test_loop_shaped_controller_and_pade_delay_blocks():
    desc = {"parameters": {"K": 2.0, "tau_i": 0.5, "tau_d": 0.05, "wz": 20.0, "wp": 80.0, "wlp": 300.0,
                           "zeta": 0.7, "Td": 0.01, "a": 3.0, "b": 7.0},
            "states": ["e"], "equations": {"e": "0"},
            "blocks": [{"output": "u", "input": "e",
                        "tf": "K*(1 + 1/(tau_i*s) + tau_d*s)*(1 + s/wz)/(1 + s/wp)*wlp**2/(s**2 + 2*zeta*wlp*s + wlp**2)"},
                       {"output": "ud", "input": "e", "delay": "Td", "order": 3},
                       {"output": "y", "input": "e", "num": ["a", "b"], "den": [1, "b", "a"]}]}
    m = hunting.model(desc)
    assert m.state_names == ("e", "u_1", "u_2", "u_3", "u_4", "ud_1", "ud_2", "ud_3", "y_1", "y_2")
    w = np.logspace(-1, 3.5, 25)
    s = 1j * w
    p = dict(zip(m.param_names, m.params))
    H = (p["K"] * (1 + 1 / (p["tau_i"] * s) + p["tau_d"] * s) * (1 + s / p["wz"]) / (1 + s / p["wp"])
         * p["wlp"] ** 2 / (s ** 2 + 2 * p["zeta"] * p["wlp"] * s + p["wlp"] ** 2))
    got = _block_response(m, ["u_1", "u_2", "u_3", "u_4"], "e", "u", w)
    np.testing.assert_allclose(got, H, rtol=1e-10)
    control = pytest.importorskip("control")
    num, den = control.pade(p["Td"], 3)
    Hd = np.polyval(num, s) / np.polyval(den, s)
    np.testing.assert_allclose(_block_response(m, ["ud_1", "ud_2", "ud_3"], "e", "ud", w), Hd, rtol=1e-10)
    assert np.abs(Hd[w < 100] - np.exp(-s[w < 100] * p["Td"])).max() < 1e-6    # a delay at low frequency
    Hy = (p["a"] * s + p["b"]) / (s ** 2 + p["b"] * s + p["a"])
    np.testing.assert_allclose(_block_response(m, ["y_1", "y_2"], "e", "y", w), Hy, rtol=1e-12)


# ------------------------------------------------------------------ derivatives
def _fd(fun, z, h):
    cols = []
    for j in range(z.size):
        e = np.zeros_like(z)
        e[j] = h * max(1.0, abs(z[j]))
        cols.append((fun(z + e) - fun(z - e)) / (2 * e[j]))
    return np.array(cols).T


def test_belt_jacobians_against_sympy_by_hand_and_finite_differences():
    import sympy as sp
    m = hunting.load_model(EXAMPLES / "belt.json")
    q, v, M, k, Fc, Fs, vs, vb = sp.symbols("q v m k Fc Fs vs vb", real=True)
    rng = np.random.default_rng(1)
    for mode, s in ((0, 1), (1, -1)):
        w = v - vb                     # slip law with sign(w) = s, |w| = s w (the mode's side)
        f = sp.Matrix([v, (-k * q - s * (Fc + (Fs - Fc) * sp.exp(-s * w / vs))) / M])
        Jx = sp.lambdify([q, v, M, k, Fc, Fs, vs, vb], f.jacobian([q, v]))
        Jp = sp.lambdify([q, v, M, k, Fc, Fs, vs, vb], f.jacobian([M, k, Fc, Fs, vs, vb]))
        for _ in range(3):
            x = np.array([rng.normal(), 0.1 + s * rng.uniform(0.01, 0.2)])
            p = m.params
            np.testing.assert_allclose(m.jacobian(x, mode=mode), np.array(Jx(*x, *p), dtype=float), rtol=1e-13, atol=1e-14)
            np.testing.assert_allclose(m.param_jacobian(x, mode=mode), np.array(Jp(*x, *p), dtype=float),
                                       rtol=1e-13, atol=1e-14)
            fx = _fd(lambda z: m.system.evaluate(z, mode=mode), x, 1e-6)
            np.testing.assert_allclose(m.jacobian(x, mode=mode), fx, rtol=1e-7, atol=1e-8)
            fp = _fd(lambda z: m.system.with_param_array(z).evaluate(x, mode=mode), p, 1e-6)
            np.testing.assert_allclose(m.param_jacobian(x, mode=mode), fp, rtol=1e-7, atol=1e-8)
    # stick: v' = 0, q' = v
    np.testing.assert_array_equal(m.jacobian([0.1, 0.1], mode=2), [[0, 1], [0, 0]])


def test_lugre_jacobians_against_the_hand_written_kernel_and_finite_differences():
    from hunting.models import servo
    m = hunting.model("table8.1-lugre", K=0.3)
    loop = hunting.preset("table8.1-lugre", K=0.3)
    rng = np.random.default_rng(2)
    for mode, s in ((0, 1), (1, -1)):
        for _ in range(3):
            x = np.array([rng.normal(), s * rng.uniform(1e-3, 0.1), rng.normal(), rng.normal() * 2e-5])
            J_hand = np.zeros((4, 4))
            servo.servo_jac(mode, 0.0, x, loop.system.params, J_hand)
            np.testing.assert_allclose(m.jacobian(x, mode=mode), J_hand, rtol=1e-12, atol=1e-9)
            fx = _fd(lambda z: m.system.evaluate(z, mode=mode), x, 1e-7)
            np.testing.assert_allclose(m.jacobian(x, mode=mode), fx, rtol=1e-6, atol=1e-6 * np.abs(fx).max())
            p = m.params
            fp = _fd(lambda z: m.system.with_param_array(z).evaluate(x, mode=mode), p, 1e-6)
            np.testing.assert_allclose(m.param_jacobian(x, mode=mode), fp, rtol=1e-6, atol=1e-7 * np.abs(fp).max())


# ------------------------------------------------------------------ user models against solve_ivp
def _belt_reference(p, x0, T, n_events):
    """The belt model by scipy: slip phases by solve_ivp (DOP853) to the terminal event w = 0,
    stick phases in closed form (v = vb, q grows at vb until |k q| = Fs). Returns event times,
    states after each event and a function of time for the trajectory."""
    from scipy.integrate import solve_ivp
    m, k, Fc, Fs, vs, vb = (p[n] for n in ("m", "k", "Fc", "Fs", "vs", "vb"))

    def slip(t, y):
        w = y[1] - vb
        return [y[1], (-k * y[0] - np.sign(w) * (Fc + (Fs - Fc) * np.exp(-abs(w) / vs))) / m]

    t, y = 0.0, np.array(x0, float)
    times, states, pieces = [], [], []
    stuck = y[1] == vb and abs(k * y[0]) <= Fs
    while t < T and len(times) < n_events:
        if stuck:                       # F = -k q until it leaves [-Fs, Fs]; q moves at vb
            q_end = (Fs if vb > 0 else -Fs) / k
            t_end = t + (q_end - y[0]) / vb
            q0, t0 = y[0], t
            pieces.append((t0, t_end, lambda s, q0=q0, t0=t0: np.array([q0 + vb * (s - t0), vb + 0 * s])))
            t, y = t_end, np.array([q_end, vb])
            stuck = False
        else:
            side = np.sign(y[1] - vb) if y[1] != vb else np.sign(-k * y[0])      # break-away direction
            ev = lambda t, y: y[1] - vb  # noqa: E731
            ev.terminal, ev.direction = True, -side
            sol = solve_ivp(slip, (t, T), y, method="DOP853", rtol=1e-13, atol=1e-15, events=ev, dense_output=True)
            pieces.append((t, sol.t[-1], lambda s, f=sol.sol: f(s)))
            t, y = sol.t[-1], sol.y[:, -1].copy()
            if sol.status != 1:
                break
            y[1] = vb
            stuck = abs(k * y[0]) <= Fs
        times.append(t)
        states.append(y.copy())

    def at(s):
        for a, b, fun in pieces:
            if a <= s <= b:
                return fun(s)
        raise ValueError(s)
    return np.array(times), np.array(states), at


def test_belt_against_solve_ivp_with_stick_events():
    m = hunting.load_model(EXAMPLES / "belt.json")
    p = dict(zip(m.param_names, m.params))
    for x0 in ([0.0, 0.1], [-0.3, 0.0]):
        tr = hunting.simulate(m.system, x0, (0.0, 30.0), rtol=1e-12, atol=1e-14)
        assert tr.success
        t_ref, x_ref, at = _belt_reference(p, x0, 30.0, len(tr.events))
        n = min(len(t_ref), len(tr.events))
        assert n >= 8
        np.testing.assert_allclose(tr.events.t[:n], t_ref[:n], atol=1e-9)
        np.testing.assert_allclose(tr.events.x_after[:n], x_ref[:n], atol=1e-9)
        # stick phases hold w = 0 exactly; the trajectory agrees between events
        stick = tr.mode == 2
        assert stick.any() and np.all(tr.x[stick, 1] == p["vb"])
        for s in np.linspace(0.3, t_ref[n - 1] - 0.3, 17):
            i = np.searchsorted(tr.t, s)
            if tr.t[i] == s or tr.mode[i - 1] != tr.mode[i]:
                continue
            xs = hunting.simulate(m.system, x0, (0.0, s), rtol=1e-12, atol=1e-14).x_final
            np.testing.assert_allclose(xs, at(s), atol=1e-9)


def test_pid_lugre_loop_against_solve_ivp():
    """Canudas de Wit et al. (1995): PID (kp 3, kv 6, ki 4) on a unit mass with LuGre friction
    hunts around x_d = 1; scipy's Radau with restarts at v = 0 (the kink of |v|). The model
    carries a LuGre observer zh written with abs(v): abs of a contact velocity takes the mode's
    side in the equations too, so the field has no kink inside a mode and zh follows z."""
    from scipy.integrate import solve_ivp
    d = json.loads((EXAMPLES / "pid_lugre.json").read_text())
    d["states"].append("zh")
    d["equations"]["zh"] = "v - sigma0*abs(v)*zh/(Fc + (Fs - Fc)*exp(-(v/vs)**2))"
    m = hunting.model(d)
    assert "abs(" not in m.cache_path.read_text().split("def vf")[1].split("def guards")[0]
    p = dict(zip(m.param_names, m.params))

    def f(t, y):
        x, v, xi, z = y
        g = p["Fc"] + (p["Fs"] - p["Fc"]) * np.exp(-(v / p["vs"]) ** 2)
        zd = v - p["sigma0"] * abs(v) * z / g
        F = p["sigma0"] * z + p["sigma1"] * zd + p["sigma2"] * v
        return [v, (-p["kp"] * (x - p["xd"]) - p["kv"] * v - p["ki"] * xi - F) / p["m"], x - p["xd"], zd]

    T = 6.0
    te = np.linspace(0, T, 61)
    t, y, ref = 0.0, np.zeros(4), {}
    for _ in range(50):
        side = np.sign(y[1]) if y[1] != 0 else np.sign(f(t, y)[1])
        ev = lambda t, y: y[1]  # noqa: E731
        ev.terminal, ev.direction = True, -side
        sol = solve_ivp(f, (t, T), y, method="Radau", rtol=1e-10, atol=[1e-11, 1e-11, 1e-11, 1e-15], events=ev,
                        dense_output=True, first_step=1e-8)
        for s in te[(te >= t) & (te <= sol.t[-1])]:
            ref[s] = sol.sol(s)
        t, y = sol.t[-1], sol.y[:, -1].copy()
        if sol.status != 1:
            break
        y[1] = 0.0
    assert t == T
    tr = hunting.simulate(m.system, m.state(), (0, T), method="radau", rtol=1e-10, atol=1e-13, t_eval=te)
    X = np.array([ref[s] for s in te])
    assert np.abs(tr.x[:, :3] - X[:, :3]).max() < 1e-8 and np.abs(tr.x[:, 3] - X[:, 3]).max() < 1e-12
    assert np.abs(tr.x[:, 4] - tr.x[:, 3]).max() < 1e-18
    assert tr.x[:, 0].max() > 1.4 and len(tr.events) >= 3          # it hunts: overshoot and reversals


# ------------------------------------------------------------------ thesis values through described systems
class _Described:
    """A preset loop whose compiled system is replaced by the one built from its description
    (the event-map code reads the break-away geometry from the loop, the flows from .system)."""

    def __init__(self, loop, system):
        self._loop, self.system = loop, system

    def __getattr__(self, name):
        return getattr(self._loop, name)


@pytest.mark.parametrize("kw, cycles, eq_stable", [
    (dict(), [(0.0034, False), (0.2523, True)], True),          # Table 9.2
    (dict(beta=1.0), [(0.2314, True)], False),                  # Table 9.3
    (dict(beta=0.5), [(0.1786, True)], False),
    (dict(beta="inf"), [(0.1485, True)], False),
])
def test_tables_9_2_and_9_3_from_the_described_loop(kw, cycles, eq_stable):
    from hunting.eventmap import fixed_points
    m = hunting.model("table9.1", **kw)
    if kw.get("beta") not in (None, "inf"):
        assert m.system.vector_field is hunting.model("table9.1").system.vector_field   # beta is a value
    fps = fixed_points(_Described(hunting.preset("table9.1", **kw), m.system), np.linspace(0.0, 0.5, 501), 2)
    eq = [f for f in fps if f.kind == "equilibrium"]
    cyc = [f for f in fps if f.kind == "cycle"]
    assert len(eq) == 1 and eq[0].stable == eq_stable
    assert [(round(f.d, 4), f.stable) for f in cyc] == cycles


def test_lugre_monodromy_of_the_described_loop_matches_the_hand_written():
    from hunting.continuation import flow
    m = hunting.model("table8.1-lugre", K=0.3)
    loop = hunting.preset("table8.1-lugre", K=0.3)
    x0 = np.array([0.0, 0.05, -0.01, 2e-5])
    kw = dict(method="radau", rtol=1e-10, atol=1e-13)
    a = flow(m.system, x0, 3.0, param_direction=m.param_direction("K"), **kw)
    dp = (loop.system.params - hunting.preset("table8.1-lugre", K=0.3 - 1e-6).system.params) / 1e-6
    b = flow(loop.system, x0, 3.0, param_direction=dp, **kw)
    assert a.ok and b.ok and len(a.event_times) >= 2
    np.testing.assert_allclose(a.x, b.x, rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(a.Phi, b.Phi, rtol=1e-5, atol=1e-6 * np.abs(b.Phi).max())
    np.testing.assert_allclose(a.dx_dmu, b.dx_dmu, rtol=1e-4, atol=1e-5 * np.abs(b.dx_dmu).max())
    np.testing.assert_allclose(a.event_times, b.event_times, atol=1e-9)


@pytest.mark.slow
def test_lugre_fold_of_the_described_loop():
    """Chapter 8: the cyclic fold at K = 0.6203 on the branch of the loop built from its
    description (continuation in K by name through the layout)."""
    from hunting.continuation import find_cycle, shoot
    from hunting.continuation.branch import ContinuationOptions, continue_orbit
    from hunting.continuation.hunting_branch import servo_amplitude
    m = hunting.model("table8.1-lugre", K=0.3)
    po = shoot(m.system, *(lambda o: (o.x0, o.period))(find_cycle("table8.1-lugre", {"K": 0.3})))
    br = continue_orbit(lambda mu: m.system.with_param_array(m.params_with(K=mu)), po, 0.3, 1.0, param="K",
                        options=ContinuationOptions(jacobian_method="radau"), stop_at_mu=0.615,
                        amplitude=servo_amplitude)
    fold = next(s for s in br.special if s.kind == "fold")
    assert fold.param == pytest.approx(0.6203, abs=5e-5)


STACKED = {
    "name": "stacked blocks",
    "parameters": {"m1": 1.0, "m2": 0.5, "k1": 1.0, "k2": 0.5, "A": 2.0, "om": 1.3,
                   "FcA": 0.8, "FsA": 1.0, "FcB": 0.3, "FsB": 0.4, "vs": 0.1},
    "states": ["q1", "v1", "q2", "v2"],
    "signals": {"u1": "-k1*q1", "u2": "-k2*q2 + A*sin(om*t)"},
    "equations": {"q1": "v1", "v1": "(u1 - FA + FB)/m1", "q2": "v2", "v2": "(u2 - FB)/m2"},
    "friction": [
        {"name": "ground", "force": "FA", "velocity": "v1", "model": "switch",
         "slip": "sign(w)*(FcA + (FsA - FcA)*exp(-(w/vs)**2))", "stick": "FsA"},
        {"name": "top", "force": "FB", "velocity": "v2 - v1", "model": "switch",
         "slip": "sign(w)*(FcB + (FsB - FcB)*exp(-(w/vs)**2))", "stick": "FsB"}]}


def _stacked_reference(p, T, n_events):
    """Block 2 on block 1 on the ground, block 2 driven by A sin(om t): an event-driven
    solve_ivp with the stick forces of each contact pair written out by hand."""
    from scipy.integrate import solve_ivp
    P = p

    def law(w, s, Fc, Fs):
        return s * (Fc + (Fs - Fc) * np.exp(-(w / P["vs"]) ** 2))

    def forces(t, y, a, b):
        q1, v1, q2, v2 = y
        u1, u2 = -P["k1"] * q1, -P["k2"] * q2 + P["A"] * np.sin(P["om"] * t)
        m1, m2 = P["m1"], P["m2"]
        FA = law(v1, a, P["FcA"], P["FsA"]) if a else None
        FB = law(v2 - v1, b, P["FcB"], P["FsB"]) if b else None
        if a == 0 and b == 0:
            FB = u2
            FA = u1 + u2
        elif a == 0:
            FA = u1 + FB                                  # v1' = 0
        elif b == 0:
            FB = (m1 * u2 - m2 * (u1 - FA)) / (m1 + m2)   # v1' = v2'
        return u1, u2, FA, FB

    def rhs(t, y, a, b):
        u1, u2, FA, FB = forces(t, y, a, b)
        return [y[1], (u1 - FA + FB) / P["m1"], y[3], (u2 - FB) / P["m2"]]

    def settle(t, y, a, b):
        for _ in range(3):
            _, _, FA, FB = forces(t, y, a, b)
            if a == 0 and abs(FA) > P["FsA"]:
                a = int(np.sign(FA))
            elif b == 0 and abs(FB) > P["FsB"]:
                b = int(np.sign(FB))
            else:
                break
        return a, b

    t, y = 0.0, np.zeros(4)
    a, b = settle(t, y, 0, 0)
    times, states, modes = [], [], []
    while t < T and len(times) < n_events:
        evs = []
        if a:
            evs.append(("A0", lambda t, y: y[1], -a))
        else:
            evs += [("A+", lambda t, y: forces(t, y, a, b)[2] - P["FsA"], 1),
                    ("A-", lambda t, y: forces(t, y, a, b)[2] + P["FsA"], -1)]
        if b:
            evs.append(("B0", lambda t, y: y[3] - y[1], -b))
        else:
            evs += [("B+", lambda t, y: forces(t, y, a, b)[3] - P["FsB"], 1),
                    ("B-", lambda t, y: forces(t, y, a, b)[3] + P["FsB"], -1)]
        fns = []
        for _, fn, d in evs:
            fn.terminal, fn.direction = True, d
            fns.append(fn)
        sol = solve_ivp(lambda t, y: rhs(t, y, a, b), (t, T), y, method="DOP853", rtol=1e-12, atol=1e-14,
                        events=fns)
        t, y = sol.t[-1], sol.y[:, -1].copy()
        if sol.status != 1:
            break
        which = next(name for (name, _, _), te in zip(evs, sol.t_events) if te.size)
        if which == "A0":
            y[1], a = 0.0, 0
        elif which == "B0":
            y[3], b = y[1], 0
        elif which[0] == "A":
            a = 1 if which == "A+" else -1
        else:
            b = 1 if which == "B+" else -1
        a, b = settle(t, y, a, b)
        times.append(t)
        states.append(y.copy())
        modes.append((a, b))
    return np.array(times), np.array(states), modes


def test_two_contacts_stacked_blocks_against_solve_ivp():
    m0 = hunting.model(STACKED)
    assert len(m0.mode_names) == 9 and m0.mode_names[8] == "ground:stick,top:stick"
    ground, top = m0.contacts
    assert (ground.surface_state, top.surface_state) == (1, 3)     # top moves v2 onto v1, not v1
    part = {"slip+": 1, "slip-": -1, "stick": 0}
    seen = set()
    for A, om in ((2.0, 1.3), (1.2, 0.5)):        # every slip/stick pair; both stuck in the second
        m = m0.with_params(A=A, om=om)
        tr = hunting.simulate(m.system, m.state(), (0.0, 25.0), rtol=1e-12, atol=1e-14)
        assert tr.success
        t_ref, x_ref, modes = _stacked_reference(dict(zip(m.param_names, m.params)), 25.0, len(tr.events))
        got = [(part[ground.part(k)], part[top.part(k)]) for k in tr.events.mode_to]
        n = len(t_ref)
        assert n >= 6 and got[:n] == modes
        np.testing.assert_allclose(tr.events.t[:n], t_ref, atol=1e-9)
        np.testing.assert_allclose(tr.events.x_after[:n], x_ref, atol=1e-9)
        seen |= set(modes)
    assert {(0, 0), (0, 1), (0, -1), (1, 1), (-1, -1)} <= seen


# ------------------------------------------------------------------ files, builder, docs
def test_yaml_json_text_and_builder_give_the_same_model(tmp_path):
    import json
    yaml = pytest.importorskip("yaml")
    f = tmp_path / "belt.yaml"
    f.write_text(yaml.safe_dump(json.loads((EXAMPLES / "belt.json").read_text()), sort_keys=False))
    a = hunting.load_model(f, k=2.5)
    b = hunting.model((EXAMPLES / "belt.json").read_text(), k=2.5)
    c = (hunting.ModelBuilder("belt").parameters(m=1.0, k=2.0, Fc=0.3, Fs=0.5, vs=0.05, vb=0.1)
         .states("q", "v").signal("u", "-k*q").equations(q="v", v="(u - F)/m")
         .friction(force="F", velocity="v - vb", model="switch",
                   slip="sign(w)*(Fc + (Fs - Fc)*exp(-abs(w)/vs))", stick="Fs").build(k=2.5))
    assert a.description == b.description == c.description
    assert a.param_names == b.param_names == c.param_names == ("m", "k", "Fc", "Fs", "vs", "vb")
    assert a.system.vector_field is b.system.vector_field is c.system.vector_field
    assert hunting.model(a.description).system.param("k") == 2.5
    with pytest.raises(hunting.SystemDefinitionError, match="does not exist"):
        hunting.load_model(tmp_path / "missing.json")
    with pytest.raises(hunting.SystemDefinitionError, match="neither a model file nor a preset"):
        hunting.model("no-such-thing")


def test_moving_belt_with_time_dependent_speed_and_signals():
    """w = v - vb (1 + a sin(W t)): in stick the block rides the belt, v(t) = vb(t), and the
    solved force is the spring's plus the belt's acceleration times the mass."""
    d = json.loads((EXAMPLES / "belt.json").read_text())
    d["parameters"].update(a=0.5, W=2.0)
    d["friction"]["velocity"] = "v - vb*(1 + a*sin(W*t))"
    m = hunting.model(d)
    p = dict(zip(m.param_names, m.params))
    tr = hunting.simulate(m.system, m.state(v=0.1), (0.0, 20.0), rtol=1e-12, atol=1e-14)
    assert tr.success and tr.mode[0] == 2 and len(tr.events) >= 4
    st = tr.mode == 2
    vb_t = p["vb"] * (1 + p["a"] * np.sin(p["W"] * tr.t[st]))
    assert np.abs(tr.x[st, 1] - vb_t).max() < 1e-9          # held on the belt to integration accuracy
    k = int(np.flatnonzero(st)[len(np.flatnonzero(st)) // 2])
    sig = m.signals(tr.x[k], tr.t[k], mode=2)
    acc = p["vb"] * p["a"] * p["W"] * np.cos(p["W"] * tr.t[k])
    assert sig["F"] == pytest.approx(-p["k"] * tr.x[k, 0] - p["m"] * acc, abs=1e-12)
    assert sig["u"] == pytest.approx(-p["k"] * tr.x[k, 0], abs=1e-15)
    brk = np.flatnonzero(tr.events.mode_from == 2)
    for i in brk:                                         # break-away exactly at |F| = Fs
        F = m.signals(tr.events.x_before[i], tr.events.t[i], mode=2)["F"]
        assert abs(abs(F) - p["Fs"]) < 1e-9


def test_docstring_examples():
    import doctest
    from hunting.describe import api, compiled
    for mod in (api, compiled):
        res = doctest.testmod(mod, optionflags=doctest.ELLIPSIS)
        assert res.failed == 0 and res.attempted > 0


def test_servo_loop_description_with_cogging_and_asymmetric_friction():
    """ServoLoop.description(): gains form, direction-dependent curve, cogging harmonics and a
    constant force, against the hand-written kernel (vector field and guards in every mode)."""
    from hunting.models import PID, Cogging, Plant, ServoLoop, StribeckCurve, Switch
    from hunting.models.friction import DirectionalCurve
    loop = ServoLoop(Plant(2.0, 1.5, setpoint=0.01, cogging=Cogging.harmonic(0.02, cos=[0.3, 0.1], sin=[0.2, 0.0]),
                           external_force=0.4),
                     Switch(DirectionalCurve(StribeckCurve(1.0, 1.5, 0.05, 0.7, 0.2), StribeckCurve(0.8, 1.1, 0.03, 2.0, 0.3))),
                     PID(20.0, 3.0, 10.0))
    m = hunting.model(loop.description())
    assert set(m.param_names) >= {"kp", "kd", "ki", "Fc_neg", "cog_a2", "f_ext"}
    rng = np.random.default_rng(3)
    for _ in range(5):
        x = rng.normal(size=3) * [0.01, 0.1, 0.01]
        for mode in range(3):
            x = x * [1, 0, 1] if mode == 2 else x          # stick holds x2 = 0
            np.testing.assert_allclose(m.system.evaluate(x, mode=mode), loop.system.evaluate(x, mode=mode),
                                       rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(m.system.guard_values(x, mode=mode), loop.system.guard_values(x, mode=mode),
                                       rtol=1e-12, atol=1e-12)
        xr = x * [1, 0, 1]
        assert m.system.initial_mode(xr) == loop.system.initial_mode(xr)


def test_belt_flow_sensitivities_across_stick_and_slip():
    """Monodromy-type Jacobians of the described belt (saltation at stick entry and break-away)
    and the parameter sensitivity by name, against central differences of the flow map."""
    from hunting.continuation import flow
    from hunting.continuation.flow import fd_jacobian
    m = hunting.load_model(EXAMPLES / "belt.json")
    x0 = np.array([0.1, -0.05])
    kw = dict(rtol=1e-12, atol=1e-14)
    f = flow(m.system, x0, 9.0, param_direction=m.param_direction("k"), **kw)
    assert list(f.modes) == [1, 2, 1, 2, 1]                   # slip-, stick, slip-, stick, slip-
    np.testing.assert_allclose(f.Phi, fd_jacobian(m.system, x0, 9.0, **kw), atol=2e-8)
    h = 1e-6
    xp = flow(m.with_params(k=2 + h).system, x0, 9.0, sensitivity=False, **kw).x
    xm = flow(m.with_params(k=2 - h).system, x0, 9.0, sensitivity=False, **kw).x
    np.testing.assert_allclose(f.dx_dmu, (xp - xm) / (2 * h), atol=1e-7)



@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.json")) + sorted(EXAMPLES.glob("*.yaml")),
                         ids=lambda p: p.name)
def test_example_files_load_and_run(path):
    m = hunting.load_model(path)
    tr = hunting.simulate(m.system, m.state(), (0.0, 0.5), method="radau", rtol=1e-8, atol=1e-12)
    assert tr.success and m.description["name"] == m.name


@pytest.mark.parametrize("desc, label", [
    (_with(friction__colour=1), "friction['friction'] (switch) keys ['colour']"),
    (_with(friction__model="coulomb"), "friction['friction'].model"),
    (_with(friction__stick=None), "friction['friction'] (switch) needs 'stick'"),
    (_with(friction__name="2nd"), "friction['friction'].name = '2nd' must be an identifier"),
    (_with(friction__velocity="vb"), "friction['friction'].velocity"),
    (_with(friction__name="belt", friction__colour=1), "friction['belt'] (switch) keys"),
    (dict(_with(), friction=[_with()["friction"], "F2"]), "friction['friction2'] = 'F2' must be a mapping"),
])
def test_contact_errors_name_the_contact_one_way(desc, label):
    """Every description error names a contact friction['<name>'] (its name or the default of its
    place), the structural checks too: they said friction[0] where the later ones said
    friction['friction'] for the same contact (reviewer's finding)."""
    with pytest.raises(hunting.SystemDefinitionError) as e:
        hunting.model(desc)
    assert str(e.value).startswith(label), str(e.value)
    assert "friction[0]" not in str(e.value) and "friction[1]" not in str(e.value)
