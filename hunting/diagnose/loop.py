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
    items = tuple(sorted(c.items()))
    try:
        hash(items)
    except TypeError:                      # a controller value that is not hashable: not cached
        return _delay_margin.__wrapped__(model.mass, model.cm, b, items)
    # the force channel's search asks once per fitted delay (289 times on one record, 8 % of it)
    return _delay_margin(model.mass, model.cm, b, items)


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
