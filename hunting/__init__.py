"""hunting: what friction does to controlled machines.

Equilibrium sets, hunting limit cycles and their bifurcations for PID-controlled mechanical
systems with friction, after R. Hensen, "Controlled Mechanical Systems with Friction" (2002).
"""
from .errors import ConvergenceError, HuntingError, Status, SystemDefinitionError
from .describe import CompiledModel, ModelBuilder, load_model, model
from .integrate import simulate
from .models import (PID, Cogging, Coulomb, DirectionalCurve, Discontinuous, LuGre, Plant, ServoLoop,
                     StribeckCurve, Switch, Viscous, preset)
from .results import EventLog, Trajectory
from .system import GUARD_SIG, JAC_SIG, MODE_SIG, RESET_SIG, VF_SIG, Mode, PiecewiseSystem

__version__ = "0.1.0"

__all__ = ["ConvergenceError", "HuntingError", "Status", "SystemDefinitionError", "simulate", "PID",
           "Cogging", "Coulomb", "DirectionalCurve", "Discontinuous", "LuGre", "Plant", "ServoLoop",
           "StribeckCurve", "Switch", "Viscous", "preset", "EventLog", "Trajectory", "GUARD_SIG",
           "JAC_SIG", "MODE_SIG", "RESET_SIG", "VF_SIG", "Mode", "PiecewiseSystem", "__version__",
           "model", "load_model", "ModelBuilder", "CompiledModel"]
