"""The static results site in a real browser: headless Chromium (Debian's ``chromium`` and
``chromium-driver``, installed by ``install.sh``), driven by Selenium, opens every page of a
generated site from disk (``file://``, no server) and checks that every image loads (its
``naturalWidth`` > 0), every table has a head and rows, and the browser logs no error; that a
click on a heading sorts a table; and that the history page of a store with an injected step
shows the change point. The checker is shown to fail on a site with a broken image and a table
emptied of its rows. Skipped, with the reason, where the browser, its driver or Selenium is
missing."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from site_store import figure_folder, first_after_step, reproduce_store, step_store

from workbench.site import write_site

CHROMIUM, CHROMEDRIVER = Path("/usr/bin/chromium"), Path("/usr/bin/chromedriver")


def _missing() -> str | None:
    for path in (CHROMIUM, CHROMEDRIVER):
        if not path.exists():
            return f"{path} is not installed (Debian: apt-get install chromium chromium-driver)"
    try:
        import selenium  # noqa: F401
    except ImportError:
        return "selenium is not installed (pip install 'selenium>=4.20')"
    return None


pytestmark = pytest.mark.skipif(_missing() is not None, reason=str(_missing()))


@pytest.fixture(scope="module")
def driver(tmp_path_factory):
    """Headless Chromium with its console log kept at every level."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = str(CHROMIUM)
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--no-first-run", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", "--window-size=1280,1000",
                f"--user-data-dir={tmp_path_factory.mktemp('chromium-profile')}"):
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    browser = webdriver.Chrome(options=options, service=Service(str(CHROMEDRIVER)))
    browser.set_page_load_timeout(60)
    yield browser
    browser.quit()


IMAGES = ("return Array.from(document.images).map("
          "i => [i.getAttribute('src'), i.complete ? i.naturalWidth : 0]);")
TABLES = ("return Array.from(document.querySelectorAll('table')).map(t => [t.id, "
          "t.tHead ? t.tHead.rows.length : 0, t.tBodies.length ? t.tBodies[0].rows.length : 0]);")


def check_site(driver, site: Path) -> list[str]:
    """The problems of every page of ``site`` opened from disk: an image that did not load,
    a table without a head or without rows, an error in the browser's console."""
    problems = []
    driver.get_log("browser")  # drop what earlier pages logged
    for page in sorted(site.glob("*.html")):
        driver.get(page.as_uri())
        for src, width in driver.execute_script(IMAGES):
            if not width:
                problems.append(f"{page.name}: image {src} did not load")
        for ident, head, rows in driver.execute_script(TABLES):
            if not head or not rows:
                problems.append(f"{page.name}: table {ident or '?'} has {head} head rows and "
                                f"{rows} rows")
        for entry in driver.get_log("browser"):
            if entry["level"] == "SEVERE":
                problems.append(f"{page.name}: console: {entry['message']}")
    return problems


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """The site of one full and two quick runs of render_paths and another experiment, with
    render_paths' figures."""
    tmp = tmp_path_factory.mktemp("browser-site")
    store = reproduce_store(tmp / "store", experiments=("render_paths", "synthetic_a"))
    figure_folder(tmp / "figures", "render_paths", "full-1")
    return write_site(store, tmp / "site", tmp / "figures").parent


def test_every_page_loads_its_images_and_tables_without_console_errors(driver, site):
    assert len(list(site.glob("*.html"))) >= 7
    assert check_site(driver, site) == []


def test_the_checker_reports_a_broken_image_and_an_empty_table(driver, site, tmp_path):
    broken = tmp_path / "broken"
    shutil.copytree(site, broken)
    page = broken / "experiment-render_paths.html"
    text = page.read_text()
    start = text.index("<tbody>", text.index('id="rows-targets"'))
    end = text.index("</tbody>", start)
    text = text[:start] + "<tbody>" + text[end:]  # the targets table loses its rows
    page.write_text(text.replace("</body>", '<img src="plots/missing.png" alt="x"></body>'))
    problems = check_site(driver, broken)
    assert any("image plots/missing.png did not load" in p for p in problems), problems
    assert any("table rows-targets has 1 head rows and 0 rows" in p for p in problems)
    assert any("console:" in p and "missing.png" in p for p in problems)
    assert all(p.startswith("experiment-render_paths.html") for p in problems)


def test_a_click_on_a_heading_sorts_the_table(driver, site):
    from selenium.webdriver.common.by import By

    driver.get((site / "experiment-render_paths.html").as_uri())
    table = driver.find_element(By.ID, "rows-table")
    heads = table.find_elements(By.CSS_SELECTOR, "thead th")
    column = [h.text for h in heads].index("max_diff_255")

    def values():
        return [float(r.find_elements(By.TAG_NAME, "td")[column].get_attribute("data-value"))
                for r in table.find_elements(By.CSS_SELECTOR, "tbody tr")]
    assert values() == [3.0, 2.0, 1.0]
    heads[column].click()
    assert values() == [1.0, 2.0, 3.0]
    heads[column].click()
    assert values() == [3.0, 2.0, 1.0]


def test_the_history_page_shows_the_change_point(driver, tmp_path):
    store = step_store(tmp_path / "store")
    site = write_site(store, tmp_path / "site", tmp_path / "figures").parent
    assert check_site(driver, site) == []
    from selenium.webdriver.common.by import By

    driver.get((site / "history-render_paths.html").as_uri())
    marks = driver.find_elements(By.CSS_SELECTOR, "li.change-point")
    assert marks and all(m.is_displayed() for m in marks)
    assert {m.get_attribute("data-run") for m in marks} == {first_after_step()}
    rows = driver.find_elements(By.CSS_SELECTOR, "tr.change-point")
    assert len(rows) == len(marks) and all(first_after_step() in r.text for r in rows)
