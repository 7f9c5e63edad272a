"""The static results site from synthetic stores, checked in its HTML: the index lists every
experiment with its claims, run, machine, commit and size; each experiment's page holds every
stored table (a sortable table with a head, all its rows and its legend), a Pareto plot where
the table has a time and an error, and its figures copied and linked to the run that made them
(or saying they are not from one); every link resolves to a file and anchor of the site; the
history page marks an injected step; the site is written whole, and a bad folder or an empty
store is refused before anything is written; ``workbench results report --html``."""

from __future__ import annotations

import os
import re
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest
from site_store import (
    MACHINE,
    add_run,
    figure_folder,
    first_after_step,
    reproduce_store,
    step_store,
)

from workbench.cli import main
from workbench.output.swap import clean_dead_swaps
from workbench.results.store import ResultsStore
from workbench.site import write_site
from workbench.site import writing as site_writing
from workbench.site.plots import pareto_columns


class Parsed(HTMLParser):
    """The links, image sources, ids and tables (rows in the body, whether it has a head) of
    one page."""

    def __init__(self, text: str) -> None:
        super().__init__()
        self.links: list[str] = []
        self.images: list[str] = []
        self.ids: set[str] = set()
        self.tables: list[dict] = []
        self._where: list[str] = []
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if "id" in attrs:
            self.ids.add(attrs["id"])
        if tag == "a" and "href" in attrs:
            self.links.append(attrs["href"])
        if tag in ("link", "script"):
            self.links.append(attrs.get("href") or attrs.get("src") or "")
        if tag == "img":
            self.images.append(attrs["src"])
        if tag == "table":
            self.tables.append({"id": attrs.get("id"), "class": attrs.get("class"),
                                "head": False, "rows": 0})
        if tag in ("thead", "tbody"):
            self._where.append(tag)
        if tag == "tr" and self.tables and self._where:
            if self._where[-1] == "thead":
                self.tables[-1]["head"] = True
            else:
                self.tables[-1]["rows"] += 1

    def handle_endtag(self, tag):
        if tag in ("thead", "tbody") and self._where:
            self._where.pop()


def pages(site: Path) -> dict[str, Parsed]:
    return {p.name: Parsed(p.read_text(encoding="utf-8")) for p in sorted(site.glob("*.html"))}


def broken_links(site: Path) -> list[str]:
    """Every link or image source of the site's pages that names no file (or no anchor) of
    the site; links out of the site count as broken too (none may need the network)."""
    parsed, broken = pages(site), []
    for name, page in parsed.items():
        for href in page.links + page.images:
            parts = urlsplit(href)
            if parts.scheme == "data" or (not parts.path and not parts.fragment):
                continue
            if parts.scheme or parts.netloc or href.startswith("/"):
                broken.append(f"{name}: {href} leaves the site")
                continue
            target = site / unquote(parts.path) if parts.path else site / name
            if not target.is_file():
                broken.append(f"{name}: {href} names no file")
            elif parts.fragment and (target.suffix != ".html"
                                     or parts.fragment not in parsed[target.name].ids):
                broken.append(f"{name}: {href} names no anchor")
    return broken


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """A store with one full and two quick runs of render_paths and synthetic_a, the figures
    of render_paths, and its site."""
    tmp = tmp_path_factory.mktemp("site")
    store = reproduce_store(tmp / "store", experiments=("render_paths", "synthetic_a"))
    files = figure_folder(tmp / "figures", "render_paths", "full-1")
    index = write_site(store, tmp / "site", tmp / "figures")
    return index.parent, files


def test_the_index_lists_every_experiment_with_its_claims_run_machine_commit_and_size(built):
    site, _ = built
    text = (site / "index.html").read_text()
    assert 'href="experiment-render_paths.html"' in text
    assert 'href="experiment-synthetic_a.html"' in text
    assert 'href="history-render_paths.html"' in text
    # each claim links to its own section of the history page (anchors checked below)
    assert 'href="history-render_paths.html#claim-per-pixel_bands_against_the_floor_and_' \
           'pyrender"' in text
    assert broken_links(site) == []
    # the claim with its interval, from the full run (the latest full one wins over quick)
    assert re.search(r"car at 640x480 \(80,000 triangles\): per-pixel bands [12]\.\d+ ms, "
                     r"1\.2\d+× \[1\.\d+, 1\.\d+\] the position-only draw", text)
    assert text.count('href="runs.html#run-full-1"') == 2  # both from the full run
    assert "run-quick-2" not in text
    assert 'href="machine-m0test.html"' in text and "2" * 10 in text  # full-1's commit
    table = pages(site)["index.html"].tables[0]
    assert table["head"] and table["rows"] == 2 and "sortable" in table["class"]


def test_each_experiment_page_holds_its_tables_legends_paretos_and_figures(built):
    site, files = built
    parsed = pages(site)
    page = parsed["experiment-render_paths.html"]
    text = (site / "experiment-render_paths.html").read_text()
    tables = {t["id"]: t for t in page.tables}
    assert tables["rows-table"]["rows"] == 3 and tables["rows-targets"]["rows"] == 2
    assert all(t["head"] and "sortable" in t["class"] for t in tables.values())
    assert "wall time of the per-pixel band draw" in text  # targets' legend, declared
    assert 'data-value="' in text  # numbers sort by value
    # a Pareto plot for the table with wall_ms and max_diff_255; targets has no error column
    assert "plots/pareto-render_paths-table.png" in page.images
    assert not any("targets" in src for src in page.images if "pareto" in src)
    # the figures: copied, shown, linked to their run or saying why they are not from one
    assert (site / "figures/render_paths/made.png").read_bytes() == files[
        "made.png"].read_bytes()
    assert {"figures/render_paths/made.png", "figures/render_paths/sub/changed.png",
            "figures/render_paths/unlisted.svg"} <= set(page.images)
    assert "figures/render_paths/movie.mp4" in page.links  # a video is linked, not shown
    made = text[text.index('id="figure-made.png"'):]
    assert made[:made.index("</figure>")].count('href="runs.html#run-full-1"') == 1
    changed = text[text.index('id="figure-sub/changed.png"'):]
    assert "not from a stored run" in changed[:changed.index("</figure>")]
    assert "changed since run full-1" in changed[:changed.index("</figure>")]
    unlisted = text[text.index('id="figure-unlisted.svg"'):]
    assert "not listed in provenance.json" in unlisted[:unlisted.index("</figure>")]
    # an experiment without a declaration: its table all the same, values escaped
    other = (site / "experiment-synthetic_a.html").read_text()
    assert parsed["experiment-synthetic_a.html"].tables[0]["rows"] == 4
    assert "&lt;b&gt;escaped&lt;/b&gt;" in other and "<b>escaped" not in other
    assert "plots/pareto-synthetic_a-table.png" in parsed["experiment-synthetic_a.html"].images
    assert "no figures in this experiment" in other


def test_every_link_resolves_and_the_machine_and_runs_pages_are_complete(built):
    site, _ = built
    assert broken_links(site) == []
    for page in pages(site).values():
        assert all(t["head"] and t["rows"] > 0 for t in page.tables)
    machine = (site / "machine-m0test.html").read_text()
    for field, value in MACHINE.items():
        assert f"<td>{field}</td>" in machine and str(value) in machine
    runs = pages(site)["runs.html"]
    assert {"run-quick-1", "run-full-1", "run-quick-2"} <= runs.ids
    for png in site.glob("plots/*.png"):
        assert png.read_bytes().startswith(b"\x89PNG") and png.stat().st_size > 1000


def test_the_history_page_marks_the_injected_step(tmp_path):
    store = step_store(tmp_path / "store")
    site = write_site(store, tmp_path / "site", tmp_path / "no-figures").parent
    text = (site / "history-render_paths.html").read_text()
    runs = re.findall(r'<li class="change-point" data-run="([^"]+)"', text)
    # the ratios and the time stepped 30 % at run 10 (both scenes); the ratio to pyrender
    # (constant) did not
    assert runs and set(runs) == {first_after_step()}
    assert text.count('<tr class="change-point">') == len(runs)
    assert "median after / before ×1.3" in text
    section = text[text.index('id="quantity-targets-contour_msaa_over_pyrender"'):]
    assert "the same in every run (0.5)" in section[:section.index("<h3", 1)]
    section = text[text.index('id="quantity-targets-contour_wall_ms"'):]
    assert "plots/history-render_paths-targets-contour_wall_ms.png" in section
    summary = text[text.index("<h2>Change points</h2>"):text.index("<h2 ", text.index(
        "<h2>Change points</h2>") + 1)]
    assert summary.count(f'href="runs.html#run-{first_after_step()}"') == len(runs)
    assert broken_links(site) == []


def test_the_site_is_written_whole_and_bad_targets_are_refused(tmp_path, monkeypatch):
    store = reproduce_store(tmp_path / "store")
    out = tmp_path / "out" / "site"
    write_site(store, out, tmp_path / "figures")
    (out / "stale.html").write_text("from before")
    write_site(store, out, tmp_path / "figures")
    assert not (out / "stale.html").exists()  # replaced whole
    assert sorted(p.name for p in out.parent.iterdir()) == ["site"]  # nothing left beside
    # a build that fails leaves the old site as it was, and no folder of its own
    (out / "kept.txt").write_text("old site")

    def fail(*args):
        raise RuntimeError("disk full")
    monkeypatch.setattr(site_writing, "index_page", fail)
    with pytest.raises(RuntimeError, match="disk full"):
        write_site(store, out, tmp_path / "figures")
    monkeypatch.undo()
    assert (out / "kept.txt").read_text() == "old site"
    assert sorted(p.name for p in out.parent.iterdir()) == ["site"]
    # refused before anything is written: a file, a link to a folder, an empty store
    (tmp_path / "file").write_text("x")
    with pytest.raises(ValueError, match="is a regular file, not a folder"):
        write_site(store, tmp_path / "file", tmp_path / "figures")
    os.symlink(out, tmp_path / "link")
    with pytest.raises(ValueError, match="is a symbolic link"):
        write_site(store, tmp_path / "link", tmp_path / "figures")
    with pytest.raises(ValueError, match="holds no experiment run"):
        write_site(ResultsStore(tmp_path / "empty"), tmp_path / "new", tmp_path / "figures")
    assert not (tmp_path / "new").exists() and (out / "kept.txt").exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]
    # what a killed build left is cleaned up by the next: its half-built folder removed, an
    # old site it had set aside (killed between the renames) put back first
    dead = 999_999_999  # no such process
    (out.parent / f".site.0a0a.{dead}.partial").mkdir()
    os.replace(out, out.parent / f".site.{dead}.old")
    assert sorted(p.name for p in clean_dead_swaps(out)) == [f".site.0a0a.{dead}.partial",
                                                             f".site.{dead}.old"]
    assert (out / "kept.txt").read_text() == "old site"
    assert sorted(p.name for p in out.parent.iterdir()) == ["site"]


def test_report_html_writes_only_the_site_and_refuses_a_bad_folder(tmp_path, capsys):
    figures = tmp_path / "figures"
    store = reproduce_store(figures / "results")  # default figures: the store's parent
    figure_folder(figures, "render_paths", "full-1")
    out = tmp_path / "site"
    base = ["results", "report", "--results", str(store.root)]
    assert main([*base, "--html", str(out)]) == 0
    assert capsys.readouterr().out.strip() == str(out / "index.html")
    assert (out / "figures/render_paths/made.png").is_file()
    assert not (tmp_path / "README.md").exists()  # only the site
    (tmp_path / "plain").write_text("x")
    assert main([*base, "--html", str(tmp_path / "plain")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("workbench: error: output folder") and err.count("\n") == 1
    assert main(["results", "report", "--results", str(tmp_path / "none"),
                 "--html", str(tmp_path / "x")]) == 2


def test_pareto_columns_need_a_time_an_error_and_two_points():
    rows = [{"wall_ms": 1.0, "wall_ms_lo": 0.9, "max_diff_255": 2.0},
            {"wall_ms": 2.0, "wall_ms_lo": 1.9, "max_diff_255": 1.0}]
    assert pareto_columns(rows) == ("wall_ms", "max_diff_255")
    assert pareto_columns([{"seconds": 1.0, "hausdorff_mm": 0.1},
                           {"seconds": 2.0, "hausdorff_mm": 0.05}]) == ("seconds",
                                                                         "hausdorff_mm")
    assert pareto_columns(rows[:1]) is None  # one point is no front
    assert pareto_columns([{"wall_ms": 1.0, "ssim": 0.9}] * 2) is None  # SSIM: higher better


def test_every_figure_of_every_experiment_is_two_clicks_from_the_index(tmp_path):
    """Twenty experiments, one full and two quick runs: each figure file of each experiment
    is shown (an image) or linked (a video) on a page the index links to. (The build's time is
    measured on real stores by ``workbench results report --html``, which prints it.)"""
    names = ("render_paths", *(f"synthetic_{k:02d}" for k in range(19)))
    store = ResultsStore(tmp_path / "store")
    for i, (run_id, size) in enumerate((("q1", "quick"), ("f1", "full"), ("q2", "quick"))):
        add_run(store, run_id, size=size, started=f"2026-12-0{i + 1}T10:00", commit=str(i) * 40,
                experiments=names, seed=i)
    for name in names:
        figure_folder(tmp_path / "figures", name, "f1")
    site = write_site(store, tmp_path / "site", tmp_path / "figures").parent
    parsed = pages(site)
    first_click = {unquote(urlsplit(h).path) for h in parsed["index.html"].links}
    reached = set()
    for page in sorted(first_click & set(parsed)):
        reached |= {unquote(urlsplit(h).path)
                    for h in parsed[page].images + parsed[page].links}
    for name in names:
        for figure in (tmp_path / "figures" / name).rglob("*"):
            if figure.is_file() and figure.name != "provenance.json":
                relative = figure.relative_to(tmp_path / "figures").as_posix()
                assert f"figures/{relative}" in reached, relative
    assert len([p for p in first_click if p.startswith("experiment-")]) == 20
