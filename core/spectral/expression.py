"""A band expression, parsed with :mod:`ast` and evaluated on NumPy arrays, never with ``eval``.

Allowed: numbers, band names (b1 .. bN, and NIR, RED, REDEDGE / REG / RE, GREEN / GRE, BLUE in any case), the
operators + - * / **, unary minus and plus, parentheses, and the functions of :data:`FUNCTIONS`.  Anything else
(an attribute, a call of anything else, a string, a comparison, a subscript, a keyword argument ...) is refused
with a :class:`~.options.SpectralError` naming the expression and the offending part.

A cell is NaN (nodata) where a denominator is zero or the result is not finite (sqrt of a negative, log of 0).
"""
from __future__ import annotations

import ast
import re
from dataclasses import dataclass
from typing import Callable, Dict, Mapping, Tuple

import numpy as np

from .errors import MAX_EXPRESSION_CHARS, SpectralError

# the band names an expression may use for the named bands, in any case -> the canonical name
NAME_ALIASES = {"NIR": "NIR", "RED": "RED", "REDEDGE": "REDEDGE", "RED_EDGE": "REDEDGE", "REG": "REDEDGE",
                "RE": "REDEDGE", "GREEN": "GREEN", "GRE": "GREEN", "BLUE": "BLUE"}
BAND_NUMBER = re.compile(r"^[bB]([1-9][0-9]{0,3})$")


def _min(*args):
    return np.minimum.reduce(np.broadcast_arrays(*args))


def _max(*args):
    return np.maximum.reduce(np.broadcast_arrays(*args))


# name -> (least, most arguments, function)
FUNCTIONS: Dict[str, Tuple[int, int, Callable]] = {
    "sqrt": (1, 1, np.sqrt), "abs": (1, 1, np.abs), "log": (1, 1, np.log), "exp": (1, 1, np.exp),
    "min": (2, 16, _min), "max": (2, 16, _max), "clip": (3, 3, np.clip)}
_BINARY = {ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply, ast.Pow: np.power}


def canonical(name: str) -> str:
    """The canonical band name of a name written in an expression: 'B4' for b4, 'REDEDGE' for reg; '' when it
    names no band."""
    m = BAND_NUMBER.match(name)
    if m:
        return f"B{int(m.group(1))}"
    return NAME_ALIASES.get(name.upper(), "")


@dataclass(frozen=True)
class Expression:
    """A checked expression: ``names`` the canonical band names it uses (B4, NIR, ...), in order of use."""

    text: str
    tree: ast.Expression
    names: Tuple[str, ...]

    def evaluate(self, values: Mapping[str, np.ndarray]) -> np.ndarray:
        """The expression over float64 arrays of one shape, ``values`` by canonical name; NaN where a denominator
        is zero or the result is not finite."""
        with np.errstate(all="ignore"):
            out = _eval(self.tree.body, values)
            shape = next(iter(values.values())).shape
            out = np.broadcast_to(np.asarray(out, dtype=np.float64), shape)
            return np.where(np.isfinite(out), out, np.nan)


def _refuse(text: str, node: ast.AST, why: str) -> SpectralError:
    part = ast.get_source_segment(text, node) or ast.unparse(node)
    return SpectralError(f"the expression {text!r} {why}: {part!r}; allowed are numbers, b1 .. bN, the band names "
                         f"NIR, RED, REDEDGE (REG, RE), GREEN (GRE), BLUE, + - * / **, parentheses and the functions "
                         f"{', '.join(FUNCTIONS)}")


def _check(text: str, node: ast.AST, names: list) -> None:
    """Raise SpectralError for any node outside the allowed grammar; collect the band names used."""
    if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow)):
        _check(text, node.left, names)
        _check(text, node.right, names)
    elif isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        _check(text, node.operand, names)
    elif isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise _refuse(text, node, "has a value that is not a number")
        try:
            float(node.value)
        except OverflowError:
            raise _refuse(text, node, "has a number too large") from None
    elif isinstance(node, ast.Name):
        name = canonical(node.id)
        if not name:
            raise _refuse(text, node, "uses an unknown name")
        names.append(name)
    elif isinstance(node, ast.Call):
        func = node.func.id if isinstance(node.func, ast.Name) else None
        if func not in FUNCTIONS:
            raise _refuse(text, node, "calls something that is not an allowed function")
        if node.keywords:
            raise _refuse(text, node, f"gives {func} a keyword argument")
        least, most, _ = FUNCTIONS[func]
        if not least <= len(node.args) <= most or any(isinstance(a, ast.Starred) for a in node.args):
            raise _refuse(text, node, f"gives {func} {len(node.args)} argument(s) ({least}"
                          + (f" to {most})" if most != least else ")"))
        for a in node.args:
            _check(text, a, names)
    else:
        raise _refuse(text, node, f"has a part that is not allowed ({type(node).__name__})")


def parse(text: str) -> Expression:
    """The checked :class:`Expression` of ``text``; SpectralError naming it and its offending part."""
    text = str(text).strip()
    if not text:
        raise SpectralError("the expression is empty")
    if len(text) > MAX_EXPRESSION_CHARS:
        raise SpectralError(f"the expression is {len(text)} characters long (at most {MAX_EXPRESSION_CHARS})")
    try:
        tree = ast.parse(text, mode="eval")
    except (SyntaxError, ValueError, RecursionError, MemoryError) as e:
        where = f" at column {e.offset}" if isinstance(e, SyntaxError) and e.offset else ""
        raise SpectralError(f"the expression {text!r} is not a formula{where}: "
                            f"{getattr(e, 'msg', None) or e}") from None
    names: list = []
    _check(text, tree.body, names)
    if not names:
        raise SpectralError(f"the expression {text!r} uses no band: name bands as b1 .. bN or NIR, RED, REDEDGE, "
                            "GREEN, BLUE")
    return Expression(text, tree, tuple(dict.fromkeys(names)))


def _eval(node: ast.AST, values: Mapping[str, np.ndarray]):
    if isinstance(node, ast.BinOp):
        a, b = _eval(node.left, values), _eval(node.right, values)
        if isinstance(node.op, ast.Div):
            b = np.asarray(b, dtype=np.float64)
            return np.where(b == 0, np.nan, np.divide(a, np.where(b == 0, 1.0, b)))
        return _BINARY[type(node.op)](a, b)
    if isinstance(node, ast.UnaryOp):
        v = _eval(node.operand, values)
        return -v if isinstance(node.op, ast.USub) else v
    if isinstance(node, ast.Constant):
        return np.float64(node.value)
    if isinstance(node, ast.Name):
        return values[canonical(node.id)]
    if isinstance(node, ast.Call):
        return FUNCTIONS[node.func.id][2](*[_eval(a, values) for a in node.args])
    raise SpectralError(f"cannot evaluate {ast.unparse(node)!r}")  # never: parse() refused it


__all__ = ["Expression", "FUNCTIONS", "NAME_ALIASES", "canonical", "parse"]
