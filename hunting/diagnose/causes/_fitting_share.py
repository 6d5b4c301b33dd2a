"""Whether a force found on the validation record alone would show on the fitting record: the
shared test of the ``seen`` hooks whose force is a change times a rate of the record (delay:
the drive force's rate; mass: the acceleration)."""
import numpy as np

from ._words import _q

# the share of the fitting record's residual RMS a change's force there must reach for that record
# to show it: a record whose residual holds a force of RMS f has a residual of RMS at least f
# wherever the rest is uncorrelated with it, so a change whose force exceeds the whole residual is
# not in that record. At the rule's min_gain share (0.33: explained, it removes 5 % of the
# residual's RMS) a delay beside a cause of its signature's family was lost (reporting62 d0569:
# 0.24 ms beside a Stribeck change, its force on the fitting record 0.64 times that record's
# residual, read there as a viscous change)
SEEN_SHARE = 1.0


def shown_on_fitting_record(kf, model, force: float, what: str) -> str | None:
    """Why a change found on the validation record alone is one the fitting record (``kf``, its
    used samples marked) would show, where it showed none: its force there (``force``, N RMS,
    ``what`` says how it was formed) reaches SEEN_SHARE of that record's force residual against
    ``model`` (RMS on its used samples); None where it does not."""
    from ..kinematics import residual
    r = residual(kf, model)[kf.moving]
    r = r[np.isfinite(r)]
    if r.size == 0:
        return None
    rms = float(np.sqrt(np.mean(r ** 2)))
    if not (rms > 0 and force >= SEEN_SHARE * rms):
        return None
    return (f"its force on the fitting record ({_q(force, None, 'N')} RMS, {what}) is {force / rms:.2g} times that "
            f"record's residual ({_q(rms, None, 'N')} RMS): that record would show it, and showed none")
