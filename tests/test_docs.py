"""The documentation: the Sphinx build (guide pages and the API reference from the docstrings)
passes with warnings as errors, a broken reference into the package fails it, the command-line
page names every subcommand, and the README stays short with its results markers and its two
commands."""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
TOOLS = ("sphinx", "myst_parser", "furo", "sphinxarg")


def _require_sphinx() -> None:
    """Skip, naming the missing package, where the docs extra is not installed."""
    for module in TOOLS:
        pytest.importorskip(module, reason=f"{module} is not installed (pip install -e '.[docs]')")


def sphinx_build(source: Path, out: Path, extra_path: Path | None = None,
                 conf: Path = DOCS) -> subprocess.CompletedProcess:
    """``sphinx -W --keep-going -b html`` of ``source`` with the configuration in ``conf``,
    into ``out``; ``extra_path`` goes on the PYTHONPATH."""
    env = dict(os.environ)
    if extra_path is not None:
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(extra_path),
                                                          env.get("PYTHONPATH")]))
    return subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
         "-c", str(conf), "-d", str(out / "doctrees"), str(source), str(out / "html")],
        capture_output=True, text=True, env=env, timeout=1800)


def probe_docs(tmp_path: Path, reference: str) -> subprocess.CompletedProcess:
    """Build a one-page project with the docs' configuration whose page documents a module
    (written here) with ``reference`` in its docstring."""
    source = tmp_path / "src"
    source.mkdir(parents=True)
    shutil.copytree(DOCS / "_templates", source / "_templates")
    shutil.copy(DOCS / "conf.py", source / "conf.py")
    modules = tmp_path / "modules"
    modules.mkdir(parents=True)
    (modules / "docs_probe.py").write_text(
        f'"""A probe module.\n\nSee {reference}.\n"""\n', encoding="utf-8")
    (source / "index.rst").write_text(
        "Probe\n=====\n\n.. automodule:: docs_probe\n\n"
        ".. autoclass:: workbench.paths.style.Style\n   :no-members:\n", encoding="utf-8")
    return sphinx_build(source, tmp_path / "out", extra_path=modules, conf=source)


@pytest.mark.slow
def test_the_docs_build_without_a_warning(tmp_path):
    _require_sphinx()
    done = sphinx_build(DOCS, tmp_path)
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-8000:]
    html = tmp_path / "html"
    for page in ("index", "cli", "python", "extending", "architecture", "api"):
        assert (html / f"{page}.html").is_file(), page
    # every package has its page in the API reference
    for package in sorted(p.parent.name for p in (ROOT / "workbench").glob("*/__init__.py")):
        assert (html / "api" / f"workbench.{package}.html").is_file(), package
    # the README is the front page, and its link to the CLI page goes to that page
    front = (html / "index.html").read_text(encoding="utf-8")
    assert "Two commands" in front and 'href="cli.html"' in front


def test_a_broken_reference_into_the_package_fails_the_build(tmp_path):
    _require_sphinx()
    broken = probe_docs(tmp_path / "broken", ":func:`workbench.nope`")
    assert broken.returncode != 0
    assert "workbench.nope" in broken.stderr
    # the same page with a reference that exists (through a package's re-export) builds
    good = probe_docs(tmp_path / "good", ":class:`workbench.paths.Style`")
    assert good.returncode == 0, good.stderr[-4000:]


def test_the_command_line_page_names_every_subcommand():
    from workbench.cli import build_parser

    parser = build_parser()
    (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    page = (DOCS / "cli.md").read_text(encoding="utf-8")
    examples = set(re.findall(r"^\.venv/bin/workbench (\w+)", page, flags=re.M))
    assert set(sub.choices) <= examples, sorted(set(sub.choices) - examples)
    assert len(sub.choices) >= 14


def test_the_readme_is_short_and_keeps_its_markers_and_two_commands():
    from workbench.experiment.report import BEGIN, END

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 160
    assert text.count(BEGIN) == 1 and text.count(END) == 1 and text.index(BEGIN) < text.index(END)
    block = re.search(r"## Two commands\n.*?```bash\n(.*?)```", text, flags=re.S).group(1)
    assert block.splitlines() == [
        "./install.sh && .venv/bin/workbench reproduce --quick    # install everything, run "
        "every experiment (small sizes)",
        ".venv/bin/python -m pytest                                # run the tests (the fast "
        "suite: a few minutes)"]
    for page in ("cli", "python", "extending", "architecture", "results", "history"):
        assert f"(docs/{page}.md)" in text, page
    for image in re.findall(r"!\[[^]]*\]\(([^)]+)\)", text):
        assert (ROOT / image).is_file() and (ROOT / image).stat().st_size < 200_000, image


def test_the_readme_headlines_are_short_and_from_full_size_runs():
    from workbench.experiment.declare import HEADLINE_CHARS
    from workbench.experiment.report import BEGIN, END, declared_headlines

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text[text.index(BEGIN):text.index(END)]
    rows = [[c.strip() for c in line.strip("|").split("|")]
            for line in section.splitlines() if line.startswith("| ") and "`" in line]
    assert {row[1].strip("`") for row in rows} == set(declared_headlines())
    for _paper, experiment, headline, ran_on in rows:
        assert len(headline) <= HEADLINE_CHARS, experiment
        assert ran_on.startswith("full, "), (experiment, ran_on)


def test_the_files_the_pages_name_exist():
    pages = [ROOT / "README.md", *(DOCS / f"{p}.md" for p in
                                   ("cli", "python", "extending", "architecture"))]
    named = re.compile(r"`((?:workbench|tests|benchmarks|sweeps|docs)/[\w/.-]*"
                       r"\.(?:py|toml|md|ipynb))`")
    missing = [(page.name, path) for page in pages
               for path in named.findall(page.read_text(encoding="utf-8"))
               if not (ROOT / path).exists()]
    assert not missing
    assert sum(len(named.findall(page.read_text(encoding="utf-8"))) for page in pages) > 20
