"""Numbers in engineering form for the reports: rounded values with SI prefixes and units, a
value with its standard uncertainty rounded to the uncertainty's second digit, and how an
extension moved an error measure."""
import math

import numpy as np

from ..stats import relative_fall

_PREFIXES = ((1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n"))
_PREFIXED = {"m", "s", "N", "Hz", "V", "m/s", "N/m"}


def _scale(value: float, unit: str) -> tuple[float, str]:
    """(factor, prefixed unit) so that value / factor lies in [1, 1000) for units that take a
    prefix (m, s, N, Hz, V, m/s, N/m); (1, unit) otherwise."""
    if unit not in _PREFIXED or value == 0 or not math.isfinite(value):
        return 1.0, unit
    a = abs(value)
    for f, p in _PREFIXES:
        if a >= f * 0.9995:
            break
    if unit == "N" and f < 1e-3:          # uN and nN read oddly for forces on a machine: mN at most
        f, p = 1e-3, "m"
    return f, p + unit


def _q(value, sigma, unit: str, digits: int = 3) -> str:
    """'1.23 mm', '-0.1265 +- 0.0004 N' (sigma: standard uncertainty or None)."""
    if value is None or not math.isfinite(float(value)):
        return f"{value} {unit}".strip()
    value = float(value)
    ref = abs(value) if value else (abs(sigma) if sigma else 0.0)
    f, u = _scale(ref, unit)
    v = value / f
    if sigma is not None and math.isfinite(sigma) and sigma > 0:
        s = sigma / f
        dec = max(0, 1 - int(math.floor(math.log10(s))))
        return f"{v:.{dec}f} ± {s:.{dec}f} {u}".strip()
    return f"{v:.{digits}g} {u}".strip()


def _pct(x: float) -> str:
    """A share as a percentage with two significant digits ('48 %', '3.1 %')."""
    p = 100 * x
    return f"{p:.2g} %" if p < 10 else f"{p:.0f} %"


def _count(n: int, noun: str, plural: str | None = None) -> str:
    """'1 sample', '0 samples', '3 rests': a count with its noun in the right number."""
    return f"{n} {noun if n == 1 else (plural or noun + 's')}"


def cut_words(before: float, after: float, what: str, plural: bool = False) -> str:
    """How an extension moved ``what`` (a re-simulated position RMS error) from ``before`` to
    ``after`` [m], in words: the relative cut where it means something; both errors where the
    nominal model's is 0 (a noise-free record of the nominal model itself) or the extension makes
    it more than tenfold worse; the failure where a loop does not re-simulate. The verb agrees with
    a ``plural`` subject (e.g. "LuGre bristles cut")."""
    if not np.isfinite(before) or not np.isfinite(after):
        return f"cannot be judged by {what}: the {'nominal ' if not np.isfinite(before) else ''}loop does not re-simulate"
    gain = relative_fall(before, after)
    if before <= 0 or gain < -9.0:
        return (f"{'make' if plural else 'makes'} {what} {_q(after, None, 'm')} against {_q(before, None, 'm')} "
                f"without {'them' if plural else 'it'}")
    return f"{'cut' if plural else 'cuts'} {what} by {gain:.1%}"


def pct_against(x: float, bar: float) -> str:
    """``x`` as a percentage with one decimal, or as many more (up to six) as it takes not to
    read as ``bar`` itself: a share of 0.04996 against a bar of 5 % is '4.996%', not '5.0%'
    beside '5% needed'."""
    for digits in range(1, 7):
        text = f"{x:.{digits}%}"
        if x == bar or float(text[:-1]) / 100 != round(bar, digits + 2):
            return text
    return f"{x:.6%}"
