"""PID controllers in the two forms of the thesis, reduced to gains on (e, e', int e).

Error e = q - q_d (the state x1). The controller output u multiplies the motor constant."""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import SystemDefinitionError, check_finite, check_finite_positive


@dataclass(frozen=True)
class PID:
    """u = -(kp e + kd e' + ki int e).

    Use :meth:`pdi` (chapter 9: u = -P (e + D e' + I int e)) or :meth:`fixed_shape`
    (chapters 8 and 10: u = -K[(1 + tau_d / tau_i) e + tau_d e' + (1 / tau_i) int e])."""

    kp: float
    kd: float
    ki: float
    form: str = "gains"
    shape: tuple = ()

    def __post_init__(self):
        for k in ("kp", "kd", "ki"):
            object.__setattr__(self, k, check_finite(k, getattr(self, k)))

    @staticmethod
    def pdi(P: float, D: float, I: float) -> "PID":
        """u = -P (e + D e' + I int e); P [N/m or V/m], D [s], I [1/s]."""
        P = check_finite("P", P)
        D = check_finite_positive("D", D, allow_zero=True)
        I = check_finite_positive("I", I, allow_zero=True)
        return PID(P, P * D, P * I, "PDI", (P, D, I))

    @staticmethod
    def fixed_shape(K: float, tau_d: float = 1 / (2 * math.pi), tau_i: float = 1 / (2 * math.pi)) -> "PID":
        """u = -K[(1 + tau_d/tau_i) e + tau_d e' + (1/tau_i) int e]; K [V/m or V/rad], tau [s]."""
        K = check_finite("K", K)
        tau_d = check_finite_positive("tau_d", tau_d, allow_zero=True)
        tau_i = check_finite_positive("tau_i", tau_i, allow_inf=True)
        if tau_i == 0:
            raise SystemDefinitionError("tau_i = 0 is not allowed: tau_i must be > 0 (inf: no integral action)")
        inv = 0.0 if math.isinf(tau_i) else 1.0 / tau_i
        return PID(K * (1 + tau_d * inv), K * tau_d, K * inv, "K", (K, tau_d, tau_i))

    def __repr__(self):
        if self.form == "PDI":
            return "PID.pdi(P={}, D={}, I={})".format(*self.shape)
        if self.form == "K":
            return "PID.fixed_shape(K={}, tau_d={}, tau_i={})".format(*self.shape)
        return f"PID(kp={self.kp}, kd={self.kd}, ki={self.ki})"

