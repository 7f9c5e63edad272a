"""The bounds of ``*PARAMETER_EXPRESSION`` evaluation and the refusal of undefined and
non-finite parameters in LS-DYNA keyword decks."""

from __future__ import annotations

import signal
from contextlib import contextmanager

import numpy as np
import pytest

from workbench.cli import main
from workbench.scene.readers import ParseError, ParseWarning
from workbench.scene.readers.keyword import read_keyword

GUARD_S = 3  # a read that runs longer than this fails the test instead of hanging it

GEOMETRY = [
    "*NODE",
    "     101             0.0             0.0             0.0",
    "     102            10.0             0.0             0.0",
    "     103            10.0            10.0             0.0",
    "     104             0.0            10.0             0.0",
    "*ELEMENT_SHELL",
    "       1       1     101     102     103     104",
    "*END",
]


class _TooSlow(Exception):
    pass


@contextmanager
def time_limit(seconds: float = GUARD_S):
    """Raise _TooSlow in the block after ``seconds`` (SIGALRM; the tests run in the main
    thread)."""
    def on_alarm(signum, frame):
        raise _TooSlow(f"no answer within {seconds} s")

    previous = signal.signal(signal.SIGALRM, on_alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def deck(tmp_path, parameters: list[str], thickness: str = "&t", name: str = "deck.k"):
    """A one-shell deck whose section thickness card is ``thickness``, after the
    ``parameters`` lines: those start at line 2, the thickness card is line
    ``len(parameters) + 7``."""
    path = tmp_path / name
    path.write_text("\n".join(["*KEYWORD", *parameters, "*PART", "p", "         1         1",
                               "*SECTION_SHELL", "         1", thickness, *GEOMETRY]) + "\n")
    return path


def expression(text: str) -> list[str]:
    return ["*PARAMETER_EXPRESSION", f"R t       {text}"]


def refused(path) -> ParseError:
    with time_limit(), pytest.raises(ParseError) as info:
        read_keyword(path)
    return info.value


def thickness_of(path) -> float:
    with time_limit():
        return float(read_keyword(path).element_fields["thickness"][0])


# --------------------------------------------------------------------------- bounds
def test_a_huge_power_is_refused_before_it_is_computed(tmp_path):
    error = refused(deck(tmp_path, expression("9**9**9")))
    assert error.line == 3 and "parameter 't'" in error.message
    assert "exponent too large" in error.message
    assert "9**9**9" in str(error) and str(error).startswith(str(tmp_path))


@pytest.mark.parametrize("text", ["10**309", "2^1100", "(-10)**400", "0.5**-1100"])
def test_powers_beyond_the_float_range_are_refused(tmp_path, text):
    assert "exponent too large" in refused(deck(tmp_path, expression(text))).message


def test_an_expression_of_100_000_terms_is_refused_not_a_recursion_error(tmp_path):
    error = refused(deck(tmp_path, expression("+".join(["1"] * 100_000))))
    assert error.line == 3 and "parameter 't'" in error.message
    assert "expression too long: 100 000 terms, at most 1 000" in error.message
    assert len(str(error)) < 400  # the 200 000-character card is shown shortened


def test_an_expression_of_many_characters_is_refused(tmp_path):
    error = refused(deck(tmp_path, expression("1" + " " * 20_000 + "+ 1")))
    assert "expression too long: 20 00" in error.message and "characters" in error.message


@pytest.mark.parametrize("text, bound", [
    ("(" * 4000 + "1" + ")" * 4000, "4 000 levels of parentheses, at most 32"),
    ("(" * 33 + "1" + ")" * 33, "33 levels of parentheses, at most 32"),
    ("-" * 900 + "1", "more than 32 levels"),
    ("sqrt(" * 40 + "1" + ")" * 40, "40 levels of parentheses"),
    ("**".join(["1"] * 900), "more than 32 levels"),
])
def test_deep_nesting_is_refused(tmp_path, text, bound):
    error = refused(deck(tmp_path, expression(text)))
    assert error.line == 3 and "expression nested too deeply" in error.message
    assert bound in error.message


def test_nesting_within_the_bound_is_evaluated(tmp_path):
    assert thickness_of(deck(tmp_path, expression("(" * 30 + "2.5" + ")" * 30))) == 2.5


@pytest.mark.parametrize("text", ["1e200*1e200", "1e999", "-1e308-1e308", "exp(1000)",
                                  "cosh(800)"])
def test_a_value_that_is_not_finite_is_refused(tmp_path, text):
    error = refused(deck(tmp_path, expression(text)))
    assert error.line == 3 and "parameter 't'" in error.message
    assert "not finite" in error.message or "range" in error.message


def test_a_long_chain_of_parameters_needs_no_recursion(tmp_path):
    chain = [f"R p{i:<7d} p{i + 1}+1" for i in range(3000)]
    path = deck(tmp_path, ["*PARAMETER_EXPRESSION", *chain, "*PARAMETER", "R p3000   1.0",
                           "*PARAMETER_EXPRESSION", "R t       p0/1000"])
    assert thickness_of(path) == pytest.approx(3.001)


@pytest.mark.parametrize("text", ["__import__('os').system('true')", "(1).__class__",
                                  "[1, 2]", "a if 1 else 2", "lambda: 1", "open(1)"])
def test_what_is_not_arithmetic_is_refused_without_python_eval(tmp_path, text):
    error = refused(deck(tmp_path, ["*PARAMETER", "R a       1.0", *expression(text)]))
    assert error.line == 5 and "cannot evaluate the expression" in error.message


# --------------------------------------------------------------------------- undefined, NaN
def warned(path) -> ParseWarning:
    """The one ParseWarning of reading ``path``, whose geometry is read, thickness missing."""
    with time_limit(), pytest.warns(ParseWarning) as said:
        mesh = read_keyword(path)
    assert len(said) == 1 and mesh.n_elements == 1
    assert np.isnan(mesh.element_fields["thickness"]).all()
    return said[0].message


def test_an_undefined_thickness_parameter_is_warned_with_its_name_and_line(tmp_path):
    """An include read without the master deck that defines its thickness parameter: the
    geometry is read; one warning names the parameter, its line, what is defined, the part."""
    card = f"{'R alpha':<10}{'1.0':<10}{'R beta':<10}2.0"
    path = deck(tmp_path, ["*PARAMETER", card], thickness="&gamma")
    warning = warned(path)
    assert warning.line == 9 and warning.keyword == "SECTION_SHELL"
    assert "parameter 'gamma' is not defined" in warning.message
    assert "defined: 'alpha', 'beta'" in warning.message
    assert "the shells of part 1 have no thickness" in warning.message


def test_an_undefined_parameter_lists_a_few_of_those_defined(tmp_path):
    names = [f"R q{i:<8d}{i}.0" for i in range(12)]
    warning = warned(deck(tmp_path, ["*PARAMETER", *names], thickness="&t"))
    assert "defined: 'q0', 'q1', 'q2', 'q3', 'q4' and 7 more" in warning.message


def test_an_undefined_parameter_in_an_expression_is_refused_at_its_line(tmp_path):
    error = refused(deck(tmp_path, ["*PARAMETER", "R a       1.0", *expression("a + b")]))
    assert error.line == 5 and error.keyword == "PARAMETER_EXPRESSION"
    assert "parameter 't'" in error.message and "'b' is not defined" in error.message


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "NaN"])
def test_a_parameter_that_is_not_finite_is_refused_where_it_is_defined(tmp_path, value):
    error = refused(deck(tmp_path, ["*PARAMETER", "R a       1.0", f"R t       {value}"]))
    assert error.line == 4 and error.keyword == "PARAMETER"
    assert f"expected a finite number for parameter 't', got '{value}'" in error.message


@pytest.mark.parametrize("value", ["nan", "inf", "-Infinity"])
def test_a_section_thickness_that_is_not_finite_is_refused(tmp_path, value):
    error = refused(deck(tmp_path, [], thickness=value))
    assert error.line == 7 and error.keyword == "SECTION_SHELL"
    assert f"expected a finite thickness, got '{value}'" in error.message


# --------------------------------------------------------------------------- what still reads
@pytest.mark.parametrize("text, expected", [
    ("2*a+0.5", 4.5),
    ("a^2/(a-1) + 2.5", 6.5),
    ("2**-1 + 3**2", 9.5),
    ("-2**2 + 10", 6.0),  # the power binds tighter than the sign, as in Python
    ("2^3^2 / 128", 4.0),  # right to left: 2^9
    ("sqrt(16)*max(1, a, 0.5) - abs(-1)", 7.0),
    ("(1 + (2 * (a + 1 - 1))) / 2.5", 2.0),
    ("sin(pi/2) + cos(0) + exp(0) + log(1) + 1.5e0", 4.5),
    ("&a*1.5D0", 3.0),
    ("mod(7, 4) + int(2.7) + nint(2.6)", 8.0),
    ("sign(2, -1) + 5", 3.0),
    ("10**308 / 1e308", 1.0),
    ("+a - -a", 4.0),
])
def test_ordinary_expressions_give_the_thickness(tmp_path, text, expected):
    path = deck(tmp_path, ["*PARAMETER", "R a       2.0", *expression(text)])
    assert thickness_of(path) == pytest.approx(expected)


def test_parameters_and_sections_that_are_finite_still_read(tmp_path):
    assert thickness_of(deck(tmp_path, ["*PARAMETER", "R T       1.25"], "-&t")) == -1.25
    assert thickness_of(deck(tmp_path, [], "0.75", name="plain.k")) == 0.75


# --------------------------------------------------------------------------- the command
@pytest.mark.parametrize("text, message", [
    ("9**9**9", "exponent too large"),
    ("+".join(["1"] * 100_000), "expression too long: 100 000 terms, at most 1 000"),
])
def test_the_command_refuses_a_bad_expression_in_one_line(tmp_path, capsys, text, message):
    path = deck(tmp_path, expression(text))
    with time_limit():
        status = main(["render", str(path), "-o", str(tmp_path / "x.png")])
    err = capsys.readouterr().err
    assert status == 2 and not (tmp_path / "x.png").exists()
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert message in err and f"{path}:3:" in err
