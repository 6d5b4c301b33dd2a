"""A wrong mass (or inertia)."""
from ._words import _pct, _q

NAME = "mass"
DESCRIPTION = "mass (inertia)"
FAMILY = "inertia"
HYPERS = 0
NOISE_FED = True      # its regressor is made of measured derivatives, which feedback fills with noise
INSTRUMENTED = True   # its coefficient is estimated with the noise-free loop's regressor as instrument
UNITS = {"mass": "kg"}


def hypers(kin, model) -> list:
    return [{}]


def design(kin, model, hyper):
    return kin.a[:, None]


def unphysical(theta, hyper, model) -> str | None:
    m = model.mass + float(theta[0])
    return f"mass = {m:.3g} kg <= 0" if m <= 0 else None


def parameters(theta, hyper, model) -> dict:
    return {"mass": float(model.mass + theta[0])}


def extend(model, theta, hyper):
    return model.replace(mass=model.mass + float(theta[0]))


def sentence(p, inc, model) -> str:
    rel = p["mass"] / model.mass - 1
    return (f"the moving mass is {_pct(abs(rel))} {'larger' if rel > 0 else 'smaller'} than the model's "
            f"({_q(p['mass'], None, 'kg')} instead of {_q(model.mass, None, 'kg')})")
