"""Safe parsing of the expressions in a model description (never ``eval``).

An expression is Python syntax restricted to a whitelist: numbers, names, ``+ - * / **``, unary
minus (and plus), and the functions ``abs sign exp log sqrt tanh sin cos min max``; ``t`` is
time and ``pi`` the constant. Anything else is a :class:`~hunting.errors.SystemDefinitionError`
that names the expression, where it occurs in the description and the character position.

The parser returns an :class:`Expr` holding the checked ``ast`` tree, its canonical text (used
for the content hash of a description) and the names it uses. Conversion to sympy happens only
when a model is compiled (:func:`to_sympy`); :func:`evaluate` computes a value from numbers
(used to check stick bounds at given parameter values) without sympy.
"""
from __future__ import annotations

import ast
import math
import operator
from dataclasses import dataclass

import numpy as np

from ..errors import SystemDefinitionError

#: function name -> number of arguments (None: two or more)
FUNCTIONS = {"abs": 1, "sign": 1, "exp": 1, "log": 1, "sqrt": 1, "tanh": 1, "sin": 1, "cos": 1,
             "min": None, "max": None}
CONSTANTS = {"pi": math.pi}
TIME = "t"
_BINOPS = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.Pow: "**"}
_MAX_LENGTH = 10_000


@dataclass(frozen=True)
class Expr:
    """A parsed, whitelisted expression.

    text : the user's text; canonical : the same expression re-printed from its tree (stable
    spacing and parentheses, what the content hash sees); names : every name it uses (free
    symbols, functions excluded); tree : the ``ast`` expression node."""

    text: str
    canonical: str
    names: frozenset
    tree: ast.AST

    def __str__(self) -> str:
        return self.canonical


def _fail(where: str, text: str, problem: str, node: ast.AST | None = None) -> SystemDefinitionError:
    lead = len(text) - len(text.lstrip())        # the parser saw the text without leading blanks
    pos = f" at position {node.col_offset + 1 + lead}" if node is not None and hasattr(node, "col_offset") else ""
    return SystemDefinitionError(f"{where} = {text!r}: {problem}{pos}")


def parse(text, where: str) -> Expr:
    """Parse one expression; ``where`` names its place in the description (for messages).

    Numbers (int or float) are accepted as well as strings."""
    if isinstance(text, bool) or not isinstance(text, (str, int, float)):
        raise SystemDefinitionError(f"{where} = {text!r}: an expression must be a string or a number")
    if isinstance(text, (int, float)):
        if not math.isfinite(text):
            raise SystemDefinitionError(f"{where} = {text!r}: numbers must be finite")
        text = repr(float(text)) if isinstance(text, float) else str(text)
    if not text.strip():
        raise SystemDefinitionError(f"{where} = {text!r}: the expression is empty")
    if len(text) > _MAX_LENGTH:
        raise SystemDefinitionError(f"{where}: the expression is longer than {_MAX_LENGTH} characters")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as e:
        col = f" at position {e.offset + len(text) - len(text.lstrip())}" if e.offset else ""
        raise SystemDefinitionError(f"{where} = {text!r}: not a valid expression ({e.msg}){col}") from None
    names: set = set()
    _check(tree.body, where, text, names)
    return Expr(text, ast.unparse(tree.body), frozenset(names), tree.body)


def _check(node, where, text, names) -> None:
    if isinstance(node, ast.Constant):
        v = node.value
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise _fail(where, text, f"the constant {v!r} is not allowed (only numbers)", node)
        if not math.isfinite(v):
            raise _fail(where, text, f"the number {v!r} is not finite", node)
        return
    if isinstance(node, ast.Name):
        if node.id in FUNCTIONS:
            raise _fail(where, text, f"{node.id!r} is a function: call it as {node.id}(...)", node)
        names.add(node.id)
        return
    if isinstance(node, ast.BinOp):
        if type(node.op) not in _BINOPS:
            raise _fail(where, text, f"the operator {type(node.op).__name__} is not allowed "
                                     f"(allowed: + - * / **)", node)
        _check(node.left, where, text, names)
        _check(node.right, where, text, names)
        return
    if isinstance(node, ast.UnaryOp):
        if not isinstance(node.op, (ast.USub, ast.UAdd)):
            raise _fail(where, text, f"the operator {type(node.op).__name__} is not allowed "
                                     "(allowed: unary minus)", node)
        _check(node.operand, where, text, names)
        return
    if isinstance(node, ast.Call):
        if not isinstance(node.func, ast.Name) or node.func.id not in FUNCTIONS:
            fname = node.func.id if isinstance(node.func, ast.Name) else ast.unparse(node.func)
            raise _fail(where, text, f"the function {fname!r} is not allowed "
                                     f"(allowed: {', '.join(FUNCTIONS)})", node)
        if node.keywords:
            raise _fail(where, text, f"{node.func.id}() takes no keyword arguments", node)
        want = FUNCTIONS[node.func.id]
        if (want is None and len(node.args) < 2) or (want is not None and len(node.args) != want):
            need = "two or more arguments" if want is None else f"{want} argument"
            raise _fail(where, text, f"{node.func.id}() takes {need}, got {len(node.args)}", node)
        for a in node.args:
            if isinstance(a, ast.Starred):
                raise _fail(where, text, "starred arguments are not allowed", a)
            _check(a, where, text, names)
        return
    kind = type(node).__name__
    raise _fail(where, text, f"{kind} is not allowed in an expression (allowed: numbers, names, "
                             f"+ - * / **, unary minus, {', '.join(FUNCTIONS)})", node)


# ------------------------------------------------------------------------- evaluation

_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.Pow: operator.pow}


def _walk(expr: Expr, number, name, call):
    """Fold a checked tree bottom-up: number(value), name(id) and call(function, args) give the
    leaves and calls; the arithmetic is Python's operators (floats or sympy objects alike)."""

    def ev(node):
        if isinstance(node, ast.Constant):
            return number(node.value)
        if isinstance(node, ast.Name):
            return name(node.id)
        if isinstance(node, ast.UnaryOp):
            v = ev(node.operand)
            return -v if isinstance(node.op, ast.USub) else v
        if isinstance(node, ast.BinOp):
            return _BINARY[type(node.op)](ev(node.left), ev(node.right))
        return call(node.func.id, [ev(a) for a in node.args])

    return ev(expr.tree)


def _sign(v: float) -> float:
    return 1.0 if v > 0 else (-1.0 if v < 0 else 0.0)


_MATH = {"abs": abs, "sign": _sign, "exp": math.exp, "log": math.log, "sqrt": math.sqrt,
         "tanh": math.tanh, "sin": math.sin, "cos": math.cos, "min": min, "max": max}


def evaluate(expr: Expr, values: dict) -> float:
    """Value of ``expr`` with every name taken from ``values`` (floats); raises
    SystemDefinitionError naming a missing name or a math domain error."""

    def name(n):
        if n in values:
            return float(values[n])
        if n in CONSTANTS:
            return CONSTANTS[n]
        raise SystemDefinitionError(f"{expr.text!r}: no value for {n!r}")

    try:
        return float(_walk(expr, float, name, lambda f, args: _MATH[f](*args)))
    except (ValueError, ZeroDivisionError, OverflowError, TypeError) as e:
        raise SystemDefinitionError(f"{expr.text!r} cannot be evaluated at {values}: {e}") from None


_NUMPY = {"abs": np.abs, "sign": np.sign, "exp": np.exp, "log": np.log, "sqrt": np.sqrt, "tanh": np.tanh,
          "sin": np.sin, "cos": np.cos, "min": lambda *a: np.min(a), "max": lambda *a: np.max(a)}


def first_non_finite(expr: Expr, values: dict) -> str | None:
    """Where ``expr`` stops being finite at ``values`` (floats by name), in words: the innermost
    name, operation or function whose value is NaN or inf while its operands are finite, e.g.
    ``"division by m = 0"`` or ``"log(x) of -1"``; None when the value is finite. Evaluated in
    IEEE arithmetic (no exceptions), as the compiled model computes it."""
    found: list = []

    def note(text):
        if not found:
            found.append(text)

    def operands(node) -> str:
        used = sorted({n.id for n in ast.walk(node) if isinstance(n, ast.Name)} - set(CONSTANTS))
        return ", ".join(f"{n} = {float(values[n]):.6g}" for n in used if n in values)

    def ev(node):
        if isinstance(node, ast.Constant):
            return np.float64(node.value)
        if isinstance(node, ast.Name):
            v = np.float64(values[node.id] if node.id in values else CONSTANTS.get(node.id, np.nan))
            if not np.isfinite(v):
                note(f"{node.id} = {v}")
            return v
        if isinstance(node, ast.UnaryOp):
            v = ev(node.operand)
            return -v if isinstance(node.op, ast.USub) else v
        if isinstance(node, ast.BinOp):
            left, right = ev(node.left), ev(node.right)
            v = _BINARY[type(node.op)](left, right)
            if not np.isfinite(v) and np.isfinite(left) and np.isfinite(right):
                den = ast.unparse(node.right)
                if isinstance(node.op, ast.Div) and right == 0:
                    where = operands(node.right)
                    note(f"division by {den} = 0" + ("" if where == f"{den} = 0" else f" ({where})"))
                else:
                    note(f"{ast.unparse(node)} is {v} ({operands(node)})")
            return v
        args = [ev(a) for a in node.args]
        v = np.float64(_NUMPY[node.func.id](*args))
        if not np.isfinite(v) and all(np.isfinite(a) for a in args):
            note(f"{ast.unparse(node)} is {v} ({operands(node)})")
        return v

    with np.errstate(all="ignore"):
        value = ev(expr.tree)
    if np.isfinite(value):
        return None
    return found[0] if found else f"its value is {value}"


def to_sympy(expr: Expr, symbols: dict):
    """The sympy expression of ``expr``; ``symbols`` maps every name it uses to a sympy object."""
    import sympy as sp

    funcs = {"abs": sp.Abs, "sign": sp.sign, "exp": sp.exp, "log": sp.log, "sqrt": sp.sqrt,
             "tanh": sp.tanh, "sin": sp.sin, "cos": sp.cos, "min": sp.Min, "max": sp.Max}

    def number(v):
        return sp.Integer(v) if isinstance(v, int) else sp.Float(repr(v), 17)

    def name(n):
        if n in symbols:
            return symbols[n]
        if n == "pi":
            return sp.pi
        raise SystemDefinitionError(f"{expr.text!r}: the name {n!r} is not known here")

    return _walk(expr, number, name, lambda f, args: funcs[f](*args))
