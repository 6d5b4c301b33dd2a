"""A force periodic in position (cogging of magnets, a screw's lead error): three harmonics of a
spatial period found from the residual's Lomb-Scargle spectrum against position."""
import numpy as np

from ...models.plant import Cogging
from ._words import _q

NAME = "cogging"
DESCRIPTION = "force periodic in position (cogging)"
FAMILY = "position"
HYPERS = 1
HYPER_KEYS = ("pitch",)
UNITS = {"pitch": "m", "amplitude_1": "N", "amplitude_2": "N", "amplitude_3": "N"}
HARMONICS = 3


def hypers(kin, model) -> list:
    """Pitch candidates: the three strongest peaks of the Lomb-Scargle spectrum of the nominal
    force residual (averaged in position bins) against position (wavelengths from 20 samples'
    travel at the slow end of the record's speeds (10th percentile) to half the stroke: two
    periods), each refined on a +-3 % grid."""
    from scipy.signal import lombscargle
    from ..kinematics import residual
    moving = kin.moving
    if moving.sum() < 50:
        return []
    q, r = kin.q[moving], residual(kin, model)[moving]
    stroke = float(np.ptp(q))
    # short pitches show where the motion is slow (a pitch shorter than 20 samples' travel at the
    # median speed missed a 0.58 mm cogging moved at 13-58 mm/s, tuning d0088); two periods in
    # the stroke suffice to tell a periodic force (a 1.7 mm pitch over 6.5 mm, d0153)
    step = float(np.percentile(np.abs(np.diff(kin.q)[moving[1:]]), 10))
    lo, hi = 5 * step, stroke / 2
    if not (lo > 0 and hi > lo):
        return []
    k = np.geomspace(1 / hi, 1 / lo, 1500)                  # wavenumbers [1/m], 0.2-0.4 % apart
    # the spectrum of the residual averaged in position bins of a tenth of the shortest
    # wavelength: what is periodic in q survives the averaging, the cost falls from the samples
    # (tens of thousands, visited again and again) to the bins
    width = max(lo / 10, stroke / 2000)                     # at most ~2000 bins
    idx = np.floor((q - q.min()) / width).astype(np.int64)
    counts = np.bincount(idx)
    full = counts > 0
    qb = (np.bincount(idx, q)[full]) / counts[full]
    rb = (np.bincount(idx, r)[full]) / counts[full]
    power = lombscargle(qb, rb - rb.mean(), 2 * np.pi * k)
    peaks = [i for i in range(1, k.size - 1) if power[i] >= power[i - 1] and power[i] >= power[i + 1]]
    peaks = sorted(peaks, key=lambda i: -power[i])[:3]
    # each peak refined on a +-3 % grid of 0.2 % steps by least squares of the harmonics on the
    # binned residual (the simplest variant, first in the grid, among those within 0.1 % of the
    # best: e.g. not a multiple of the pitch)
    out = []
    for i in peaks:
        fits = []
        for f in np.linspace(0.97, 1.03, 31):
            pitch = float(f / k[i])
            A = _harmonics(qb, pitch)
            th, *_ = np.linalg.lstsq(A, rb - rb.mean(), rcond=None)
            fits.append((float(np.sum((rb - rb.mean() - A @ th) ** 2)), pitch))
        best = min(s for s, _ in fits)
        out.append({"pitch": next(p for s, p in fits if s <= best * (1 + 1e-3))})
    return sorted(out, key=lambda h: h["pitch"])


def _harmonics(q, pitch):
    cols = []
    for k in range(1, HARMONICS + 1):
        w = 2 * np.pi * k / pitch
        cols += [np.cos(w * q), np.sin(w * q)]
    return np.column_stack(cols)


def untestable(kin, model) -> str | None:
    if kin.moving.sum() < 50:
        return "fewer than 50 sliding samples"
    return None


def design(kin, model, hyper):
    return kin.sliding(_harmonics(kin.q, hyper["pitch"]))


def parameters(theta, hyper, model) -> dict:
    amp = [float(np.hypot(theta[2 * k], theta[2 * k + 1])) for k in range(HARMONICS)]
    out = {"pitch": hyper["pitch"]}
    out.update({f"amplitude_{k + 1}": a for k, a in enumerate(amp)})
    return out


def extend(model, theta, hyper):
    comp = Cogging.harmonic(hyper["pitch"], cos=list(theta[0::2]), sin=list(theta[1::2]))
    return model.replace(cogging=model.cogging + (comp,))


def sentence(p, inc, model) -> str:
    return (f"a force periodic in position that the model lacks: pitch {_q(p['pitch'], None, 'm')}, "
            f"first harmonic {_q(p['amplitude_1'], None, 'N')}")
