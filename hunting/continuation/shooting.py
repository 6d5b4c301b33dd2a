"""Single shooting for periodic orbits of piecewise-smooth systems, Floquet multipliers.

Unknowns: the initial state on a section x[i] = c (the phase condition) and the period T.
Residual r = phi(T; x0) - x0; Newton's Jacobian [(Phi - I) without column i | f(phi(T))]
uses the monodromy matrix with its saltation matrices, so unstable cycles converge as readily
as stable ones.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ConvergenceError, SystemDefinitionError, status_message
from ..integrate.simulate import simulate
from ..system import PiecewiseSystem
from .flow import flow
from .status import OrbitStatus


@dataclass(frozen=True)
class ShootingOptions:
    """tol : Newton stops when the scaled residual max|r_i| / scale_i <= tol (scale_i =
    max(|x0_i|, floor)); max_iter : Newton iterations; rtol, atol, method : integration;
    floor : absolute floor of the state scales."""

    tol: float = 1e-9
    max_iter: int = 30
    rtol: float = 1e-11
    atol: float = 1e-13
    method: str = "dop853"
    floor: float = 1e-6
    max_events: int = 10_000
    max_steps: int = 1_000_000

    def __post_init__(self):
        for name in ("tol", "rtol", "atol", "floor"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise SystemDefinitionError(f"{name} = {v!r} is not allowed: it must be a finite number > 0")
        if self.method not in ("dop853", "dp5", "radau"):
            raise SystemDefinitionError(f"method = {self.method!r} is not allowed: use dop853, dp5 or radau")


@dataclass(frozen=True)
class PeriodicOrbit:
    """A periodic orbit.

    x0 : (n,) state on the section; period : T [s]; modes : the mode sequence over one period;
    event_times : (k,) within [0, T]; monodromy : (n, n); multipliers : (n,) complex, the trivial
    one first, then by decreasing modulus; trivial_error : |lambda_trivial - 1|; amplitude :
    max |x1| over the orbit; stable : every non-trivial |lambda| < 1; status : OrbitStatus;
    message : what happened and, on failure, what to change; iterations : Newton iterations;
    residual : final scaled residual; params : the flat parameter array of the orbit;
    section : the state held fixed by the phase condition (x0[section] is on the section)."""

    x0: np.ndarray
    period: float
    modes: tuple
    event_times: np.ndarray
    monodromy: np.ndarray
    multipliers: np.ndarray
    trivial_error: float
    amplitude: float
    stable: bool
    status: OrbitStatus
    message: str
    iterations: int
    residual: float
    params: np.ndarray = field(repr=False, default=None)
    section: int = 0

    @property
    def success(self) -> bool:
        return self.status == OrbitStatus.SUCCESS

    @property
    def nontrivial(self) -> np.ndarray:
        return self.multipliers[1:]


def floquet(M: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, float]:
    """Multipliers of a monodromy matrix, the trivial one (eigenvector along the flow f) first,
    the others by decreasing modulus; and |lambda_trivial - 1|."""
    lam, vec = np.linalg.eig(M)
    fn = f / max(np.linalg.norm(f), 1e-300)
    align = np.abs(np.conj(vec.T) @ fn) / np.maximum(np.linalg.norm(vec, axis=0), 1e-300)
    # the trivial multiplier: eigenvector along f, among those near 1
    score = align - 0.1 * np.abs(lam - 1.0)
    k = int(np.argmax(score))
    rest = np.delete(lam, k)
    rest = rest[np.argsort(-np.abs(rest))]
    return np.concatenate([[lam[k]], rest]), float(abs(lam[k] - 1.0))


def orbit_amplitude(system: PiecewiseSystem, x0, T, params=None, n: int = 4001, method="dop853") -> float:
    """max |x1| over one period, from output at n points plus every event state."""
    sys_ = system if params is None else system.with_param_array(params)
    tr = simulate(sys_, x0, (0.0, T), t_eval=np.linspace(0.0, T, n), rtol=1e-10, atol=1e-13, method=method)
    a = np.max(np.abs(tr.x[:, 0]))
    if len(tr.events):
        a = max(a, np.max(np.abs(tr.events.x_before[:, 0])))
    return float(a)


def shoot(system: PiecewiseSystem, x0, T, *, section: int = 0, params=None,
          options: ShootingOptions | None = None, throw: bool = False) -> PeriodicOrbit:
    """Converge on a periodic orbit from a guess (x0, T) by single shooting.

    Parameters
    ----------
    system : PiecewiseSystem (autonomous)
    x0 : (n,) guess of a state on the orbit; x0[section] stays fixed (the phase condition: the
        section x[section] = x0[section], which the orbit must cross transversally)
    T : float
        Period guess [time unit of the system].
    section : int
        Index of the state held fixed.
    params : flat parameter array replacing ``system.params``, optional
    options : ShootingOptions
    throw : raise ConvergenceError (carrying the PeriodicOrbit) when the status is not SUCCESS

    Returns
    -------
    PeriodicOrbit
        status is an :class:`OrbitStatus`: SUCCESS, SINGULAR_JACOBIAN, NOT_CONVERGED,
        EQUILIBRIUM (the iteration reached a rest point, periodic for every T) or
        INTEGRATION_FAILED (with the integrator's status and advice in the message).

    Examples
    --------
    The hunting cycle of the chapter-8 Switch loop at K = 0.3 from a rough guess on the
    section x1 = 0:

    >>> from hunting import preset
    >>> from hunting.continuation import shoot
    >>> lp = preset("table8.1-switch", K=0.3)
    >>> po = shoot(lp.system, [0.0, 0.079, -0.0166], 14.3)
    >>> po.status.name, round(po.period, 4), po.stable
    ('SUCCESS', 14.3081, True)
    """
    opt = options or ShootingOptions()
    x = system.check_state(x0).copy()
    n = system.n_states
    if not 0 <= section < n:
        raise SystemDefinitionError(f"section = {section!r} is not a state index 0..{n - 1}")
    if not (np.isfinite(T) and T > 0):
        raise SystemDefinitionError(f"T = {T!r} is not allowed: the period guess must be > 0")
    p = system.params if params is None else np.ascontiguousarray(params, dtype=float)
    free = [i for i in range(n) if i != section]
    scale = np.append(np.maximum(np.maximum(np.abs(x), 0.1 * np.max(np.abs(x))), opt.floor), max(T, 1e-12))
    T = float(T)
    kw = dict(params=p, method=opt.method, rtol=opt.rtol, atol=opt.atol, max_events=opt.max_events,
              max_steps=opt.max_steps)

    def evaluate(xv, Tv, sensitivity=True):
        fl = flow(system, xv, Tv, sensitivity=sensitivity, **kw)
        return fl, (fl.x - xv)

    fl, r = evaluate(x, T)
    status, message = OrbitStatus.SUCCESS, "converged"
    it = 0
    res = np.inf
    for it in range(1, opt.max_iter + 1):
        if not fl.ok:
            status, message = OrbitStatus.INTEGRATION_FAILED, (f"the flow failed at Newton iteration {it} with "
                                                               f"{fl.status.name}: {status_message(fl.status)}")
            break
        res = float(np.max(np.abs(r) / scale[:n]))
        if res <= opt.tol:
            break
        A = np.column_stack([(fl.Phi - np.eye(n))[:, free], fl.f])
        try:
            # singular in the scaled unknowns (states of very different sizes, e.g. the LuGre
            # bristle state, must not read as singular)
            colscale = np.append(scale[free], scale[n])
            if np.linalg.cond(A * colscale[None, :] / scale[:n, None]) > 1e14:
                raise np.linalg.LinAlgError
            dz = np.linalg.solve(A, -r)
        except np.linalg.LinAlgError:
            status, message = OrbitStatus.SINGULAR_JACOBIAN, (f"singular shooting Jacobian at iteration {it}: "
                                                              + OrbitStatus.SINGULAR_JACOBIAN.advice)
            break
        # the full step is tried with sensitivities (it is usually taken); shorter trial steps
        # without them (a LuGre flow with them costs several plain ones), and the accepted
        # one then gets its own flow with them
        lam = 1.0
        for _ in range(12):
            xn = x.copy()
            xn[free] += lam * dz[:-1]
            Tn = T + lam * dz[-1]
            if Tn > 0:
                fln, rn = evaluate(xn, Tn, sensitivity=lam == 1.0)
                if fln.ok and np.max(np.abs(rn) / scale[:n]) < (1 - 0.25 * lam) * res + 1e-300:
                    if lam != 1.0:
                        fln, rn = evaluate(xn, Tn)
                    break
            lam *= 0.5
        else:
            status, message = OrbitStatus.NOT_CONVERGED, (f"damped Newton could not reduce the residual ({res:.3g}) "
                                                          f"at iteration {it}: improve the guess (x0, T)")
            break
        x, T, fl, r = xn, Tn, fln, rn
    else:
        status, message = OrbitStatus.NOT_CONVERGED, (f"no convergence in {opt.max_iter} iterations (residual "
                                                      f"{res:.3g}): improve the guess (x0, T) or raise max_iter")
    if status == OrbitStatus.SUCCESS:
        res = float(np.max(np.abs(r) / scale[:n]))
        if res > opt.tol:
            status, message = OrbitStatus.NOT_CONVERGED, f"residual {res:.3g} above tol {opt.tol:.3g}"
        elif np.linalg.norm(fl.f) <= 1e-9 * max(np.linalg.norm(x), 1e-300) / T:
            # a rest point is periodic for every T: not a cycle
            status, message = OrbitStatus.EQUILIBRIUM, ("converged to an equilibrium (the vector field vanishes "
                                                     "on the orbit): start closer to the cycle")
    mult, triv = (floquet(fl.Phi, fl.f) if fl.ok else (np.full(n, np.nan + 0j), np.nan))
    amp = orbit_amplitude(system, x, T, p, method=opt.method) if status == OrbitStatus.SUCCESS else np.nan
    stable = bool(np.all(np.abs(mult[1:]) < 1.0)) if status == OrbitStatus.SUCCESS else False
    orbit = PeriodicOrbit(x, float(T), tuple(int(m) for m in fl.modes), fl.event_times, fl.Phi, mult, triv, amp,
                          stable, status, message, it, res, p, section)
    if throw and status != OrbitStatus.SUCCESS:
        raise ConvergenceError(f"{system.name}: shooting failed: {message}", orbit)
    return orbit


def guess_from_stick_error(loop, d: float, *, section: int = 0) -> tuple[np.ndarray, float]:
    """A shooting guess for the symmetric stick-slip cycle with stick error |d| (a fixed point of
    the event map): start at the break-away state of -|d|, find the first upward crossing of
    x[section] = 0 and the time to the next one (Switch loops with an exact stick mode)."""
    from ..eventmap.engine import evaluate_map
    d = -abs(float(d))
    mv = evaluate_map(loop, [d], 2)
    if not mv.ok[0]:
        raise ConvergenceError(f"{loop.name}: the event map failed at d = {d}", mv)
    mv1 = evaluate_map(loop, [d], 1)
    period = float(mv.slip_time[0] + mv1.stick_time[0] + mv.stick_time[0])
    X0, mode0 = loop.breakaway_state([d])
    n_out = 400001
    t_end = 2.2 * period
    tr = simulate(loop.system, X0[0], (0.0, t_end), mode0=int(mode0[0]), rtol=1e-11, atol=1e-14,
                  t_eval=np.linspace(0.0, t_end, n_out))
    s = tr.x[:, section]
    up = np.flatnonzero((s[:-1] < 0) & (s[1:] >= 0) & (tr.x[1:, 1] > 0))
    if up.size < 2:
        raise ConvergenceError(f"{loop.name}: no two upward crossings of x{section + 1} = 0 from d = {d}", tr)
    k = up[0]
    t1 = tr.t[k] + (tr.t[k + 1] - tr.t[k]) * (-s[k]) / (s[k + 1] - s[k])
    x1 = simulate(loop.system, X0[0], (0.0, t1), mode0=int(mode0[0]), rtol=1e-12, atol=1e-15).x_final.copy()
    x1[section] = 0.0
    return x1, period
