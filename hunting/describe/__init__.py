"""Systems from equations: model descriptions (JSON/YAML files or Python) compiled into
piecewise-smooth systems.

    description (dict / file)  --validate-->  Spec            (description.py, expressions.py)
                               --sympy-->     Symbolic        (symbolic.py: modes, stick forces, Jacobians)
                               --print-->     Python source   (codegen.py: the protocol's numba functions)
                               --cache-->     imported module (cache.py: keyed by the structure hash)
                               -->            CompiledModel   (compiled.py: .system, layout, contacts)

Public entry points: :func:`model`, :func:`load_model`, :class:`ModelBuilder`,
:class:`CompiledModel`, :class:`Contact`, :class:`Layout`.
"""
from .api import ModelBuilder, load_model, model, read_description
from .compiled import CompiledModel, Contact, Layout
from .description import MAX_CONTACTS, Spec, validate

__all__ = ["model", "load_model", "read_description", "ModelBuilder", "CompiledModel", "Contact", "Layout",
           "Spec", "validate", "MAX_CONTACTS"]
