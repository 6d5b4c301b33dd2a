"""Start and follow the hunting branch of a servo preset in one parameter."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import ConvergenceError, SystemDefinitionError
from ..models import servo as S
from ..models.presets import PRESETS, preset
from .branch import Branch, ContinuationOptions, continue_orbit
from .shooting import PeriodicOrbit, ShootingOptions, cycle_guess, guess_from_stick_error, shoot


def _stick_twin(name: str, overrides: dict):
    """The exact-Switch version of a preset (same parameters), for event-map guesses."""
    ov = dict(overrides)
    ov["model"] = "switch"
    return preset(name, **ov)


def servo_amplitude(system, x0, T, fl) -> float:
    """max |x1| over a servo loop's orbit from its flow: x1' = x2 and x2 = 0 is an event of the
    exact Switch and LuGre loops (reversal, stick entry, the LuGre kink), so the extremes of
    x1 are among the event states and the ends (not for the banded Switch: no event at 0)."""
    a = max(abs(x0[0]), abs(fl.x[0]))
    if fl.event_states is not None and len(fl.event_states):
        a = max(a, float(np.max(np.abs(fl.event_states[:, 0]))))
    return float(a)


def find_cycle(name: str, overrides: dict | None = None, *, which: str = "stable", d_max: float = 0.05,
               shooting: ShootingOptions | None = None) -> PeriodicOrbit:
    """A hunting cycle of ``preset(name, **overrides)``: the event map of the loop's Switch twin
    gives the stick error of the stable (or unstable) cycle, a short simulation from its
    break-away state the shooting guess (for LuGre the bristle state starts at its
    steady-state value), and shooting converges on the loop's own cycle."""
    from ..eventmap import fixed_points
    overrides = dict(overrides or {})
    loop = preset(name, **overrides)
    twin = _stick_twin(name, overrides)
    fps = [f for f in fixed_points(twin, np.linspace(0.0, d_max, 801), 2) if f.kind == "cycle"]
    cand = [f for f in fps if f.stable == (which == "stable")]
    if not cand:
        raise ConvergenceError(f"{loop.name}: the event map of the Switch twin has no {which} cycle "
                               f"on [0, {d_max}]; cycles found: {[(f.d, f.stable) for f in fps]}")
    f = max(cand, key=lambda c: c.d) if which == "stable" else min(cand, key=lambda c: c.d)
    x0, T = guess_from_stick_error(twin, f.d)
    if loop.n_states == 4:
        c = loop.friction.curve.positive
        g = float(c.level(x0[1])) if x0[1] != 0 else c.Fs
        x0 = np.append(x0, g / loop.friction.sigma0)
    po = shoot(loop.system, x0, T, options=shooting)
    if not po.success:
        # fall back on a long simulation from the stick state
        xg, Tg = cycle_guess(loop.system, loop.state(x1=f.d), t_settle=20 * T)
        po = shoot(loop.system, xg, Tg, options=shooting)
    if not po.success:
        raise ConvergenceError(f"{loop.name}: no {which} hunting cycle found: {po.message}", po)
    return po


def follow(name: str, param: str, start: float, end: float, *, overrides: dict | None = None,
           stop_at: float | None = None, options: ContinuationOptions | None = None,
           shooting: ShootingOptions | None = None, orbit: PeriodicOrbit | None = None) -> Branch:
    """The hunting branch of a preset from ``param = start`` towards ``end``; after a fold the
    branch is followed back until ``param`` reaches ``stop_at`` (default: ``start``). ``orbit``:
    the cycle at ``start`` when already known (else find_cycle finds the stable one)."""
    if name not in PRESETS:
        raise SystemDefinitionError(f"preset = {name!r} is not known: presets are {sorted(PRESETS)}")
    overrides = dict(overrides or {})
    po = orbit if orbit is not None else find_cycle(name, {**overrides, param: start}, shooting=shooting)
    loop = preset(name, **{**overrides, param: start})
    base = loop.system
    opt = options or ContinuationOptions()
    if opt.jacobian_method is None and loop.model_code == S.MODEL_LUGRE:
        opt = replace(opt, jacobian_method="radau")       # the stiff loop's sensitivities: implicit

    def system_at(mu):
        return base.with_param_array(preset(name, **{**overrides, param: mu}).param_array())
    br = continue_orbit(system_at, po, start, end, param=param, options=opt, shooting=shooting,
                        stop_at_mu=start if stop_at is None else stop_at,
                        amplitude=None if loop.model_code == S.MODEL_BANDED else servo_amplitude)
    return Branch(br.param, br.mu, br.period, br.amplitude, br.multipliers, br.stable, br.x0, br.modes,
                  br.special, br.status, br.message, label=f"{name} {overrides}" if overrides else name)
