"""Friction laws, plants, controllers, closed loops and the thesis presets."""
from .controller import PID
from .friction import (Coulomb, DirectionalCurve, Discontinuous, LuGre, StribeckCurve, Switch,
                       Viscous)
from .loop import ServoLoop
from .plant import Cogging, Plant
from .presets import PRESETS, describe_presets, loop_from_parameters, preset, preset_description

__all__ = ["PID", "Coulomb", "DirectionalCurve", "Discontinuous", "LuGre", "StribeckCurve", "Switch",
           "Viscous", "ServoLoop", "Cogging", "Plant", "PRESETS", "describe_presets",
           "loop_from_parameters", "preset", "preset_description"]
