"""Identification from measured (or simulated) signals: frequency responses and their fits."""
from .frf import (FRF, ParameterFit, controller_frf, estimate_frf, fit_double_integrator, fit_second_order,
                  plant_from_sensitivity)

__all__ = ["FRF", "ParameterFit", "controller_frf", "estimate_frf", "fit_double_integrator", "fit_second_order",
           "plant_from_sensitivity"]
