"""What the blind generator simulates: plant, controller, sensor and noise, as plain dataclasses;
their parameter vectors for :mod:`benchmarks.blind.simulate`; the nominal model JSON a user
would write for them (the public schema of ``hunting diagnose --model``); one closed-loop record.

Nothing here imports ``hunting``: the JSON is written from the schema's documentation."""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from . import simulate as sim


@dataclass(frozen=True)
class Curve:
    """Steady friction of one direction: g(r) = Fc + (Fs - Fc) exp(-(r / vs)^beta), F = g + b r
    [N, N, m/s, -, N s/m]."""

    Fc: float
    Fs: float
    vs: float = 0.01
    beta: float = 2.0
    b: float = 0.0

    def vector(self) -> list:
        return [self.Fc, self.Fs, self.vs, self.beta, self.b]


@dataclass(frozen=True)
class Plant:
    """mass [kg]: the total (rigid) mass; cm [N per unit of u]; pos, neg : the friction curves
    of each direction; offset [N] (acts like friction: m a = cm u - F - offset - F_cog); law :
    "static" (Switch stick at Fs) or "lugre"; sigma0 [N/m], sigma1 [N s/m]; lag [s] (frictional
    memory of the Stribeck level); dwell : (level [N], gain [N], time [s]) or None; flex :
    (load mass m2 [kg], frequency [Hz], damping ratio) with the motor side m1 = mass - m2, or
    None; cogging : (pitch [m], cos coefficients [N], sin coefficients [N]) or None, F_cog(q) =
    sum_k cos_k cos(2 pi k q / pitch) + sin_k sin(2 pi k q / pitch); delay [s] of the actuation."""

    mass: float
    cm: float
    pos: Curve
    neg: Curve
    offset: float = 0.0
    law: str = "static"
    sigma0: float = 0.0
    sigma1: float = 0.0
    lag: float = 0.0
    dwell: tuple | None = None
    flex: tuple | None = None
    cogging: tuple | None = None
    delay: float = 0.0

    def vector(self) -> np.ndarray:
        P = np.zeros(sim.NPAR)
        m2 = self.flex[0] if self.flex else 0.0
        P[sim.M1] = self.mass - m2
        P[sim.CM] = self.cm
        P[sim.OFFSET] = self.offset
        P[sim.LUGRE] = 1.0 if self.law == "lugre" else 0.0
        P[sim.POS:sim.POS + 5] = self.pos.vector()
        P[sim.NEG:sim.NEG + 5] = self.neg.vector()
        P[sim.SIGMA0], P[sim.SIGMA1], P[sim.LAG] = self.sigma0, self.sigma1, self.lag
        if self.dwell:
            P[sim.DW_LEVEL], P[sim.DW_GAIN], P[sim.DW_TIME] = self.dwell
        if self.flex:
            m2, f, zeta = self.flex
            w = 2 * math.pi * f
            P[sim.M2], P[sim.K2], P[sim.C2] = m2, m2 * w * w, 2 * zeta * m2 * w
        return P

    def cog_vector(self) -> np.ndarray:
        if not self.cogging:
            return np.zeros(0)
        pitch, cos, sin = self.cogging
        out = [pitch]
        for a, b in zip(cos, sin):
            out += [a, b]
        return np.array(out, float)

    @property
    def symmetric(self) -> bool:
        return self.pos == self.neg


@dataclass(frozen=True)
class Controller:
    """kind "pid" (u = -(kp e + kd D + ki I), e = y - r) or "pd-velocity-loop" (u = kv (kp
    (r - y) - v_f)); tau_f [s] the derivative filter; d_on_meas : derivative of the measurement;
    saturation : |u| bound (inf: none); dac : the output's quantization step (0: none)."""

    kind: str
    kp: float
    kd: float = 0.0
    ki: float = 0.0
    kv: float = 0.0
    tau_f: float = 0.0
    d_on_meas: bool = False
    saturation: float = math.inf
    dac: float = 0.0

    def vector(self) -> np.ndarray:
        C = np.zeros(sim.NCTRL)
        C[sim.C_TYPE] = sim.PID if self.kind == "pid" else sim.PDV
        C[sim.C_KP], C[sim.C_KD], C[sim.C_KI], C[sim.C_KV] = self.kp, self.kd, self.ki, self.kv
        C[sim.C_TAUF], C[sim.C_DMEAS] = self.tau_f, float(self.d_on_meas)
        C[sim.C_SAT], C[sim.C_DAC] = self.saturation, self.dac
        return C


@dataclass(frozen=True)
class Sensor:
    """resolution [m] of the encoder (round to nearest); noise [m]: standard deviation of the
    white position noise before quantization."""

    resolution: float
    noise: float = 0.0


@dataclass(frozen=True)
class Noise:
    """Actuator (current) noise added to u before the motor constant, in u's unit, held per
    sample: an AR(1) component of standard deviation ar_std and correlation time ar_time [s]
    plus a white component white_std."""

    ar_std: float = 0.0
    ar_time: float = 0.01
    white_std: float = 0.0

    def draw(self, n: int, dt: float, rng: np.random.Generator) -> np.ndarray:
        out = self.white_std * rng.standard_normal(n)
        if self.ar_std > 0:
            from scipy.signal import lfilter
            phi = math.exp(-dt / self.ar_time)
            e = rng.standard_normal(n) * self.ar_std * math.sqrt(1 - phi * phi)
            # start in the stationary distribution
            ar = lfilter([1.0], [1.0, -phi], e, zi=[phi * self.ar_std * rng.standard_normal()])[0]
            out = out + ar
        return out


@dataclass(frozen=True)
class Setup:
    """One benchmark system: the true plant and controller, the sensor and noise, and the
    nominal plant and controller the user's model JSON describes."""

    plant: Plant
    controller: Controller
    sensor: Sensor
    noise: Noise
    nominal_plant: Plant
    nominal_controller: Controller
    dt: float
    extra: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return asdict(self)


def nominal_json(plant: Plant, ctrl: Controller, sensor: Sensor) -> dict:
    """The model JSON of ``hunting diagnose`` for this plant, controller and sensor (its
    documented schema: plant, friction, controller, sensor)."""
    p, n = plant.pos, plant.neg
    dip = p.Fs > p.Fc or n.Fs > n.Fc
    law = "lugre" if plant.law == "lugre" else ("stribeck" if dip else "coulomb-viscous")
    fr = {"law": law, "Fc": p.Fc, "b": p.b}
    if law != "coulomb-viscous":
        fr.update(Fs=p.Fs, vs=p.vs, beta=p.beta)
    if not plant.symmetric:
        fr.update(Fc_neg=n.Fc, b_neg=n.b)
        if law != "coulomb-viscous":
            fr.update(Fs_neg=n.Fs, vs_neg=n.vs, beta_neg=n.beta)
    if law == "lugre":
        fr.update(sigma0=plant.sigma0, sigma1=plant.sigma1)
    if plant.lag:
        fr["lag"] = plant.lag
    if plant.dwell:
        fr["dwell"] = dict(zip(("level", "gain", "time"), plant.dwell))
    pl = {"mass": plant.mass, "motor_constant": plant.cm, "offset": plant.offset}
    if plant.delay:
        pl["delay"] = plant.delay
    if plant.cogging:
        pitch, cos, sin = plant.cogging
        pl["cogging"] = [{"pitch": pitch, "cos": list(cos), "sin": list(sin)}]
    if plant.flex:
        pl["flexibility"] = dict(zip(("load_mass", "frequency", "damping"), plant.flex))
    if ctrl.kind == "pid":
        c = {"type": "pid", "kp": ctrl.kp, "kd": ctrl.kd, "ki": ctrl.ki,
             "derivative_on": "measurement" if ctrl.d_on_meas else "error"}
        if ctrl.tau_f:
            c["tau_f"] = ctrl.tau_f
    else:
        c = {"type": "pd-velocity-loop", "kp": ctrl.kp, "kv": ctrl.kv}
    if math.isfinite(ctrl.saturation):
        c["saturation"] = ctrl.saturation
    if ctrl.dac:
        c["output_resolution"] = ctrl.dac
    sens = {"resolution": sensor.resolution}
    if sensor.noise:
        sens["noise"] = sensor.noise
    return {"plant": pl, "friction": fr, "controller": c, "sensor": sens}


@dataclass
class Record:
    """One closed-loop run sampled at dt: t, r (reference), q (measured), u (controller output)
    (n,); X (n, 5) the true state [q, v, w, q2, v2] and stuck (n,) at each sample instant;
    i_noise (n,) the actuator noise; status (0 ok) and message."""

    t: np.ndarray
    r: np.ndarray
    q: np.ndarray
    u: np.ndarray
    X: np.ndarray
    stuck: np.ndarray
    i_noise: np.ndarray
    status: int
    message: str


def atol_for(plant: Plant, r: np.ndarray, rtol: float) -> np.ndarray:
    """Absolute tolerances per state from the record's scales (stroke, speed, force)."""
    qs = max(float(np.ptp(r)), 1e-4)
    fs = max(plant.pos.Fs, plant.neg.Fs, 1e-3)
    zs = fs / plant.sigma0 if plant.law == "lugre" and plant.sigma0 > 0 else qs
    return rtol * np.array([qs, qs, zs if plant.law == "lugre" else fs, qs, qs])


def run(plant: Plant, ctrl: Controller, sensor: Sensor, r: np.ndarray, dt: float, i_noise=None, s_noise=None,
        *, rtol: float = 1e-10, rest_before: float = 1.0) -> Record:
    """The closed loop from rest at q = r[0] (stuck, rested ``rest_before`` [s]) over the
    reference r (n,) sampled at dt [s]; i_noise, s_noise (n,): actuator noise [u units] and
    position noise [m] (default none)."""
    n = r.size
    i_noise = np.zeros(n) if i_noise is None else np.asarray(i_noise, float)
    s_noise = np.zeros(n) if s_noise is None else np.asarray(s_noise, float)
    P = plant.vector()
    x = np.zeros(5)
    x[0] = x[3] = r[0]
    if plant.law == "lugre":
        x[2] = 0.0
    elif plant.lag:
        x[2] = 0.5 * (plant.pos.Fs + plant.neg.Fs)
    st = np.array([0.0 if plant.law == "lugre" else 1.0, 1.0, rest_before])
    q, u = np.zeros(n), np.zeros(n)
    X, stuck = np.zeros((n, 5)), np.zeros(n)
    status, done = sim.run_loop(P, plant.cog_vector(), ctrl.vector(), plant.delay, dt, np.asarray(r, float), i_noise,
                                s_noise, sensor.resolution, x, st, rtol, atol_for(plant, r, rtol), q, u, X, stuck)
    msg = sim.STATUS_TEXT[status] + ("" if status == sim.OK else f" at sample {done} of {n}")
    return Record(np.arange(n) * dt, np.asarray(r, float), q, u, X, stuck.astype(bool), i_noise, int(status), msg)
