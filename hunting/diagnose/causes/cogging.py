"""A force periodic in position (cogging of magnets, a screw's lead error): three harmonics of a
spatial period found from the residual's Lomb-Scargle spectrum against position.

When the model has a harmonic cogging of about that pitch (within ``MATCH``), the cause corrects
it rather than adding a second one: its parameters are the merged harmonics (the model's plus the
fitted change, harmonic by harmonic), the component the extended model holds in place of the
model's at the fitted pitch; the model's higher harmonics (beyond ``HARMONICS``) stay at its own
pitch. The fitted coefficients theta are the change of the model's coefficients; the model's
coefficients moved from its pitch to the fitted one are the known, unfitted part of the force
change (``shift``: zero when the pitches agree)."""
import numpy as np

from ...models.plant import COG_HARMONIC, Cogging
from ._words import _q

NAME = "cogging"
DESCRIPTION = "force periodic in position (cogging)"
FAMILY = "position"
HYPERS = 1
HYPER_KEYS = ("pitch",)
UNITS = {"pitch": "m", "amplitude_1": "N", "amplitude_2": "N", "amplitude_3": "N"}
HARMONICS = 3
MATCH = 0.03          # a model cogging within 3 % of the pitch is the one corrected (the pitch grid's half width)
MIN_PERIODS = 1.5     # the longest pitch searched: the fitting stroke over this many periods
SIDEBANDS = 1.1      # two peaks' wavenumbers this close: sidebands, their midpoint a candidate too
GONE = 0.05           # merged amplitude below 5 % of the model's: the model's cogging is not in the data (as offset)
# the validation record's stroke over the fitting record's above which the validation record can
# show pitches the fitting record cannot (:func:`unseen`), as for a resonance above the fitting
# band (flexibility.UNSEEN_FACTOR): at 2, 93 of reporting36's 636 records paid the validation-only
# search for pitches of which the validation record holds 1.5-3 periods; at 3, 37
UNSEEN_FACTOR = 3.0
# the friction curve's possible errors the pitch search fits beside the harmonics (per direction: a
# level, a slope, and Stribeck dips of this many widths spanning the record's sliding speeds): a
# curve error left in the residual is not periodic in position but, over a stroke of a few pitches
# travelled at changing speeds, it leaks into the harmonics and pulls the pitch (reporting66
# d0546: a Stribeck change beside a 5.56 mm cogging moved the best pitch to the search's -1 %
# edge, 11 periods away the validation record's phase was 40 degrees off and the cogging
# predicted it 6 % worse; fitted beside the curve terms, +0.2 % and a valley 100 times deeper)
CURVE_DIPS = 4
SUBPERIOD_SHARE = 0.01  # a variant whose harmonics off a multiple k hold less than this share: period pitch / k
SPECTRUM_WINDOW = 31  # [samples] the pitch search's smoothing window at most (:func:`spectrum_kinematics`)


def matched(model, pitch: float) -> int | None:
    """Index in ``model.cogging`` of the harmonic component whose period is nearest ``pitch`` [m]
    and within MATCH of it (None: the model has no cogging of that pitch)."""
    best = None
    for i, c in enumerate(model.cogging):
        if c.kind != COG_HARMONIC:
            continue
        d = abs(c.period / pitch - 1.0)
        if d <= MATCH and (best is None or d < best[0]):
            best = (d, i)
    return None if best is None else best[1]


def model_coefficients(model, pitch: float) -> np.ndarray:
    """The matched component's first HARMONICS coefficients (cos_1, sin_1, cos_2, ..) [N] (2 HARMONICS,),
    zeros without a match."""
    out = np.zeros(2 * HARMONICS)
    i = matched(model, pitch)
    if i is not None:
        d = np.asarray(model.cogging[i].data, dtype=float)[:2 * HARMONICS]
        out[:d.size] = d
    return out


def hypers(kin, model) -> list:
    """Pitch candidates: the three strongest peaks of the Lomb-Scargle spectrum of the nominal
    force residual less its fit by the friction curve's error terms (:func:`curve_terms`;
    averaged in position bins) against position (wavelengths from 20 samples'
    travel at the slow end of the record's speeds (10th percentile) to the stroke over
    MIN_PERIODS), and the longest of these wavelengths where the spectrum falls from it and the
    harmonics' fit has its minimum inside the +-3 % grid around it; each
    refined on a +-3 % grid of the binned residual, then on the cause's filtered design
    (:func:`_refined`). Where two of the three peaks lie within SIDEBANDS of each other, their
    midpoint too, refined on the filtered design alone: a cogging whose amplitude in the
    residual changes along the stroke shows as two sidebands (reporting22 d0330: 0.746 and
    0.790 mm around a 0.767 mm pitch over 109 periods, each sideband 3 % off, so the phase
    drifted by three periods over the stroke and nothing held out of sample)."""
    from scipy.signal import lombscargle
    from ..kinematics import residual
    moving = kin.moving
    if moving.sum() < 50:
        return []
    C = curve_terms(kin)[moving]          # once: the refinements below fit beside the same terms
    r_all = _without_curve(kin, residual(kin, model), C)
    # the spectrum and its binned refinement read the residual through the short window
    # (:func:`spectrum_kinematics`); the final refinement, the cause's design, the record's own
    short = spectrum_kinematics(kin)
    q = kin.q[moving]
    r = r_all[moving] if short is kin else _without_curve(short, residual(short, model))[moving]
    travel = stroke(kin)
    # short pitches show where the motion is slow (a pitch shorter than 20 samples' travel at the
    # median speed missed a 0.58 mm cogging moved at 13-58 mm/s, tuning d0088); two periods in
    # the stroke suffice to tell a periodic force (a 1.7 mm pitch over 6.5 mm, d0153)
    step = float(np.percentile(np.abs(np.diff(kin.q)[moving[1:]]), 10))
    lo, hi = 5 * step, travel / MIN_PERIODS
    if not (lo > 0 and hi > lo):
        return []
    k = np.geomspace(1 / hi, 1 / lo, 1500)                  # wavenumbers [1/m], 0.2-0.4 % apart
    # the spectrum of the residual averaged in position bins of a tenth of the shortest
    # wavelength: what is periodic in q survives the averaging, the cost falls from the samples
    # (tens of thousands, visited again and again) to the bins
    width = max(lo / 10, travel / 2000)                     # at most ~2000 bins
    idx = np.floor((q - q.min()) / width).astype(np.int64)
    counts = np.bincount(idx)
    full = counts > 0
    qb = (np.bincount(idx, q)[full]) / counts[full]
    rb = (np.bincount(idx, r)[full]) / counts[full]
    power = lombscargle(qb, rb - rb.mean(), 2 * np.pi * k)
    peaks = [i for i in range(1, k.size - 1) if power[i] >= power[i - 1] and power[i] >= power[i + 1]]
    peaks = sorted(peaks, key=lambda i: -power[i])[:3]
    # and the longest wavelength searched where the spectrum falls from it, as a fourth: a pitch
    # of about MIN_PERIODS in the stroke shows no interior peak (reporting10 d0428: 0.70 mm over
    # 1.39 mm; d0512: 4.5 mm over 9.4 mm), and leakage from a slow trend puts power there too,
    # which must not push a true short pitch out of the three
    if power[0] > power[1] and 0 not in peaks:
        peaks.append(0)
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
        j = next(j for j, (s, _) in enumerate(fits) if s <= best * (1 + 1e-3))
        if i == 0 and j in (0, len(fits) - 1):
            # the longest wavelength is a candidate only where the harmonics' fit has a minimum
            # near it: at the grid's short edge the fit improves towards the interior, which the
            # peaks cover; at its long edge it wants fewer than MIN_PERIODS periods, a trend.
            # Either way no period: as a candidate it fitted a slow trend of the fitting record
            # (independent seed 11 d0050: 5.35 mm over 8.4 mm beside a Coulomb level 22 % low
            # one way), mispredicted the validation record, and in the whole library's residual,
            # the out-of-sample tests' noise model, cost the true cause its significance
            continue
        out.append({"pitch": _refined(kin, model, r_all, fits[j][1], C)})
    # two of the strongest peaks close either side of a wavenumber: the sidebands of a cogging
    # whose amplitude in the residual changes along the stroke (the filter passes it where the
    # motion is slow, not where it is fast); the carrier between them, refined on the filtered
    # design only (the binned harmonics' grid falls back onto a sideband)
    top = sorted(i for i in peaks if i != 0)
    for a, b in zip(top, top[1:]):
        if k[b] / k[a] <= SIDEBANDS:
            out.append({"pitch": _refined(kin, model, r_all, float(2.0 / (k[a] + k[b])), C)})
    return sorted(out, key=lambda h: h["pitch"])


def spectrum_kinematics(kin):
    """The record's Kinematics with the smoothing window shortened to SPECTRUM_WINDOW samples
    where it is longer (the same samples, ``moving`` unchanged), for the pitch search's spectrum.

    The diagnosis smooths over half a period of the loop's bandwidth where that is longer than 31
    samples, and that window passes a cogging force only where the motion is slow: on reporting70
    d0512 (a 0.94 mm pitch over 44 periods, an 82 ms window) the long window's spectrum put the
    candidates 2.3 % and 2.6 % either side of the pitch, the phase drifted by a period over the
    stroke and the validation gain fell to -18 %, where the 31-sample window's spectrum has the
    pitch within 0.01 %; d0442 (0.72 mm, 77 ms): -1.8 % against -0.3 %."""
    w = SPECTRUM_WINDOW
    if int(round(kin.window / kin.dt)) <= w:
        return kin
    from dataclasses import replace
    return replace(kin, window=w * kin.dt)


def curve_terms(kin) -> np.ndarray:
    """Regressors of the friction curve's possible errors [-, m/s] (n, 2 (2 + CURVE_DIPS)) as the
    force channel sees them (:meth:`Kinematics.sliding`): per direction of the filtered velocity
    its indicator, the velocity itself and exp(-(v / vs)^2) for CURVE_DIPS widths vs geometric
    between the 10th and 90th percentiles of the sliding speeds."""
    v = kin.vf
    speed = np.abs(v[kin.slide & (v != 0)])
    if speed.size < 10:
        return np.zeros((v.size, 0))
    widths = np.geomspace(*np.percentile(speed, [10, 90]), CURVE_DIPS)
    cols = []
    for side in (v > 0, v < 0):
        cols += [side * 1.0, side * v] + [side * np.exp(-(v / w) ** 2) for w in widths]
    return kin.sliding(np.column_stack(cols))


def _without_curve(kin, r: np.ndarray, C: np.ndarray | None = None) -> np.ndarray:
    """The residual r (n,) [N] less its least-squares fit by :func:`curve_terms` on the moving
    samples (elsewhere unchanged): what the friction curve's errors leave of it. ``C``: those
    terms on the moving samples, where already formed."""
    m = kin.moving
    C = curve_terms(kin)[m] if C is None else C
    if not C.shape[1]:
        return r
    th, *_ = np.linalg.lstsq(C, r[m], rcond=None)
    out = r.copy()
    out[m] = r[m] - C @ th
    return out


def _refined(kin, model, r, pitch: float, C: np.ndarray) -> float:
    """The pitch [m] within +-1 % of ``pitch`` whose filtered harmonics (the cause's design),
    beside the friction curve's error terms (:func:`curve_terms`), fit the residual r (n,) [N]
    best on the moving samples (``C``: those terms there): a 0.2 % grid, then the vertex of the
    parabola through the best point and its neighbours (the valley is quadratic over a few tenths
    of a percent; each point costs a filtered design, 0.45 s of a 7.7 s diagnosis at 0.05 %).

    The binned spectrum holds all of the residual, not only what is periodic, and its least
    squares is flat near the pitch: its best grid point was 0.5 % short on reporting9 d0344
    (62 periods in the stroke, so the phase drifted by a third of a period and the validation
    gain fell from 7 % to 5 %), where the filtered design's minimum is sharp at the truth."""
    m = kin.moving
    y = r[m]
    grid = pitch * np.linspace(0.99, 1.01, 11)
    rss = []
    for p in grid:
        X = np.column_stack([design(kin, model, {"pitch": float(p)})[m], C])
        th, *_ = np.linalg.lstsq(X, y, rcond=None)
        rss.append(float(np.sum((y - X @ th) ** 2)))
    i = int(np.argmin(rss))
    if 0 < i < grid.size - 1:
        a, b, c = rss[i - 1], rss[i], rss[i + 1]
        den = a - 2 * b + c
        if den > 0:
            return float(grid[i] + 0.5 * (a - c) / den * (grid[1] - grid[0]))
    return float(grid[i])


def _harmonics(q, pitch):
    cols = []
    for k in range(1, HARMONICS + 1):
        w = 2 * np.pi * k / pitch
        cols += [np.cos(w * q), np.sin(w * q)]
    return np.column_stack(cols)


def unphysical(theta, hyper, model) -> str | None:
    """Why a fitted variant is not a cogging of its pitch (None when it is): its merged harmonics
    (:func:`merged`) repeat every pitch / k (k = 2 or 3; the harmonics that are no multiple of k
    hold less than SUBPERIOD_SHARE of their square sum), so the force's period is that, a
    candidate of its own; read at k times it, the fundamental and its first harmonics are
    missing. reporting70 d0545 (a 2.778 mm cogging beside a delay): the candidate at three times
    the pitch, 8.311 mm, fitted the cogging as its third harmonic (0.01 % of the square sum in the
    other two) and was chosen over the 2.766 mm candidate."""
    c = merged(theta, hyper, model)
    power = c[0::2] ** 2 + c[1::2] ** 2              # per harmonic 1..HARMONICS
    total = float(power.sum())
    if not total > 0:
        return None
    for k in (2, 3):
        other = float(sum(power[i] for i in range(HARMONICS) if (i + 1) % k))
        if other < SUBPERIOD_SHARE * total:
            return (f"its harmonics repeat every pitch / {k} ({_q(hyper['pitch'] / k, None, 'm')}; "
                    f"{other / total:.2%} of their power at the others): the ripple's period is that")
    return None


def unidentified(p, sig, model=None, theta=None) -> str | None:
    """Why a selected cogging is no cause (None when it is): a new ripple (the model has none of
    about its pitch) whose RMS over a period, sqrt(sum of the fitted coefficients squared / 2), is
    below the friction force's relevance floor (:data:`~hunting.diagnose.force.RELEVANCE` of the
    mean Coulomb level). Friction is neither known nor steady along a stroke to better than that,
    and the force channel sizes the friction force's own changes against the same floor; a
    position ripple is measured in the same newtons. On reporting70 d0214 (clean, a 4.1 mm pitch
    from the spectrum read through 31 samples) a ripple of 0.13 % of Fc passed its test at
    p = 3e-4 with a validation gain of 8 %; the smallest true cogging named on that set was 0.8 %
    (d0533), the generator's smallest amplitude 1 %."""
    if model is None or theta is None or matched(model, p["pitch"]) is not None:
        return None
    from ..force import RELEVANCE, relevance_level
    ripple = float(np.sqrt(np.sum(np.asarray(theta, float) ** 2) / 2.0))
    floor = relevance_level(model)
    if ripple >= floor:
        return None
    return (f"its ripple, {_q(ripple, None, 'N')} RMS, is below {RELEVANCE:.1%} of the mean Coulomb level "
            f"({_q(floor / RELEVANCE, None, 'N')}): friction is neither known nor steady along the stroke to better "
            "than that")


def untestable(kin, model) -> str | None:
    if kin.moving.sum() < 50:
        return "fewer than 50 sliding samples"
    return None


def stroke(kin) -> float:
    """The travel of the record's moving samples [m] (0 with fewer than 50: :func:`untestable`):
    the pitches :func:`hypers` searches end at it over MIN_PERIODS."""
    moving = kin.moving
    return float(np.ptp(kin.q[moving])) if moving.sum() >= 50 else 0.0


def unseen(kf, kv, model) -> str | None:
    """Why the fitting record (``kf``) cannot show a pitch the validation record (``kv``) can: its
    stroke holds fewer than MIN_PERIODS periods of it, and the validation record's stroke is more
    than UNSEEN_FACTOR times as long (reporting36 d0588: an offset beside a 1.97 mm cogging, the
    fitting record moving 0.40 mm, the validation record 17 mm; the offset alone was named)."""
    sf, sv = stroke(kf), stroke(kv)
    if sv <= UNSEEN_FACTOR * sf:
        return None
    return (f"a pitch longer than {_q(sf / MIN_PERIODS, None, 'm')} (the fitting record moves {_q(sf, None, 'm')}, "
            f"fewer than {MIN_PERIODS:g} periods of it; the validation record {_q(sv, None, 'm')})")


def seen(hyper, kf, model, parameters=None) -> str | None:
    """Why a pitch found on the validation record alone (:func:`unseen`) is one the fitting record
    could show, where it showed none: at most its stroke over MIN_PERIODS."""
    longest = stroke(kf) / MIN_PERIODS
    if hyper["pitch"] > longest:
        return None
    return (f"its pitch ({_q(hyper['pitch'], None, 'm')}) is one the fitting record's stroke shows (up to "
            f"{_q(longest, None, 'm')}), where that record shows none")


def design(kin, model, hyper):
    return kin.sliding(_harmonics(kin.q, hyper["pitch"]))


def shift(kin, model, hyper) -> np.ndarray:
    """The model's matched harmonics moved from its pitch to the fitted one [N] (n,): zero
    without a match or at the model's own pitch."""
    i = matched(model, hyper["pitch"])
    if i is None:
        return np.zeros(kin.t.size)
    c0 = model_coefficients(model, hyper["pitch"])
    moved = _harmonics(kin.q, hyper["pitch"]) @ c0 - _harmonics(kin.q, model.cogging[i].period) @ c0
    return kin.sliding(moved)


def merged(theta, hyper, model) -> np.ndarray:
    """The final coefficients (cos_1, sin_1, ..) [N] (2 HARMONICS,) at the fitted pitch: the
    model's matched ones plus the fitted change."""
    return model_coefficients(model, hyper["pitch"]) + np.asarray(theta, dtype=float)


def parameters(theta, hyper, model) -> dict:
    c = merged(theta, hyper, model)
    out = {"pitch": hyper["pitch"]}
    out.update({f"amplitude_{k + 1}": float(np.hypot(c[2 * k], c[2 * k + 1])) for k in range(HARMONICS)})
    return out


def extend(model, theta, hyper):
    c = merged(theta, hyper, model)
    comp = Cogging.harmonic(hyper["pitch"], cos=list(c[0::2]), sin=list(c[1::2]))
    i = matched(model, hyper["pitch"])
    if i is None:
        return model.replace(cogging=model.cogging + (comp,))
    old = model.cogging[i]
    rest = list(model.cogging[:i]) + [comp] + list(model.cogging[i + 1:])
    if old.n > HARMONICS:        # the model's higher harmonics stay at its pitch
        d = [0.0] * (2 * HARMONICS) + list(old.data[2 * HARMONICS:])
        rest.append(Cogging.harmonic(old.period, cos=d[0::2], sin=d[1::2]))
    return model.replace(cogging=tuple(rest))


def _size(a) -> float:
    return float(np.sqrt(np.sum(np.square(a))))


def sentence(p, inc, model) -> str:
    pitch, amp = p["pitch"], [p[f"amplitude_{k + 1}"] for k in range(HARMONICS)]
    i = matched(model, pitch)
    if i is None:
        return (f"a force periodic in position that the model lacks: pitch {_q(pitch, None, 'm')}, "
                f"first harmonic {_q(amp[0], None, 'N')}")
    c0 = model_coefficients(model, pitch)
    amp0 = np.hypot(c0[0::2], c0[1::2])
    if _size(amp) < GONE * _size(amp0):
        # the finding is that the model's cogging is not there, not the component cancelling it
        return (f"the model's force periodic in position (pitch {_q(model.cogging[i].period, None, 'm')}, first "
                f"harmonic {_q(amp0[0], None, 'N')}) is not in the data (what remains of it is "
                f"{_q(_size(amp), None, 'N')} over its harmonics, less than {100 * GONE:.0f} % of it)")
    return (f"the force periodic in position differs from the model's: pitch {_q(pitch, None, 'm')} (the model's "
            f"{_q(model.cogging[i].period, None, 'm')}), first harmonic {_q(amp[0], None, 'N')} (the model's "
            f"{_q(amp0[0], None, 'N')})")
