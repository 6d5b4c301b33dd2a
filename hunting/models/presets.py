"""Named closed loops from the thesis, overridable parameter by parameter.

``preset("table9.1", P=20, beta=1)`` returns a :class:`ServoLoop`. Every preset is a flat dict
of the parameters below; ``hunting models`` lists them with units.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import SystemDefinitionError
from .controller import PID
from .friction import LuGre, StribeckCurve, Switch
from .loop import ServoLoop
from .plant import Cogging, Plant

TWO_PI = 2 * math.pi

# name -> (description, unit in a translational loop, unit in a rotational loop)
VOCABULARY = {
    "m": ("mass or inertia", "kg", "kg m^2"),
    "cm": ("motor constant", "N/V", "N m/V"),
    "q_d": ("setpoint", "m", "rad"),
    "P": ("PID gain, u = -P(e + D e' + I int e)", "N/m", "N m/rad"),
    "D": ("PID derivative time", "s", "s"),
    "I": ("PID integral rate", "1/s", "1/s"),
    "K": ("PID gain, u = -K[(1 + tau_d/tau_i) e + tau_d e' + int e / tau_i]", "V/m", "V/rad"),
    "tau_d": ("derivative time", "s", "s"),
    "tau_i": ("integral time", "s", "s"),
    "model": ("friction model: switch | switch-banded | lugre", "-", "-"),
    "curve": ("steady-state curve: stribeck | discontinuous", "-", "-"),
    "Fs": ("static friction level", "N", "N m"),
    "Fc": ("Coulomb friction level", "N", "N m"),
    "vs": ("Stribeck velocity", "m/s", "rad/s"),
    "beta": ("Stribeck shape exponent (inf: discontinuous curve)", "-", "-"),
    "b": ("viscous coefficient (sigma2 for LuGre)", "N s/m", "N m s/rad"),
    "Fs_neg": ("static level for v < 0 (default Fs)", "N", "N m"),
    "Fc_neg": ("Coulomb level for v < 0 (default Fc)", "N", "N m"),
    "vs_neg": ("Stribeck velocity for v < 0 (default vs)", "m/s", "rad/s"),
    "beta_neg": ("shape exponent for v < 0 (default beta)", "-", "-"),
    "b_neg": ("viscous coefficient for v < 0 (default b)", "N s/m", "N m s/rad"),
    "eta": ("banded Switch: stick band half-width", "m/s", "rad/s"),
    "alpha": ("banded Switch: stick decay rate", "1/s", "1/s"),
    "sigma0": ("LuGre bristle stiffness", "N/m", "N m/rad"),
    "sigma1": ("LuGre bristle damping", "N s/m", "N m s/rad"),
    "vd": ("LuGre damping velocity scale, sigma1(v) = sigma1 exp(-(v/vd)^2) (inf: constant)", "m/s", "rad/s"),
    "cog_amplitude": ("cogging amplitude, F_cog = A sin(2 pi q / pitch + phase)", "N", "N m"),
    "cog_pitch": ("cogging pitch", "m", "rad"),
    "cog_phase": ("cogging phase", "rad", "rad"),
    "force_amplitude": ("triangle-wave external force amplitude (0: none)", "N", "N m"),
    "force_period": ("triangle-wave external force period", "s", "s"),
}
STRING_PARAMS = {"model": ("switch", "switch-banded", "lugre"), "curve": ("stribeck", "discontinuous")}
ALIASES = {"sigma2": "b", "friction": "curve", "J": "m", "mass": "m", "motor_constant": "cm"}

_LIMMS_QD = -0.38
# Single-harmonic cogging with the thesis' pitch that meets F_cog(q_d) = 4.866 N and
# dF_cog/dq(q_d) = -7.1586e3 N/m (TARGETS.md); the identified table of chapter 10 is a figure only.
_LIMMS_PITCH = 0.015
_w = TWO_PI / _LIMMS_PITCH
_LIMMS_AMP = math.hypot(4.866, -7.1586e3 / _w)
_LIMMS_PHASE = math.atan2(4.866, -7.1586e3 / _w) - _w * _LIMMS_QD


@dataclass(frozen=True)
class Preset:
    name: str
    description: str
    defaults: dict
    rotational: bool = False

    def units(self) -> dict:
        col = 2 if self.rotational else 1
        return {k: VOCABULARY[k][col] for k in self.defaults}


_T91 = dict(m=1.0, cm=1.0, q_d=0.0, P=10.0, D=1.0, I=10.0, model="switch", curve="stribeck",
            Fs=4.0, Fc=2.0, vs=0.1, beta=2.0, b=1.0, eta=1e-8, alpha=10.0)
_T81 = dict(m=0.026, cm=16.0, q_d=1.0, K=0.04, tau_d=1 / TWO_PI, tau_i=1 / TWO_PI, model="switch",
            curve="stribeck", Fs=0.53, Fc=0.44, vs=0.02, beta=2.0, b=0.1, eta=1e-6, alpha=10.0)
_LIMMS = dict(m=8.93, cm=74.4, q_d=_LIMMS_QD, K=10.0, tau_d=1 / TWO_PI, tau_i=1 / TWO_PI, model="switch",
              curve="stribeck", Fs=27.9, Fc=13.4, vs=0.0195, beta=2.0, b=37.2, eta=1e-6, alpha=10.0,
              cog_amplitude=_LIMMS_AMP, cog_pitch=_LIMMS_PITCH, cog_phase=_LIMMS_PHASE)

PRESETS = {
    "table9.1": Preset("table9.1", "Chapter 9: unit mass, PID (P, D, I) form, Switch friction (Table 9.1)", _T91),
    "table8.1-switch": Preset("table8.1-switch", "Chapter 8: rotating arm, fixed-shape PID, Switch friction (Table 8.1)",
                              _T81, rotational=True),
    "table8.1-lugre": Preset("table8.1-lugre", "Chapter 8: rotating arm, fixed-shape PID, LuGre friction (Table 8.1)",
                             {**_T81, "model": "lugre", "sigma0": 2.2e4, "sigma1": 7.58, "vd": math.inf},
                             rotational=True),
    "limms-switch": Preset("limms-switch", "Chapter 10: linear motor, fixed-shape PID, Switch friction, "
                           "single-harmonic cogging matching F_cog(q_d) and its slope", _LIMMS),
    "limms-lugre": Preset("limms-lugre", "Chapter 10: linear motor, fixed-shape PID, LuGre friction, cogging",
                          {**_LIMMS, "model": "lugre", "sigma0": 1.3e6, "sigma1": 3.61e3, "vd": math.inf}),
    "table4.1": Preset("table4.1", "Chapter 4: unit mass with LuGre friction (Table 4.1) under a slow "
                       "triangle-wave force to 95 % of Fs (presliding hysteresis, Fig. 4.2)",
                       dict(m=1.0, cm=1.0, q_d=0.0, P=0.0, D=0.0, I=0.0, model="lugre", curve="stribeck",
                            Fs=1.5, Fc=1.0, vs=0.001, beta=2.0, b=0.4, sigma0=1e5, sigma1=math.sqrt(1e5),
                            vd=math.inf, force_amplitude=0.95 * 1.5, force_period=56.0)),
}


def _coerce(name: str, value):
    if name in STRING_PARAMS:
        v = str(value).lower()
        if v not in STRING_PARAMS[name]:
            raise SystemDefinitionError(f"{name} = {value!r} is not allowed: use one of {STRING_PARAMS[name]}")
        return v
    if isinstance(value, str):
        s = value.strip().lower()
        if s in ("inf", "+inf", "infinity"):
            return math.inf
        try:
            return float(s)
        except ValueError:
            raise SystemDefinitionError(f"{name} = {value!r} is not a number") from None
    try:
        return float(value)
    except (TypeError, ValueError):
        raise SystemDefinitionError(f"{name} = {value!r} is not a number") from None


def resolve_parameters(name: str, overrides: dict) -> dict:
    """The preset's flat parameters with ``overrides`` applied and checked."""
    if name not in PRESETS:
        raise SystemDefinitionError(f"preset = {name!r} is not known: presets are {sorted(PRESETS)}")
    pr = PRESETS[name]
    values = dict(pr.defaults)
    for k, v in overrides.items():
        key = ALIASES.get(k, k)
        if key == "curve" and str(v).lower() == "stribeck" and math.isinf(values.get("beta", 2.0)):
            values["beta"] = 2.0
        allowed = set(pr.defaults) | {"Fs_neg", "Fc_neg", "vs_neg", "beta_neg", "b_neg", "cog_amplitude",
                                      "cog_pitch", "cog_phase", "force_amplitude", "force_period",
                                      "sigma0", "sigma1", "vd", "eta", "alpha"}
        if "P" in pr.defaults:
            allowed |= {"P", "D", "I"}
        else:
            allowed |= {"K", "tau_d", "tau_i"}
        if key not in allowed:
            raise SystemDefinitionError(
                f"parameter {k!r} is not a parameter of preset {name!r}: parameters are {sorted(allowed)}")
        values[key] = _coerce(key, v)
    if values.get("curve") == "discontinuous":
        values["beta"] = math.inf
    elif math.isinf(values.get("beta", 2.0)):
        values["curve"] = "discontinuous"
    if values.get("model") == "lugre":
        values.setdefault("sigma0", 1e5)
        values.setdefault("sigma1", math.sqrt(values["sigma0"]))
        values.setdefault("vd", math.inf)
    return values


def loop_from_parameters(values: dict, name: str = "servo", rotational: bool = False) -> ServoLoop:
    """Build a ServoLoop from a flat parameter dict (vocabulary: ``VOCABULARY``)."""
    v = values

    def curve(sfx: str) -> StribeckCurve:
        get = lambda k: v.get(k + sfx, v[k]) if sfx else v[k]  # noqa: E731
        return StribeckCurve(Fc=get("Fc"), Fs=get("Fs"), vs=get("vs"), beta=get("beta"), b=get("b"))

    pos = curve("")
    neg = curve("_neg") if any(k.endswith("_neg") for k in v) else pos
    from .friction import DirectionalCurve
    dc = DirectionalCurve(pos, neg)
    model = v.get("model", "switch")
    if model == "lugre":
        friction = LuGre(dc, sigma0=v["sigma0"], sigma1=v["sigma1"], vd=v.get("vd", math.inf))
    else:
        friction = Switch(dc, variant="banded" if model == "switch-banded" else "filippov",
                          eta=v.get("eta", 1e-8), alpha=v.get("alpha", 10.0))
    if "P" in v:
        controller = PID.pdi(v["P"], v["D"], v["I"])
    else:
        controller = PID.fixed_shape(v["K"], v["tau_d"], v["tau_i"])
    cog = None
    if v.get("cog_amplitude", 0.0) != 0.0:
        cog = Cogging.sine(v["cog_amplitude"], v["cog_pitch"], v.get("cog_phase", 0.0))
    fext = None
    if v.get("force_amplitude", 0.0) != 0.0:
        fext = ("triangle", v["force_amplitude"], v["force_period"])
    plant = Plant(mass=v["m"], motor_constant=v.get("cm", 1.0), setpoint=v.get("q_d", 0.0), cogging=cog,
                  external_force=fext)
    units = {"q": "rad", "F": "N m", "u": "V"} if rotational else {"q": "m", "F": "N", "u": "V" if v.get("cm", 1.0) != 1.0 else "N"}
    return ServoLoop(plant, friction, controller, name=name, units=units)


def preset(name: str, **overrides) -> ServoLoop:
    """A thesis closed loop by name, e.g. ``preset("table9.1", P=20, beta=1)``.

    Names: table9.1, table8.1-switch, table8.1-lugre, limms-switch, limms-lugre, table4.1.
    ``beta=inf`` or ``curve="discontinuous"`` selects the discontinuous curve;
    ``model="switch-banded"`` the thesis' banded Switch variant."""
    values = resolve_parameters(name, overrides)
    pr = PRESETS[name]
    label = name if not overrides else name + "(" + ", ".join(f"{k}={v}" for k, v in overrides.items()) + ")"
    return loop_from_parameters(values, name=label, rotational=pr.rotational)


def preset_description(name: str, **overrides) -> dict:
    """The preset as a model description (``hunting.model(preset_description("table9.1"))``
    compiles it like a user model; parameter names are the preset vocabulary). Raises
    SystemDefinitionError for presets with no expression form (the banded Switch variant, the
    triangle-wave force of table4.1)."""
    from .servo_description import servo_description
    values = resolve_parameters(name, overrides)
    label = name if not overrides else name + "(" + ", ".join(f"{k}={v}" for k, v in overrides.items()) + ")"
    return servo_description(values, name=label)


def describe_presets() -> str:
    """Text listing of every preset with its parameters and units (for ``hunting models``)."""
    lines = []
    for pr in PRESETS.values():
        lines.append(f"{pr.name}: {pr.description}")
        units = pr.units()
        for k, val in pr.defaults.items():
            val_s = val if isinstance(val, str) else f"{val:.6g}"
            lines.append(f"    {k:<16} = {val_s:<14} [{units[k]}]  {VOCABULARY[k][0]}")
        lines.append("")
    return "\n".join(lines)
