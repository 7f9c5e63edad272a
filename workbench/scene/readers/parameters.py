"""``*PARAMETER`` and ``*PARAMETER_EXPRESSION`` of an LS-DYNA keyword deck, and the ``&name``
references of section thicknesses to them.

A ``*PARAMETER`` card holds pairs of a name (prefixed R, I or C for its type; R when none)
and a value; ``*PARAMETER_EXPRESSION`` holds a name and an arithmetic expression, evaluated
when the parameter is first used (:class:`_Expression`). Names are case-insensitive. Refused
with :class:`~workbench.scene.readers.errors.ParseError`: a value that is no number, an
expression that is not arithmetic of numbers and parameters, a parameter defined through
itself, and a text parameter used as a number. A parameter that no card of the deck defines
is a missing thickness (NaN) with a :class:`~workbench.scene.readers.errors.ParseWarning`.
"""

from __future__ import annotations

import ast
import math
import operator
import warnings
from dataclasses import dataclass

from .cards import _TEN, _Block, _card_fields, _convert, _shown, _Source, field_width
from .errors import ParseError, ParseWarning


class _Undefined(LookupError):
    """A parameter that no *PARAMETER of the deck defines (its name in ``args[0]``)."""


_FUNCTIONS = {"sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin,
              "acos": math.acos, "atan": math.atan, "atan2": math.atan2, "sqrt": math.sqrt,
              "exp": math.exp, "log": math.log, "log10": math.log10, "abs": abs, "min": min,
              "max": max, "mod": math.fmod, "int": lambda x: float(math.trunc(x)),
              "nint": lambda x: float(round(x)), "sign": math.copysign,
              "sinh": math.sinh, "cosh": math.cosh, "tanh": math.tanh}
_OPERATORS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
              ast.Div: operator.truediv, ast.Pow: operator.pow, ast.USub: operator.neg,
              ast.UAdd: operator.pos}


@dataclass
class _Expression:
    """A ``*PARAMETER_EXPRESSION`` right-hand side: arithmetic (+ − * / ** or ^) of numbers,
    other parameters (by name, or ``&name``) and the functions of :data:`_FUNCTIONS`."""

    text: str
    src: _Source
    row: int

    def evaluate(self, lookup) -> float:
        """The float value, names resolved by ``lookup(name)``; ParseError for anything else
        (unknown functions, text, division by zero), naming the expression's line."""
        source = self.text.replace("&", "").replace("^", "**")
        try:
            tree = ast.parse(source, mode="eval")
            return float(self._value(tree.body, lookup))
        except _Undefined:
            raise
        except ParseError:
            raise
        except (SyntaxError, ValueError, TypeError, ZeroDivisionError, OverflowError) as exc:
            raise self.src.error(f"cannot evaluate the expression {self.text!r}: {exc}",
                                 self.row, "PARAMETER_EXPRESSION") from None

    def _value(self, node, lookup):
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
            return node.value
        if isinstance(node, ast.Name):
            if node.id.lower() == "pi":
                return math.pi
            return lookup(node.id)
        if isinstance(node, ast.BinOp) and type(node.op) in _OPERATORS:
            return _OPERATORS[type(node.op)](self._value(node.left, lookup),
                                             self._value(node.right, lookup))
        if isinstance(node, ast.UnaryOp) and type(node.op) in _OPERATORS:
            return _OPERATORS[type(node.op)](self._value(node.operand, lookup))
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
                and node.func.id.lower() in _FUNCTIONS and not node.keywords:
            return _FUNCTIONS[node.func.id.lower()](*(self._value(a, lookup) for a in node.args))
        raise ValueError(f"{ast.unparse(node)!r} is not arithmetic of numbers and parameters")



class _Parameters:
    """The parameters a deck defines, by name: a float, a text, or an :class:`_Expression`
    not yet evaluated."""

    def __init__(self):
        self.values: dict[str, object] = {}

    def read(self, block: _Block, expressions: bool) -> None:
        """Add the parameters of a ``*PARAMETER`` block, or with ``expressions`` of a
        ``*PARAMETER_EXPRESSION`` block; ParseError at a value that is no number."""
        for row in block.rows.tolist():
            line = block.src.lines[row]
            if not line.strip():
                continue
            if expressions:  # a name, then the expression (which may hold commas itself)
                if b"," in line[:field_width(10, block.fmt)]:
                    head, expression = line.split(b",", 1)
                else:
                    width = field_width(10, block.fmt)
                    head, expression = line[:width], line[width:]
                names = [head]
                values = [_Expression(expression.decode("utf-8", "replace").strip(),
                                      block.src, row)]
            else:
                texts = _card_fields(line, _TEN, block.fmt)
                names, values = texts[0::2], texts[1::2]
            for name, value in zip(names, values):
                name = name.decode("utf-8", "replace").strip()
                if not name:
                    continue
                kind = name[0].upper()
                if kind in "RIC" and len(name) > 1:
                    name = name[1:].strip()
                else:
                    kind = "R"
                if isinstance(value, _Expression):
                    self.values[name] = value  # evaluated when used
                elif kind == "C":
                    self.values[name] = value.decode("utf-8", "replace").strip()
                else:
                    try:
                        self.values[name] = _convert(value, "f")
                    except ValueError:
                        raise block.error(f"expected a number for parameter {name!r}, got "
                                          f"{_shown(value)!r}", row) from None

    def thickness(self, text: bytes, src: _Source, row: int) -> float:
        """A section thickness field: a number or a (signed) ``&name`` reference, evaluated
        when its parameter is an expression. A parameter defined nowhere (an include read on its
        own, whose including deck defines it) is NaN with a :class:`ParseWarning` naming file,
        line and parameter: the geometry is still drawn, the thickness is missing."""
        text = text.strip()
        sign = -1.0 if text.startswith(b"-") else 1.0
        if text.lstrip(b"+-").startswith(b"&"):
            name = text.lstrip(b"+-")[1:].decode("utf-8", "replace").strip()
            try:
                value = self.value(name, src, row, ())
            except _Undefined as undefined:
                warnings.warn(ParseWarning(src.path, f"parameter {undefined.args[0]!r} is not "
                                           f"defined by *PARAMETER in this deck or its includes: "
                                           f"the thickness is missing", row + 1,
                                           "SECTION_SHELL"), stacklevel=2)
                return float("nan")
            return sign * value
        try:
            return _convert(text, "f")
        except ValueError:
            raise src.error(f"expected a thickness, got {_shown(text)!r}", row,
                            "SECTION_SHELL") from None

    def value(self, name: str, src: _Source, row: int, chain: tuple) -> float:
        """The number parameter ``name`` stands for (names are case-insensitive), evaluating
        ``*PARAMETER_EXPRESSION`` arithmetic; _Undefined for a name defined nowhere, ParseError
        for a text parameter, a bad expression or a cycle."""
        if name not in self.values:
            folded = {k.lower(): k for k in self.values}
            if name.lower() not in folded:
                raise _Undefined(name)
            name = folded[name.lower()]
        value = self.values[name]
        if isinstance(value, _Expression):
            if name in chain:
                raise value.src.error(f"parameter {name!r} is defined through itself: "
                                      f"{' -> '.join((*chain, name))}", value.row,
                                      "PARAMETER_EXPRESSION")
            value = value.evaluate(lambda n: self.value(n, src, row, (*chain, name)))
            self.values[name] = value
        if not isinstance(value, float):
            raise src.error(f"parameter {name!r} is not a number", row, "SECTION_SHELL")
        return value

