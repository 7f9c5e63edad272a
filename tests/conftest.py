"""Test-wide settings and fixtures.

* Property tests draw the same examples on every CI run (set CI=1).
* ``WORKBENCH_HYPOTHESIS_SCALE=K`` multiplies every property test's ``max_examples`` by ``K``
  (its own ``@settings`` included, which a loaded profile would not override): a one-off
  search for examples the everyday run has not met yet, not for CI. Give it a fresh example
  database so stored examples do not stand in for new ones, e.g.
  ``WORKBENCH_HYPOTHESIS_SCALE=20 HYPOTHESIS_STORAGE_DIRECTORY=$(mktemp -d) pytest -p
  no:cacheprovider tests/algo/test_x.py``; ``--hypothesis-show-statistics`` shows the examples run.
* ``ctx``: an offscreen GL context per test module, skipped with the reason where none can be
  made; a test using it is marked ``gl``.
* ``car``, ``car_deck``, ``d3plot_file``: the shared LS-DYNA car deck (as a fresh mesh, and as
  a file) and the shared d3plot, skipped with the reason where the shared data is absent; a
  test using one is marked ``shared_data``.
* ``experiment_run``: ``experiment_run(name, size)`` runs a registered experiment once per
  session at ``size`` ("tiny", or "quick" for the slow tests) and returns ``(rows, out_dir)``.
* Every run a test starts (in process or as a subprocess) records into a results store of the
  test session's own (``WORKBENCH_RESULTS``), never into ``figures/results``.
* Markers: ``slow`` (end-to-end experiment runs and cluster sweeps; ``pytest`` leaves them out,
  ``pytest -m "slow or not slow"`` runs everything), ``gl``, ``shared_data``.
"""

import os

import pytest
from hypothesis import settings

from workbench.data import CAR_DECK, D3PLOT, shared_file
from workbench.gl import GLUnavailable, create_context

settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

SHARED_FIXTURES = {"car", "car_deck", "d3plot_file"}
SCALE_ENV = "WORKBENCH_HYPOTHESIS_SCALE"


def _hypothesis_scale() -> float:
    """The factor ``WORKBENCH_HYPOTHESIS_SCALE`` asks for (1 where unset)."""
    text = os.environ.get(SCALE_ENV, "").strip()
    if not text:
        return 1.0
    try:
        scale = float(text)
    except ValueError:
        raise pytest.UsageError(f"{SCALE_ENV}={text!r} is not a number") from None
    if not scale > 0:
        raise pytest.UsageError(f"{SCALE_ENV}={text!r} must be positive")
    return scale


def _scale_examples(item, scale: float, done: set) -> None:
    """Give the property test of ``item`` ``scale`` times its ``max_examples``.

    ``@given`` reads its settings from the wrapper's ``_hypothesis_internal_use_settings`` at
    every call (``@settings`` above or below ``@given`` ends there too), so a child of those
    settings set there scales the test whatever set the count. The items of a parametrized test
    share one wrapper (a test method's items reach it through ``__func__``): each is scaled once.
    """
    from hypothesis import is_hypothesis_test

    obj = getattr(item, "obj", None)
    if obj is None or not is_hypothesis_test(obj):
        return
    fn = getattr(obj, "__func__", obj)
    if id(fn) in done:
        return
    done.add(id(fn))
    current = getattr(fn, "_hypothesis_internal_use_settings", None) or settings.default
    fn._hypothesis_internal_use_settings = settings(
        parent=current, max_examples=max(1, round(current.max_examples * scale)))


def pytest_addoption(parser):
    parser.addoption("--update-golden", action="store_true", default=False,
                     help="rewrite the golden reference images of tests/golden (and the "
                          "renderer they were made on) from this run's images")


@pytest.fixture(scope="session")
def update_golden(request):
    """Whether ``--update-golden`` asks the golden-image tests to rewrite their references."""
    return bool(request.config.getoption("--update-golden"))


@pytest.fixture(autouse=True, scope="session")
def session_results_store(tmp_path_factory):
    """The results store of the session: set as ``WORKBENCH_RESULTS`` for every test."""
    from workbench.results.store import RESULTS_ENV

    root = tmp_path_factory.mktemp("results")
    before = os.environ.get(RESULTS_ENV)
    os.environ[RESULTS_ENV] = str(root)
    yield root
    if before is None:
        os.environ.pop(RESULTS_ENV, None)
    else:
        os.environ[RESULTS_ENV] = before


def pytest_collection_modifyitems(items):
    scale = _hypothesis_scale()
    scaled = set()
    for item in items:
        if scale != 1.0:
            _scale_examples(item, scale, scaled)
        names = set(getattr(item, "fixturenames", ()))
        if "ctx" in names:
            item.add_marker(pytest.mark.gl)
        if names & SHARED_FIXTURES:
            item.add_marker(pytest.mark.shared_data)


@pytest.fixture(scope="module")
def ctx():
    try:
        return create_context()
    except GLUnavailable as exc:
        pytest.skip(str(exc))


def _shared(relative):
    path = shared_file(relative)
    if path is None:
        pytest.skip(f"shared data absent: {relative} (set WORKBENCH_DATA to the shared data "
                    f"folder)")
    return path


@pytest.fixture(scope="session")
def car_deck():
    """The path of the shared LS-DYNA car deck."""
    return _shared(CAR_DECK)


@pytest.fixture(scope="session")
def d3plot_file():
    """The path of the shared d3plot result."""
    return _shared(D3PLOT)


@pytest.fixture
def car(car_deck):
    """The shared car deck as an FE mesh of its own (read once per session; its arrays shared,
    its derived data and fields fresh for each test)."""
    from workbench.scene.builtin import fresh_scene

    return fresh_scene("car")


@pytest.fixture(scope="session")
def experiment_run(tmp_path_factory):
    """``run(name, size) -> (rows, out_dir)``: experiment ``name`` at ``size``, run once per
    session into a folder of its own (its tables and figures stay for every test that reads
    them)."""
    from workbench.experiment.registry import discover, run_experiment

    done = {}

    def run(name: str, size: str):
        if (name, size) not in done:
            discover()
            root = tmp_path_factory.mktemp(f"{name}-{size}")
            done[name, size] = run_experiment(name, figures_root=root, size=size)
        return done[name, size]

    return run
