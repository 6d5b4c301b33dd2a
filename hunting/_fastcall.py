"""Memoize numba's lookup of first-class function addresses.

When a compiled kernel receives a numba function as an argument typed ``FunctionType``, numba
calls back into Python on *every* call to look up the function's two entry addresses
(``_get_wrapper_address`` and ``_get_jit_address`` in ``numba.experimental.function_type``),
each through ``Dispatcher.get_compile_result``: about 20 us per function argument, 100 us per
kernel call with the five functions of a system. The addresses of a compiled overload never
change, so they are memoized here per (dispatcher, signature). Installed once at import; the
originals are kept and used for anything that is not a plain dispatcher.
"""
from __future__ import annotations

from numba.core.dispatcher import Dispatcher
from numba.experimental import function_type as _ft

_orig_wrapper = _ft._get_wrapper_address
_orig_jit = _ft._get_jit_address
_cache_wrapper: dict = {}
_cache_jit: dict = {}


def _memo(cache, orig):
    def lookup(func, sig):
        if not isinstance(func, Dispatcher):
            return orig(func, sig)
        # the protocol's functions have exactly one overload: key on the dispatcher alone
        # (hashing numba signatures costs more than the lookup it saves)
        single = len(func.overloads) == 1
        key = id(func) if single else (id(func), sig)
        hit = cache.get(key)
        if hit is not None and hit[0] is func and hit[2] == len(func.overloads):
            return hit[1]
        addr = orig(func, sig)
        if addr > 0:
            cache[key] = (func, addr, len(func.overloads))
        return addr
    lookup.__wrapped__ = orig
    return lookup


def install() -> None:
    """Install the memoized lookups (idempotent) and silence numba's notice that first-class
    function types are experimental (the kernels are built on them on purpose)."""
    import warnings

    from numba.core.errors import NumbaExperimentalFeatureWarning
    warnings.filterwarnings("ignore", category=NumbaExperimentalFeatureWarning)
    if getattr(_ft._get_wrapper_address, "__wrapped__", None) is None:
        _ft._get_wrapper_address = _memo(_cache_wrapper, _orig_wrapper)
        _ft._get_jit_address = _memo(_cache_jit, _orig_jit)
