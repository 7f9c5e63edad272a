"""``*PARAMETER`` and ``*PARAMETER_EXPRESSION`` of an LS-DYNA keyword deck, and the ``&name``
references of section thicknesses to them.

A ``*PARAMETER`` card holds pairs of a name (prefixed R, I or C for its type; R when none)
and a value; ``*PARAMETER_EXPRESSION`` holds a name and an arithmetic expression, evaluated
when the parameter is first used (:class:`_Expression`). Names are case-insensitive. Refused
with :class:`~workbench.scene.readers.errors.ParseError` (file, line, parameter): a value that is
no finite number, an expression that is not arithmetic of numbers and parameters, one beyond
the bounds of :class:`_Expression` (length, nesting, exponent, time) or whose value is not
finite, a parameter defined through itself, a text parameter used as a number, and a parameter
that no card of the deck or its includes defines (an include read on its own cannot use the
parameters of the deck that includes it).
"""

from __future__ import annotations

import math
import re
import time
from dataclasses import dataclass, field

from .cards import _TEN, _Block, _card_fields, _convert, _shown, _Source, field_width
from .errors import ParseError

_FUNCTIONS = {"sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin,
              "acos": math.acos, "atan": math.atan, "atan2": math.atan2, "sqrt": math.sqrt,
              "exp": math.exp, "log": math.log, "log10": math.log10, "abs": abs, "min": min,
              "max": max, "mod": math.fmod, "int": lambda x: float(math.trunc(x)),
              "nint": lambda x: float(round(x)), "sign": math.copysign,
              "sinh": math.sinh, "cosh": math.cosh, "tanh": math.tanh}

MAX_TERMS = 1_000  # numbers and names in one expression
MAX_CHARACTERS = 10_000
MAX_DEPTH = 32  # levels of parentheses, function calls, signs and powers
MAX_DECADES = 308  # a power whose result would exceed about 10**308 (the float range)
MAX_SECONDS = 1.0  # evaluating one expression

_OPERAND = re.compile(r"(?:\d+\.?\d*|\.\d+)(?:[eEdD][+-]?\d+)?|[A-Za-z_][A-Za-z0-9_]*")
_TOKEN = re.compile(r"\s*(?:(?P<number>(?:\d+\.?\d*|\.\d+)(?:[eEdD][+-]?\d+)?)"
                    r"|&?(?P<name>[A-Za-z_][A-Za-z0-9_]*)|(?P<op>\*\*|[-+*/^(),]))")
_SHOWN = 80  # characters of a long expression shown in a message


def _count(n: int) -> str:
    return f"{n:,}".replace(",", " ")


def _abridged(text: str) -> str:
    if len(text) <= _SHOWN:
        return text
    return f"{text[:_SHOWN]}… ({_count(len(text))} characters)"


class _Refused(Exception):
    """An expression the parser refuses; ``args[0]`` is the whole message."""


class _Parser:
    """Recursive descent over the tokens of an expression, into a postfix program of steps
    ``("number", value, text)``, ``("name", name)``, ``("negate",)``, ``("binary", op)`` and
    ``("call", function, n_arguments)``. Precedence as in Python: ``**`` (or ``^``, right to
    left, binding tighter than a sign on its left) over ``* /`` over ``+ -``. Recursion goes one
    level deeper only at parentheses, calls, signs and exponents, at most :data:`MAX_DEPTH`."""

    def __init__(self, tokens: list[tuple[str, str]]):
        self.tokens, self.at, self.depth, self.program = tokens, 0, 0, []

    def parse(self) -> list[tuple]:
        self.sum()
        if self.at < len(self.tokens):
            raise _Refused(f"expected an operator, got {self.tokens[self.at][1]!r}")
        return self.program

    def peek(self) -> str | None:
        return self.tokens[self.at][1] if self.at < len(self.tokens) else None

    def take(self, expected: str | None = None) -> tuple[str, str]:
        if self.at >= len(self.tokens):
            raise _Refused("the expression ends early" if expected is None
                           else f"expected {expected!r} at the end")
        token = self.tokens[self.at]
        if expected is not None and token[1] != expected:
            raise _Refused(f"expected {expected!r}, got {token[1]!r}")
        self.at += 1
        return token

    def deeper(self, part) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise _Refused(f"expression nested too deeply: more than {MAX_DEPTH} levels of "
                           f"parentheses, calls, signs and powers")
        part()
        self.depth -= 1

    def sum(self) -> None:
        self.product()
        while self.peek() in ("+", "-"):
            op = self.take()[1]
            self.product()
            self.program.append(("binary", op))

    def product(self) -> None:
        self.signed()
        while self.peek() in ("*", "/"):
            op = self.take()[1]
            self.signed()
            self.program.append(("binary", op))

    def signed(self) -> None:
        if self.peek() in ("+", "-"):
            op = self.take()[1]
            self.deeper(self.signed)
            if op == "-":
                self.program.append(("negate",))
        else:
            self.power()

    def power(self) -> None:
        self.atom()
        if self.peek() in ("**", "^"):
            self.take()
            self.deeper(self.signed)
            self.program.append(("binary", "**"))

    def atom(self) -> None:
        kind, text = self.take()
        if kind == "number":
            self.program.append(("number", float(text.replace("D", "E").replace("d", "e")),
                                 text))
        elif kind == "name" and self.peek() == "(":
            function = text.lower()
            if function not in _FUNCTIONS:
                raise _Refused(f"{text!r} is no function of an expression (known: "
                               f"{', '.join(_FUNCTIONS)})")
            self.take()
            arguments = []

            def listed():
                self.sum()
                arguments.append(1)
                while self.peek() == ",":
                    self.take()
                    self.sum()
                    arguments.append(1)

            self.deeper(listed)
            self.take(")")
            self.program.append(("call", function, len(arguments)))
        elif kind == "name":
            self.program.append(("number", math.pi, text) if text.lower() == "pi"
                                else ("name", text))
        elif text == "(":
            self.deeper(self.sum)
            self.take(")")
        else:
            raise _Refused(f"expected a number, a parameter or '(', got {text!r}")


@dataclass
class _Expression:
    """A ``*PARAMETER_EXPRESSION`` right-hand side: arithmetic (+ − * / ** or ^, parentheses)
    of numbers, other parameters (by name, or ``&name``), ``pi`` and the functions of
    :data:`_FUNCTIONS`; parsed by :class:`_Parser`, never by Python's ``eval``.

    Refused with ParseError naming file, line and parameter: more than :data:`MAX_TERMS`
    numbers and names or :data:`MAX_CHARACTERS` characters, nesting deeper than
    :data:`MAX_DEPTH`, a power whose result would exceed about 1e308 (:data:`MAX_DECADES`;
    checked before it is computed), a step whose value is not finite, an evaluation longer
    than :data:`MAX_SECONDS`, and anything else that does not evaluate (an unknown function,
    division by zero, a domain error)."""

    name: str
    text: str
    src: _Source
    row: int
    _program: list[tuple] | None = field(default=None, repr=False)

    def fail(self, what: str) -> ParseError:
        """A ParseError at this expression's line about parameter ``name``."""
        return ParseError(self.src.path, f"parameter {self.name!r}: {what}", line=self.row + 1,
                          card=_abridged(self.src.card(self.row)),
                          keyword="PARAMETER_EXPRESSION")

    @property
    def program(self) -> list[tuple]:
        """The postfix steps of :class:`_Parser`, the bounds on length and nesting checked."""
        if self._program is None:
            self._program = self._compile()
        return self._program

    @property
    def uses(self) -> list[str]:
        """The names of the parameters the expression uses, as written."""
        return [step[1] for step in self.program if step[0] == "name"]

    def _compile(self) -> list[tuple]:
        text = self.text
        terms = len(_OPERAND.findall(text))
        if terms > MAX_TERMS:
            raise self.fail(f"expression too long: {_count(terms)} terms, at most "
                            f"{_count(MAX_TERMS)}")
        if len(text) > MAX_CHARACTERS:
            raise self.fail(f"expression too long: {_count(len(text))} characters, at most "
                            f"{_count(MAX_CHARACTERS)}")
        level = deepest = 0
        for character in text:
            if character == "(":
                level += 1
                deepest = max(deepest, level)
            elif character == ")":
                level -= 1
        if deepest > MAX_DEPTH:
            raise self.fail(f"expression nested too deeply: {_count(deepest)} levels of "
                            f"parentheses, at most {MAX_DEPTH}")
        tokens, at = [], 0
        while at < len(text):
            match = _TOKEN.match(text, at)
            if match is None:
                if not text[at:].strip():
                    break
                raise self.fail(f"cannot evaluate the expression {_abridged(text)!r}: "
                                f"unexpected {text[at:].lstrip()[0]!r}")
            tokens.append((match.lastgroup, match.group(match.lastgroup)))
            at = match.end()
        try:
            return _Parser(tokens).parse()
        except _Refused as refused:
            message = refused.args[0]
            if not message.startswith("expression nested"):
                message = f"cannot evaluate the expression {_abridged(text)!r}: {message}"
            raise self.fail(message) from None

    def evaluate(self, lookup) -> float:
        """The finite float value, each parameter name resolved by ``lookup(name)`` (a float,
        or a text for a text parameter); ParseError as the class says."""
        deadline = time.monotonic() + MAX_SECONDS
        stack: list[float] = []
        try:
            for step in self.program:
                if time.monotonic() > deadline:
                    raise self.fail(f"evaluating the expression took more than "
                                    f"{MAX_SECONDS:g} s")
                kind = step[0]
                if kind == "number":
                    value, shown = step[1], step[2]
                elif kind == "name":
                    value, shown = lookup(step[1]), f"parameter {step[1]!r}"
                    if not isinstance(value, float):
                        raise self.fail(f"parameter {step[1]!r} is a text, not a number")
                elif kind == "negate":
                    value, shown = -stack.pop(), "a negation"
                elif kind == "call":
                    arguments = stack[len(stack) - step[2]:]
                    del stack[len(stack) - step[2]:]
                    value = float(_FUNCTIONS[step[1]](*arguments))
                    shown = f"{step[1]}({', '.join(f'{a:g}' for a in arguments)})"
                else:
                    right, left = stack.pop(), stack.pop()
                    value = self._binary(step[1], left, right)
                    shown = f"{left:g} {step[1]} {right:g}"
                if not math.isfinite(value):
                    raise self.fail(f"the value is not finite: {shown} is {value}")
                stack.append(value)
        except ParseError:
            raise
        except (ValueError, TypeError, ZeroDivisionError, OverflowError) as exc:
            raise self.fail(f"cannot evaluate the expression {_abridged(self.text)!r}: "
                            f"{exc}") from None
        return stack[0]

    def _binary(self, op: str, left: float, right: float) -> float:
        if op == "+":
            return left + right
        if op == "-":
            return left - right
        if op == "*":
            return left * right
        if op == "/":
            return left / right
        if left != 0.0 and abs(left) != 1.0:
            decades = right * math.log10(abs(left))
            if decades > MAX_DECADES:
                size = f"about 1e{decades:.0f}" if decades < 1e15 else "far beyond that"
                raise self.fail(f"exponent too large: {left:g} ** {right:g} is {size}, at "
                                f"most about 1e{MAX_DECADES}")
        return math.pow(left, right)


class _Parameters:
    """The parameters a deck defines, by name: a float, a text, or an :class:`_Expression`
    not yet evaluated."""

    def __init__(self):
        self.values: dict[str, object] = {}
        self.folded: dict[str, str] = {}  # lower-case name -> name as defined

    def read(self, block: _Block, expressions: bool) -> None:
        """Add the parameters of a ``*PARAMETER`` block, or with ``expressions`` of a
        ``*PARAMETER_EXPRESSION`` block; ParseError at a value that is no finite number."""
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
                names, values = [head], [expression]
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
                if expressions:  # evaluated when used
                    value = _Expression(name, value.decode("utf-8", "replace").strip(),
                                        block.src, row)
                elif kind == "C":
                    value = value.decode("utf-8", "replace").strip()
                else:
                    text = value
                    try:
                        value = _convert(text, "f")
                    except ValueError:
                        raise block.error(f"expected a number for parameter {name!r}, got "
                                          f"{_shown(text)!r}", row) from None
                    if not math.isfinite(value):
                        raise block.error(f"expected a finite number for parameter {name!r}, "
                                          f"got {_shown(text)!r}", row)
                self.values[name] = value
                self.folded[name.lower()] = name

    def thickness(self, text: bytes, src: _Source, row: int) -> float:
        """A section thickness field (mm): a finite number or a (signed) ``&name`` reference,
        evaluated when its parameter is an expression; ParseError naming file and line for
        anything else, a parameter defined nowhere included."""
        text = text.strip()
        sign = -1.0 if text.startswith(b"-") else 1.0
        if text.lstrip(b"+-").startswith(b"&"):
            name = text.lstrip(b"+-")[1:].decode("utf-8", "replace").strip()
            if not name:
                raise src.error("expected a parameter name after '&'", row, "SECTION_SHELL")
            return sign * self.value(name, src, row)
        try:
            number = _convert(text, "f")
        except ValueError:
            raise src.error(f"expected a thickness, got {_shown(text)!r}", row,
                            "SECTION_SHELL") from None
        if not math.isfinite(number):
            raise src.error(f"expected a finite thickness, got {_shown(text)!r}", row,
                            "SECTION_SHELL")
        return number

    def undefined(self, text: bytes) -> str | None:
        """The parameter name of a (signed) ``&name`` thickness field whose parameter is
        defined nowhere in the deck and its includes; None for anything else."""
        text = text.strip().lstrip(b"+-")
        if not text.startswith(b"&"):
            return None
        name = text[1:].decode("utf-8", "replace").strip()
        return name if name and self._key(name) is None else None

    def value(self, name: str, src: _Source, row: int) -> float:
        """The number parameter ``name`` stands for (names are case-insensitive), evaluating
        ``*PARAMETER_EXPRESSION`` arithmetic; ParseError at line ``row`` of ``src`` for a name
        defined nowhere or a text parameter, at the expression's line for a bad expression or
        a cycle."""
        key = self._key(name)
        if key is None:
            raise src.error(self._undefined(name), row, "SECTION_SHELL")
        if isinstance(self.values[key], _Expression):
            self._evaluate(key)
        value = self.values[key]
        if not isinstance(value, float):
            raise src.error(f"parameter {key!r} is a text, not a number", row, "SECTION_SHELL")
        return value

    def _key(self, name: str) -> str | None:
        if name in self.values:
            return name
        return self.folded.get(name.lower())

    def undefined_message(self, name: str) -> str:
        """``parameter 'name' is not defined by *PARAMETER in this deck or its includes
        (defined: ...)``."""
        return self._undefined(name)

    def _undefined(self, name: str) -> str:
        defined = list(self.values)
        if not defined:
            known = "it defines no parameter"
        else:
            known = "defined: " + ", ".join(repr(n) for n in defined[:5])
            if len(defined) > 5:
                known += f" and {_count(len(defined) - 5)} more"
        return (f"parameter {name!r} is not defined by *PARAMETER in this deck or its "
                f"includes ({known})")

    def _evaluate(self, root: str) -> None:
        """Replace the expression of ``root``, and first those of the parameters it uses,
        by their values: depth first with an explicit stack, so that a long chain of
        parameters defined through parameters needs no recursion."""
        path = [root]  # each waits for the parameters its expression uses
        on_path = {root}
        progress = [0]  # how many of its uses are resolved
        while path:
            name = path[-1]
            expression = self.values[name]
            uses = expression.uses
            while progress[-1] < len(uses):
                used = uses[progress[-1]]
                key = self._key(used)
                if key is None:
                    raise expression.fail(self._undefined(used))
                if isinstance(self.values[key], _Expression):
                    if key in on_path:
                        cycle = self.values[key]
                        raise cycle.src.error(
                            f"parameter {key!r} is defined through itself: "
                            f"{' -> '.join((*path[path.index(key):], key))}", cycle.row,
                            "PARAMETER_EXPRESSION")
                    break
                progress[-1] += 1
            if progress[-1] < len(uses):
                path.append(key)
                on_path.add(key)
                progress.append(0)
                continue
            self.values[name] = expression.evaluate(lambda n: self.values[self._key(n)])
            on_path.discard(path.pop())
            progress.pop()
