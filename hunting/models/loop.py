"""``ServoLoop``: plant + friction + PID assembled into a compiled closed loop."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..errors import SystemDefinitionError
from ..system import PiecewiseSystem
from . import servo as S
from .controller import PID
from .friction import LuGre, Switch
from .plant import Plant


@dataclass(frozen=True)
class ServoLoop:
    """A PID-controlled mass with friction (thesis eqs. 8.1-8.2, 9.2, 10.1).

    plant : Plant; friction : Switch or LuGre; controller : PID; name : label; units : names of
    the position and force units (e.g. {"q": "m", "F": "N"} or {"q": "rad", "F": "N m"})."""

    plant: Plant
    friction: object
    controller: PID
    name: str = "servo"
    units: dict = field(default_factory=lambda: {"q": "m", "F": "N", "u": "V"})

    def __post_init__(self):
        if not isinstance(self.plant, Plant):
            raise SystemDefinitionError(f"plant = {self.plant!r} must be a hunting.models.Plant")
        if not isinstance(self.friction, (Switch, LuGre)):
            raise SystemDefinitionError(f"friction = {self.friction!r} must be a Switch or LuGre model")
        if not isinstance(self.controller, PID):
            raise SystemDefinitionError(f"controller = {self.controller!r} must be a hunting.models.PID")

    @property
    def model_code(self) -> int:
        if isinstance(self.friction, LuGre):
            return S.MODEL_LUGRE
        return S.MODEL_BANDED if self.friction.variant == "banded" else S.MODEL_SWITCH

    def param_array(self) -> np.ndarray:
        """The flat parameter array in the layout of :mod:`hunting.models.servo`."""
        p = np.zeros(S.COG)
        pl, c, fr = self.plant, self.controller, self.friction
        p[[S.M, S.CM, S.KP, S.KD, S.KI, S.QD]] = [pl.mass, pl.motor_constant, c.kp, c.kd, c.ki, pl.setpoint]
        p[[S.FEXT_KIND, S.FEXT_AMP, S.FEXT_PERIOD]] = pl.external_force_encoded()
        p[S.MODEL] = self.model_code
        p[S.POS:S.POS + 5] = fr.curve.positive.encoded()
        p[S.NEG:S.NEG + 5] = fr.curve.negative.encoded()
        if isinstance(fr, Switch):
            p[S.ETA], p[S.ALPHA] = fr.eta, fr.alpha
        else:
            p[S.SIGMA0], p[S.SIGMA1] = fr.sigma0, fr.sigma1
            p[S.VD] = 0.0 if math.isinf(fr.vd) else fr.vd
        return np.concatenate([p, self.plant.cogging_encoded()])

    @property
    def odd(self) -> bool:
        """True when the loop is odd in x (symmetric friction, no cogging, no external force)."""
        return (self.friction.curve.symmetric and self.plant.cogging is None
                and self.plant.external_force is None)

    @cached_property
    def system(self) -> PiecewiseSystem:
        q, F = self.units.get("q", "m"), self.units.get("F", "N")
        units = {"x1": q, "x2": f"{q}/s", "x3": f"{q} s", "x4": q, "F": F}
        return S.build_servo_system(self.name, self.param_array(), odd=self.odd, units=units)

    def description(self) -> dict:
        """This loop as a model description (controller gains kp, kd, ki; the friction curve's
        parameters; cogging harmonics): ``hunting.model(loop.description())`` compiles the same
        loop from equations. Raises SystemDefinitionError for what has no expression form
        (banded Switch, cogging tables, the triangle-wave force)."""
        from .servo_description import servo_description
        pl, c, fr = self.plant, self.controller, self.friction
        v = {"m": pl.mass, "cm": pl.motor_constant, "q_d": pl.setpoint, "kp": c.kp, "kd": c.kd, "ki": c.ki}
        if isinstance(fr, LuGre):
            v.update(model="lugre", sigma0=fr.sigma0, sigma1=fr.sigma1, vd=fr.vd)
        else:
            v["model"] = "switch" if fr.variant == "filippov" else "switch-banded"
        pos, neg = fr.curve.positive, fr.curve.negative
        for sfx, cv in (("", pos), ("_neg", neg)) if pos != neg else (("", pos),):
            v.update({k + sfx: getattr(cv, k) for k in ("Fc", "Fs", "vs", "beta", "b")})
        fe = pl.external_force
        if isinstance(fe, tuple):
            v["force_amplitude"] = fe[1]
        elif fe is not None:
            v["f_ext"] = float(fe)
        cog = pl.cogging
        if cog is not None:
            from .plant import COG_HARMONIC
            if cog.kind != COG_HARMONIC:
                raise SystemDefinitionError(f"{self.name}: a cogging table has no expression form; use harmonics")
            v.update(cog_period=cog.period, cog_cos=cog.data[0::2], cog_sin=cog.data[1::2])
        return servo_description(v, name=self.name)

    @property
    def n_states(self) -> int:
        return 4 if self.model_code == S.MODEL_LUGRE else 3

    @property
    def stick_mode(self) -> int | None:
        """Index of the exact stick mode (Switch, variant filippov), else None."""
        return S.STICK if self.model_code == S.MODEL_SWITCH else None

    def state(self, x1: float = 0.0, x2: float = 0.0, x3: float = 0.0, z: float = 0.0) -> np.ndarray:
        """A state vector of the right size (z only for LuGre)."""
        return np.array([x1, x2, x3, z][: self.n_states], dtype=float)

    def nonfriction_force(self, x, t: float = 0.0) -> float:
        """F_nf = cm u + f_ext - F_cog at state x [force unit]."""
        return float(S.nonfriction_force(float(t), self.system.check_state(x, "x"), self.system.params))

    def require_stick_map(self) -> None:
        """Raise unless the loop has an exact stick mode and is time invariant (event maps)."""
        if self.stick_mode is None:
            raise SystemDefinitionError(
                f"{self.name}: event maps need the exact Switch model (model='switch'); "
                f"this loop uses {type(self.friction).__name__}"
                f"{'' if isinstance(self.friction, LuGre) else ' variant ' + repr(self.friction.variant)}")
        if isinstance(self.plant.external_force, tuple):
            raise SystemDefinitionError(
                f"{self.name}: event maps need a time-invariant loop; external_force = "
                f"{self.plant.external_force!r} depends on time")
        if self.controller.ki * self.plant.motor_constant <= 0:
            raise SystemDefinitionError(
                f"{self.name}: event maps need integral action with cm ki > 0 (ki = {self.controller.ki!r})")

    def _static_force(self, d) -> np.ndarray:
        """Force on the mass at rest with error d, apart from the integral term: F_nf + cm ki x3."""
        d = np.asarray(d, dtype=float)
        pl = self.plant
        fcog = 0.0 if pl.cogging is None else pl.cogging(d + pl.setpoint)
        fconst = pl.external_force if isinstance(pl.external_force, (int, float)) else 0.0
        return -pl.motor_constant * self.controller.kp * d + fconst - fcog

    def breakaway_state(self, d) -> tuple[np.ndarray, np.ndarray]:
        """States (m, n) at the end of a stick phase with error d (m,), and the slip mode that
        follows. In stick x1 = d and x3 grows at rate d, so the non-friction force drifts at
        rate -cm ki d until it leaves the stick set: at -Fs_neg for d > 0, at +Fs_pos for d < 0.
        d = 0 is the equilibrium set: it never breaks away (mode = stick)."""
        self.require_stick_map()
        d = np.atleast_1d(np.asarray(d, dtype=float))
        lo, hi = self.friction.stick_set
        target = np.where(d > 0, lo, hi)
        cm_ki = self.plant.motor_constant * self.controller.ki
        x3 = (self._static_force(d) - target) / cm_ki
        X = np.zeros((d.size, self.n_states))
        X[:, 0] = d
        X[:, 2] = np.where(d == 0, 0.0, x3)
        mode = np.where(d > 0, S.SLIP_NEG, np.where(d < 0, S.SLIP_POS, S.STICK))
        return X, mode

    def stick_duration(self, X_entry) -> np.ndarray:
        """Duration [s] of the stick phases entered at states X_entry (m, n): from entry until
        break-away (inf for d = 0)."""
        X_entry = np.atleast_2d(X_entry)
        d = X_entry[:, 0]
        Xb, _ = self.breakaway_state(d)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(d == 0, np.inf, (Xb[:, 2] - X_entry[:, 2]) / d)

    def equilibrium_set(self) -> tuple[float, float]:
        """Bounds of x3 on the equilibrium set x1 = x2 = 0 (Switch: cm ki |x3| within the stick
        set shifted by the cogging force at q_d) [x3 unit]."""
        lo, hi = self.friction.stick_set
        cm, ki = self.plant.motor_constant, self.controller.ki
        fcog = 0.0 if self.plant.cogging is None else float(self.plant.cogging(self.plant.setpoint)[0])
        if cm * ki == 0:
            raise SystemDefinitionError("the equilibrium set needs integral action (ki != 0)")
        # F_nf = -cm ki x3 - F_cog(q_d) must lie in [lo, hi]
        a, b = (-(hi + fcog) / (cm * ki), -(lo + fcog) / (cm * ki))
        return (min(a, b), max(a, b))
