"""Analytic side of the equilibrium set (thesis sections 9.3, 10.4.2 and chapter 11).

The equilibrium set x1 = x2 = 0, x3 in ServoLoop.equilibrium_set() is locally stable when the
slip dynamics, with the friction curve linearized at zero velocity, are asymptotically stable
(a sufficient condition). The linearization depends on the curve's shape exponent:

* beta > 1 (and Coulomb): g(v) ~ Fs, so the slip dynamics are those of a PID-controlled mass with
  Coulomb friction Fs and viscous b:  m s^3 + (cm kd + b) s^2 + (cm kp + alpha) s + cm ki,
  alpha = dF_cog/dq at q_d (chapter 10);
* beta = 1: g(v) ~ Fs - (Fs - Fc)|v|/vs adds the negative damping -(Fs - Fc)/vs;
* 0 < beta < 1: g is not linearizable at 0, no sufficient condition;
* the discontinuous curve (Fc < Fs): the equilibrium set is unstable.
Chapter 11: with Coulomb friction only the event map is linear, and the equilibrium set stays
stable down to a critical viscous damping b* below zero; the friction force splits into a
signum block Fs sgn(v) + b* v and a Stribeck-related block F_nl(v) whose passivity decides.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from .errors import SystemDefinitionError
from .models.loop import ServoLoop


@dataclass(frozen=True)
class StabilityCondition:
    """The sufficient condition for a locally stable equilibrium set.

    regime : "beta>1", "beta=1", "0<beta<1" or "discontinuous"; polynomial : [1, a2, a1, a0]
    of the linearized slip dynamics (None when there is none); holds : True / False / None
    (no condition available); margin : a2 a1 - a0 (Routh-Hurwitz, > 0 with positive
    coefficients means stable); text : the condition in words."""

    regime: str
    polynomial: tuple | None
    holds: bool | None
    margin: float | None
    text: str


def _regime(curve) -> str:
    if curve.Fs == curve.Fc:
        return "beta>1"              # Coulomb: g is constant
    if math.isinf(curve.beta):
        return "discontinuous"
    if curve.beta > 1:
        return "beta>1"
    if curve.beta == 1:
        return "beta=1"
    return "0<beta<1"


def cogging_slope(loop: ServoLoop) -> float:
    """alpha = dF_cog/dq at the setpoint [N/m] (0 without cogging)."""
    cg = loop.plant.cogging
    return 0.0 if cg is None else float(cg.slope(loop.plant.setpoint)[0])


def slip_polynomial(loop: ServoLoop, extra_damping: float = 0.0) -> tuple:
    """[1, a2, a1, a0] of m s^3 + (cm kd + b + extra) s^2 + (cm kp + alpha) s + cm ki, divided by m
    (the worse of the two directions' viscous coefficients is used)."""
    m, cm = loop.plant.mass, loop.plant.motor_constant
    c = loop.controller
    b = min(loop.friction.curve.positive.b, loop.friction.curve.negative.b) + extra_damping
    return (1.0, (cm * c.kd + b) / m, (cm * c.kp + cogging_slope(loop)) / m, cm * c.ki / m)


def routh_hurwitz_margin(poly) -> float:
    """a2 a1 - a0 for s^3 + a2 s^2 + a1 s + a0 (stable iff all a > 0 and margin > 0)."""
    _, a2, a1, a0 = poly
    return a2 * a1 - a0


def _hurwitz(poly) -> bool:
    return all(a > 0 for a in poly[1:]) and routh_hurwitz_margin(poly) > 0


def stability_condition(loop: ServoLoop) -> StabilityCondition:
    """The thesis' sufficient condition for the loop's equilibrium set (section 9.3 / 10.4.2)."""
    curves = (loop.friction.curve.positive, loop.friction.curve.negative)
    regimes = {_regime(c) for c in curves}
    for r in ("discontinuous", "0<beta<1", "beta=1", "beta>1"):
        if r in regimes:
            regime = r
            break
    if regime == "discontinuous":
        return StabilityCondition(regime, None, False, None,
                                  "discontinuous curve with Fc < Fs: the equilibrium set is unstable")
    if regime == "0<beta<1":
        return StabilityCondition(regime, None, None, None,
                                  "0 < beta < 1: g is not linearizable at zero velocity; no sufficient condition")
    extra = 0.0
    if regime == "beta=1":
        extra = -max((c.Fs - c.Fc) / c.vs for c in curves)
    poly = slip_polynomial(loop, extra)
    text = ("Routh-Hurwitz on s^3 + a2 s^2 + a1 s + a0 of the slip dynamics linearized at v = 0"
            + (" with the negative damping -(Fs - Fc)/vs" if regime == "beta=1" else "")
            + ": all a > 0 and a2 a1 > a0")
    return StabilityCondition(regime, poly, _hurwitz(poly), routh_hurwitz_margin(poly), text)


def critical_value(build, lo: float, hi: float) -> float:
    """Parameter value in [lo, hi] where the Routh-Hurwitz margin of ``build(value)`` (a
    ServoLoop) changes sign, by Brent's method. E.g. the chapter-10 gain K > 50.3389 V/m."""
    def margin(v):
        return routh_hurwitz_margin(stability_condition(build(v)).polynomial)
    ml, mh = margin(lo), margin(hi)
    if np.sign(ml) == np.sign(mh):
        raise SystemDefinitionError(f"the margin does not change sign on [{lo}, {hi}]: {ml:.4g}, {mh:.4g}")
    return float(brentq(margin, lo, hi, xtol=1e-12, rtol=1e-14))


def coulomb_map_slope(loop: ServoLoop, iterate: int = 2, d: float = 0.1) -> float:
    """Slope of P^k for Coulomb friction only (Fs = Fc): the map is linear, P^k(d) = slope * d."""
    from .eventmap.engine import evaluate_map
    c = loop.friction.curve.positive
    if c.Fs != c.Fc:
        raise SystemDefinitionError(f"coulomb_map_slope needs Fs == Fc, got Fs = {c.Fs}, Fc = {c.Fc}")
    mv = evaluate_map(loop, [d], iterate)
    if not mv.ok[0]:
        raise SystemDefinitionError(f"the map failed at d = {d}: status {mv.status[0]}")
    return float(mv.image[0] / d)


def critical_damping(build, lo: float = -3.0, hi: float = 0.0, iterate: int = 2) -> float:
    """b* where the linear Coulomb-friction event map's slope |P^k'| crosses 1 (chapter 11:
    -1.253 N s/m for Table 9.1 with Fc = Fs = 4 N). ``build(b)`` returns the ServoLoop."""
    return float(brentq(lambda b: abs(coulomb_map_slope(build(b), iterate)) - 1.0, lo, hi, xtol=1e-10))


def stribeck_block(curve, b_star: float, v) -> np.ndarray:
    """F_nl(v) = g(v) sgn(v) - Fs sgn(v) + (b - b*) v: the Stribeck-related block of the
    decomposition g sgn + b v = F_nl + (Fs sgn + b* v) (thesis Fig. 11.2)."""
    v = np.asarray(v, dtype=float)
    return curve.force(v) - curve.Fs * np.sign(v) - b_star * v


def nonpassive_intervals(curve, b_star: float, v) -> list:
    """Velocity intervals (from the samples v) where v F_nl(v) < 0 (the block is not passive)."""
    v = np.asarray(v, dtype=float)
    bad = v * stribeck_block(curve, b_star, v) < 0
    out, start = [], None
    for i, flag in enumerate(bad):
        if flag and start is None:
            start = i
        if (not flag or i == v.size - 1) and start is not None:
            end = i if flag else i - 1
            out.append((float(v[start]), float(v[end])))
            start = None
    return out


def lugre_equilibrium_eigenvalues(loop: ServoLoop, beta_frac: float, q: float) -> np.ndarray:
    """Eigenvalues of the generalized (Clarke) Jacobian (1 - q) J- + q J+ of the LuGre loop at
    the equilibrium x = [0, 0, -(F_cog(q_d) + sigma0 beta)/(cm ki), beta] (the integral action
    balancing the bristle force and the cogging force; thesis sections 4.3, 8.4.1, 10.4.2), with
    beta = beta_frac * Fs / sigma0 and Fs of the direction of beta (direction-dependent curves
    bound the bristle deflection by Fs+ / sigma0 and -Fs- / sigma0)."""
    from .models import servo as S
    from .models.friction import LuGre
    if not isinstance(loop.friction, LuGre):
        raise SystemDefinitionError(f"{loop.name}: the generalized Jacobian applies to LuGre loops")
    curve = loop.friction.curve.positive if beta_frac >= 0 else loop.friction.curve.negative
    beta = beta_frac * curve.Fs / loop.friction.sigma0
    pl = loop.plant
    fcog = 0.0 if pl.cogging is None else float(pl.cogging(pl.setpoint)[0])
    x = np.array([0.0, 0.0, -(fcog + loop.friction.sigma0 * beta) / (pl.motor_constant * loop.controller.ki), beta])
    p = loop.system.params
    Jp, Jm = np.empty((4, 4)), np.empty((4, 4))
    S.servo_jac(S.V_POS, 0.0, x, p, Jp)
    S.servo_jac(S.V_NEG, 0.0, x, p, Jm)
    return np.linalg.eigvals((1.0 - q) * Jm + q * Jp)


def _poly_text(poly) -> str:
    """'s^3 + 1 s^2 - 5 s + 50' for [1, a2, a1, a0]."""
    text = "s^3"
    for a, power in zip(poly[1:], (" s^2", " s", "")):
        text += f" {'-' if a < 0 else '+'} {abs(a):.4g}{power}"
    return text


def _growth_rate(poly) -> float:
    """Largest real part of the roots of s^3 + a2 s^2 + a1 s + a0 [1/s]."""
    return float(np.max(np.roots(np.asarray(poly, dtype=float)).real))


def unstable_linear_parts(loop: ServoLoop) -> list[str]:
    """Sentences naming each linear part of the loop that is unstable (empty when none is).

    Two linear loops are checked: the loop without friction, m s^3 + cm kd s^2 + (cm kp +
    alpha) s + cm ki, and the slip dynamics linearized at zero velocity (the equilibrium set's
    linearization of :func:`stability_condition`, with viscous damping and, for beta = 1, the
    Stribeck slope). An unstable part is allowed (it may be the study); a caller reports it up
    front. Loops without a controller (kp = kd = ki = 0) have no linear loop to check."""
    c, pl = loop.controller, loop.plant
    if c.kp == c.kd == c.ki == 0:
        return []
    m, cm = pl.mass, pl.motor_constant
    free = (1.0, cm * c.kd / m, (cm * c.kp + cogging_slope(loop)) / m, cm * c.ki / m)
    out = []
    tol = 1e-9 * max(1.0, max(abs(a) for a in free))
    rate = _growth_rate(free)
    if rate > tol:
        out.append(f"the linear loop without friction is unstable: {_poly_text(free)} has a root with real part {rate:+.4g} 1/s (controller gains kp = {c.kp:.4g}, "
                   f"kd = {c.kd:.4g}, ki = {c.ki:.4g})")
    cond = stability_condition(loop)
    if cond.polynomial is not None:
        rate_slip = _growth_rate(cond.polynomial)
        if rate_slip > tol:
            out.append(f"the slip dynamics linearized at zero velocity are unstable ({cond.regime}): "
                       f"{_poly_text(cond.polynomial)} has a root with real part {rate_slip:+.4g} 1/s, "
                       "so the equilibrium set is not stable by the sufficient condition (thesis section 9.3)")
    return out
