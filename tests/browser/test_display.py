"""Headless Chromium loads the live display, sees the intruders and the warning at the right time.

Nothing is installed from here: ``make test`` / ``make test-browser`` install Debian's ``chromium``
(target ``browser-deps``) and the ``playwright`` Python package (dev extra; the browser build
Playwright would download is never used). A missing ``/usr/bin/chromium`` fails the test with the
command that provides it. The display server runs on 127.0.0.1 in a thread, bounded in time, and
is stopped by the fixture. The screenshot goes to ``$SKYRADAR_SCREENSHOT_DIR`` (``make
test-browser`` sets ``out/browser``) or the test's tmp dir.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest
from playwright.sync_api import sync_playwright

pytestmark = [
    pytest.mark.browser,
    pytest.mark.filterwarnings("ignore::RuntimeWarning", "ignore::UserWarning"),
]

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
# Sample run (skyradar.web.sample): the head-on intruder's issued warning starts at 35 s (see test_web.py).
WARNING_AT_S = 35.0
WARNING_COLOUR = (0xFF, 0x30, 0x30)


@pytest.fixture(scope="session")
def chromium() -> str:
    if not Path(CHROMIUM).exists():
        pytest.fail(
            f"{CHROMIUM} is missing: run `make browser-deps` (as root it runs `apt-get install -y chromium`)"
        )
    return CHROMIUM


@pytest.fixture()
def display_url(tmp_path):
    from skyradar.web.sample import write_sample_run
    from skyradar.web.server import create_app, serve_in_thread

    run = write_sample_run(tmp_path / "run.zarr", n_frames=50)
    with serve_in_thread(create_app(run, speed=1.0, autoplay=False)) as url:  # 127.0.0.1, stopped on exit
        yield url + "/"


def _count_colour(page, selector: str, rgb: tuple[int, int, int]) -> int:
    return page.eval_on_selector(
        selector,
        """(cv, rgb) => { const d = cv.getContext('2d').getImageData(0, 0, cv.width, cv.height).data;
            let n = 0; for (let i = 0; i < d.length; i += 4)
              if (d[i] === rgb[0] && d[i + 1] === rgb[1] && d[i + 2] === rgb[2]) n++; return n; }""",
        list(rgb),
    )


def test_display_shows_intruders_and_warning(chromium, display_url, tmp_path):
    shot_dir = Path(os.environ.get("SKYRADAR_SCREENSHOT_DIR", tmp_path))
    shot_dir.mkdir(parents=True, exist_ok=True)
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=chromium, args=CHROMIUM_ARGS, timeout=60_000)
        try:
            page = browser.new_page(viewport={"width": 1200, "height": 760})
            page.set_default_timeout(30_000)
            page.goto(display_url)
            page.wait_for_function("window.skyradar.frame && window.skyradar.frame.index === 0")
            assert page.get_attribute("#alert", "data-level") == "0"
            # Seek (slider) to 20 s: the head-on intruder is in range with a corrective alert.
            page.eval_on_selector("#seek", "el => { el.value = 20; el.dispatchEvent(new Event('change')); }")
            page.wait_for_function("window.skyradar.frame.index === 20")
            assert page.locator("#traffic tr[data-track='0']").get_attribute("data-level") == "2"
            assert page.locator("#traffic tr[data-track='1']").get_attribute("data-level") == "0"
            assert _count_colour(page, "#plan", WARNING_COLOUR) == 0
            # Play from 30 s at 10x and wait for the warning.
            page.eval_on_selector("#seek", "el => { el.value = 30; el.dispatchEvent(new Event('change')); }")
            page.wait_for_function("window.skyradar.frame.index === 30")
            page.select_option("#speed", "10")
            page.click("#play")
            page.wait_for_selector("#alert[data-level='3']")
            history = page.evaluate("window.skyradar.history")
            played = [(t, lvl) for t, lvl in history if t >= 30.0]
            first_warning = next(t for t, lvl in played if lvl == 3)
            assert first_warning == pytest.approx(WARNING_AT_S)
            assert all(lvl == 2 for t, lvl in played if t < WARNING_AT_S)
            page.click("#play")  # pause to hold the picture for the screenshot
            page.wait_for_function("window.skyradar.frame.max_level === 3")
            assert "WARNING" in page.text_content("#alert") and "12 o'clock" in page.text_content("#alert")
            assert _count_colour(page, "#plan", WARNING_COLOUR) > 50  # the red square symbol
            assert page.locator("#traffic tbody tr").count() == 2
            assert page.get_attribute("#rd", "src").startswith("data:image/png;base64,")
            shot = shot_dir / "display.png"
            page.screenshot(path=str(shot))
            assert shot.stat().st_size > 10_000
        finally:
            browser.close()
    if shot_dir != tmp_path:
        shutil.copy(shot, tmp_path / "display.png")
