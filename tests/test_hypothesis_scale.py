"""``WORKBENCH_HYPOTHESIS_SCALE`` (tests/conftest.py) multiplies a property test's examples: its
own ``@settings(max_examples=...)`` and the default alike, once per test function."""

from types import SimpleNamespace

import pytest
from conftest import SCALE_ENV, _hypothesis_scale, _scale_examples
from hypothesis import given, settings
from hypothesis import strategies as st


def _counting(max_examples=None):
    calls = []

    def body(x):
        calls.append(x)

    prop = given(st.integers(0, 10**12))(body)
    if max_examples is not None:
        prop = settings(max_examples=max_examples, database=None, derandomize=True)(prop)
    else:
        prop = settings(database=None, derandomize=True)(prop)
    return prop, calls


def test_an_explicit_max_examples_is_multiplied_once_per_function():
    prop, calls = _counting(7)
    done = set()
    for _ in range(3):  # three items of one parametrized test share the function
        _scale_examples(SimpleNamespace(obj=prop), 3, done)
    prop()
    assert len(calls) == 21


def test_the_default_max_examples_is_multiplied_and_plain_functions_are_left_alone():
    prop, calls = _counting()
    _scale_examples(SimpleNamespace(obj=prop), 0.5, set())
    prop()
    assert len(calls) == settings().max_examples // 2

    def plain():
        pass

    _scale_examples(SimpleNamespace(obj=plain), 3, set())
    assert not hasattr(plain, "_hypothesis_internal_use_settings")


def test_the_scale_is_read_from_the_environment(monkeypatch):
    monkeypatch.delenv(SCALE_ENV, raising=False)
    assert _hypothesis_scale() == 1.0
    monkeypatch.setenv(SCALE_ENV, "20")
    assert _hypothesis_scale() == 20.0
    for bad in ("x", "0", "-2", "nan"):
        monkeypatch.setenv(SCALE_ENV, bad)
        with pytest.raises(pytest.UsageError):
            _hypothesis_scale()
