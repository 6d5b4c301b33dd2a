"""hunting: what friction does to controlled machines.

Equilibrium sets, hunting limit cycles and their bifurcations for PID-controlled mechanical
systems with friction, after R. Hensen, "Controlled Mechanical Systems with Friction" (2002).

The public names below are imported on first use (PEP 562): ``import hunting`` (and the command
line's argument checking) does not load the numba kernels until something needs them.
"""
import importlib

from .errors import ConvergenceError, HuntingError, Status, SystemDefinitionError

__version__ = "0.1.0"

_LAZY = {"simulate": ".integrate", "find_cycle": ".continuation", "follow": ".continuation",
         **{n: ".describe" for n in ("model", "load_model", "ModelBuilder", "CompiledModel")},
         **{n: ".models" for n in ("PID", "Cogging", "Coulomb", "DirectionalCurve", "Discontinuous", "LuGre",
                                   "Plant", "ServoLoop", "StribeckCurve", "Switch", "Viscous", "preset")},
         **{n: ".results" for n in ("EventLog", "Trajectory")},
         **{n: ".system" for n in ("GUARD_SIG", "JAC_SIG", "MODE_SIG", "RESET_SIG", "VF_SIG", "Mode",
                                   "PiecewiseSystem")}}

__all__ = ["ConvergenceError", "HuntingError", "Status", "SystemDefinitionError", "__version__", *_LAZY]


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name], __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'hunting' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
