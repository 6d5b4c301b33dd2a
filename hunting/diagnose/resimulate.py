"""Re-simulation of the closed loop from the measured reference: the behaviour view of a diagnosis.

The model (a :class:`NominalModel`, nominal or extended) is driven by the digital controller of
its ``controller`` description, sampled at the data's instants, with a zero-order hold, the
encoder resolution of the data and the controller's saturation:

    m q'' = cm u(t - delay) + f_ext - F - offset - F_cog(q)

with a flexible load (``plant.flexibility``) of mass m2 behind the motor on a spring k and damper c:
the motor side's mass is m - m2 and it feels k d + c d' besides, d the load's position relative to
the motor, m2 (q + d)'' = -(k d + c d'); the load swings on while the motor sticks.

Friction F: for the static laws (coulomb-viscous, stribeck, switch) the exact stick of the Switch
model in its Filippov limit (the mass sticks when its velocity reaches zero and the force it
needs, |cm u + f_ext - offset - F_cog| <= Fs of that direction, is available; it slips again when
not); reversals are located inside a substep by linear interpolation of v. For lugre the bristle
state z is integrated (F = sigma0 z + sigma1 z' + b v). The plant is integrated with fixed RK4
substeps between samples (``substeps`` per sample).

Controllers (the MODEL.json ``controller`` schema):
  {"type": "pid", "form": "PDI", "P", "D", "I"}  u = -P (e + D e' + I int e), e = q - q_ref
  {"type": "pid", "form": "K", "K", "tau_d", "tau_i"}  the fixed shape of chapters 8 and 10
  {"type": "pid", "kp", "kd", "ki"}                     plain gains
  common pid keys: "derivative_on": "error" | "measurement", "tau_f" [s] (first-order filter of
  the difference quotient), "sample_time" [s], "saturation" (|u| bound, default none);
  "output_resolution" (the DAC's step of u, default none);
  {"type": "pd-velocity-loop", "kp" [1/s], "kv", "sample_time", "saturation", "output_resolution"}:
  u = kv (kp (q_ref - q) - v_f), v_f the backward difference of the 2-tap averaged position
  (the EMPS benchmark's controller).
The integral state starts where the first controller output equals the measured u[0]."""
from __future__ import annotations

import math
import os
import threading
import warnings
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace

import numba
import numpy as np

from ..errors import SystemDefinitionError, check_finite, check_finite_positive
from ..models.controller import PID
from ..models.friction import lugre_rates, stribeck_level
from ..models.plant import cogging_force
from .data import Measurement
from .model import NominalModel

_PID, _PDV = 1.0, 2.0


def _threads() -> int:
    """The threads re-simulations run on side by side (:func:`side_by_side`): the environment's
    HUNTING_THREADS (a positive integer; set 1 where processes already fill the cores, as the test
    suite's workers do), else min(4, the machine's cores)."""
    default = min(4, os.cpu_count() or 1)
    raw = os.environ.get("HUNTING_THREADS")
    if raw is None:
        return default
    try:
        n = int(raw)
    except ValueError:
        n = 0
    if n < 1:
        warnings.warn(f"HUNTING_THREADS = {raw!r} is not a positive integer: re-simulating on {default} threads")
        return default
    return n


THREADS = _threads()
_POOL_THREAD = threading.local()   # marks side_by_side's own threads (no pool inside a pool)

_CTRL_KEYS = {"pid": {"type", "form", "P", "D", "I", "K", "tau_d", "tau_i", "kp", "kd", "ki", "derivative_on",
                      "tau_f", "sample_time", "saturation", "output_resolution"},
              "pd-velocity-loop": {"type", "kp", "kv", "sample_time", "saturation", "output_resolution"}}


@dataclass(frozen=True)
class SampledController:
    """A digital controller from the schema: kind "pid" or "pd-velocity-loop"; kp, kd, ki [u/m,
    u s/m, u/(m s)] for pid (kp [1/s] and kv [u s/m] for the velocity loop); tau_f [s];
    derivative_on_measurement; sample_time [s] or None (the data's); saturation (|u| bound, inf
    for none); output_resolution (the DAC's step of u, 0 for none)."""

    kind: str
    kp: float
    kd: float = 0.0
    ki: float = 0.0
    kv: float = 0.0
    tau_f: float = 0.0
    derivative_on_measurement: bool = False
    sample_time: float | None = None
    saturation: float = math.inf
    output_resolution: float = 0.0

    @staticmethod
    def from_schema(d: dict) -> "SampledController":
        if not isinstance(d, dict) or d.get("type") not in _CTRL_KEYS:
            raise SystemDefinitionError(f"controller = {d!r}: 'type' must be one of {sorted(_CTRL_KEYS)}")
        kind = d["type"]
        bad = set(d) - _CTRL_KEYS[kind]
        if bad:
            raise SystemDefinitionError(f"controller ({kind}): unknown keys {sorted(bad)}; allowed: "
                                        f"{sorted(_CTRL_KEYS[kind])}")
        ts = d.get("sample_time")
        ts = None if ts is None else check_finite_positive("controller sample_time", ts)
        sat = check_finite_positive("controller saturation", d.get("saturation", math.inf), allow_inf=True)
        dac = check_finite_positive("controller output_resolution", d.get("output_resolution", 0.0), allow_zero=True)
        if kind == "pd-velocity-loop":
            for k in ("kp", "kv"):
                if k not in d:
                    raise SystemDefinitionError(f"controller (pd-velocity-loop): {k!r} is required")
            return SampledController(kind, check_finite("kp", d["kp"]), kv=check_finite("kv", d["kv"]),
                                     sample_time=ts, saturation=sat, output_resolution=dac)
        form = d.get("form", "gains")
        if form == "PDI":
            pid = PID.pdi(d.get("P", 0.0), d.get("D", 0.0), d.get("I", 0.0))
        elif form == "K":
            pid = PID.fixed_shape(d["K"], d.get("tau_d", 1 / (2 * math.pi)), d.get("tau_i", 1 / (2 * math.pi)))
        elif form == "gains":
            pid = PID(check_finite("kp", d.get("kp", 0.0)), check_finite("kd", d.get("kd", 0.0)),
                      check_finite("ki", d.get("ki", 0.0)))
        else:
            raise SystemDefinitionError(f"controller form = {form!r} is not allowed: use 'PDI', 'K' or 'gains'")
        on = d.get("derivative_on", "error")
        if on not in ("error", "measurement"):
            raise SystemDefinitionError(f"controller derivative_on = {on!r}: use 'error' or 'measurement'")
        tau_f = check_finite_positive("controller tau_f", d.get("tau_f", 0.0), allow_zero=True)
        return SampledController("pid", pid.kp, pid.kd, pid.ki, 0.0, tau_f, on == "measurement", ts, sat, dac)

    def array(self, dt: float) -> np.ndarray:
        """[kind code, kp, kd, ki, kv, tau_f, d_on_meas, saturation, hold, output_resolution] for the
        kernel; hold =
        data samples per controller update (sample_time / dt, an integer)."""
        hold = 1
        if self.sample_time is not None:
            hold = int(round(self.sample_time / dt))
            if hold < 1 or abs(hold * dt - self.sample_time) > 1e-3 * self.sample_time:
                raise SystemDefinitionError(
                    f"controller sample_time = {self.sample_time!r} s is not an integer multiple of the data's "
                    f"sample interval {dt!r} s: resample the data or correct sample_time")
        code = _PID if self.kind == "pid" else _PDV
        return np.array([code, self.kp, self.kd, self.ki, self.kv, self.tau_f, float(self.derivative_on_measurement),
                         self.saturation, float(hold), self.output_resolution])


@numba.njit(cache=True, error_model="numpy")
def _control(ctrl, x, y, rk, T):
    """One controller update from the measured position y [m] and the reference rk [m], T [s]
    after the last: the output before injection, saturation and DAC; updates the controller
    state x[4:9] = [I, D, x_prev, y_prev, qf_prev] in place."""
    if ctrl[0] == 1.0:
        e = y - rk
        sig = y if ctrl[6] > 0.5 else e
        x[4] += T * e
        x[5] = (ctrl[5] * x[5] + (sig - x[6])) / (ctrl[5] + T)
        x[6] = sig
        uc = -(ctrl[1] * e + ctrl[2] * x[5] + ctrl[3] * x[4])
    else:
        qf = 0.5 * y + 0.5 * x[7]
        uc = ctrl[4] * (ctrl[1] * (rk - y) - (qf - x[8]) / T)
        x[8] = qf
    x[7] = y
    return uc


@numba.njit(cache=True, error_model="numpy")
def _output(ctrl, u):
    """The controller output u after its saturation and the DAC's step."""
    if u > ctrl[7]:
        u = ctrl[7]
    elif u < -ctrl[7]:
        u = -ctrl[7]
    if ctrl[9] > 0.0:                  # the DAC's step
        u = ctrl[9] * math.floor(u / ctrl[9] + 0.5)
    return u


@numba.njit(cache=True, error_model="numpy")
def _replay(ctrl, r, y, inj, x, dt, u_out):
    """The controller's outputs u_out (n,) on measured positions y (n,) [m] and references r
    (n,) [m] sampled every dt [s], with the injection inj (n,) added, from the controller state x
    (as in _loop)."""
    hold = int(ctrl[8])
    uc = 0.0
    for k in range(y.size):
        if k % hold == 0:
            uc = _control(ctrl, x, y[k], r[k], dt * hold)
        u_out[k] = _output(ctrl, uc + inj[k])


@numba.njit(cache=True, error_model="numpy")
def _cog(q, cog, bases):
    out = 0.0
    for b in bases:
        out += cogging_force(q, cog, b)
    return out


@numba.njit(cache=True, error_model="numpy")
def _load_force(d, w, p):
    """The flexible load's force on the motor side [N]: its spring p[21] and damper p[22] at the
    load's position d and velocity w relative to the motor."""
    return p[21] * d + p[22] * w


@numba.njit(cache=True, error_model="numpy")
def _load_rate(d, w, a, p):
    """w' of the flexible load relative to the motor at motor acceleration a (0 without a load)."""
    return -_load_force(d, w, p) / p[20] - a if p[20] > 0.0 else 0.0


@numba.njit(cache=True, error_model="numpy")
def _rates(q, v, z, d, w, s, fa, p, cog, bases, steady):
    """(q', v', z', d', w') at applied force fa (cm u + f_ext - offset), direction s for the
    curve. z is LuGre's bristle deflection, or for a static law with frictional memory (lag p[16]
    > 0) the lagging Stribeck level: z' = (g(|v|) - z) / lag, F = s z + b v. steady: LuGre's
    bristles at their steady deflection (z' = 0, F = s g(|v|) + b v: the static curve while
    sliding). d, w: the flexible load's position and velocity relative to the motor (load mass
    p[20], 0 without one: the motor side then carries the whole mass p[0])."""
    base = 4 if s > 0 else 9
    fd = fa - _cog(q, cog, bases) + _load_force(d, w, p)
    m1 = p[0] - p[20]
    if p[3] > 0.5 and not steady:
        zd, F = lugre_rates(v, z, s, p[base], p[base + 1], p[base + 2], p[base + 3], p[base + 4], p[14], p[15], 0.0)
        a = (fd - F) / m1
        return v, a, zd, w, _load_rate(d, w, a, p)
    g = stribeck_level(s * v, p[base], p[base + 1], p[base + 2], p[base + 3])
    if p[16] > 0.0:
        a = (fd - s * z - p[base + 4] * v) / m1
        return v, a, (g - z) / p[16], w, _load_rate(d, w, a, p)
    a = (fd - s * g - p[base + 4] * v) / m1
    return v, a, 0.0, w, _load_rate(d, w, a, p)


@numba.njit(cache=True, error_model="numpy")
def _rk4(q, v, z, d, w, s, fa, h, p, cog, bases, steady):
    """One classical RK4 step of length h with the friction direction s held (steady: as in
    :func:`_rates`): the new (q, v, z, d, w)."""
    a1, b1, c1, d1, e1 = _rates(q, v, z, d, w, s, fa, p, cog, bases, steady)
    a2, b2, c2, d2, e2 = _rates(q + 0.5 * h * a1, v + 0.5 * h * b1, z + 0.5 * h * c1, d + 0.5 * h * d1,
                                w + 0.5 * h * e1, s, fa, p, cog, bases, steady)
    a3, b3, c3, d3, e3 = _rates(q + 0.5 * h * a2, v + 0.5 * h * b2, z + 0.5 * h * c2, d + 0.5 * h * d2,
                                w + 0.5 * h * e2, s, fa, p, cog, bases, steady)
    a4, b4, c4, d4, e4 = _rates(q + h * a3, v + h * b3, z + h * c3, d + h * d3, w + h * e3, s, fa, p, cog, bases,
                                steady)
    return (q + h / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4), v + h / 6.0 * (b1 + 2 * b2 + 2 * b3 + b4),
            z + h / 6.0 * (c1 + 2 * c2 + 2 * c3 + c4), d + h / 6.0 * (d1 + 2 * d2 + 2 * d3 + d4),
            w + h / 6.0 * (e1 + 2 * e2 + 2 * e3 + e4))


@numba.njit(cache=True, error_model="numpy")
def _rk4_load(d, w, h, p):
    """One RK4 step of length h of the flexible load while the motor sticks (its acceleration 0):
    the new (d, w)."""
    d1, e1 = w, _load_rate(d, w, 0.0, p)
    d2, e2 = w + 0.5 * h * e1, _load_rate(d + 0.5 * h * d1, w + 0.5 * h * e1, 0.0, p)
    d3, e3 = w + 0.5 * h * e2, _load_rate(d + 0.5 * h * d2, w + 0.5 * h * e2, 0.0, p)
    d4, e4 = w + h * e3, _load_rate(d + h * d3, w + h * e3, 0.0, p)
    return d + h / 6.0 * (d1 + 2 * d2 + 2 * d3 + d4), w + h / 6.0 * (e1 + 2 * e2 + 2 * e3 + e4)


STIFF_RK4 = 1.0   # h sigma0 |v| / g above which a LuGre substep takes the bristles at steady state (RK4: stable below 2.8)


@numba.njit(cache=True, error_model="numpy")
def _bristle_relaxation(v, s, p):
    """The LuGre bristles' relaxation rate sigma0 |v| / g(v) [1/s] in direction s."""
    base = 4 if s > 0 else 9
    g = stribeck_level(s * v, p[base], p[base + 1], p[base + 2], p[base + 3])
    return p[14] * abs(v) / g if g > 0.0 else 0.0


@numba.njit(cache=True, error_model="numpy")
def _rk4_steady_bristles(q, v, d, w, s, fa, h, p, cog, bases):
    """One RK4 step of length h of a LuGre loop whose bristles relax within the step (h sigma0
    |v| / g beyond STIFF_RK4): they are taken at their steady deflection z = s g(|v|) / sigma0,
    where dz/dt = 0 and the friction is the steady curve (the singular-perturbation limit; its
    error is the bristles' lag, a fraction 1 / (h sigma0 |v| / g) of the step). Plain RK4 on the
    bristle state needs h sigma0 |v| / g < 2.8 to stay stable. Returns (q, v, z, d, w)."""
    qn, vn, _, dn, wn = _rk4(q, v, 0.0, d, w, s, fa, h, p, cog, bases, True)
    base = 4 if s > 0 else 9
    return qn, vn, s * stribeck_level(s * vn, p[base], p[base + 1], p[base + 2], p[base + 3]) / p[14], dn, wn


@numba.njit(cache=True, error_model="numpy", nogil=True)
def _loop(p, cog, bases, ctrl, r, fext, inj, noise, u_init, resolution, dt, substeps, delay_sub, x, q_out, u_out,
          v_out, stuck_out):
    """Advance r.size samples from x = [q, v, z, stuck, I, D, x_prev, y_prev, qf_prev, rest time,
    d, w] (updated in place; d, w the flexible load's position and velocity relative to the
    motor). Returns the number of samples done (< r.size when the state stopped being finite). The break-away force after a rest of t_r is Fs + dwell level + gain (1 - exp(-t_r /
    time)) (p[17:20]); with p[23] = 1 (the seven-parameter form) the slip that follows has it as
    its Stribeck curve's Fs until the next stop. The controller output is quantized to ctrl[9]
    when that is > 0."""
    h = dt / substeps
    pl = p.copy()                      # the parameters of the current slip (its Fs, p[5] or p[10], may have grown)
    lugre = p[3] > 0.5
    hold = int(ctrl[8])
    u = u_init
    uc = 0.0
    q, v, z, stuck = x[0], x[1], x[2], x[3] > 0.5
    t_rest = x[9]
    d, w = x[10], x[11]
    for k in range(r.size):
        qm = q + noise[k]
        y = resolution * math.floor(qm / resolution + 0.5) if resolution > 0.0 else qm
        if k % hold == 0:
            uc = _control(ctrl, x, y, r[k], dt * hold)
        u = _output(ctrl, uc + inj[k])
        q_out[k] = y
        u_out[k] = u
        v_out[k] = v
        stuck_out[k] = stuck
        for i in range(substeps):
            j = (k * substeps + i - delay_sub)
            ua = u_init if j < 0 else u_out[j // substeps]
            fa = p[1] * ua + fext[k] - p[2]
            if lugre:
                s = 1.0 if v >= 0.0 else -1.0
                if h * _bristle_relaxation(v, s, p) <= STIFF_RK4:
                    q, v, z, d, w = _rk4(q, v, z, d, w, s, fa, h, p, cog, bases, False)
                else:
                    q, v, z, d, w = _rk4_steady_bristles(q, v, d, w, s, fa, h, p, cog, bases)
                continue
            rem = h
            for _ in range(3):             # a substep holds at most a stop and a restart
                if stuck:
                    need = fa - _cog(q, cog, bases) + _load_force(d, w, p)
                    grow = p[17] + (p[18] * (1.0 - math.exp(-t_rest / p[19])) if p[19] > 0.0 else 0.0)
                    if -(p[10] + grow) <= need <= p[5] + grow:
                        t_rest += rem
                        if p[20] > 0.0:    # the load swings on while the motor sticks
                            d, w = _rk4_load(d, w, rem, p)
                        if p[16] > 0.0:    # the lagging level relaxes to Fs at rest
                            fs = p[5] if need >= 0.0 else p[10]
                            z = fs + (z - fs) * math.exp(-rem / p[16])
                        break              # friction holds the mass
                    stuck = False
                    s = 1.0 if need > 0.0 else -1.0
                    if p[23] > 0.5:        # the slip starts from the grown break-away force
                        pl[5], pl[10] = p[5] + grow, p[10] + grow
                        if p[16] > 0.0:    # ... and so does the lagging level
                            z = (p[5] if s > 0.0 else p[10]) + grow
                else:
                    s = 1.0 if v > 0.0 else -1.0
                qn, vn, zn, dn, wn = _rk4(q, v, z, d, w, s, fa, rem, pl, cog, bases, False)
                if s * vn > 0.0:
                    q, v, z, d, w = qn, vn, zn, dn, wn
                    break
                # the velocity reaches zero inside: stop there (located by Newton on the RK4
                # step's length from the linear estimate, so the stop is as accurate as the
                # steps), then decide stick or slip for the rest of the substep
                th = s * v / (s * v - s * vn) if s * v - s * vn > 0.0 else 1.0
                for it in range(5):
                    qa, va, za, da, wa = _rk4(q, v, z, d, w, s, fa, th * rem, pl, cog, bases, False)
                    acc = _rates(qa, va, za, da, wa, s, fa, pl, cog, bases, False)[1]
                    th_new = th - va / (rem * acc) if acc != 0.0 else th
                    if it == 4 or not 0.0 < th_new <= 1.0 or abs(th_new - th) <= 1e-13:
                        break              # (qa, za, da, wa) is the state at th
                    th = th_new
                q, z, d, w = qa, za, da, wa
                v = 0.0
                stuck = True
                t_rest = 0.0
                rem *= 1.0 - th
                if rem <= 0.0:
                    break
        if not (math.isfinite(q) and math.isfinite(v) and math.isfinite(z) and math.isfinite(d) and math.isfinite(w)):
            return k
    x[0], x[1], x[2], x[3] = q, v, z, 1.0 if stuck else 0.0
    x[9] = t_rest
    x[10], x[11] = d, w
    return r.size


def model_arrays(model: NominalModel):
    """(p, cog, bases): the flat parameter vector and the cogging components' encodings
    (concatenated; component i starts at bases[i]) of a NominalModel, as the kernel reads them."""
    law = 1.0 if model.law == "lugre" else 0.0
    dw = model.dwell
    fl = model.flexibility
    load = (0.0, 0.0, 0.0)
    if fl is not None and fl.load_mass > 0:
        wn = 2 * np.pi * fl.frequency
        load = (fl.load_mass, fl.load_mass * wn ** 2, 2 * fl.damping * wn * fl.load_mass)
    p = np.array([model.mass, model.cm, model.offset, law, *model.curve.positive.encoded(),
                  *model.curve.negative.encoded(), model.sigma0 or 0.0, model.sigma1 or 0.0, model.lag,
                  *((dw.level, dw.gain, dw.time) if dw is not None else (0.0, 0.0, 0.0)), *load,
                  1.0 if dw is not None and dw.sliding else 0.0])
    blocks = [c.encoded() for c in model.cogging] or [np.zeros(3)]
    bases = np.cumsum([0] + [b.size for b in blocks[:-1]]).astype(np.int64)
    if not model.cogging:
        bases = np.zeros(0, np.int64)
    return p, np.concatenate(blocks), bases


@dataclass(frozen=True)
class Simulation:
    """A re-simulated run on the measurement's instants: t [s], q (quantized like the data) [m],
    u (controller output plus injection: comparable to the measured u), v [m/s], stuck (bool,
    static laws only); ok/message as in the integrators (the state stopped being finite)."""

    t: np.ndarray
    q: np.ndarray
    u: np.ndarray
    v: np.ndarray
    stuck: np.ndarray
    ok: bool = True
    message: str = ""

    def tail(self, start: int) -> "Simulation":
        """The run from sample ``start`` on (a part's, re-simulated through the record before it)."""
        return replace(self, t=self.t[start:], q=self.q[start:], u=self.u[start:], v=self.v[start:],
                       stuck=self.stuck[start:])


def resolution_of(q: np.ndarray) -> float:
    """Encoder resolution [m] read from quantized positions: the largest step s (the fifth
    smallest nonzero position step, or it divided by 2..5) of which at least 95 % of all steps
    are integer multiples (0 when the positions do not look quantized). A percentile of the steps
    is not enough: in fast motion one-count steps are rare, and the percentile lands on two."""
    d = np.abs(np.diff(q))
    d = d[d > 1e-15]
    if d.size < 10:
        return 0.0
    smallest = float(np.partition(d, 4)[4])
    for divisor in range(1, 6):
        k, n = steps_on_grid(q, smallest / divisor)
        if k > 0.95 * n:
            return smallest / divisor
    return 0.0


def steps_on_grid(x: np.ndarray, step: float) -> tuple[int, int]:
    """(k, n): of the n nonzero steps of x (n,), k are integer multiples of ``step`` (within 2 %)."""
    d = np.abs(np.diff(x))
    c = d[d > 1e-15] / step
    return int(np.sum(np.abs(c - np.round(c)) < 0.02)), int(c.size)


def resimulate(meas: Measurement, model: NominalModel, *, controller: dict | None = None,
               substeps: int = 20, resolution: float | None = None, force_noise=None, x0=None, sensor_noise: float | None = None,
               seed: int = 0) -> Simulation:
    """Re-simulate the closed loop of ``model`` on the instants of ``meas``, tracking its q_ref,
    with its f_ext and its injection u_inj (added to the controller output, before the
    saturation), from its initial position (at rest when the measured speed is below one count
    per sample). controller : the schema dict (default: the model's); resolution [m] : encoder
    quantization (default: the model's ``sensor`` resolution, else read from the data); force_noise : optional (n,) force [N] added to the
    drive (for synthetic data); x0 : (q [m], v [m/s], z [m]) to start from instead (z: LuGre's
    bristle deflection; the default carries the force the first measured u applies);
    sensor_noise [m] : standard deviation of the position noise before quantization (default: the
    model's ``sensor`` noise, else 0; near rest it dithers the controller output, which moves a
    LuGre contact), drawn with ``seed``. A part of a record (``meas.source``, :meth:`Measurement.part`)
    is run from the record's first sample and its own samples returned (unless x0 is given)."""
    ctrl_d = controller if controller is not None else model.controller
    if ctrl_d is None:
        raise SystemDefinitionError("the model has no 'controller': re-simulation needs one (see the MODEL.json schema)")
    if meas.q_ref is None:
        raise SystemDefinitionError(f"{meas.name}: re-simulation needs the reference column q_ref")
    if not (isinstance(substeps, (int, np.integer)) and 1 <= substeps <= 10_000):
        raise SystemDefinitionError(f"substeps = {substeps!r} must be an integer in [1, 10000]")
    ctrl = SampledController.from_schema(ctrl_d)
    dt = meas.dt
    if resolution is None and model.resolution is not None:
        resolution = model.resolution
    res = resolution_of(meas.q) if resolution is None else check_finite_positive("resolution", resolution,
                                                                                 allow_zero=True)
    fext = meas.force_ext() + (0.0 if force_noise is None else np.asarray(force_noise, float))
    if fext.shape != (meas.n,):
        raise SystemDefinitionError(f"force_noise must have {meas.n} samples")
    if meas.source is not None and x0 is None:
        # a part of a longer record: run through the record before it, so that the part starts from
        # the state the loop had there (its own start in motion gives guessed controller and
        # friction states: reporting58 d0625, LuGre bristles that cut the record's error by 85 %
        # cut the part's, re-simulated from its start, by -24 %)
        whole = meas.from_record_start()
        noise = None if force_noise is None else np.concatenate([np.zeros(meas.start), np.asarray(force_noise, float)])
        sim = resimulate(whole, model, controller=ctrl_d, substeps=substeps, resolution=res, force_noise=noise,
                         sensor_noise=sensor_noise, seed=seed)
        return sim.tail(meas.start)
    p, cog, bases = model_arrays(model)
    q0 = float(meas.q[0])
    k = min(5, meas.n - 1)
    secant = float((meas.q[k] - meas.q[0]) / (k * dt))
    # the velocity at t = 0 from a cubic through the first six samples, and at rest as well when it
    # is below a tenth of the secant's: a record that starts at rest under a large error
    # accelerates at once, and the secant alone read the mass at rest as moving at 0.2 m/s (a
    # clean record then re-simulated 29 um off, 0.45 um when started at rest)
    v0 = float(np.polyfit(np.arange(k + 1) * dt, meas.q[:k + 1] - meas.q[0], 3)[2]) if k >= 4 else secant
    at_rest = abs(secant) * dt <= max(res, 1e-12) or abs(v0) <= 0.1 * abs(secant)
    inj = np.zeros(meas.n) if meas.u_inj is None else np.ascontiguousarray(meas.u_inj)
    u0 = float(meas.u[0])
    c = ctrl.array(dt)
    I0, sig0 = _controller_start(ctrl, c, meas, inj)
    z0 = 0.0
    if model.law == "lugre":
        # the bristles carry the force that holds the mass at the start (quasi-static)
        pos, neg = model.curve.positive, model.curve.negative
        need = model.cm * u0 + fext[0] - model.offset - float(model.cogging_force(q0))
        z0 = float(np.clip(need, -0.99 * neg.Fs, 0.99 * pos.Fs)) / model.sigma0 if at_rest else 0.0
    elif model.lag > 0:
        # the lagging Stribeck level starts where it settles: Fs at rest, g(|v0|) when moving
        c0 = model.curve.positive if v0 >= 0 else model.curve.negative
        z0 = c0.Fs if at_rest else float(c0.level(np.array([abs(v0)]))[0])
    # a record that starts at rest has rested long before it (the dwell effect fully grown)
    x = np.array([q0, 0.0 if at_rest else v0, z0, 1.0 if (at_rest and model.law != "lugre") else 0.0,
                  I0, 0.0, sig0, q0, q0, 1e9, 0.0, 0.0])
    if x0 is not None:
        x0 = np.asarray(x0, float)
        if x0.shape != (3,) or not np.all(np.isfinite(x0)):
            raise SystemDefinitionError(f"x0 = {x0!r} must be three finite numbers (q, v, z)")
        x[:3] = x0
        x[3] = 1.0 if (x0[1] == 0.0 and model.law != "lugre") else 0.0
    n = meas.n
    qo, uo, vo, so = np.empty(n), np.empty(n), np.empty(n), np.zeros(n, np.bool_)
    delay_sub = int(round(model.delay / (dt / substeps)))
    sn = model.sensor_noise if sensor_noise is None else check_finite_positive("sensor_noise", sensor_noise,
                                                                               allow_zero=True)
    noise = np.random.default_rng(seed).normal(0.0, sn, n) if sn > 0 else np.zeros(n)
    done = _loop(p, cog, bases, c, np.ascontiguousarray(meas.q_ref), np.ascontiguousarray(fext), inj, noise, u0, res, dt,
                 int(substeps), delay_sub, x, qo, uo, vo, so)
    ok = done == n
    msg = "" if ok else (f"the simulated state stopped being finite at t = {meas.t[done]:.6g} s: increase substeps "
                         f"(now {substeps}) or check the model's parameters")
    m = n if ok else done
    return Simulation(meas.t[:m], qo[:m], uo[:m], vo[:m], so[:m], ok, msg)


def _controller_start(ctrl: SampledController, c: np.ndarray, meas: Measurement, inj: np.ndarray) -> tuple:
    """(integral, derivative signal) of the controller state at the first sample, so that its
    first output is the measured u[0] (the integral carries the force the loop needed before the
    record started)."""
    q0, e0 = float(meas.q[0]), float(meas.q[0] - meas.q_ref[0])
    I0 = (-(float(meas.u[0]) - inj[0] + c[1] * e0) / c[3] - c[8] * meas.dt * e0
          if (ctrl.kind == "pid" and c[3] != 0.0) else 0.0)
    return I0, (q0 if ctrl.derivative_on_measurement else e0)


def controller_output(meas: Measurement, controller: dict) -> np.ndarray:
    """The output u (n,) of the ``controller`` (the MODEL.json schema) fed the measured q and
    q_ref of ``meas`` (its injection u_inj added, saturation and DAC step applied), from the state
    whose first output is the measured u[0]: what the model's controller would have sent. A part
    of a record is replayed from the record's first sample."""
    if meas.q_ref is None:
        raise SystemDefinitionError(f"{meas.name}: the controller's output needs the reference column q_ref")
    if meas.source is not None:          # a part: replayed through the record before it (resimulate)
        return controller_output(meas.from_record_start(), controller)[meas.start:]
    ctrl = SampledController.from_schema(controller)
    c = ctrl.array(meas.dt)
    inj = np.zeros(meas.n) if meas.u_inj is None else np.ascontiguousarray(meas.u_inj)
    I0, sig0 = _controller_start(ctrl, c, meas, inj)
    q0 = float(meas.q[0])
    x = np.array([q0, 0.0, 0.0, 0.0, I0, 0.0, sig0, q0, q0, 0.0])
    u = np.empty(meas.n)
    _replay(c, np.ascontiguousarray(meas.q_ref), np.ascontiguousarray(meas.q), inj, x, meas.dt, u)
    return u


def position_rms_error(meas: Measurement, model: NominalModel) -> float:
    """RMS [m] of the re-simulated positions of ``model`` against the measured ones (inf when the
    re-simulation failed): the validation metric of the behaviour-channel causes."""
    sim = resimulate(meas, model)
    return float(np.sqrt(np.mean((sim.q - meas.q[:sim.q.size]) ** 2))) if sim.ok else np.inf


def side_by_side(run, items: list) -> list:
    """[run(item) for item in items], on up to ``THREADS`` threads: for runs that re-simulate (the
    kernel releases the GIL) and are independent, so that the results are those of the runs one
    after the other, in the order of ``items``."""
    items = list(items)
    if len(items) < 2 or THREADS < 2 or getattr(_POOL_THREAD, "busy", False):
        return [run(item) for item in items]   # (inside a pool's thread the machine's cores are taken)

    def in_pool(item):
        _POOL_THREAD.busy = True
        return run(item)
    with ThreadPoolExecutor(max_workers=min(len(items), THREADS)) as pool:
        return list(pool.map(in_pool, items))


def resimulate_many(meas: Measurement, models: list) -> list:
    """:func:`resimulate` of ``meas`` with each of ``models`` (default keywords), side by side
    (:func:`side_by_side`)."""
    return side_by_side(lambda m: resimulate(meas, m), models)


def position_rms_errors(meas: Measurement, models: list) -> list:
    """:func:`position_rms_error` [m] of each of ``models`` on ``meas``, side by side
    (:func:`side_by_side`)."""
    return side_by_side(lambda m: position_rms_error(meas, m), models)

