"""Periodic orbits of piecewise-smooth systems: flow sensitivities with saltation matrices,
single shooting, Floquet multipliers and pseudo-arclength continuation."""
from .branch import Branch, ContinuationOptions, continue_orbit
from .flow import Flow, fd_jacobian, flow
from .hunting_branch import find_cycle, follow
from .shooting import PeriodicOrbit, ShootingOptions, cycle_guess, floquet, orbit_amplitude, shoot

__all__ = ["find_cycle", "follow", "Branch", "ContinuationOptions", "continue_orbit", "Flow", "fd_jacobian", "flow", "PeriodicOrbit",
           "ShootingOptions", "cycle_guess", "floquet", "orbit_amplitude", "shoot"]
