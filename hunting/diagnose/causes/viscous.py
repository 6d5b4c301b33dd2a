"""A wrong viscous coefficient."""
NAME = "viscous"
DESCRIPTION = "viscous coefficient b"


def hypers(kin, model) -> list:
    return [{}]


def design(kin, model, hyper):
    return kin.v[:, None]


def parameters(theta, hyper, model) -> dict:
    return {"b": float(model.curve.positive.b + theta[0])}
