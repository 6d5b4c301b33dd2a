"""The flow map x(T) = phi(T; x0) of a piecewise-smooth system and its Jacobian (monodromy when
the orbit closes): variational equations integrated with the state, saltation matrices at
every event (hunting.integrate._kernel)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import Status, SystemDefinitionError
from ..integrate import _kernel as K
from ..integrate._tableau import METHODS
from ..system import PiecewiseSystem, kernel_jacobian


@dataclass(frozen=True)
class Flow:
    """x : (n,) state at T; Phi : (n, n) d x(T) / d x0; mode : mode at T; f : (n,) vector field at
    x(T) in that mode; events : (k,) event times; modes : (k + 1,) mode sequence; status;
    dx_dmu : (n,) d x(T) / d mu when a parameter direction was given."""

    x: np.ndarray
    Phi: np.ndarray
    mode: int
    f: np.ndarray
    event_times: np.ndarray
    modes: np.ndarray
    guards: np.ndarray
    status: Status
    dx_dmu: np.ndarray | None = None
    event_states: np.ndarray | None = None

    @property
    def ok(self) -> bool:
        return self.status in (Status.SUCCESS, Status.STOPPED)


def flow(system: PiecewiseSystem, x0, T: float, *, mode0: int | None = None, params=None,
         method: str = "dop853", rtol: float = 1e-11, atol: float = 1e-13, sensitivity: bool = True,
         max_steps: int = 500_000, max_events: int = 10_000, guard_tol: float = 1e-12,
         stop_mode: int = -1, stop_count: int = 1, param_direction=None, max_step: float = np.inf) -> Flow:
    """Integrate over [0, T] (or until the stop condition) with the fundamental matrix Phi.

    max_step : bound on the step [time unit] (events are found where a guard changes sign
    between steps: a guard that dips through zero and back within one step goes unseen, e.g.
    a short break-away while another part of the system moves fast).

    param_direction : (len(params),) d params / d mu of a scalar parameter mu: the parameter
    sensitivity d x(T) / d mu is integrated with Phi (variational column with forcing f_mu,
    event terms from the guards' and transitions' mu-derivatives) and returned as dx_dmu."""
    x0 = system.check_state(x0)
    hmax = float(max_step)
    if not hmax > 0:
        raise SystemDefinitionError(f"max_step = {max_step!r} is not allowed: it must be > 0 (inf: no bound)")
    if not (np.isfinite(T) and T > 0):
        raise SystemDefinitionError(f"T = {T!r} is not allowed: the period must be a finite number > 0")
    n = system.n_states
    p = system.params if params is None else np.ascontiguousarray(params, dtype=np.float64)
    dpw = K.NO_PARAM_DIRECTION
    m = n
    if param_direction is not None:
        dp = np.asarray(param_direction, dtype=np.float64)
        if dp.shape != p.shape or not np.all(np.isfinite(dp)) or not np.any(dp):
            raise SystemDefinitionError(f"param_direction has shape {dp.shape} or is zero/non-finite: it must be a "
                                        f"finite, non-zero array of shape {p.shape} (d params / d mu)")
        if not sensitivity:
            raise SystemDefinitionError("param_direction needs sensitivity=True")
        dpw = np.vstack([dp, np.zeros_like(dp)])
        p = p.copy()                              # the kernel perturbs p in place for f_mu
        m = n + 1
    y0 = np.concatenate([x0, np.eye(n, m).ravel()]) if sensitivity else x0.copy()
    N = y0.size
    out_t, out_x, out_m = np.empty(1), np.empty((1, N)), np.empty(1, dtype=np.int64)
    cap = max_events + 1
    ev_t, ev_xb, ev_xa, ev_g, ev_f, ev_to, info, finfo = K.event_buffers(cap, n)
    yf = np.empty(N)
    jac, has_jac = kernel_jacobian(system)
    nf, ni = K.workspace_sizes(N, n, system.n_guards, system.n_modes, 50)
    kernel = K.flow_kernel(METHODS[method])
    kernel(system.vector_field, system.guards, system.transition, jac, system.mode_of,
           has_jac, METHODS[method], n, 0.0, float(T), y0,
           -1 if mode0 is None else int(mode0), p, dpw, system.directions, rtol, atol, 0.0, hmax,
           int(max_steps), int(max_events), guard_tol, False, np.empty(0), False, int(stop_mode),
           int(stop_count), 50, 1e-12 * T, out_t, out_x, out_m, ev_t, ev_xb, ev_xa, ev_g, ev_f,
           ev_to, info, finfo, yf, np.empty(nf), np.empty(ni, dtype=np.int64))
    st = Status(int(info[K.I_STATUS]))
    if st == Status.BUFFER_FULL:
        st = Status.MAX_EVENTS
    nev = int(info[K.I_NEV])
    mode = int(info[K.I_MODE])
    x = yf[:n].copy()
    f = np.empty(n)
    if 0 <= mode < system.n_modes:
        system.vector_field(mode, float(finfo[K.F_T]), x, p, f)
    else:
        f[:] = np.nan
    Phim = yf[n:].reshape(n, m) if sensitivity else np.full((n, m), np.nan)
    modes = np.concatenate([[ev_f[0]] if nev else [mode], ev_to[:nev]])
    return Flow(x, Phim[:, :n].copy(), mode, f, ev_t[:nev].copy(), modes, ev_g[:nev].copy(), st,
                Phim[:, n].copy() if m > n else None, ev_xb[:nev].copy())


def fd_jacobian(system, x0, T, *, mode0=None, rel: float = 1e-6, **kw) -> np.ndarray:
    """Central finite differences of the flow map x0 -> x(T) (for checks)."""
    x0 = np.asarray(x0, dtype=float)
    n = x0.size
    J = np.empty((n, n))
    for j in range(n):
        h = rel * max(abs(x0[j]), 1e-3)
        xp, xm = x0.copy(), x0.copy()
        xp[j] += h
        xm[j] -= h
        J[:, j] = (flow(system, xp, T, mode0=mode0, sensitivity=False, **kw).x
                   - flow(system, xm, T, mode0=mode0, sensitivity=False, **kw).x) / (2 * h)
    return J
