"""Friction laws of the thesis (chapters 2, 4, 8, 9): Stribeck family, Coulomb, viscous,
direction-dependent sets, the Switch model (exact Filippov stick or the banded variant) and LuGre.

Each law is usable on its own: ``force(v)`` is the slip force as a function of velocity (the
steady-state force for LuGre), ``stick_set`` the set-valued force at zero velocity. The scalar
kernels below are the single source of the formulas: the closed loops call them from numba and
the Python methods call them through vectorized wrappers.

Sign convention: the friction force opposes motion, ``F(v) = g(|v|) sgn(v) + b v`` for v != 0
with the Stribeck level ``g(|v|) = Fc + (Fs - Fc) exp(-|v / vs|^beta)``; ``beta = inf`` is the
discontinuous curve (g = Fc for v != 0, static level Fs).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from ..errors import SystemDefinitionError, check_finite, check_finite_positive

# Encoding of beta = inf (discontinuous curve) inside the finite flat parameter array.
BETA_DISCONTINUOUS = 0.0


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def pow_ext(r, beta):
    """|r|^beta for r >= 0, extended smoothly a little past r = 0 (used near events): the
    analytic continuation r^beta for integer beta, 0 for r < 0 otherwise."""
    if beta == 2.0:          # the common case; pow() costs several times a multiply
        return r * r
    if beta == 1.0:
        return r
    if r >= 0.0:
        return r ** beta
    if beta == math.floor(beta):
        return r ** beta
    return 0.0


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def stribeck_level(vrel, Fc, Fs, vs, beta):
    """Stribeck level g for relative speed ``vrel`` (>= 0 in slip), without viscous part [N].

    beta == BETA_DISCONTINUOUS encodes the discontinuous curve (g = Fc)."""
    if beta == BETA_DISCONTINUOUS or Fs == Fc:
        return Fc
    return Fc + (Fs - Fc) * math.exp(-pow_ext(vrel / vs, beta))


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def stribeck_level_slope(vrel, Fc, Fs, vs, beta):
    """d g / d vrel of :func:`stribeck_level` (consistent with its extension past 0)."""
    if beta == BETA_DISCONTINUOUS or Fs == Fc:
        return 0.0
    r = vrel / vs
    if beta == 2.0:
        dpow = 2.0 * r
    elif beta == 1.0:
        dpow = 1.0
    elif r > 0.0 or beta == math.floor(beta):
        dpow = beta * r ** (beta - 1.0)
    else:
        dpow = 0.0
    return -(Fs - Fc) * math.exp(-pow_ext(r, beta)) * dpow / vs


@numba.njit(cache=True, error_model="numpy")
def _levels(a, Fc, Fs, vs, beta, slope):
    """stribeck_level (or its slope) at each speed of a (n,)."""
    out = np.empty(a.size)
    for i in range(a.size):
        out[i] = stribeck_level_slope(a[i], Fc, Fs, vs, beta) if slope else stribeck_level(a[i], Fc, Fs, vs, beta)
    return out


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def slip_force(v, s, Fc, Fs, vs, beta, b):
    """Friction force in slip with direction s = +1 / -1 (taken from the mode): s g(s v) + b v."""
    return s * stribeck_level(s * v, Fc, Fs, vs, beta) + b * v


@numba.njit(cache=True, error_model="numpy")
def _slip_force_array(v, Fc_p, Fs_p, vs_p, beta_p, b_p, Fc_n, Fs_n, vs_n, beta_n, b_n, out):
    for k in range(v.size):
        if v[k] > 0:
            out[k] = slip_force(v[k], 1.0, Fc_p, Fs_p, vs_p, beta_p, b_p)
        elif v[k] < 0:
            out[k] = slip_force(v[k], -1.0, Fc_n, Fs_n, vs_n, beta_n, b_n)
        else:
            out[k] = 0.0


@dataclass(frozen=True)
class StribeckCurve:
    """Steady-state friction in one or both directions: g(|v|) sgn(v) + b v.

    Fc : Coulomb level [N] (>= 0); Fs : static level [N] (>= Fc); vs : Stribeck velocity [m/s]
    (> 0); beta : shape exponent (> 0, ``inf`` for the discontinuous curve); b : viscous
    coefficient [N s/m] (any finite value; negative values are used in chapter 11).
    """

    Fc: float
    Fs: float
    vs: float = 1.0
    beta: float = 2.0
    b: float = 0.0

    def __post_init__(self):
        Fc = check_finite_positive("Fc", self.Fc, allow_zero=True)
        Fs = check_finite_positive("Fs", self.Fs, allow_zero=True)
        if Fs < Fc:
            raise SystemDefinitionError(f"Fs = {self.Fs!r} is not allowed: the static level Fs must be >= Fc = {self.Fc!r}")
        check_finite_positive("vs", self.vs)
        check_finite_positive("beta", self.beta, allow_inf=True)
        check_finite("b", self.b)
        for k in ("Fc", "Fs", "vs", "beta", "b"):
            object.__setattr__(self, k, float(getattr(self, k)))

    @property
    def discontinuous(self) -> bool:
        return math.isinf(self.beta)

    def encoded(self) -> tuple[float, float, float, float, float]:
        """(Fc, Fs, vs, beta code, b) as stored in flat parameter arrays."""
        beta = BETA_DISCONTINUOUS if self.discontinuous else self.beta
        return (self.Fc, self.Fs, self.vs, beta, self.b)

    def level(self, v) -> np.ndarray:
        """Stribeck level g(|v|) [N] (without the viscous part), for v != 0; v any shape."""
        v = np.abs(np.asarray(v, dtype=float))
        return _levels(v.ravel(), *self.encoded()[:4], False).reshape(v.shape)

    def level_slope(self, v) -> np.ndarray:
        """d g / d|v| [N s/m] of the Stribeck level at speeds |v|; v any shape."""
        v = np.abs(np.asarray(v, dtype=float))
        return _levels(v.ravel(), *self.encoded()[:4], True).reshape(v.shape)

    def force(self, v) -> np.ndarray:
        """Slip friction force [N] for velocities v (array); 0 where v == 0 (see stick_set)."""
        return DirectionalCurve(self, self).force(v)

    @property
    def stick_set(self) -> tuple[float, float]:
        """The set of friction forces at zero velocity, [-Fs, Fs]."""
        return (-self.Fs, self.Fs)


def Coulomb(Fc: float, b: float = 0.0) -> StribeckCurve:
    """Coulomb friction Fc sgn(v) (+ viscous b v): a Stribeck curve with Fs = Fc."""
    return StribeckCurve(Fc=Fc, Fs=Fc, vs=1.0, beta=2.0, b=b)


def Viscous(b: float) -> StribeckCurve:
    """Pure viscous friction b v (no stick)."""
    return StribeckCurve(Fc=0.0, Fs=0.0, vs=1.0, beta=2.0, b=b)


def Discontinuous(Fc: float, Fs: float, b: float = 0.0) -> StribeckCurve:
    """The discontinuous curve: g = Fc for v != 0, static level Fs (beta = inf)."""
    return StribeckCurve(Fc=Fc, Fs=Fs, vs=1.0, beta=math.inf, b=b)


@dataclass(frozen=True)
class DirectionalCurve:
    """Direction-dependent steady-state friction: ``positive`` for v > 0, ``negative`` for v < 0.

    Both curves give magnitudes; the force for v < 0 is -g_neg(|v|) + b_neg v. The stick set
    is [-Fs_neg, Fs_pos]."""

    positive: StribeckCurve
    negative: StribeckCurve

    def __post_init__(self):
        for name in ("positive", "negative"):
            if not isinstance(getattr(self, name), StribeckCurve):
                raise SystemDefinitionError(f"{name} = {getattr(self, name)!r} must be a StribeckCurve")

    @property
    def symmetric(self) -> bool:
        return self.positive == self.negative

    def force(self, v) -> np.ndarray:
        v = np.ascontiguousarray(np.atleast_1d(np.asarray(v, dtype=float)))
        out = np.empty_like(v)
        _slip_force_array(v.reshape(-1), *self.positive.encoded(), *self.negative.encoded(), out.reshape(-1))
        return out

    @property
    def stick_set(self) -> tuple[float, float]:
        return (-self.negative.Fs, self.positive.Fs)


def as_directional(curve) -> DirectionalCurve:
    if isinstance(curve, DirectionalCurve):
        return curve
    if isinstance(curve, StribeckCurve):
        return DirectionalCurve(curve, curve)
    raise SystemDefinitionError(f"curve = {curve!r} must be a StribeckCurve or DirectionalCurve")


@dataclass(frozen=True)
class Switch:
    """The Switch friction model (Leine et al.; thesis eq. 9.1-9.3).

    variant "filippov" (default): exact stick -- the velocity is held at zero while the
    non-friction force stays inside the stick set [-Fs, Fs], which may be larger than the
    Filippov hull of the slip limits (discontinuous curve); break-away and stick entry are
    located as events. variant "banded": the thesis' pseudo-code of section 9.2 with a band
    |v| <= eta [m/s] and stick dynamics dv/dt = -alpha v [1/s], kept for fidelity comparisons.
    """

    curve: object
    variant: str = "filippov"
    eta: float = 1e-8
    alpha: float = 10.0

    def __post_init__(self):
        object.__setattr__(self, "curve", as_directional(self.curve))
        if self.variant not in ("filippov", "banded"):
            raise SystemDefinitionError(f"variant = {self.variant!r} is not allowed: use 'filippov' or 'banded'")
        check_finite_positive("eta", self.eta)
        check_finite_positive("alpha", self.alpha)

    def force(self, v) -> np.ndarray:
        return self.curve.force(v)

    @property
    def stick_set(self) -> tuple[float, float]:
        return self.curve.stick_set


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def lugre_rates(v, z, s, Fc, Fs, vs, beta, b, sigma0, sigma1, vd):
    """LuGre bristle rate and force for velocity v, bristle state z, direction s (= sign of v
    from the mode). Returns (dz/dt [m/s], friction force [N]).

    dz/dt = v - sigma0 |v| z / g(v);  F = sigma0 z + sigma1(v) dz/dt + b v with
    sigma1(v) = sigma1 exp(-(v / vd)^2) (vd <= 0: constant sigma1)."""
    g = stribeck_level(s * v, Fc, Fs, vs, beta)
    zdot = v - sigma0 * s * v * z / g
    s1 = sigma1
    if vd > 0.0:
        s1 = sigma1 * math.exp(-(v / vd) ** 2)
    return zdot, sigma0 * z + s1 * zdot + b * v


@numba.njit(cache=True, error_model="numpy", _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def lugre_partials(v, z, s, Fc, Fs, vs, beta, b, sigma0, sigma1, vd):
    """Partial derivatives of (dz/dt, F) of :func:`lugre_rates` with respect to v and z:
    returns (dzdot/dv, dzdot/dz, dF/dv, dF/dz)."""
    r = s * v
    g = stribeck_level(r, Fc, Fs, vs, beta)
    dg = stribeck_level_slope(r, Fc, Fs, vs, beta) * s
    zdot = v - sigma0 * r * z / g
    dzv = 1.0 - sigma0 * z * (s * g - r * dg) / (g * g)
    dzz = -sigma0 * r / g
    s1 = sigma1
    ds1 = 0.0
    if vd > 0.0:
        s1 = sigma1 * math.exp(-(v / vd) ** 2)
        ds1 = -2.0 * v / (vd * vd) * s1
    return dzv, dzz, ds1 * zdot + s1 * dzv + b, sigma0 + s1 * dzz


@dataclass(frozen=True)
class LuGre:
    """The LuGre model (Canudas de Wit et al.; thesis eqs. 2.1, 4.1-4.2, 8.2).

    curve : steady-state curve g (its viscous coefficient b plays the role of sigma2)
    sigma0 : bristle stiffness [N/m] (> 0); sigma1 : bristle damping [N s/m] (>= 0)
    vd : velocity scale of the velocity-dependent damping sigma1(v) = sigma1 exp(-(v/vd)^2)
         [m/s]; ``inf`` (default) is the standard parametrization (constant sigma1)
    """

    curve: object
    sigma0: float
    sigma1: float
    vd: float = math.inf

    def __post_init__(self):
        object.__setattr__(self, "curve", as_directional(self.curve))
        check_finite_positive("sigma0", self.sigma0)
        check_finite_positive("sigma1", self.sigma1, allow_zero=True)
        check_finite_positive("vd", self.vd, allow_inf=True)
        for c in (self.curve.positive, self.curve.negative):
            if c.Fc <= 0:
                raise SystemDefinitionError(f"Fc = {c.Fc!r} is not allowed for LuGre: the bristle equation divides by g >= Fc > 0")

    @property
    def sigma2(self) -> float:
        return self.curve.positive.b

    def force(self, v) -> np.ndarray:
        """Steady-state force at constant velocity (the curve): g(v) sgn(v) + sigma2 v."""
        return self.curve.force(v)

    @property
    def stick_set(self) -> tuple[float, float]:
        return self.curve.stick_set

    def rates(self, v: float, z: float) -> tuple[float, float]:
        """(dz/dt, F) at velocity v and bristle deflection z (scalars)."""
        c = self.curve.positive if v >= 0 else self.curve.negative
        Fc, Fs, vs, beta, b = c.encoded()
        vd = 0.0 if math.isinf(self.vd) else self.vd
        return lugre_rates(float(v), float(z), 1.0 if v >= 0 else -1.0, Fc, Fs, vs, beta, b,
                           self.sigma0, self.sigma1, vd)
