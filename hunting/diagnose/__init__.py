"""Measured data against the model: where the simulation departs from the measurement, why (named
causes with evidence), the extended model and its gain on validation data."""
from .causes import CAUSES
from .data import Measurement, load, save_csv
from .kinematics import Kinematics, kinematics, residual
from .model import NominalModel, fit_coulomb_viscous
from .select import Cause, Diagnosis, diagnose

__all__ = ["CAUSES", "Measurement", "load", "save_csv", "Kinematics", "kinematics", "residual", "NominalModel",
           "fit_coulomb_viscous", "Cause", "Diagnosis", "diagnose"]
