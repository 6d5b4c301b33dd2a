"""A force periodic in position (cogging of magnets, a screw's lead error): three harmonics of a
spatial period found from the residual's Lomb-Scargle spectrum against position."""
import numpy as np

from ...models.plant import Cogging

NAME = "cogging"
DESCRIPTION = "force periodic in position (cogging)"
HARMONICS = 3


def hypers(kin, model) -> list:
    """Pitch candidates: the three strongest peaks of the Lomb-Scargle spectrum of the nominal
    force residual (averaged in position bins) against position (wavelengths from 20 samples' travel at the typical speed to
    a quarter of the stroke), each refined on a +-3 % grid of 0.2 % steps."""
    from scipy.signal import lombscargle
    from ..kinematics import residual
    moving = kin.moving
    if moving.sum() < 50:
        return []
    q, r = kin.q[moving], residual(kin, model)[moving]
    stroke = float(np.ptp(q))
    step = float(np.median(np.abs(np.diff(kin.q)[moving[1:]])))
    lo, hi = 20 * step, stroke / 4
    if not (lo > 0 and hi > lo):
        return []
    k = np.geomspace(1 / hi, 1 / lo, 1500)                  # wavenumbers [1/m], 0.2-0.4 % apart
    # the spectrum of the residual averaged in position bins of a tenth of the shortest
    # wavelength: what is periodic in q survives the averaging, the cost falls from the samples
    # (tens of thousands, visited again and again) to the bins
    width = lo / 10
    idx = np.floor((q - q.min()) / width).astype(np.int64)
    counts = np.bincount(idx)
    full = counts > 0
    qb = (np.bincount(idx, q)[full]) / counts[full]
    rb = (np.bincount(idx, r)[full]) / counts[full]
    power = lombscargle(qb, rb - rb.mean(), 2 * np.pi * k)
    peaks = [i for i in range(1, k.size - 1) if power[i] >= power[i - 1] and power[i] >= power[i + 1]]
    peaks = sorted(peaks, key=lambda i: -power[i])[:3]
    out = []
    for i in peaks:
        out += [{"pitch": float(f / k[i])} for f in np.linspace(0.97, 1.03, 31)]
    return out


def design(kin, model, hyper):
    cols = []
    for k in range(1, HARMONICS + 1):
        w = 2 * np.pi * k / hyper["pitch"]
        cols += [np.cos(w * kin.q), np.sin(w * kin.q)]
    return kin.filtered(np.column_stack(cols))


def parameters(theta, hyper, model) -> dict:
    amp = [float(np.hypot(theta[2 * k], theta[2 * k + 1])) for k in range(HARMONICS)]
    out = {"pitch": hyper["pitch"]}
    out.update({f"amplitude_{k + 1}": a for k, a in enumerate(amp)})
    return out


def extend(model, theta, hyper):
    comp = Cogging.harmonic(hyper["pitch"], cos=list(theta[0::2]), sin=list(theta[1::2]))
    return model.replace(cogging=model.cogging + (comp,))
