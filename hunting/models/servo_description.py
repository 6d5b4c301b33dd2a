"""The PID servo loop of :mod:`hunting.models.servo` written as a model description.

The same closed loop as the hand-written kernels (states x1 = q - q_d, x2 = q', x3 = int x1 dt,
LuGre: x4 = z), with the controller as a signal and the friction law as expressions, so that
``hunting.model(servo_description(values))`` compiles it like any user model. The banded
Switch variant, cogging tables and the triangle-wave force have no expression form and stay
with the hand-written kernels.
"""
from __future__ import annotations

import math

from ..errors import SystemDefinitionError


def _num(v) -> float:
    return float(v)


def _stribeck(sfx: str, v: dict, params: dict) -> str:
    """g(|w|) of one direction with its parameters added to ``params`` (suffix '' or '_neg');
    beta = inf is the discontinuous curve g = Fc (a different structure: the exponent is gone)."""
    get = lambda k: v.get(k + sfx, v[k])  # noqa: E731
    for k in ("Fc", "Fs", "vs", "b"):
        params[k + sfx] = _num(get(k))
    beta = _num(get("beta"))
    if math.isinf(beta):
        return f"Fc{sfx}"
    params["beta" + sfx] = beta
    return f"(Fc{sfx} + (Fs{sfx} - Fc{sfx})*exp(-(abs(w)/vs{sfx})**beta{sfx}))"


def servo_description(values: dict, name: str = "servo") -> dict:
    """A model description of the servo loop with flat parameter ``values`` (the preset
    vocabulary of :data:`hunting.models.presets.VOCABULARY`: m, cm, q_d; P, D, I or K, tau_d,
    tau_i or kp, kd, ki; model 'switch' or 'lugre'; Fc, Fs, vs, beta (inf: discontinuous), b and
    their ``_neg`` variants; sigma0, sigma1, vd; cog_amplitude, cog_pitch, cog_phase or
    cog_period, cog_cos, cog_sin; f_ext (a constant force)).

    Raises SystemDefinitionError for what has no expression form (banded Switch, cogging
    tables, the triangle-wave force)."""
    v = dict(values)
    model = v.get("model", "switch")
    if model not in ("switch", "lugre"):
        raise SystemDefinitionError(f"model = {model!r} has no description: the banded Switch variant stays "
                                    "with the hand-written kernels (use model='switch' or 'lugre')")
    if v.get("force_amplitude", 0.0) != 0.0:
        raise SystemDefinitionError("the triangle-wave external force has no expression form (no periodic "
                                    "functions but sin and cos): use the hand-written loop")
    p: dict = {"m": _num(v["m"]), "cm": _num(v.get("cm", 1.0)), "q_d": _num(v.get("q_d", 0.0))}
    if "P" in v:
        p.update(P=_num(v["P"]), D=_num(v["D"]), I=_num(v["I"]))
        u = "-P*(x1 + D*x2 + I*x3)"
    elif "K" in v:
        tau_i = _num(v["tau_i"])
        p.update(K=_num(v["K"]), tau_d=_num(v["tau_d"]))
        if math.isinf(tau_i):
            u = "-K*(x1 + tau_d*x2)"
        else:
            p["tau_i"] = tau_i
            u = "-K*((1 + tau_d/tau_i)*x1 + tau_d*x2 + x3/tau_i)"
    else:
        p.update(kp=_num(v["kp"]), kd=_num(v["kd"]), ki=_num(v["ki"]))
        u = "-(kp*x1 + kd*x2 + ki*x3)"
    signals = {"u": u}
    force = "cm*u"
    if v.get("f_ext", 0.0) != 0.0:
        p["f_ext"] = _num(v["f_ext"])
        force += " + f_ext"
    if v.get("cog_amplitude", 0.0) != 0.0:
        p.update(cog_amplitude=_num(v["cog_amplitude"]), cog_pitch=_num(v["cog_pitch"]),
                 cog_phase=_num(v.get("cog_phase", 0.0)))
        signals["F_cog"] = "cog_amplitude*sin(2*pi*(x1 + q_d)/cog_pitch + cog_phase)"
        force += " - F_cog"
    elif v.get("cog_period") is not None:
        p["cog_period"] = _num(v["cog_period"])
        terms = []
        for k, (a, b) in enumerate(zip(v.get("cog_cos", ()), v.get("cog_sin", ())), start=1):
            p[f"cog_a{k}"], p[f"cog_b{k}"] = _num(a), _num(b)
            arg = f"2*pi*{k}*(x1 + q_d)/cog_period"
            terms.append(f"cog_a{k}*cos({arg}) + cog_b{k}*sin({arg})")
        if terms:
            signals["F_cog"] = " + ".join(terms)
            force += " - F_cog"
    asym = any(k.endswith("_neg") for k in v)
    g_pos = _stribeck("", v, p)
    g = g_pos
    visc = "b*w"
    if asym:
        g_neg = _stribeck("_neg", v, p)
        g = f"((1 + sign(w))/2*{g_pos} + (1 - sign(w))/2*{g_neg})"
        visc = "(1 + sign(w))/2*b*w + (1 - sign(w))/2*b_neg*w"
    contact = {"name": "friction", "force": "F", "velocity": "x2", "model": model}
    states = ["x1", "x2", "x3"]
    if model == "switch":
        contact.update(slip=f"sign(w)*{g} + {visc}", stick=["Fs_neg", "Fs"] if asym else "Fs")
    else:
        p.update(sigma0=_num(v["sigma0"]), sigma1=_num(v["sigma1"]))
        vd = _num(v.get("vd", math.inf))
        sigma1 = "sigma1"
        if math.isfinite(vd) and vd > 0:
            p["vd"] = vd
            sigma1 = "sigma1*exp(-(w/vd)**2)"
        contact.update(level=g, sigma0="sigma0", sigma1=sigma1, viscous=visc, state="x4")
    return {"name": name, "parameters": p, "states": states, "signals": signals,
            "equations": {"x1": "x2", "x2": f"({force} - F)/m", "x3": "x1"}, "friction": contact}
