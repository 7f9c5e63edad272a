"""Test-wide settings: property tests draw the same examples on every CI run (set CI=1); an
offscreen GL context per test module, skipped with the reason where none can be made."""

import os

import pytest
from hypothesis import settings

from workbench.gl import GLUnavailable, create_context

settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")


@pytest.fixture(scope="module")
def ctx():
    try:
        return create_context()
    except GLUnavailable as exc:
        pytest.skip(str(exc))
