"""A diagnosis' nominal model read off a model description (the equations format of
``hunting simulate --model``), so a system written once diagnoses measured data.

The reading itself (mass, motor constant, offset, Stribeck or LuGre friction, PID gains and how
the reference enters) is :func:`hunting.describe.mechanical.mechanical_parameters`, exact or an
error naming the part that has none; this module assembles the :class:`NominalModel`:

- friction: ``switch`` with Fs = Fc in both directions is the law ``coulomb-viscous``, otherwise
  ``switch`` (a Stribeck dip); ``lugre`` is ``lugre`` with its sigma0 and sigma1;
- controller: ``{"type": "pid", "kp", "kd", "ki"}`` with ``"tau_f"`` for a derivative filter and
  ``"derivative_on": "measurement"`` when the reference enters the P and I terms only; the data's
  ``q_ref`` column is the reference (the description's reference parameter or signal is only its
  placeholder), ``"saturation"`` for a ``min(max(.., -S), S)`` limit, and the controller is
  updated every data sample (a description is continuous);
- cogging: the harmonics read off the velocity equation, as functions of the description's
  position state (which is the data's q column);
- what a description cannot say stays at the nominal model's defaults: no delay, flexibility,
  frictional lag or dwell, sample time, and the sensor's resolution read from the data.
"""
from __future__ import annotations

import math
from pathlib import Path

from ..describe.mechanical import MechanicalParameters, mechanical_parameters
from .model import NominalModel


def nominal_from_description(description, **overrides) -> NominalModel:
    """The :class:`NominalModel` of a model description.

    Parameters
    ----------
    description : dict, str or Path
        A model description (dict), or the path of a JSON or YAML file holding one.
    **overrides : float
        Parameter values replacing the description's defaults.

    Returns
    -------
    NominalModel
        Its ``source`` is the nominal-model JSON it maps to (``to_dict()``).

    Raises
    ------
    SystemDefinitionError
        One line naming the part of the description that has no exact nominal-model reading
        (see :mod:`hunting.describe.mechanical`).

    Examples
    --------
    >>> d = {"parameters": {"m": 95.0, "cm": 35.15, "Fc": 20.0, "b": 200.0, "kp": 3.9e4, "kd": 243.0,
    ...                     "r": 0.0},
    ...      "states": ["q", "v"], "signals": {"u": "-kp*(q - r) - kd*v"},
    ...      "equations": {"q": "v", "v": "(cm*u - F)/m"},
    ...      "friction": {"force": "F", "velocity": "v", "model": "switch",
    ...                   "slip": "sign(w)*Fc + b*w", "stick": "Fc"}}
    >>> nominal_from_description(d).to_dict()["controller"]
    {'type': 'pid', 'kp': 39000.0, 'kd': 243.0, 'ki': 0.0, 'derivative_on': 'measurement'}
    """
    if isinstance(description, (str, Path)):
        from ..describe import read_description
        description = read_description(description)
    return nominal_from_parameters(mechanical_parameters(description, **overrides))


def nominal_from_parameters(p: MechanicalParameters) -> NominalModel:
    """The :class:`NominalModel` of parameters read off a description (see the module docstring)."""
    if p.law == "lugre":
        law = "lugre"
    else:
        flat = all(c.Fs == c.Fc for c in (p.curve.positive, p.curve.negative))
        law = "coulomb-viscous" if flat else "switch"
    ctrl = None
    if p.controller is not None:
        c = p.controller
        ctrl = {"type": "pid", "kp": c.kp, "kd": c.kd, "ki": c.ki}
        if c.tau_f:
            ctrl["tau_f"] = c.tau_f
        if c.derivative_on != "error":
            ctrl["derivative_on"] = c.derivative_on
        if math.isfinite(c.saturation):
            ctrl["saturation"] = c.saturation
    model = NominalModel(p.mass, p.cm, p.curve, law, offset=p.offset, sigma0=p.sigma0, sigma1=p.sigma1,
                         controller=ctrl, cogging=() if p.cogging is None else (p.cogging,))
    return model.replace()
