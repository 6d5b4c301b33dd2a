"""The nominal loop's linear properties: its bandwidth and its delay margin, from the model's
controller and plant (Coulomb friction has no linear part)."""
import functools
import math

import numpy as np

from .model import NominalModel


def loop_bandwidth(model: NominalModel) -> float | None:
    """The closed loop's bandwidth [Hz] from the controller's gains and the mass (None without a
    controller): the larger of the stiffness frequency sqrt(kp cm / m) and the damping rate
    kd cm / m of a PID (2 pi rad/s per Hz), or of kv cm / m and kp for the PD + velocity loop."""
    c = model.controller
    if not c:
        return None
    from .resimulate import SampledController
    ctrl = SampledController.from_schema(c)
    m, cm = model.mass, model.cm
    if ctrl.kind == "pd-velocity-loop":
        w = max(abs(ctrl.kv) * cm / m, abs(ctrl.kp))
    else:
        w = max(math.sqrt(abs(ctrl.kp) * cm / m), abs(ctrl.kd) * cm / m)
    return w / (2 * math.pi) if w > 0 else None


def delay_margin(model: NominalModel) -> float | None:
    """The delay [s] that would take the nominal loop to the edge of stability: its phase margin
    over the crossover frequency, the smallest over the crossovers, for the linear loop of the
    model's controller (a PID with its derivative filter, or the PD + velocity loop, taken
    continuous) and the plant cm / (m s^2 + b s) (b the mean viscous coefficient; Coulomb friction
    has no linear part). None without a controller, without a crossover in 1e-3..1e6 rad/s, or
    when the loop has no positive margin already (its linear part says nothing then)."""
    c = model.controller
    if not c:
        return None
    b = max(0.5 * (model.curve.positive.b + model.curve.negative.b), 0.0)
    # the force channel's search asks once per fitted delay (289 times on one record, 8 % of it)
    return _cached(_delay_margin, model.mass, model.cm, b, tuple(sorted(c.items())))


def _cached(fn, *args):
    """fn(*args) through its lru_cache, or past it where an argument (a controller value) is not
    hashable."""
    try:
        hash(args)
    except TypeError:
        return fn.__wrapped__(*args)
    return fn(*args)


@functools.lru_cache(maxsize=64)
def _delay_margin(mass: float, cm: float, b: float, controller: tuple) -> float | None:
    """:func:`delay_margin` of the loop with that plant and controller (its schema's items)."""
    from scipy.signal import freqs
    from .resimulate import SampledController
    ctrl = SampledController.from_schema(dict(controller))
    plant_num, plant_den = [cm], [mass, b, 0.0]
    # polynomials as coefficient arrays, highest power first (np.convolve multiplies them; a
    # leading zero, tf = 0, changes no value freqs computes, and np.polymul took half the time)
    if ctrl.kind == "pd-velocity-loop":
        c_num, c_den = [ctrl.kv, ctrl.kv * ctrl.kp], [1.0]
    else:
        tf = max(ctrl.tau_f, 0.0)
        # kp + ki / s + kd s / (tf s + 1) over the common denominator s (tf s + 1)
        c_num = np.array([ctrl.kp * tf + ctrl.kd, ctrl.kp + ctrl.ki * tf, ctrl.ki])
        c_den = np.array([tf, 1.0, 0.0])
    w = np.geomspace(1e-3, 1e6, 2000)
    _, L = freqs(np.convolve(c_num, plant_num), np.convolve(c_den, plant_den), worN=w)
    mag = np.abs(L)
    cross = np.flatnonzero((mag[:-1] - 1.0) * (mag[1:] - 1.0) < 0)
    if cross.size == 0:
        return None
    margins = []
    for k in cross:
        f = np.log(mag[k]) / (np.log(mag[k]) - np.log(mag[k + 1]))         # log-linear between grid points
        wc = float(np.exp(np.log(w[k]) + f * (np.log(w[k + 1]) - np.log(w[k]))))
        phase = float(np.angle(L[k] + f * (L[k + 1] - L[k])))
        pm = math.remainder(math.pi + phase, 2 * math.pi)                     # in (-pi, pi]
        if pm <= 0:
            return None
        margins.append(pm / wc)
    return float(min(margins))


# a slide counts as steady on a falling branch down to this share of the slope the linear loop
# tolerates: near that edge the loop rings for long after every disturbance, and the drive's
# noise and the sensor's count, which the linear loop leaves out, can make a stick of it
STEADY_SHARE = 0.5


def steady_slope(model: NominalModel, dt: float) -> float:
    """The most negative slope c [N s/m] of the friction curve (d F / d|v|: the Stribeck level's
    slope plus the viscous coefficient) on which a steady slide of the model's closed loop is
    stable, times STEADY_SHARE; 0 without a controller (the free mass needs c >= 0).

    Sliding at a constant speed on a branch of slope c, the loop's small motions are those of the
    linear plant m q'' + c q' = cm u under the model's sampled controller (``dt`` [s] the data's
    sample interval, the controller's own sample time where it has one; zero-order hold; the
    plant's delay is left out). A stiff loop holds a slide on a falling Stribeck branch that the
    free mass would leave in stick-slip (the thesis's ch. 9: the PID's damping against the
    curve's negative slope); the stability edge is where the spectral radius of the loop's
    transition matrix reaches 1 (bracketed by doubling the slope, then scipy's brentq)."""
    c = model.controller
    if not c:
        return 0.0
    return _cached(_steady_slope, model.mass, model.cm, tuple(sorted(c.items())), float(dt))


@functools.lru_cache(maxsize=64)
def _steady_slope(mass: float, cm: float, controller: tuple, dt: float) -> float:
    from .resimulate import SampledController
    ctrl = SampledController.from_schema(dict(controller))
    T = dt if ctrl.sample_time is None else ctrl.sample_time

    def excess(slope: float) -> float:
        """The loop's spectral radius less 1 (negative: stable)."""
        return float(np.max(np.abs(np.linalg.eigvals(_sampled_loop(mass, cm, ctrl, slope, T))))) - 1.0

    if excess(0.0) >= 0:
        return 0.0
    # the first slope of a doubling series at which the loop is unstable brackets the edge
    steep = next((c for c in -np.geomspace(1.0, 2.0 ** 80, 81) if excess(c) > 0), None)
    if steep is None:
        return 0.0
    from scipy.optimize import brentq
    return STEADY_SHARE * brentq(excess, steep, 0.0, rtol=1e-8)


def steady_slide(model: NominalModel, dt: float):
    """The callable v (n,) [m/s] -> bool (n,) that tells where a slow slide of the model's loop,
    sampled every ``dt`` [s], is steady (:meth:`NominalModel.steady_slide` down to
    :func:`steady_slope`): what the kinematics' ``steady`` takes."""
    least = steady_slope(model, dt)
    return lambda v: model.steady_slide(v, least)


def _sampled_loop(mass: float, cm: float, ctrl, slope: float, T: float) -> np.ndarray:
    """The transition matrix over one controller period T [s] of the loop's small motions about
    a steady slide: plant m q'' + slope q' = cm u held over the period (exact zero-order hold),
    and the controller's update as :func:`~hunting.diagnose.resimulate._control` makes it; the
    state is the plant's q, v and the controller's (I, D and the last signal for a PID; the last
    position and its filtered value for the PD + velocity loop), z_k+1 = step z_k."""
    from scipy.linalg import expm
    M = np.zeros((3, 3))
    M[0, 1] = 1.0
    M[1, 1] = -slope / mass
    M[1, 2] = cm / mass
    E = expm(M * T)
    Ad, Bd = E[:2, :2], E[:2, 2]
    if ctrl.kind == "pid":
        # e_k = q_k (the reference's ramp is the slide); I_k = I_k-1 + T q_k; D_k = (tf D_k-1 +
        # s_k - s_k-1) / (tf + T), s the error or the measurement (the same for small motions);
        # u_k = -(kp q_k + kd D_k + ki I_k). z = [q, v, I, D, s]: the controller's states are
        # updated from q_k first, then u_k acts over the period
        g = 1.0 / (ctrl.tau_f + T)
        update = np.array([[1, 0, 0, 0, 0], [0, 1, 0, 0, 0], [T, 0, 1, 0, 0], [g, 0, 0, ctrl.tau_f * g, -g],
                           [1, 0, 0, 0, 0]], float)
        u = -np.array([ctrl.kp, 0.0, ctrl.ki, ctrl.kd, 0.0]) @ update
    else:
        # qf_k = (q_k + y_k-1) / 2; u_k = kv (-kp q_k - (qf_k - qf_k-1) / T); z = [q, v, y, qf]
        # (the last measurement and its filtered value)
        update = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [1, 0, 0, 0], [0.5, 0, 0.5, 0]], float)
        u = ctrl.kv * np.array([-ctrl.kp - 0.5 / T, 0.0, -0.5 / T, 1.0 / T])
    step = update.copy()
    step[:2, :2] = Ad
    step[:2, :] += np.outer(Bd, u)
    return step
