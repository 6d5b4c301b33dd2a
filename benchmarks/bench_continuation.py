"""Periodic orbits and branches of chapter 8 against a scipy-based shooting (issue: continuation).

1. One hunting cycle of the LuGre loop (Table 8.1, K = 0.3) by single shooting to the same
   tolerance: hunting (DOP853, variational equations + saltation matrices, one integration per
   Newton step) against scipy (solve_ivp Radau at rtol 1e-10 with the analytic Jacobian, monodromy
   by forward differences: n + 1 integrations per Newton step), both from the same guess.
2. Both branches of chapter 8 from K = 0.05 through the cyclic fold and back along the unstable
   branch (LuGre to K = 0.615, Switch to K = 0.634): wall time and fold location.
AUTO-07p is compared in bench_auto.py (where it is installed).

    python benchmarks/bench_continuation.py
"""
from __future__ import annotations

import functools
import time

import numpy as np
from scipy.integrate import solve_ivp

from hunting.continuation import find_cycle, follow, shoot
from hunting.models import preset
from hunting.models import servo as S


def scipy_shoot(loop, x0, T, tol=1e-9, rtol=1e-10, atol=1e-13, max_iter=8):
    p = loop.system.params

    def rhs(t, x):
        out = np.empty(4)
        S.servo_vf(S.V_POS if x[1] >= 0 else S.V_NEG, t, np.ascontiguousarray(x), p, out)
        return out

    def jac(t, x):
        J = np.empty((4, 4))
        S.servo_jac(S.V_POS if x[1] >= 0 else S.V_NEG, t, np.ascontiguousarray(x), p, J)
        return J

    def phi(x, T):
        return solve_ivp(rhs, (0, T), x, method="Radau", rtol=rtol, atol=atol, jac=jac).y[:, -1]

    x = np.array(x0, float)
    n = x.size
    nint = 0
    xT = phi(x, T)
    nint += 1
    for it in range(max_iter):
        r = xT - x
        scale = np.maximum(np.abs(x), 0.1 * np.max(np.abs(x)))
        res = np.max(np.abs(r) / scale)
        if res < tol:
            return x, T, it, nint
        M = np.empty((n, n))
        for j in range(n):
            h = 1e-6 * max(abs(x[j]), 1e-3 * np.max(np.abs(x[:3])) if j < 3 else 1e-3 * abs(x[3]) + 1e-9)
            xp = x.copy()
            xp[j] += h
            M[:, j] = (phi(xp, T) - xT) / h
            nint += 1
        A = np.column_stack([(M - np.eye(n))[:, 1:], rhs(0, xT)])
        dz = np.linalg.solve(A, -r)
        lam = 1.0
        for _ in range(8):          # the same damping as hunting.shoot
            xn = x.copy()
            xn[1:] += lam * dz[:-1]
            Tn = T + lam * dz[-1]
            xTn = phi(xn, Tn)
            nint += 1
            if np.max(np.abs(xTn - xn) / scale) < (1 - 0.25 * lam) * res:
                break
            lam *= 0.5
        x, T, xT = xn, Tn, xTn
    return x, T, max_iter, nint


print = functools.partial(print, flush=True)  # noqa: A001


def main() -> None:
    lp = preset("table8.1-lugre", K=0.3)
    po = find_cycle("table8.1-lugre", params={"K": 0.3}, throw=True).orbit
    x0 = po.x0 * np.array([1.0, 1.002, 1.002, 1.0])
    T0 = po.period * 1.001
    shoot(lp.system, x0, T0)                                  # compile / load
    t0 = time.perf_counter()
    ph = shoot(lp.system, x0, T0)
    t_h = time.perf_counter() - t0
    t0 = time.perf_counter()
    xs, Ts, its, nint = scipy_shoot(lp, x0, T0)
    t_s = time.perf_counter() - t0
    print("One LuGre hunting cycle (Table 8.1, K = 0.3) by single shooting, same guess and tolerance")
    print(f"  hunting (DOP853 + saltation)       : {t_h:7.3f} s, {ph.iterations} Newton steps, T = {ph.period:.9f}")
    print(f"  scipy (Radau + FD monodromy)       : {t_s:7.3f} s, {its} Newton steps, {nint} integrations, "
          f"T = {Ts:.9f}")
    print(f"  ratio: {t_s / t_h:.0f}x")
    # scipy baseline along the LuGre branch: natural-parameter shooting (each orbit from the last)
    # at K = 0.58, 0.60, 0.61, 0.62, 0.63, started from hunting's orbit at 0.58
    start = find_cycle("table8.1-lugre", params={"K": 0.58}, throw=True).orbit   # a converged start helps the baseline
    xk, Tk = start.x0.copy(), start.period
    K_ok, t_sc, per_orbit = None, 0.0, []
    for K in (0.58, 0.60, 0.61, 0.62, 0.63):
        lpk = preset("table8.1-lugre", K=K)
        t0 = time.perf_counter()
        xn, Tn, its, nint = scipy_shoot(lpk, xk, Tk)
        dt = time.perf_counter() - t0
        t_sc += dt
        per_orbit.append(dt)
        ok = its < 8
        print(f"  scipy shooting at K = {K}: {'converged' if ok else 'no convergence'} in {dt:.1f} s ({nint} integrations)")
        if not ok:
            break
        K_ok, xk, Tk = K, xn, Tn
    print(f"  scipy: last converged K = {K_ok} after {t_sc:.0f} s in all; at best its fold would be a bracket of "
          f"width 0.01, and bisecting to the 1e-10 bracket of hunting would take ~{27 * np.mean(per_orbit):.0f} s "
          f"more (27 orbits at the mean cost above)")
    for name, k_end, thesis in (("table8.1-lugre", 0.615, 0.620), ("table8.1-switch", 0.634, 0.647)):
        t0 = time.perf_counter()
        br = follow(name, "K", 0.05, 1.0, stop_at=k_end)
        dt = time.perf_counter() - t0
        fold = next(s for s in br.special if s.kind == "fold")
        print(f"{name}: K = 0.05 -> fold -> {br.mu[-1]:.4f}: {len(br.mu)} points in {dt:.1f} s; "
              f"fold at K = {fold.param:.7f} (bracket {fold.precision:.1e}; thesis {thesis})")


if __name__ == "__main__":
    main()
