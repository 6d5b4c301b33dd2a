"""The nominal model a diagnosis starts from: plant, friction law, controller, read from the
MODEL.json schema of ``hunting diagnose`` (or a preset, or a model description through
:func:`nominal_from_description`), with the static friction map the force residual needs.

Schema (keys beyond these are errors, so typos are caught):

    {"preset": "table9.1", "set": {"P": 60.0}}     # the preset's plant, friction, cogging and PID
    {"plant": {"mass": 95.0, "motor_constant": 35.15, "offset": 0.0, "delay": 0.0,
               "cogging": [{"pitch": 0.02, "cos": [..], "sin": [..]}, ...],      # harmonics k = 1, 2..
               "cogging_table": [{"q": [..], "F": [..]}, ...],                  # linear interpolation
               "flexibility": {"load_mass": 20.0, "frequency": 25.0, "damping": 0.05}},  # [kg, Hz, -]
     "friction": {"law": "coulomb-viscous" | "stribeck" | "switch" | "lugre",
                  "Fc": .., "Fs": .., "vs": .., "beta": .., "b": .., "sigma0": .., "sigma1": ..,
                  "sigma2": (alias of b), "Fc_neg": .., ... (direction-dependent values),
                  "lag": 0.01,                                   # [s] frictional memory
                  "dwell": {"level": 0.0, "gain": 5.0, "time": 1.0}},   # [N, N, s] break-away growth
                  # (optional "sliding": true: the slip after a rest starts from the grown force)
     "controller": {"type": "pid", "form": "PDI" | "K", ...} | {"type": "pd-velocity-loop", ...},
     "sensor": {"resolution": 1e-6, "noise": 2e-7}}          # [m]; optional (see resimulate.py)
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import SystemDefinitionError, check_finite, check_finite_positive
from ..models.friction import DirectionalCurve, LuGre, StribeckCurve
from ..models.plant import COG_TABLE, Cogging

SCHEMA_HELP = """\
MODEL.json: the nominal model, a JSON object with the keys below (SI units; unknown keys are
errors, so typos are caught). The plant is  m q'' = cm u(t - delay) + f_ext - F(q') - offset - F_cog(q).

  "plant":      "mass" [kg] (required; the total moving mass), "motor_constant" cm [N per unit
                of u] (default 1), "offset" [N], "delay" [s],
                "cogging": [{"pitch": m, "cos": [N, ..], "sin": [N, ..]}]  (harmonics 1, 2, ..),
                "flexibility": {"load_mass": kg, "frequency": Hz, "damping": ratio}
  "friction":   "law": "coulomb-viscous" | "stribeck" | "switch" | "lugre";
                "Fc" [N] (required), "Fs" [N], "vs" [m/s], "beta", "b" [N s/m];
                "Fc_neg", "Fs_neg", "vs_neg", "beta_neg", "b_neg" for the negative direction;
                "sigma0" [N/m], "sigma1" [N s/m] (lugre); "lag" [s] (static laws);
                "dwell": {"level": N, "gain": N, "time": s, optional "sliding": true (the
                seven-parameter form: the slip after a rest starts from the grown force)}
                (static laws: a LuGre contact never rests)
  "controller": {"type": "pid", "kp", "kd", "ki"} (or "form": "PDI" with "P", "D", "I", or
                "form": "K" with "K"), optional "derivative_on": "error" | "measurement",
                "tau_f" [s], "sample_time" [s], "saturation", "output_resolution";
                or {"type": "pd-velocity-loop", "kp" [1/s], "kv", "sample_time", "saturation"}
                (u = kv (kp (q_ref - q) - v)). Used, with q_ref in the data, by the
                behaviour view and the saturation, quantization and presliding causes (which
                re-simulate the loop), by the noise-fed causes (viscous, asymmetry, mass,
                delay, flexibility, lag), checked along the nominal loop's noise-free
                re-simulation from q_ref (without a controller: along q_ref itself with the
                model's inverse dynamics), and by a check that it gives the measured u from
                the measured q (a note above 10 % RMS mismatch).
  "sensor":     {"resolution": m, "noise": m}  (encoder step; noise before quantization)
  or a preset:  {"preset": "table9.1", "set": {"P": 60.0}}  (see: hunting models)

  or a model description (the equations format of 'hunting simulate --model', JSON or YAML), read
  exactly or refused with one line naming the part: one friction contact whose velocity is a state
  v, a state q with q' = v, m v' = cm u - F - b v - offset - F_cog(q) (constant coefficients; u
  the data's u; F_cog sines and cosines of 2 pi k q / pitch + phase: the plant's cogging);
  friction 'switch' with slip = Fc + (Fs - Fc) exp(-(|w|/vs)^beta) + b|w| per direction and stick
  = Fs, or 'lugre' with constant sigma0, sigma1, a Stribeck level and viscous b*w; u a PID
  -(kp + ki/s + kd s/(tau_f s + 1)) of q from signals or transfer-function blocks, the reference
  r (a parameter or signal of t, replaced by the data's q_ref) in every term (derivative on the
  error) or in P and I only (on the measurement), optionally min(max(PID, -S), S) (saturation
  S), or u a parameter (no controller). Example:
  examples/pd_servo.json in a checkout.

Example (examples/emps/model.json, the EMPS benchmark's published model):
  {"plant": {"mass": 95.1089, "motor_constant": 35.15065188},
   "friction": {"law": "coulomb-viscous", "Fc": 20.3935, "b": 203.5034},
   "controller": {"type": "pd-velocity-loop", "kp": 160.18, "kv": 243.45,
                  "sample_time": 0.001, "saturation": 10.0}}
"""
LAWS = ("coulomb-viscous", "stribeck", "switch", "lugre")
_FRICTION_KEYS = {"law", "Fc", "Fs", "vs", "beta", "b", "sigma0", "sigma1", "sigma2",
                  "Fc_neg", "Fs_neg", "vs_neg", "beta_neg", "b_neg", "lag", "dwell"}
_PLANT_KEYS = {"mass", "motor_constant", "offset", "delay", "cogging", "cogging_table", "flexibility"}
_CONTROLLER_TYPES = ("pid", "pd-velocity-loop")


@dataclass(frozen=True)
class Flexibility:
    """A load of mass load_mass [kg] on a spring-damper behind the measured (motor) side: natural
    frequency [Hz] and damping ratio of the load on its coupling. The rigid model's mass is the
    total; the flexible load adds the force m2 (a2 - a1) = -m2 H(s) a1 to the motor side, with
    H(s) = s^2 / (s^2 + 2 zeta w s + w^2) acting on the measured acceleration a1."""

    load_mass: float
    frequency: float
    damping: float

    def __post_init__(self):
        check_finite_positive("flexibility load_mass", self.load_mass, allow_zero=True)
        check_finite_positive("flexibility frequency", self.frequency)
        check_finite_positive("flexibility damping", self.damping)

    def force(self, a: np.ndarray, dt: float) -> np.ndarray:
        """The load's force on the motor side [N] for motor accelerations a (n,) sampled at dt."""
        return -self.load_mass * highpass_response(a, dt, self.frequency, self.damping)


@dataclass(frozen=True)
class Dwell:
    """Break-away force growing with the time at rest t_r (static laws): Fs + level + gain (1 -
    exp(-t_r / time)) in either direction [N, N, s] (Kato's dwell-time effect). ``sliding`` says
    what the slip after the rest feels: False, the nominal sliding friction (the break-away alone
    grows); True, the seven-parameter model's form (Armstrong-Helouvry; thesis section 2.2): the
    Stribeck curve of that slip has the grown break-away force as its static level Fs, until the
    next stop (a curve with a Stribeck velocity, Fs > Fc, is needed: the grown force decays along
    it; with frictional memory the lagging level starts there too). The seven-parameter form acts
    in the re-simulated loop; the force channel's friction map is the nominal curve."""

    level: float
    gain: float
    time: float
    sliding: bool = False

    def __post_init__(self):
        if not isinstance(self.sliding, bool):
            raise SystemDefinitionError(f"dwell sliding = {self.sliding!r} must be True or False")
        check_finite("dwell level", self.level)
        check_finite_positive("dwell gain", self.gain, allow_zero=True)
        check_finite_positive("dwell time", self.time)

    def breakaway(self, Fs, t_rest) -> np.ndarray:
        """Break-away force [N] after rests t_rest [s] for static level Fs [N]."""
        return Fs + self.level + self.gain * (1.0 - np.exp(-np.asarray(t_rest, float) / self.time))


def highpass_response(a: np.ndarray, dt: float, frequency: float, damping: float) -> np.ndarray:
    """H(s) a with H(s) = s^2 / (s^2 + 2 zeta w s + w^2), w = 2 pi frequency: causal, discretized
    by the bilinear transform s = K (1 - 1/z) / (1 + 1/z), K = 2 / dt, prewarped at w (exact gain and
    phase at the resonance); a (n,) or (n, k) along axis 0."""
    from scipy.signal import lfilter
    w = 2 * np.pi * frequency
    K = 2.0 / dt
    wa = K * np.tan(w * dt / 2)          # the analog frequency the bilinear map sends to w
    c = 2 * damping * wa * K
    den = np.array([K * K + c + wa * wa, 2 * (wa * wa - K * K), K * K - c + wa * wa])
    b = K * K * np.array([1.0, -2.0, 1.0])
    return lfilter(b / den[0], den / den[0], np.asarray(a, dtype=float), axis=0)


_NOMINAL_KEYS = {"preset", "set", "plant", "friction", "controller", "sensor"}
# the keys of a model description (hunting.describe: states and equations), read by
# nominal_from_description
_DESCRIPTION_KEYS = {"states", "equations", "signals", "parameters", "blocks"}


def _looks_like_description(text: str) -> bool:
    """Whether a file that is not JSON reads like a YAML model description (an 'equations:' or
    'states:' key at the start of a line)."""
    return any(line.split(":", 1)[0].strip() in _DESCRIPTION_KEYS for line in text.splitlines() if ":" in line
               and not line.startswith((" ", "\t", "#")))


@dataclass(frozen=True)
class NominalModel:
    """mass [kg or kg m^2]; cm : motor constant [N/V] (1 if u is a force); curve : the static
    friction-velocity map (per direction); law : its name; offset [N] : constant force (plant
    equation m q'' = cm u + f_ext - F(q') - offset); sigma0, sigma1 : LuGre parameters when the
    law is lugre; controller : the controller description (dict), or None; source : the dict.
    cogging : tuple of :class:`hunting.models.plant.Cogging` components (harmonic or table),
    summed; flexibility : a :class:`Flexibility` (load on a spring behind the measured side, its
    mass part of ``mass``; residual and re-simulation); lag [s] : frictional memory of static
    laws (the Stribeck level follows g(|v|) through a first-order lag, relaxing to Fs at rest;
    residual and re-simulation, both exactly); dwell : a :class:`Dwell` (break-away force growing with the time at rest;
    re-simulation); delay [s] : actuation delay (the plant
    receives cm u(t - delay)); resolution [m] and sensor_noise [m] : the position sensor's
    quantization step and noise standard deviation before quantization (used by re-simulation;
    resolution None: read from the data). All forces act like friction: m q'' = cm u - F(q') - offset - F_cog(q)."""

    mass: float
    cm: float
    curve: DirectionalCurve
    law: str = "coulomb-viscous"
    offset: float = 0.0
    sigma0: float | None = None
    sigma1: float | None = None
    controller: dict | None = None
    source: dict = field(default_factory=dict)
    cogging: tuple = ()
    delay: float = 0.0
    resolution: float | None = None
    sensor_noise: float = 0.0
    flexibility: Flexibility | None = None
    lag: float = 0.0
    dwell: Dwell | None = None

    def __post_init__(self):
        check_finite_positive("friction lag", self.lag, allow_zero=True)
        if self.lag and self.law == "lugre":
            raise SystemDefinitionError("friction lag applies to the static laws; LuGre has its own memory (sigma0, sigma1)")
        if self.dwell is not None and not isinstance(self.dwell, Dwell):
            raise SystemDefinitionError(f"dwell = {self.dwell!r} must be a Dwell")
        if self.dwell is not None and self.law == "lugre":
            # the LuGre re-simulation has no rest (the bristles' state carries the contact), so a
            # growth with the time at rest would be silently left out of every re-simulated run
            raise SystemDefinitionError(
                "friction dwell applies to the static laws: with law 'lugre' the contact never rests (the bristles' "
                "state carries it), so a break-away growth with the time at rest has nothing to act on; give a static "
                "law (coulomb-viscous, stribeck or switch) with dwell, or LuGre without it")
        if self.dwell is not None and self.dwell.sliding and not self.has_stribeck_shape():
            raise SystemDefinitionError(
                "friction dwell sliding = true needs a Stribeck curve in both directions (Fs > Fc, a finite beta): "
                "the slip after a rest starts from the grown break-away force and decays along it; with law "
                f"{self.law!r} and Fs {self.curve.positive.Fs:g}/{self.curve.negative.Fs:g} N, Fc "
                f"{self.curve.positive.Fc:g}/{self.curve.negative.Fc:g} N there is none: give the Stribeck law's Fs and "
                "vs, or leave sliding out (Kato's form)")
        check_finite_positive("mass", self.mass)
        if self.flexibility is not None and not self.flexibility.load_mass < self.mass:
            raise SystemDefinitionError(f"flexibility load_mass = {self.flexibility.load_mass!r} kg must be below the "
                                        f"mass {self.mass!r} kg: the mass is the total, motor side and load")
        check_finite_positive("motor_constant", self.cm)
        check_finite("offset", self.offset)
        check_finite_positive("delay", self.delay, allow_zero=True)
        check_finite_positive("sensor_noise", self.sensor_noise, allow_zero=True)
        if self.resolution is not None:
            check_finite_positive("sensor resolution", self.resolution, allow_zero=True)
        if not all(isinstance(c, Cogging) for c in self.cogging):
            raise SystemDefinitionError(f"cogging = {self.cogging!r} must be a tuple of Cogging components")
        object.__setattr__(self, "cogging", tuple(self.cogging))
        if self.law == "lugre":
            check_finite_positive("sigma0", self.sigma0)
            check_finite_positive("sigma1", self.sigma1, allow_zero=True)
        if self.law not in LAWS:
            raise SystemDefinitionError(f"friction law = {self.law!r} is not allowed: use one of {LAWS}")

    def friction(self, v) -> np.ndarray:
        """Static friction force F(v) [N] (0 at v = 0, where it is set-valued)."""
        v = np.asarray(v, dtype=float)
        pos, neg = self.curve.positive, self.curve.negative
        out = np.zeros_like(v)
        p, n = v > 0, v < 0
        out[p] = pos.level(v[p]) + pos.b * v[p]
        out[n] = -neg.level(-v[n]) + neg.b * v[n]
        return out

    def lagged_level(self, v, slide, dt: float, lag: float | None = None) -> np.ndarray:
        """The Stribeck level L [N] (n,) that follows g(|v|) through the first-order lag
        L' = (g(|v|) - L) / lag (Hess and Soom's frictional memory), for velocities v (n,) [m/s]
        sampled every dt [s]; where the mass sticks (``slide`` false, bool (n,)) it relaxes to the
        static level Fs (the mean of the two directions'). Exact for g linear between samples
        (first-order hold), at any lag, so a lag of many samples or longer than the passage
        through the Stribeck dip is modelled as well as a short one; starts settled (L = g).
        ``lag`` [s] defaults to the model's; 0 gives g itself."""
        from scipy.signal import lfilter
        v = np.asarray(v, dtype=float)
        lag = self.lag if lag is None else float(lag)
        pos, neg = self.curve.positive, self.curve.negative
        g = np.where(v >= 0, pos.level(v), neg.level(v))
        g = np.where(np.asarray(slide, bool), g, 0.5 * (pos.Fs + neg.Fs))
        if lag <= 0 or g.size == 0:
            return g
        e = np.exp(-dt / lag)
        c = lag * (1.0 - e) / dt          # L_k+1 = e L_k + (1 - c) g_k+1 + (c - e) g_k
        out, _ = lfilter([1.0 - c, c - e], [1.0, -e], g, zi=[c * g[0]])   # y_0 = g_0: settled
        return out

    def lag_force(self, v, slide, dt: float, lag: float | None = None) -> np.ndarray:
        """The frictional memory's change of the sliding friction force [N] (n,): sign(v) (L - g)
        with L the lagged level (:meth:`lagged_level`) and g the static one at v (n,) [m/s];
        lower than the static curve while accelerating out of the Stribeck dip, higher while
        decelerating into it (to first order -lag g'(|v|) a). 0 without lag and where the mass
        sticks (``slide`` false)."""
        v = np.asarray(v, dtype=float)
        lag = self.lag if lag is None else float(lag)
        if lag <= 0:
            return np.zeros_like(v)
        slide = np.asarray(slide, bool)
        L = self.lagged_level(v, slide, dt, lag)
        g = self.lagged_level(v, slide, dt, 0.0)
        return np.where(slide, np.sign(v) * (L - g), 0.0)

    def bristle_force(self, v, dt: float) -> np.ndarray:
        """LuGre's change of the sliding friction force from the static curve [N] (n,) along the
        velocity v (n,) [m/s] sampled every dt [s] (:func:`hunting.diagnose.bristles.bristle_change`:
        the bristles' lag, sigma0 z + sigma1 z' - sign(v) g(|v|), an inertia-like force where the
        curve has a slope and presliding after reversals); zeros for the static laws."""
        v = np.asarray(v, dtype=float)
        if self.law != "lugre":
            return np.zeros_like(v)
        from .bristles import bristle_change
        return bristle_change(v, dt, self.curve, self.sigma0, self.sigma1)

    def v_stick(self) -> float:
        """Speed [m/s] below which this model's mass counts as stuck when judging data: a tenth
        of the smaller Stribeck velocity (0 for curves without a Stribeck dip)."""
        pos, neg = self.curve.positive, self.curve.negative
        return 0.1 * min(pos.vs, neg.vs) if (pos.Fs > pos.Fc or neg.Fs > neg.Fc) else 0.0

    def has_stribeck_shape(self) -> bool:
        """Whether both directions' curves have a continuous Stribeck dip (Fs > Fc, a finite beta):
        the shape a seven-parameter dwell growth decays along (:class:`Dwell` ``sliding``)."""
        return all(c.Fs > c.Fc and not c.discontinuous for c in (self.curve.positive, self.curve.negative))

    def steady_slide(self, v, least: float = 0.0) -> np.ndarray:
        """bool (n,): where the static curve's slope d F / d|v| (Stribeck level and viscous term,
        per direction) at velocities v (n,) [m/s] is at least ``least`` [N s/m] (<= 0): a slow
        slide there is steady. The free mass needs a slope that is not negative: on the falling
        branch of a Stribeck dip a slow motion is stick-slip below the encoder's count (tuning
        d0042 progressed one count per 20 ms at 0.5 mm/s with vs = 4 mm/s while its drive ramped
        as in a stick); a controller holds a slide down to the slope its loop tolerates
        (:func:`~hunting.diagnose.loop.steady_slope`)."""
        v = np.asarray(v, dtype=float)
        pos, neg = self.curve.positive, self.curve.negative
        return np.where(v >= 0, pos.level_slope(v) + pos.b, neg.level_slope(v) + neg.b) >= least

    def cogging_force(self, q) -> np.ndarray:
        """F_cog(q) [N]: the sum of the components (0 without cogging)."""
        q = np.asarray(q, dtype=float)
        return sum((c(q).reshape(q.shape) for c in self.cogging), np.zeros_like(q))

    def replace(self, **changes) -> "NominalModel":
        """A copy with fields changed (an extended model); ``source`` is rebuilt from it."""
        from dataclasses import replace
        new = replace(self, **changes)
        object.__setattr__(new, "source", new.to_dict())
        return new

    def to_dict(self) -> dict:
        c = self.curve
        fr = {"law": self.law, "Fc": c.positive.Fc, "Fs": c.positive.Fs, "vs": c.positive.vs,
              "beta": c.positive.beta, "b": c.positive.b}
        if not c.symmetric:
            fr.update(Fc_neg=c.negative.Fc, Fs_neg=c.negative.Fs, vs_neg=c.negative.vs,
                      beta_neg=c.negative.beta, b_neg=c.negative.b)
        if self.law == "lugre":
            fr.update(sigma0=self.sigma0, sigma1=self.sigma1)
        if self.lag:
            fr["lag"] = self.lag
        if self.dwell is not None:
            fr["dwell"] = {"level": self.dwell.level, "gain": self.dwell.gain, "time": self.dwell.time}
            if self.dwell.sliding:
                fr["dwell"]["sliding"] = True
        plant = {"mass": self.mass, "motor_constant": self.cm, "offset": self.offset}
        if self.delay:
            plant["delay"] = self.delay
        harm = [c for c in self.cogging if c.kind != COG_TABLE]
        tabs = [c for c in self.cogging if c.kind == COG_TABLE]
        if harm:
            plant["cogging"] = [{"pitch": c.period, "cos": list(c.data[0::2]), "sin": list(c.data[1::2])} for c in harm]
        if tabs:
            plant["cogging_table"] = [{"q": list(c.data[:c.n]), "F": list(c.data[c.n:])} for c in tabs]
        if self.flexibility is not None:
            f = self.flexibility
            plant["flexibility"] = {"load_mass": f.load_mass, "frequency": f.frequency, "damping": f.damping}
        d = {"plant": plant, "friction": fr}
        if self.controller is not None:
            d["controller"] = self.controller
        if self.resolution is not None or self.sensor_noise:
            d["sensor"] = {k: v for k, v in (("resolution", self.resolution), ("noise", self.sensor_noise)) if v}
        return d

    @staticmethod
    def from_json(path) -> "NominalModel":
        path = Path(path)
        try:
            text = path.read_text()
        except OSError as exc:
            raise SystemDefinitionError(f"model file {path}: {exc.strerror or exc}") from None
        try:
            d = json.loads(text)
        except json.JSONDecodeError as exc:
            if path.suffix.lower() in (".yaml", ".yml") or _looks_like_description(text):
                from ..describe import read_description
                d = read_description(path)
                return NominalModel.from_dict(d, where=f"model description {path}")
            raise SystemDefinitionError(f"model file {path} is not JSON ({exc.msg} at line {exc.lineno} column "
                                        f"{exc.colno}); diagnose takes a nominal model JSON or a model description, "
                                        "see 'hunting diagnose --help' and examples/emps/model.json") from None
        return NominalModel.from_dict(d, where=f"model description {path}")

    @staticmethod
    def from_dict(d: dict, where: str = "model description") -> "NominalModel":
        """The nominal model of the schema above, or of a model description (the equations
        format of ``hunting.model``: read by :func:`nominal_from_description`, whose
        errors are prefixed with ``where``)."""
        if not isinstance(d, dict):
            raise SystemDefinitionError(f"model = {d!r} must be a JSON object")
        if _DESCRIPTION_KEYS & set(d):
            return _from_description(d, where)
        unknown = set(d) - _NOMINAL_KEYS
        if unknown:
            raise SystemDefinitionError(f"model: unknown keys {sorted(unknown)}; allowed: preset, set, plant, "
                                        "friction, controller, sensor")
        sensor = d.get("sensor", {})
        if not isinstance(sensor, dict) or set(sensor) - {"resolution", "noise"}:
            raise SystemDefinitionError(f"model sensor = {sensor!r}: allowed keys are 'resolution' and 'noise' [m]")
        sens = dict(resolution=sensor.get("resolution"), sensor_noise=float(sensor.get("noise", 0.0)))
        if "preset" in d:
            from ..models import preset
            loop = preset(d["preset"], **d.get("set", {}))
            fr = loop.friction
            law = "lugre" if isinstance(fr, LuGre) else "switch"
            # the preset's PID (continuous in the thesis: updated every data sample here, unless a
            # 'controller' is given) and its cogging come along
            c = loop.controller
            ctrl = d.get("controller") or {"type": "pid", "kp": c.kp, "kd": c.kd, "ki": c.ki}
            cog = () if loop.plant.cogging is None else (loop.plant.cogging,)
            return NominalModel(loop.plant.mass, loop.plant.motor_constant, fr.curve, law,
                                sigma0=getattr(fr, "sigma0", None), sigma1=getattr(fr, "sigma1", None),
                                controller=ctrl, cogging=cog, source=d, **sens)
        for k in ("plant", "friction"):
            if k not in d:
                raise SystemDefinitionError(f"model: missing {k!r} (or give a 'preset')")
        pl, fr = dict(d["plant"]), dict(d["friction"])
        bad = set(pl) - _PLANT_KEYS
        if bad:
            raise SystemDefinitionError(f"model plant: unknown keys {sorted(bad)}; allowed: {sorted(_PLANT_KEYS)}")
        bad = set(fr) - _FRICTION_KEYS
        if bad:
            raise SystemDefinitionError(f"model friction: unknown keys {sorted(bad)}; allowed: {sorted(_FRICTION_KEYS)}")
        if "mass" not in pl:
            raise SystemDefinitionError("model plant: 'mass' is required [kg]")
        law = fr.get("law", "coulomb-viscous")
        if law not in LAWS:
            raise SystemDefinitionError(f"friction law = {law!r} is not allowed: use one of {LAWS}")
        if "sigma2" in fr:
            fr.setdefault("b", fr.pop("sigma2"))
        if "Fc" not in fr:
            raise SystemDefinitionError("model friction: 'Fc' is required [N]")

        def curve(sfx: str) -> StribeckCurve:
            get = lambda k, dflt=None: fr.get(k + sfx, fr.get(k, dflt))  # noqa: E731
            Fc = float(get("Fc"))
            if law == "coulomb-viscous":
                return StribeckCurve(Fc=Fc, Fs=Fc, vs=1.0, beta=2.0, b=float(get("b", 0.0)))
            for k in ("Fs", "vs"):
                if get(k) is None:
                    raise SystemDefinitionError(f"model friction: {law} needs {k!r}")
            return StribeckCurve(Fc=Fc, Fs=float(get("Fs")), vs=float(get("vs")), beta=float(get("beta", 2.0)),
                                 b=float(get("b", 0.0)))
        pos = curve("")
        neg = curve("_neg") if any(k.endswith("_neg") for k in fr) else pos
        ctrl = d.get("controller")
        if ctrl is not None and ctrl.get("type") not in _CONTROLLER_TYPES:
            raise SystemDefinitionError(f"controller type = {ctrl.get('type')!r} is not allowed: use one of "
                                        f"{_CONTROLLER_TYPES}")
        if law == "lugre" and not ("sigma0" in fr and "sigma1" in fr):
            raise SystemDefinitionError("model friction: lugre needs 'sigma0' and 'sigma1'")
        return NominalModel(float(pl["mass"]), float(pl.get("motor_constant", 1.0)), DirectionalCurve(pos, neg), law,
                            offset=float(pl.get("offset", 0.0)), sigma0=fr.get("sigma0"), sigma1=fr.get("sigma1"),
                            controller=ctrl, source=d, cogging=_cogging(pl.get("cogging", []), pl.get("cogging_table", [])), delay=float(pl.get("delay", 0.0)),
                            flexibility=_flexibility(pl.get("flexibility")), lag=float(fr.get("lag", 0.0)),
                            dwell=_dwell(fr.get("dwell")), **sens)


def _from_description(d: dict, where: str) -> NominalModel:
    """The nominal model of the description d; its errors start with ``where``."""
    try:
        return nominal_from_description(d)
    except SystemDefinitionError as exc:
        raise SystemDefinitionError(f"{where}: {exc}") from None


def _dwell(d) -> Dwell | None:
    if d is None:
        return None
    if not isinstance(d, dict) or not {"level", "gain", "time"} <= set(d) <= {"level", "gain", "time", "sliding"}:
        raise SystemDefinitionError(f"friction dwell = {d!r} must be {{'level': N, 'gain': N, 'time': s}}, optionally "
                                    "with 'sliding': true (the slip after a rest starts from the grown break-away force)")
    if not isinstance(d.get("sliding", False), bool):
        raise SystemDefinitionError(f"friction dwell sliding = {d['sliding']!r} must be true or false")
    return Dwell(float(d["level"]), float(d["gain"]), float(d["time"]), bool(d.get("sliding", False)))


def _flexibility(d) -> Flexibility | None:
    if d is None:
        return None
    keys = {"load_mass", "frequency", "damping"}
    if not isinstance(d, dict) or set(d) != keys:
        raise SystemDefinitionError(f"plant flexibility = {d!r} must be {{'load_mass': kg, 'frequency': Hz, "
                                    "'damping': ratio}")
    return Flexibility(float(d["load_mass"]), float(d["frequency"]), float(d["damping"]))


def _cogging(harmonics, tables) -> tuple:
    """Cogging components from the schema: harmonics [{"pitch", "cos", "sin"}], tables
    [{"q", "F"}] (a single object is accepted for either)."""
    out = []
    for it in [harmonics] if isinstance(harmonics, dict) else harmonics:
        if not (isinstance(it, dict) and set(it) == {"pitch", "cos", "sin"}):
            raise SystemDefinitionError(f"plant cogging entry {it!r} must be {{'pitch': p, 'cos': [..], 'sin': [..]}}")
        out.append(Cogging.harmonic(it["pitch"], it["cos"], it["sin"]))
    for it in [tables] if isinstance(tables, dict) else tables:
        if not (isinstance(it, dict) and set(it) == {"q", "F"}):
            raise SystemDefinitionError(f"plant cogging_table entry {it!r} must be {{'q': [..], 'F': [..]}}")
        out.append(Cogging.table(it["q"], it["F"]))
    return tuple(out)


def fit_coulomb_viscous(kin, *, v_min_frac: float = 0.02) -> tuple[NominalModel, dict]:
    """Symmetric Coulomb + viscous model without offset by least squares on the inverse dynamics
    (IDIM-LS): force = m a + H_a[Fc sign(v) + b v] on the samples with |v| > v_min_frac max|v|.
    kin : Kinematics. Returns (model, {"mass", "Fc", "b"} standard uncertainties)."""
    sel = kin.moving & (np.abs(kin.v) > v_min_frac * np.max(np.abs(kin.v)))
    Phi = np.column_stack([kin.a, kin.sliding(np.column_stack([np.sign(kin.vf), kin.vf]))])[sel]
    y = kin.sliding(kin.drive)[sel]
    theta, *_ = np.linalg.lstsq(Phi, y, rcond=None)
    r = y - Phi @ theta
    s2 = float(r @ r) / max(sel.sum() - 3, 1)
    sd = np.sqrt(np.diag(np.linalg.inv(Phi.T @ Phi)) * s2)
    m, Fc, b = map(float, theta)
    curve = StribeckCurve(Fc=Fc, Fs=Fc, vs=1.0, beta=2.0, b=b)
    model = NominalModel(m, kin.cm, DirectionalCurve(curve, curve), "coulomb-viscous")
    return model, {"mass": float(sd[0]), "Fc": float(sd[1]), "b": float(sd[2])}


def nominal_from_description(description, **overrides) -> NominalModel:
    """The :class:`NominalModel` of a model description.

    Parameters
    ----------
    description : dict, str or Path
        A model description (dict), or the path of a JSON or YAML file holding one.
    **overrides : float
        Parameter values replacing the description's defaults.

    Returns
    -------
    NominalModel
        Its ``source`` is the nominal-model JSON it maps to (``to_dict()``).

    Raises
    ------
    SystemDefinitionError
        One line naming the part of the description that has no exact nominal-model reading
        (see :mod:`hunting.describe.mechanical`).

    Examples
    --------
    >>> d = {"parameters": {"m": 95.0, "cm": 35.15, "Fc": 20.0, "b": 200.0, "kp": 3.9e4, "kd": 243.0,
    ...                     "r": 0.0},
    ...      "states": ["q", "v"], "signals": {"u": "-kp*(q - r) - kd*v"},
    ...      "equations": {"q": "v", "v": "(cm*u - F)/m"},
    ...      "friction": {"force": "F", "velocity": "v", "model": "switch",
    ...                   "slip": "sign(w)*Fc + b*w", "stick": "Fc"}}
    >>> nominal_from_description(d).to_dict()["controller"]
    {'type': 'pid', 'kp': 39000.0, 'kd': 243.0, 'ki': 0.0, 'derivative_on': 'measurement'}
    """
    from ..describe import cache
    from ..describe.mechanical import mechanical_parameters
    if isinstance(description, (str, Path)):
        from ..describe import read_description
        description = read_description(description)
    key = _reading_key(description, overrides)
    known = cache.json_lookup(READINGS, key) if key else None
    if isinstance(known, dict):
        try:
            return NominalModel.from_dict(known)
        except Exception:  # noqa: BLE001 -- an entry this code did not write: read the description again
            pass
    model = nominal_from_parameters(mechanical_parameters(description, **overrides))
    if key:
        cache.json_store(READINGS, key, model.to_dict())
    return model


READINGS = "readings"       # the model cache's folder of nominal models read off descriptions


def _reading_key(description, overrides: dict) -> str | None:
    """The digest the nominal model of ``description`` with ``overrides`` is cached under: of
    their JSON text and of the source of the code that reads it (this module and the
    hunting.describe package, so an upgrade or an edit never loads a reading of other code).
    None when the description is not plain JSON data (then it is read each time)."""
    import hashlib

    from .. import describe
    try:
        text = json.dumps({"description": description, "overrides": overrides}, sort_keys=True, allow_nan=False)
        sources = [Path(__file__)] + sorted(Path(describe.__file__).parent.glob("*.py"))
        code = b"".join(f.read_bytes() for f in sources)
    except (TypeError, ValueError, OSError):
        return None
    return hashlib.sha256(text.encode() + code).hexdigest()[:32]


def nominal_from_parameters(p) -> NominalModel:
    """The :class:`NominalModel` of parameters read off a description
    (:func:`hunting.describe.mechanical.mechanical_parameters`, exact or an error naming the part
    that has no reading):

    - friction: ``switch`` with Fs = Fc in both directions is the law ``coulomb-viscous``, otherwise
      ``switch`` (a Stribeck dip); ``lugre`` is ``lugre`` with its sigma0 and sigma1;
    - controller: ``{"type": "pid", "kp", "kd", "ki"}`` with ``"tau_f"`` for a derivative filter and
      ``"derivative_on": "measurement"`` when the reference enters the P and I terms only; the data's
      ``q_ref`` column is the reference (the description's reference parameter or signal is only its
      placeholder), ``"saturation"`` for a ``min(max(.., -S), S)`` limit, and the controller is
      updated every data sample (a description is continuous);
    - cogging: the harmonics read off the velocity equation, as functions of the description's
      position state (which is the data's q column);
    - what a description cannot say stays at the nominal model's defaults: no delay, flexibility,
      frictional lag or dwell, sample time, and the sensor's resolution read from the data.
    """
    if p.law == "lugre":
        law = "lugre"
    else:
        flat = all(c.Fs == c.Fc for c in (p.curve.positive, p.curve.negative))
        law = "coulomb-viscous" if flat else "switch"
    ctrl = None
    if p.controller is not None:
        c = p.controller
        ctrl = {"type": "pid", "kp": c.kp, "kd": c.kd, "ki": c.ki}
        if c.tau_f:
            ctrl["tau_f"] = c.tau_f
        if c.derivative_on != "error":
            ctrl["derivative_on"] = c.derivative_on
        if math.isfinite(c.saturation):
            ctrl["saturation"] = c.saturation
    model = NominalModel(p.mass, p.cm, p.curve, law, offset=p.offset, sigma0=p.sigma0, sigma1=p.sigma1,
                         controller=ctrl, cogging=() if p.cogging is None else (p.cogging,))
    return model.replace()
