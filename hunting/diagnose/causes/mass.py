"""A wrong mass (or inertia)."""
NAME = "mass"
DESCRIPTION = "mass (inertia)"


def hypers(kin, model) -> list:
    return [{}]


def design(kin, model, hyper):
    return kin.a[:, None]


def parameters(theta, hyper, model) -> dict:
    return {"mass": float(model.mass + theta[0])}


def extend(model, theta, hyper):
    return model.replace(mass=model.mass + float(theta[0]))
