"""What a diagnosis reports: one cause (:class:`Cause`: final parameters with standard
uncertainties, the test that admitted it, its validation gain) and the whole diagnosis
(:class:`Diagnosis`: causes, alternatives, rejected and untested causes with reasons, residuals,
the extended model, the behaviour view, notes; ``as_dict`` is the JSON contract)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .causes import CAUSES
from .data import Measurement
from .kinematics import Kinematics
from .model import NominalModel


@dataclass(frozen=True)
class Cause:
    """One reported cause: name; score (relative growth of the validation metric when it is
    dropped from the extended model); statistic and p_value of the test that admitted it;
    parameters : final values (those the extended model holds) and sigma their standard
    uncertainties (None where not estimated); gain : the validation metric of the model without
    and with it (metric, nominal, extended; evidence: the rule that admitted it where that is not
    a p-value, p_value then None); increments : parameters' change against the nominal model;
    family : causes that share a signature share it; hyper : the hyper-parameter variant; theta :
    fitted coefficients."""

    name: str
    score: float
    statistic: float
    p_value: float
    parameters: dict
    sigma: dict
    gain: dict
    hyper: dict = field(default_factory=dict)
    theta: np.ndarray | None = None
    increments: dict = field(default_factory=dict)
    family: str = ""

    def as_dict(self) -> dict:
        return dict(name=self.name, score=self.score, statistic=self.statistic, p_value=self.p_value,
                    parameters=self.parameters, sigma=self.sigma, increments=self.increments, gain=self.gain,
                    family=self.family or self.name, description=CAUSES[self.name].DESCRIPTION, role="selected")


@dataclass
class Diagnosis:
    """causes : list of Cause ranked by score over all channels; nominal /
    extended : validation force-residual RMS [N] (None when the force channel was skipped);
    criterion : the selection rule; kin_fit, kin_val : kinematics; r_* : residuals (n,) of the
    nominal and extended model on both sets (NaN where not used: |v| small or filter edges);
    rejected : candidates that failed the rule (with the reason); alternatives : other readings
    of the data (a cause of the same family that would replace a selected one, a cause that
    explains the data alone but adds nothing once the selected ones are in, or another reading of
    a selected cause's own evidence, kind "same evidence"), each with its parameters, validation
    gain and BIC difference (None for "same evidence"); explanations : the runner-up sets of the
    force channel's search with their BIC difference and validation RMS; untested : causes this
    record cannot test, with the reason; extended_model : the nominal model with every selected
    extension; behaviour : the behaviour view on the validation data (None without a controller
    or a reference); notes : what was skipped and why; validation : the validation Measurement
    used; simulations : the behaviour view's re-simulations {"nominal", "extended"}."""

    causes: list
    nominal: float | None
    extended: float | None
    criterion: str
    model: NominalModel
    kin_fit: Kinematics
    kin_val: Kinematics
    r_fit_nominal: np.ndarray
    r_val_nominal: np.ndarray
    r_val_extended: np.ndarray
    rejected: list = field(default_factory=list)
    alternatives: list = field(default_factory=list)
    extended_model: NominalModel | None = None
    behaviour: dict | None = None
    notes: list = field(default_factory=list)
    validation: Measurement | None = None
    simulations: dict | None = None
    untested: list = field(default_factory=list)
    explanations: list = field(default_factory=list)

    def gains(self) -> list:
        """Validation metrics of the nominal against the extended model, rows {metric, unit,
        nominal, extended} and for behaviour metrics the measured value (errors are against it):
        force residual RMS, and from the behaviour view the re-simulation's position and
        drive-force RMS errors, stick error, cycle amplitude and period, final error, event-map
        contraction, whether the loop ends at rest (rows the runs do not have are left out)."""
        out = []
        if self.nominal is not None:
            out.append(dict(metric="force residual RMS", unit="N", nominal=self.nominal, extended=self.extended))
        b = self.behaviour
        if b:
            for key, label, unit in (("position_rms", "re-simulated position RMS error", "m"),
                                     ("force_rms", "re-simulated drive force RMS error", "N")):
                out.append(dict(metric=label, unit=unit, nominal=b["nominal"][key], extended=b["extended"][key]))
            for key, label, unit in (("stick_error", "stick error RMS", "m"), ("cycle_amplitude", "cycle amplitude", "m"),
                                     ("cycle_period", "cycle period", "s"), ("final_error", "final error", "m"),
                                     ("map_contraction", "event map contraction |d_n+1| / |d_n|", "")):
                m = b["measured"][key]
                if m is None or b["nominal"].get(key) is None or b["extended"].get(key) is None:
                    continue
                err = [abs(b[k][key] - m) for k in ("nominal", "extended")]
                out.append(dict(metric=f"{label}: error against the measured", unit=unit, measured=m, nominal=err[0],
                                extended=err[1]))
            if None not in (b["measured"].get("at_rest"), b["nominal"].get("at_rest"), b["extended"].get("at_rest")):
                out.append(dict(metric="ends at rest", unit="", measured=b["measured"]["at_rest"],
                                nominal=b["nominal"]["at_rest"], extended=b["extended"]["at_rest"]))
        return out

    def as_dict(self) -> dict:
        """The diagnosis as plain data for JSON: every number finite (a value that is not, e.g. the
        gain of an extension whose loop does not re-simulate, is None; its row's reason says why)."""
        alts = [dict(a, score=0.0, role="alternative") for a in self.alternatives]
        return _finite(dict(causes=[c.as_dict() for c in self.causes] + alts,
                    gain=dict(metric="force residual RMS [N] on the validation data", nominal=self.nominal,
                              extended=self.extended),
                    gains=self.gains(), behaviour=self.behaviour, notes=self.notes,
                    criterion=self.criterion, rule=self.criterion, rejected=self.rejected,
                    alternatives=self.alternatives, explanations=self.explanations, untested=self.untested,
                    nominal_model=self.model.to_dict(),
                    extended_model=None if self.extended_model is None else self.extended_model.to_dict()))


def _finite(x):
    """``x`` (nested dicts, lists and tuples) with every float that is not finite replaced by None
    (strict JSON has no NaN or Infinity)."""
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_finite(v) for v in x]
    if isinstance(x, (float, np.floating)) and not np.isfinite(x):
        return None
    return x
