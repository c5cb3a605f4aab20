"""Open every page of the built book in headless Chromium and check what a reader sees.

Needs the built book (``make book``) plus Debian's ``chromium`` and ``chromium-driver``.
Without them the test is skipped, unless TILTLAB_REQUIRE_BOOK=1 (set by .ci/run), which
turns a missing book or browser into a failure.
"""

import functools
import http.server
import os
import shutil
import threading
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.browser

ROOT = Path(__file__).resolve().parents[1]
HTML = ROOT / "book" / "_build" / "html"
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--disable-dev-shm-usage",
]


def _skip_or_fail(why: str):
    if os.environ.get("TILTLAB_REQUIRE_BOOK", "") not in ("", "0"):
        pytest.fail(why)
    pytest.skip(why)


def chapter_pages() -> list[str]:
    """Pages listed in the book's table of contents, as paths relative to the site root."""
    import yaml

    toc = yaml.safe_load((ROOT / "book" / "_toc.yml").read_text())
    files = [toc["root"]]
    for part in toc.get("parts", []):
        files += [c["file"] for c in part.get("chapters", [])]
    return [f + ".html" for f in files]


@pytest.fixture(scope="module")
def server():
    if not (HTML / "index.html").is_file():
        _skip_or_fail(f"the book is not built ({HTML}); run `make book` first")
    handler = functools.partial(
        http.server.SimpleHTTPRequestHandler, directory=str(HTML)
    )

    class Quiet(handler.func):  # type: ignore[misc]
        def log_message(self, *args):
            pass

    httpd = http.server.ThreadingHTTPServer(
        ("127.0.0.1", 0), functools.partial(Quiet, directory=str(HTML))
    )
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{httpd.server_address[1]}"
    httpd.shutdown()


@pytest.fixture(scope="module")
def browser():
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    driver_path = shutil.which("chromedriver")
    if not chromium or not driver_path:
        _skip_or_fail(
            "chromium and chromedriver are not installed (Debian: chromium chromium-driver)"
        )
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = chromium
    for f in CHROMIUM_FLAGS:
        opts.add_argument(f)
    drv = webdriver.Chrome(service=Service(executable_path=driver_path), options=opts)
    drv.set_page_load_timeout(60)
    yield drv
    drv.quit()


def _wait_for(drv, script: str, timeout: float = 30.0):
    end = time.time() + timeout
    while time.time() < end:
        value = drv.execute_script(script)
        if value:
            return value
        time.sleep(0.25)
    return drv.execute_script(script)


def test_toc_lists_pages():
    pages = chapter_pages()
    assert "conventions.html" in pages and any(
        p.startswith("notebooks/") for p in pages
    )


@pytest.mark.parametrize("page", chapter_pages())
def test_page_renders(server, browser, page):
    browser.get(f"{server}/{page}")
    assert _wait_for(browser, "return document.readyState === 'complete'")
    title = browser.title
    assert "404" not in title and "Error" not in title, title
    text = browser.execute_script("return document.body.innerText")
    assert len(text) > 200, f"{page}: almost empty page"
    # no Python error made it into the page
    for marker in ("Traceback (most recent call last)", "CellExecutionError"):
        assert marker not in text, f"{page}: contains {marker!r}"
    errors = browser.execute_script(
        "return document.querySelectorAll('div.output.error, .output_error, .cell_output .ansi-red-fg').length"
    )
    assert errors == 0, f"{page}: {errors} error outputs"
    # every image is present, loaded and non-empty
    imgs = browser.execute_script(
        "return Array.from(document.querySelectorAll('main img')).map(i => [i.currentSrc || i.src, i.complete, i.naturalWidth, i.naturalHeight])"
    )
    for src, complete, w, h in imgs:
        assert complete and w > 0 and h > 0, f"{page}: image not loaded {src}"
    if page.startswith("notebooks/"):
        assert len(imgs) >= 1, f"{page}: a chapter without any figure"
    # math: any TeX on the page has been typeset by the vendored MathJax
    has_math = browser.execute_script(
        "return document.querySelectorAll('.math').length"
    )
    if page == "conventions.html":
        assert has_math > 10, "the conventions page states its equations in TeX"
    if has_math:
        typeset = _wait_for(
            browser, "return document.querySelectorAll('mjx-container').length"
        )
        assert typeset >= has_math, (
            f"{page}: {has_math} math elements but {typeset} typeset"
        )
        raw = browser.execute_script(
            "return Array.from(document.querySelectorAll('.math')).filter(e => !e.querySelector('mjx-container')).length"
        )
        assert raw == 0, f"{page}: {raw} math elements left as raw TeX"
        errs = browser.execute_script(
            "return document.querySelectorAll('mjx-merror').length"
        )
        assert errs == 0, f"{page}: {errs} MathJax errors"
