"""Identification from measured (or simulated) signals: frequency responses and their fits."""
from .friction_map import cogging_table, curve_from_fit, fit_stribeck
from .frf import (FRF, ParameterFit, controller_frf, estimate_frf, fit_double_integrator, fit_second_order,
                  plant_from_sensitivity)

__all__ = ["cogging_table", "curve_from_fit", "fit_stribeck", "FRF", "ParameterFit", "controller_frf", "estimate_frf", "fit_double_integrator", "fit_second_order",
           "plant_from_sensitivity"]
