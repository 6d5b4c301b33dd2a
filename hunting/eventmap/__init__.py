"""Stick-to-stick event maps, their fixed points, basins and bifurcation diagrams."""
from .attractors import Attractor, attractors
from .basins import basins
from .bifurcation import MapDiagram, default_grid, map_diagram
from .engine import EventMap, MapOptions, MapValues, evaluate_map, event_map, stick_map
from .family import StickFamily, as_stick_map, stick_family
from .fixedpoints import FixedPoint, OriginSlope, fixed_points, origin_slope
from .origin import LinearOrigin, linear_origin
from .resolution import MapResolution, check_resolution

__all__ = ["Attractor", "attractors", "basins", "MapDiagram", "default_grid", "map_diagram", "EventMap", "MapOptions", "MapValues",
           "evaluate_map", "event_map", "stick_map", "StickFamily", "as_stick_map", "stick_family", "FixedPoint",
           "OriginSlope", "fixed_points", "origin_slope", "LinearOrigin", "linear_origin", "MapResolution",
           "check_resolution"]
