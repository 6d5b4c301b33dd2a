"""The chapter-8 LuGre branch by hunting and by AUTO-07p (issue: continuation, performance).

Both follow the hunting cycles of the Table 8.1 LuGre loop from K = 0.05 through the cyclic fold
and back along the unstable branch to K = 0.615, in the same process:

- hunting: single shooting on the exact (non-smooth) loop with events at x2 = 0: residual flows
  by DOP853, Jacobian flows (state and parameter sensitivities) by Radau IIA with the
  variational stages solved exactly, pseudo-arclength continuation with a quasi-Newton
  corrector, fold refined by bisection of the tangent; timed from the same cycle at K = 0.05
  that AUTO starts from, at three settings (the last one for the fold only);
- AUTO-07p (Debian package ``auto-07p`` with gfortran): orthogonal collocation (NCOL = 4) on the
  loop with |x2| smoothed as sqrt(x2^2 + eps^2), eps = 1e-9 m/s (benchmarks/auto/lugre.f90). Its
  starting orbit is hunting's cycle at K = 0.05, written at every accepted integration step: a
  uniform sampling misses the presliding oscillations (period 7 ms, the cycle lasts 10-19 s) and
  AUTO's first Newton iteration then fails (MX).

Skipped with a message when AUTO-07p is not installed.

    python benchmarks/bench_auto.py
"""
from __future__ import annotations

import contextlib
import io
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from hunting.continuation import find_cycle, follow
from hunting.continuation.branch import ContinuationOptions
from hunting.continuation.shooting import ShootingOptions
from hunting.integrate.simulate import simulate
from hunting.models import preset

AUTO_DIR = Path(os.environ.get("AUTO_DIR", "/usr/lib/auto-07p"))
F90 = Path(__file__).parent / "auto" / "lugre.f90"
K_START, K_BACK, LOG10_EPS = 0.05, 0.615, -9.0


def write_start(path: Path, K: float) -> None:
    """hunting's cycle at K as AUTO starting data: t, x1, x2, x3, sigma0 z at every step."""
    loop = preset("table8.1-lugre", K=K)
    po = find_cycle("table8.1-lugre", params={"K": K}, throw=True).orbit
    tr = simulate(loop.system, po.x0, (0.0, po.period), rtol=1e-11, atol=1e-13)
    keep = np.concatenate([[True], np.diff(tr.t) > 1e-12])
    t, x = tr.t[keep], tr.x[keep].copy()
    x[:, 3] *= loop.friction.sigma0
    x[-1] = x[0]
    np.savetxt(path, np.column_stack([t, x]))


def run_auto(ntst: int, workdir: Path) -> tuple[float, float, int]:
    """(wall time [s], fold K, points) of AUTO's branch with NTST mesh intervals."""
    sys.path.insert(0, str(AUTO_DIR / "python"))
    import auto  # noqa: PLC0415  (only where AUTO-07p exists)
    cwd = os.getcwd()
    os.chdir(workdir)
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            t0 = time.perf_counter()
            b = auto.run(e="lugre", dat="lugre", IPS=2, NDIM=4, ICP=[1, 11], NTST=ntst, NCOL=4, IAD=3,
                         ILP=1, ISP=2, DS=0.01, DSMIN=1e-7, DSMAX=0.02, NMX=2000, NPR=10000,
                         EPSL=1e-7, EPSU=1e-7, EPSS=1e-4, ITNW=12, NWTN=3, ITMX=8, JAC=0, NPAR=11,
                         THL={11: 0.0}, UZR={1: K_BACK}, STOP=["UZ2"], UZSTOP={1: [0.04, 0.9]},
                         PAR={1: K_START, 2: LOG10_EPS})
            wall = time.perf_counter() - t0
    finally:
        os.chdir(cwd)
    folds = b("LP")
    return wall, (float(folds[0]["PAR(1)"]) if folds else float("nan")), len(b.data[0])


def hunting_branch(po, newton_tol: float, rtol: float, **opts):
    """(wall time [s], fold K, points, max trivial-multiplier error) of hunting's branch."""
    t0 = time.perf_counter()
    br = follow("table8.1-lugre", "K", K_START, 1.0, stop_at=K_BACK, orbit=po,
                options=ContinuationOptions(newton_tol=newton_tol, **opts),
                shooting=ShootingOptions(rtol=rtol, atol=rtol * 1e-2))
    wall = time.perf_counter() - t0
    fold = [s.param for s in br.special if s.kind == "fold"]
    lam = br.multipliers
    triv = float(np.max(np.abs(lam[:, 0] - 1) / np.maximum(1.0, np.abs(lam[:, 1]))))
    return wall, (fold[0] if fold else float("nan")), len(br.mu), triv


def main() -> None:
    rows = []
    # both methods start from the same cycle at K_START (AUTO from its sampled output), so
    # finding it is not timed
    po = find_cycle("table8.1-lugre", params={"K": K_START}, throw=True).orbit
    follow("table8.1-lugre", "K", K_START, 0.06, orbit=po)               # load the compiled kernels
    # the reference fold: corrector tolerance 1e-10, flows at rtol 1e-12 (not timed)
    ref = hunting_branch(po, 1e-10, 1e-12)[1]
    settings = [
        ("hunting, defaults (newton_tol 1e-9)", 1e-9, 1e-11, {}),
        ("hunting, newton_tol 1e-8", 1e-8, 1e-10, {}),
        # the fold only: looser corrector, Jacobians kept from further away, no recomputation
        # for the trivial multiplier (multipliers next to the fold are then rough)
        ("hunting, fold only (newton_tol 1e-6)", 1e-6, 1e-9, dict(jacobian_reuse=1e-4, trivial_tol=1.0)),
    ]
    for name, tol, rtol, opts in settings:
        wall, fold, npts, triv = hunting_branch(po, tol, rtol, **opts)
        rows.append((name, wall, fold, npts, f"{triv:.0e}"))
    if not (AUTO_DIR / "python" / "auto").is_dir() or shutil.which("gfortran") is None:
        print(f"AUTO-07p not found at {AUTO_DIR} (or no gfortran): only hunting's numbers")
    else:
        with tempfile.TemporaryDirectory() as tmp:
            work = Path(tmp)
            shutil.copy(F90, work / "lugre.f90")
            write_start(work / "lugre.dat", K_START)
            run_auto(300, work)                                     # compile the equations once
            for ntst in (500, 1000, 2000, 4000):
                wall, fold, npts = run_auto(ntst, work)
                rows.append((f"AUTO-07p collocation, NTST {ntst}", wall, fold, npts, "-"))
    print(f"LuGre branch K = {K_START} -> fold -> {K_BACK} (thesis fold 0.620); reference fold {ref:.10f} "
          f"(hunting at newton_tol 1e-10, rtol 1e-12)")
    print(f"{'method':<40} {'wall [s]':>9} {'fold K':>13} {'fold error':>11} {'points':>7} {'trivial':>8}")
    for name, wall, fold, npts, triv in rows:
        if np.isfinite(fold):
            print(f"{name:<40} {wall:9.2f} {fold:13.9f} {abs(fold - ref):11.1e} {npts:7d} {triv:>8}")
        else:
            print(f"{name:<40} {wall:9.2f} {'no fold':>13} {'-':>11} {npts:7d} {triv:>8}")
    best_auto = min((r for r in rows if r[0].startswith("AUTO") and np.isfinite(r[2])), key=lambda r: abs(r[2] - ref),
                    default=None)
    if best_auto is not None:
        for r in rows[:3]:
            print(f"  {r[0]}: {best_auto[1] / r[1]:.2f}x the speed of AUTO's most accurate fold "
                  f"({best_auto[0]}), fold error {abs(r[2] - ref):.0e} against {abs(best_auto[2] - ref):.0e}")


if __name__ == "__main__":
    main()
