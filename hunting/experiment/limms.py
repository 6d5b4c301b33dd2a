"""The thesis' experiments on the virtual LiMMS (sections 10.3-10.4) and the identification of
the Switch and LuGre models from their signals, exactly as on measured data.

Controllers (thesis section 10.3): a weak PD for the closed-loop FRF (bandwidth ~5 Hz), a
strong PID (cross-over ~74 Hz, like the thesis' tuned controller) for tracking, and the
fixed-shape regulator PID u = -K[2 e + e'/(2 pi) + 2 pi int e] at q_d = -0.38 m."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..diagnose.behaviour import stick_phases as _stick_phases
from ..errors import SystemDefinitionError
from ..identify import (cogging_table, curve_from_fit, estimate_frf, fit_double_integrator, fit_second_order,
                        fit_stribeck)
from ..identify.frf import FRF, ParameterFit, prbs
from ..models.controller import PID
from ..models.friction import DirectionalCurve, LuGre, Switch
from ..models.loop import ServoLoop
from ..models.plant import Cogging, Plant
from .motor import Q_D, VirtualMotor
from .sampled import DiscretePID, Record, run

WEAK_PD = DiscretePID(kp=120.0, kd=5.3, ki=0.0)
STRONG_PID = DiscretePID(kp=8.2e3, kd=53.0, ki=3.8e5, tau_f=4.3e-4)
STROKE_FRF = (-0.475, -0.025)
STROKE_COG = (-0.49, -0.04)


def regulator(K: float) -> DiscretePID:
    """The chapter-10 regulator (fixed-shape PID, tau_d = tau_i = 1/(2 pi)) as a sampled law."""
    return DiscretePID.from_pid(PID.fixed_shape(K))


def _trapezoid(a: float, b: float, speed: float, fs: float, strokes: int, accel: float = 1.0,
               dwell: float = 0.2) -> tuple[np.ndarray, np.ndarray]:
    """Reference forth and back between a and b: constant speed, acceleration ``accel``, rest
    ``dwell`` s at each end. Returns (r, r') sampled at fs."""
    t_acc = speed / accel
    L = abs(b - a)
    t_cruise = (L - speed * t_acc) / speed
    if t_cruise <= 0:
        raise SystemDefinitionError(f"stroke {L} m is too short for speed {speed} m/s at {accel} m/s^2")
    T1 = 2 * t_acc + t_cruise
    t = np.arange(0.0, dwell + T1, 1.0 / fs)
    v = np.where(t < dwell, 0.0, np.minimum.reduce([np.full_like(t, speed), accel * (t - dwell),
                                                    accel * (dwell + T1 - t)]))
    v = np.clip(v, 0.0, speed)
    x = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1])) / fs])
    x *= L / x[-1]
    rs, vs = [], []
    for k in range(strokes):
        sgn = 1.0 if (k % 2 == 0) == (b > a) else -1.0
        start = a if k % 2 == 0 else b
        rs.append(start + sgn * x)
        vs.append(sgn * v)
    return np.concatenate(rs), np.concatenate(vs)


def _hold_then(motor: VirtualMotor, q_hold: float, t_hold: float, seed: int) -> Record:
    """Bring the mass from rest at q_hold to a settled hold with the strong PID."""
    return run(motor, STRONG_PID, int(t_hold * motor.fs), reference=q_hold, x0=(q_hold, 0.0, 0.0), seed=seed)


# ----------------------------------------------------------------------------------- experiments
def sensitivity_experiment(motor: VirtualMotor, *, strokes: int = 8, rms: float = 0.1, bandwidth: float = 500.0,
                           speed: float = 0.1, seed: int = 1) -> tuple[Record, list]:
    """Closed-loop FRF run (section 10.3.1): weak PD, reference forth and back at ``speed`` over
    0.45 m, a PRBS v of ``rms`` [V] up to ``bandwidth`` [Hz] added to the controller output.
    Returns the record and the constant-velocity fragments (index slices) to use."""
    r, rv = _trapezoid(*STROKE_FRF, speed, motor.fs, strokes)
    v = prbs(r.size, bandwidth=bandwidth, fs=motor.fs, amplitude=rms, seed=seed)
    rec = run(motor, WEAK_PD, r.size, reference=r, injection=v, x0=(r[0], 0.0, 0.0), seed=seed)
    cruise = np.abs(np.abs(rv) - speed) < 1e-12
    edges = np.flatnonzero(np.diff(cruise.astype(int)))
    starts = [0] + list(edges + 1) if cruise[0] else list(edges + 1)
    frags = []
    for s in starts:
        if not cruise[s]:
            continue
        e = s
        while e < cruise.size and cruise[e]:
            e += 1
        margin = int(0.1 * motor.fs)                # settle after the acceleration phase
        if e - s > 2 * margin:
            frags.append(slice(s + margin, e))
    return rec, frags


def identify_mass(motor: VirtualMotor, rec: Record, frags: list, *, nperseg: int = 4096,
                  band=(30.0, 140.0)) -> tuple[ParameterFit, FRF, FRF]:
    """m/cm from the sensitivity S = W/V (W the plant input) and P = (1/S - 1)/C with the known
    sampled controller, fitted as a double integrator on ``band`` [Hz] (Fig. 10.4).
    Returns (fit with m_over_cm, S, P)."""
    S = estimate_frf([rec.v[s] for s in frags], [rec.u[s] for s in frags], motor.fs, nperseg=nperseg)
    C = WEAK_PD.frf(S.f, motor.fs)
    P = FRF(S.f, (1.0 / S.H - 1.0) / C, S.coherence, S.n_averages)
    fit = fit_double_integrator(P, *band)
    g, sg = fit.values["g"], fit.sigma["g"]
    vals = dict(fit.values, m_over_cm=1.0 / g)
    sig = dict(fit.sigma, m_over_cm=sg / g ** 2)
    return ParameterFit(vals, sig, fit.residual, fit.n), S, P


def cogging_experiment(motor: VirtualMotor, *, speed: float = 0.05, seed: int = 2) -> tuple[Record, np.ndarray, np.ndarray]:
    """Slow tracking run (section 10.3.2): strong PID, 0.05 m/s forth and back over 0.45 m.
    Returns (record, reference velocity per sample, mask of the constant-velocity samples)."""
    r, rv = _trapezoid(*STROKE_COG, speed, motor.fs, 2)
    rec = run(motor, STRONG_PID, r.size, reference=r, x0=(r[0], 0.0, 0.0), seed=seed)
    cruise = np.abs(np.abs(rv) - speed) < 1e-12
    return rec, rv, cruise


def identify_cogging(motor: VirtualMotor, rec: Record, rv: np.ndarray, cruise: np.ndarray,
                     cutoff_hz: float = 15.0, speed: float = 0.05) -> Cogging:
    """Cogging table: feedback force cm uc per direction minus its mean, zero-phase 5th-order
    Butterworth in position, both directions averaged. The thesis filters at 35 Hz (700 1/m at
    0.05 m/s); here 15 Hz (300 1/m) is the default: it still passes four harmonics of the 15 mm
    pitch, and on the virtual motor it cuts the error of the table's slope (the quantity the
    analysis uses) from 1200 to 340 N/m rms, the noise being the strong PID's derivative acting
    on 1 um encoder steps."""
    return cogging_table(rec.y[cruise], motor.cm * rec.uc[cruise], rv[cruise], spacing=1e-4,
                         cutoff=cutoff_hz / speed)


FRICTION_SPEEDS = (0.001, 0.002, 0.004, 0.007, 0.01, 0.015, 0.02, 0.03, 0.05, 0.08, 0.12, 0.2)


def friction_map_experiment(motor: VirtualMotor, cogging: Cogging | None, *, speeds=FRICTION_SPEEDS,
                            seed: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """Constant-velocity runs (section 10.3.3) in both directions with the strong PID and the
    cogging table as feedforward: the mean feedback force over a whole number of magnet pitches
    at constant speed is the friction force. Returns (v [m/s], F [N]) for both directions."""
    vs, Fs = [], []
    for i, speed in enumerate(speeds):
        L = min(0.4, max(0.03, 8.0 * speed))
        for sgn in (1.0, -1.0):
            a = -0.45 if sgn > 0 else -0.05
            b = a + sgn * L
            r, rv = _trapezoid(a, b, speed, motor.fs, 1, accel=2.0, dwell=0.05)
            ff = 0.0 if cogging is None else cogging(r) / motor.cm
            rec = run(motor, STRONG_PID, r.size, reference=r, feedforward=ff, x0=(a, 0.0, 0.0), seed=seed + i)
            cruise = np.flatnonzero(np.abs(np.abs(rv) - speed) < 1e-12)
            # skip the first fifth (settling), then average over whole magnet pitches
            c0 = cruise[cruise.size // 5]
            dist = np.abs(r[cruise[-1]] - r[c0])
            n_pitch = max(1, int(dist / 0.015))
            c1 = c0 + int(round(n_pitch * 0.015 / speed * motor.fs))
            c1 = min(c1, cruise[-1])
            vs.append(sgn * speed)
            Fs.append(motor.cm * float(np.mean(rec.uc[c0:c1])))
    return np.array(vs), np.array(Fs)


def presliding_experiment(motor: VirtualMotor, q_star: float, *, amplitude: float = 1.5, bandwidth: float = 200.0,
                          duration: float = 40.0, seed: int = 4) -> Record:
    """Open-loop PRBS force of +-``amplitude`` [N] up to ``bandwidth`` [Hz] at q_star, after a
    hold with the strong PID (section 10.3.3, Fig. 10.7). The default 1.5 N (about 5 % of Fs)
    keeps sigma0 z far below g: LuGre's presliding softens as sigma0 |z| approaches g (the
    estimate falls by 5 % at 1-2 N and 25 % at 4 N, where the mass also breaks loose)."""
    hold = _hold_then(motor, q_star, 0.5, seed)
    n = int(duration * motor.fs)
    v = prbs(n, bandwidth=bandwidth, fs=motor.fs, amplitude=amplitude / motor.cm, seed=seed)
    hold_u = float(np.mean(hold.u[-200:]))
    return run(motor, None, n, injection=v, feedforward=hold_u, x0=hold.state, seed=seed + 1)


def identify_presliding(motor: VirtualMotor, rec: Record, m: float, alpha: float, b: float, *,
                        band=(5.0, 150.0), nperseg: int = 8192) -> tuple[ParameterFit, FRF]:
    """sigma0 and sigma1 from the presliding FRF y/u ~ b0 / (s^2 + a1 s + a0), b0 = cm/m,
    a0 = (sigma0 + alpha)/m, a1 = (sigma1 + b)/m (section 10.3.3), with m the identified mass,
    alpha the identified cogging slope at the measuring position, b the identified viscous term."""
    H = estimate_frf(rec.u - rec.u.mean(), rec.y - rec.y.mean(), motor.fs, nperseg=nperseg)
    fit = fit_second_order(H, *band)
    a0, a1 = fit.values["a0"], fit.values["a1"]
    vals = dict(fit.values, sigma0=a0 * m - alpha, sigma1=a1 * m - b)
    sig = dict(fit.sigma, sigma0=fit.sigma["a0"] * m, sigma1=fit.sigma["a1"] * m)
    return ParameterFit(vals, sig, fit.residual, fit.n), H


# ---------------------------------------------------------------------------- regulator experiments
def regulator_experiment(motor: VirtualMotor, K: float, d0: float, duration: float, *, seed: int = 5,
                         hold: bool = True) -> Record:
    """The regulator task at q_d = -0.38 m with gain K [V/m], starting at rest with error d0
    [m] (held there first by the strong PID when ``hold``, so the bristles carry the load)."""
    x0 = _hold_then(motor, Q_D + d0, 0.3, seed).state if hold else (Q_D + d0, 0.0, 0.0)
    x0 = np.array([x0[0], 0.0, x0[2]])
    return run(motor, regulator(K), int(duration * motor.fs), reference=Q_D, x0=x0, seed=seed + 1)


def stick_phases(rec: Record, resolution: float, *, window: float = 0.03, counts: int = 2,
                 moved: float = 60e-6) -> list[tuple[int, int]]:
    """Stick phases in a measured record: maximal runs where the measured position stays within
    ``counts`` encoder counts for at least ``window`` s, after moving more than ``moved`` [m]
    from the previous one (more than the presliding range 2 Fs / sigma0 ~ 45 um, which the
    mass creeps through while the integral action loads the bristles).
    Returns (first, last) sample indices. (With presliding there is no exact stick; the thesis
    decides it by inspection.)"""
    return _stick_phases(rec.y, float(rec.t[1] - rec.t[0]), resolution, window=window, counts=counts, moved=moved,
                  origin=float(rec.y[0]))


def experimental_event_map(motor: VirtualMotor, K: float, grid, *, t_max: float = 20.0, seed: int = 6,
                           workers: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """The "experimental" event map of section 10.4.3: for each d in grid, hold the mass at
    q_d + d with the strong PID, switch to the regulator (fresh integrator), and record the
    error at the next stick. Returns (d, d_next) with NaN where no stick came within t_max."""
    from concurrent.futures import ThreadPoolExecutor
    grid = np.asarray(grid, float)

    def one(i):
        rec = regulator_experiment(motor, K, float(grid[i]), t_max, seed=seed + i)
        ph = stick_phases(rec, motor.resolution)
        return rec.y[ph[0][0]] - Q_D if ph else np.nan
    with ThreadPoolExecutor(max_workers=max(1, workers)) as ex:
        out = np.array(list(ex.map(one, range(grid.size))), float)
    return grid, out


# ------------------------------------------------------------------------------ identified models
@dataclass
class IdentifiedLiMMS:
    """Everything identified from the virtual experiments, with uncertainties, and the loops.

    mass : ParameterFit (m_over_cm); friction : {"positive", "negative"} Stribeck fits;
    presliding : ParameterFit (sigma0, sigma1); cogging : the table; cm : the motor constant
    (given, as in the thesis); records : the experiment records and FRFs for the figures."""

    cm: float
    mass: ParameterFit
    friction: dict
    cogging: Cogging
    presliding: ParameterFit
    q_star: float
    records: dict = field(default_factory=dict)

    @property
    def m(self) -> float:
        return self.cm * self.mass.values["m_over_cm"]

    @property
    def curve(self) -> DirectionalCurve:
        return DirectionalCurve(curve_from_fit(self.friction["positive"]), curve_from_fit(self.friction["negative"]))

    def loop(self, K: float, model: str = "switch") -> ServoLoop:
        """The identified closed loop at gain K [V/m]: model "switch" or "lugre"."""
        if model not in ("switch", "lugre"):
            raise SystemDefinitionError(f"model = {model!r} is not allowed: use 'switch' or 'lugre'")
        plant = Plant(mass=self.m, motor_constant=self.cm, setpoint=Q_D, cogging=self.cogging)
        if model == "switch":
            fr = Switch(self.curve)
        else:
            fr = LuGre(self.curve, sigma0=self.presliding.values["sigma0"], sigma1=self.presliding.values["sigma1"])
        return ServoLoop(plant, fr, PID.fixed_shape(K), name=f"identified LiMMS ({model}, K={K:g})")

    def table(self, motor: VirtualMotor) -> list[tuple[str, float, float, float]]:
        """(name, identified, standard uncertainty, true) for every identified parameter."""
        rows = [("m [kg]", self.m, self.cm * self.mass.sigma["m_over_cm"], motor.mass)]
        for key, true in (("positive", motor.positive), ("negative", motor.negative)):
            f = self.friction[key]
            for p in ("Fs", "Fc", "vs", "b"):
                rows.append((f"{p} ({'+' if key == 'positive' else '-'}) ", f.values[p], f.sigma[p], getattr(true, p)))
        rows.append(("sigma0 [N/m]", self.presliding.values["sigma0"], self.presliding.sigma["sigma0"], motor.sigma0))
        rows.append(("sigma1 [N s/m]", self.presliding.values["sigma1"], self.presliding.sigma["sigma1"], motor.sigma1))
        return rows


def _cogging_zero(cog: Cogging, near: float) -> float:
    """The zero crossing of the table closest to ``near`` (where section 10.3.3 measures)."""
    q = np.linspace(near - 0.012, near + 0.012, 4801)
    F = cog(q)
    idx = np.flatnonzero(np.sign(F[1:]) != np.sign(F[:-1]))
    if idx.size == 0:
        return near
    i = idx[np.argmin(np.abs(q[idx] - near))]
    return float(q[i] - F[i] * (q[i + 1] - q[i]) / (F[i + 1] - F[i]))


def identify(motor: VirtualMotor, *, seed: int = 0) -> IdentifiedLiMMS:
    """Run the three identification stages of section 10.3 on the motor and fit the models."""
    rec_s, frags = sensitivity_experiment(motor, seed=seed + 1)
    mass, S, P = identify_mass(motor, rec_s, frags)
    rec_c, rv, cruise = cogging_experiment(motor, seed=seed + 2)
    cog = identify_cogging(motor, rec_c, rv, cruise)
    v, F = friction_map_experiment(motor, cog, seed=seed + 3)
    fric = fit_stribeck(v, F, direction_dependent=True)
    q_star = _cogging_zero(cog, Q_D)
    rec_p = presliding_experiment(motor, q_star, seed=seed + 4)
    m = motor.cm * mass.values["m_over_cm"]
    b_avg = 0.5 * (fric["positive"].values["b"] + fric["negative"].values["b"])
    alpha = float(cog.slope(np.array([q_star]))[0])
    pre, H = identify_presliding(motor, rec_p, m, alpha, b_avg)
    return IdentifiedLiMMS(motor.cm, mass, fric, cog, pre, q_star,
                           records=dict(sensitivity=rec_s, S=S, P=P, cogging=(rec_c, rv, cruise),
                                        friction_map=(v, F), presliding=rec_p, presliding_frf=H))


# ------------------------------------------------------------------ bifurcation diagram by simulation
@dataclass(frozen=True)
class MeasuredAttractor:
    """What a long regulator run of the motor settles to at gain K [V/m]: ``stick_errors`` (k,)
    of one period in order (period k; 0 when no period <= 32 is found within ``tol`` [m]),
    ``at_rest`` when the motion has stopped (no slip in the recorded window), ``n_sticks``
    stick phases recorded, ``amplitude`` max |e| [m] over the window."""

    K: float
    period: int
    stick_errors: np.ndarray
    at_rest: bool
    n_sticks: int
    amplitude: float

    def as_dict(self) -> dict:
        return dict(K=self.K, period=self.period, stick_errors=[float(v) for v in self.stick_errors],
                    at_rest=self.at_rest, n_sticks=self.n_sticks, amplitude=self.amplitude)


def measured_attractor(motor: VirtualMotor, K: float, d0: float, *, t_settle: float = 40.0,
                       t_record: float = 40.0, tol: float = 8e-6, rest: float = 1e-4,
                       seed: int = 7) -> MeasuredAttractor:
    """Run the regulator from rest at error d0 for t_settle + t_record s and read the stick errors
    of the last t_record s as the thesis reads its measured limit cycles (Fig. 10.12a). The motor
    counts as at rest when |e| stays below ``rest`` [m] over the second half of the window (near
    the equilibrium set, quantization and the integral action still cause micro-slips of a few
    tens of um now and then)."""
    rec = regulator_experiment(motor, K, d0, t_settle + t_record, seed=seed, hold=False)
    tail = rec.since(int(t_settle * motor.fs))
    e = tail.y - Q_D
    amp = float(np.max(np.abs(e)))
    if np.max(np.abs(e[e.size // 2:])) < rest:
        return MeasuredAttractor(K, 0, np.zeros(0), True, 0, amp)
    d = np.array([e[a] for a, _ in stick_phases(tail, motor.resolution)])
    period = 0
    for p in range(1, min(32, d.size // 2) + 1):
        if np.all(np.abs(d[p:] - d[:-p]) <= tol):
            period = p
            break
    pts = d[-period:] if period else d
    return MeasuredAttractor(K, period, pts, False, int(d.size), amp)


def measured_diagram(motor: VirtualMotor, K_values, d0: float = 0.01, *, workers: int = 2, **kw) -> list:
    """measured_attractor over gains K (runs in ``workers`` threads; the simulator releases the GIL)."""
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(max_workers=max(1, workers)) as ex:
        return list(ex.map(lambda K: measured_attractor(motor, float(K), d0, **kw), K_values))
