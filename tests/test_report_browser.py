"""The campaign report in a real browser (headless Chromium through
Selenium): the page loads with no console error and every figure renders.

Skipped where Chromium and its driver are not installed (Debian: apt-get
install chromium chromium-driver), unless IMGMTF_REQUIRE_BROWSER is set:
CI installs them and sets it (.ci/run), so there it runs or fails."""
import os
import shutil
from pathlib import Path

import pytest

from imgmtf.campaign.acquisitions import Acquisition
from imgmtf.campaign.report import write_report
from imgmtf.campaign.store import write_acquisition
from imgmtf.records import Record

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
DRIVER = shutil.which("chromedriver")
if not (CHROMIUM and DRIVER) and os.environ.get("IMGMTF_REQUIRE_BROWSER"):
    raise RuntimeError("IMGMTF_REQUIRE_BROWSER is set but chromium or chromedriver is missing")
pytestmark = pytest.mark.skipif(not (CHROMIUM and DRIVER), reason="needs chromium and chromedriver (apt)")
webdriver = pytest.importorskip("selenium.webdriver")

# what keeps the browser from reaching anything but the page: no network of its own, no profile
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--window-size=1366,900")


@pytest.fixture
def report(tmp_path):
    store = tmp_path / "site.gpkg"
    for k in range(4):
        value = 0.3 - 0.02 * k
        row = Record("scene.tif", 1, "edge", "", "fitted", site={"scope": "scene"},
                     figures={"summary": "fit", "direction": "across-track", "mtf_nyquist": value,
                              "mtf_nyquist_ci": [value - 0.005, value + 0.005], "fwhm_px": 1.2 + 0.05 * k})
        oblique = Record("scene.tif", 1, "edge", "", "combined", site={"scope": "scene"},
                         figures={"summary": "combined", "direction": "oblique", "normal_angle_deg": -73.2,
                                  "mtf_nyquist": value, "mtf_nyquist_ci": [value - 0.005, value + 0.005]})
        write_acquisition(store, Acquisition(f"a{k}", f"scene{k}.tif", "0" * 64, f"{2020 + k}-06-01T03:30:00Z",
                                             "Simsat-1", None, "PAN"), [], [row, oblique])
    return write_report(store, tmp_path / "report", requirement="across=0.2,along=0.1").report_html


@pytest.fixture
def browser(tmp_path, monkeypatch):
    from selenium.webdriver.chrome.service import Service
    monkeypatch.setenv("SE_OFFLINE", "true")         # Selenium Manager must not fetch a driver
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in (*FLAGS, f"--user-data-dir={tmp_path / 'profile'}"):
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(executable_path=DRIVER), options=options)
    yield driver
    driver.quit()


def test_the_report_loads_without_console_errors_and_every_figure_renders(report, browser):
    browser.get(Path(report).as_uri())
    assert browser.title.startswith("MTF campaign")
    images = browser.find_elements("tag name", "img")
    assert len(images) == 2                                  # across track, and the oblique normal
    complete = browser.execute_script(
        "return Array.from(document.images).map(i => [i.complete, i.naturalWidth, i.naturalHeight])")
    assert all(done and width > 0 and height > 0 for done, width, height in complete), complete
    # the figure opens at full resolution: a link to its PNG beside the page, larger than the page's copy
    link = browser.execute_script("return document.images[0].parentElement.href")
    browser.get(link)
    full = browser.execute_script("return [document.images[0].naturalWidth, document.images[0].complete]")
    assert full[1] and full[0] > complete[0][1]
    browser.back()
    errors = [entry for entry in browser.get_log("browser") if entry["level"] in ("SEVERE", "ERROR")]
    assert not errors, errors
    external = browser.execute_script(
        "return performance.getEntriesByType('resource').map(r => r.name)"
        ".filter(n => !n.startsWith('data:') && !n.startsWith('file:'))")
    assert external == []
    assert browser.execute_script("return document.documentElement.scrollWidth") <= 1366   # no sideways scroll
