"""Periodic orbits of piecewise-smooth systems: flow sensitivities with saltation matrices,
single shooting, Floquet multipliers, a robust cycle search from rough starts and
pseudo-arclength continuation in a parameter given by name."""
from .branch import Branch, ContinuationOptions, continue_orbit
from .cycle import CycleResult, Phase, event_map_start, find_cycle, search_grid, stick_error_range
from .flow import Flow, fd_jacobian, flow
from .hunting_branch import follow
from .shooting import PeriodicOrbit, ShootingOptions, floquet, orbit_amplitude, shoot
from .status import OrbitStatus
from .target import ParameterLens, Target, resolve
from .transient import StartOptions, settle

__all__ = ["find_cycle", "follow", "Branch", "ContinuationOptions", "continue_orbit", "CycleResult", "Phase",
           "event_map_start", "search_grid", "stick_error_range", "Flow", "fd_jacobian", "flow", "PeriodicOrbit",
           "ShootingOptions", "floquet", "orbit_amplitude", "shoot", "OrbitStatus", "ParameterLens",
           "Target", "resolve", "StartOptions", "settle"]
