"""The helper process of :mod:`hunting.integrate.ahead`: ``python -m
hunting.integrate.compile_kernels KIND ...`` compiles each integration kernel named (one of
:data:`hunting.integrate._kernel.KINDS`), in order, into numba's disk cache, as a command
would (:func:`hunting.integrate._kernel.compiled`)."""
from __future__ import annotations

import sys


def main(argv: list[str]) -> int:
    """Compile the kernels ``argv`` names; 2 for a name that is not a kind."""
    from . import _kernel as K
    bad = [k for k in argv if k not in K.KINDS]
    if bad:
        print(f"kernel kinds {bad} are not allowed: use {tuple(K.KINDS)}", file=sys.stderr)
        return 2
    for kind in argv:
        K.compiled(kind)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
