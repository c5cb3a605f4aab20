"""Open every page of the built book in headless Chromium and check what a reader sees.

A page fails on: a JavaScript console error, raw TeX outside typeset math, a missing
image, an image shown below 70 % of its natural width (its text would shrink), a
traceback, a Python warning or stderr in an output, internal wording (test or benchmark
paths, absolute machine paths, development vocabulary), a chapter number that disagrees
with its file name, or exercises without hidden solutions.

Needs the built book (``make book``) plus Debian's ``chromium`` and ``chromium-driver``.
Without them the test is skipped, unless TILTLAB_REQUIRE_BOOK=1 (set by .ci/run), which
turns a missing book or browser into a failure. TILTLAB_BOOK_HTML points at another
build; TILTLAB_SCREENSHOTS=folder saves a full-page screenshot of every page there.
"""

import functools
import http.server
import os
import re
import shutil
import threading
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.browser

ROOT = Path(__file__).resolve().parents[1]
HTML = Path(os.environ.get("TILTLAB_BOOK_HTML", ROOT / "book" / "_build" / "html"))
WIDTH = 1400  # px, the window a reader is assumed to have
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--disable-dev-shm-usage",
    f"--window-size={WIDTH},1000",
    "--hide-scrollbars",
]
# wording that belongs to the repository, not to a reader
INTERNAL = [
    (r"\btests?/test_\w*", "a test file path"),
    (r"\bbenchmarks/bench_\w*", "a benchmark file path"),
    (
        r"(?<![\w.~:/])/(?:work|tmp|home|root|usr|opt|var|mnt|srv|Users)/[\w.-]",
        "an absolute path",
    ),
    (r"\bacceptance\b", "development vocabulary ('acceptance')"),
    (r"\bseeds?/|\bseeds? \d{3}\b", "development vocabulary ('seeds')"),
    (r"\.\./shared\b|\bsite-packages\b|\.venv/", "a machine path"),
    (r"\bTILTLAB_REQUIRE_\w+", "a CI switch"),
]
RAW_TEX = re.compile(
    r"\$\$|\\(?:frac|sum|mathrm|mathbf|begin|end|left|right|sqrt|cdot|hat|boldsymbol|operatorname)\b"
)


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
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
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


def _text_outside(browser, drop: str) -> str:
    """The page's visible text with the elements matching ``drop`` removed."""
    return browser.execute_script(
        """
        const main = document.querySelector('main') || document.body;
        const copy = main.cloneNode(true);
        copy.querySelectorAll(arguments[0]).forEach(e => e.remove());
        document.body.appendChild(copy);
        copy.style.position = 'absolute'; copy.style.left = '-20000px';
        const text = copy.innerText;
        copy.remove();
        return text;
        """,
        drop,
    )


def _screenshot(browser, page: str) -> None:
    folder = os.environ.get("TILTLAB_SCREENSHOTS")
    if not folder:
        return
    import base64

    height = browser.execute_script("return document.documentElement.scrollHeight")
    # lay the whole page out in one tall viewport, as a reader scrolling it would see it
    browser.execute_cdp_cmd(
        "Emulation.setDeviceMetricsOverride",
        {"width": WIDTH, "height": height, "deviceScaleFactor": 1, "mobile": False},
    )
    browser.execute_script("window.scrollTo(0, 0)")
    time.sleep(0.5)
    shot = browser.execute_cdp_cmd("Page.captureScreenshot", {"format": "png"})
    browser.execute_cdp_cmd("Emulation.clearDeviceMetricsOverride", {})
    out = Path(folder) / (page.replace("/", "_").removesuffix(".html") + ".png")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_bytes(base64.b64decode(shot["data"]))


def _figure_problems(browser) -> list[str]:
    """Figures of executed cells: numbered caption, alt text, sharp on a dense screen."""
    figs = browser.execute_script(
        """
        return Array.from(document.querySelectorAll('main .cell_output img')).map(i => {
            const fig = i.closest('figure');
            const num = fig && fig.querySelector('figcaption .caption-number');
            const cap = fig && fig.querySelector('figcaption');
            // textContent: a solution's figure sits in a closed toggle
            return [i.currentSrc || i.src, num ? num.textContent : '',
                    cap ? cap.textContent : '', i.getAttribute('alt') || '',
                    i.naturalWidth, i.getBoundingClientRect().width];
        });
        """
    )
    out = []
    for src, number, caption, alt, natural, shown in figs:
        name = src.rsplit("/", 1)[-1][:16]
        if not re.match(r"Fig\.\s*\d+", number):
            out.append(f"figure {name} has no numbered caption")
        elif len(caption) - len(number) < 40:
            out.append(f"figure {name}: caption too short to explain it ({caption!r})")
        if len(alt.strip()) < 10:
            out.append(f"figure {name} has no alt text")
        if not src.endswith(".svg") and shown > 0 and natural < 1.5 * shown:
            # (a figure in a closed toggle has no width: nothing to compare)
            out.append(
                f"figure {name}: {natural} px shown at {shown:.0f} px "
                f"({natural / shown:.1f}x): blurred on a high-density screen"
            )
    return out


@pytest.mark.parametrize("page", chapter_pages())
def test_page_renders(server, browser, page):
    browser.get_log("browser")  # forget the previous page's messages
    browser.get(f"{server}/{page}")
    assert _wait_for(browser, "return document.readyState === 'complete'")
    title = browser.title
    assert "404" not in title and "Error" not in title, title
    text = browser.execute_script("return document.body.innerText")
    assert len(text) > 200, f"{page}: almost empty page"
    problems = []

    # no Python error made it into the page
    for marker in ("Traceback (most recent call last)", "CellExecutionError"):
        if marker in text:
            problems.append(f"contains {marker!r}")
    errors = browser.execute_script(
        "return document.querySelectorAll('div.output.error, .output_error, .cell_output .ansi-red-fg, .cell_output .output.stderr').length"
    )
    if errors:
        problems.append(f"{errors} error or stderr outputs")
    outputs = browser.execute_script(
        "return Array.from(document.querySelectorAll('.cell_output')).map(e => e.innerText).join('\\n')"
    )
    for warning in re.findall(r"\b\w*Warning: .{0,60}", outputs):
        problems.append(f"a warning in an output: {warning!r}")
    # outputs are for reading: no raw xarray/dict reprs, no 16-digit floats
    reprs = browser.execute_script(
        "return document.querySelectorAll('.cell_output .xr-wrap').length"
    )
    if reprs or "<xarray." in outputs:
        problems.append("a raw xarray repr in an output")
    for m in re.finditer(r"^\{'\w+': .{0,60}", outputs, re.M):
        problems.append(f"a raw dict in an output: {m.group(0)!r}")
    for m in re.finditer(r"(?<![\w.])-?\d+\.\d{9,}", outputs):
        problems.append(
            f"a {len(m.group(0))}-character float in an output: {m.group(0)}"
        )

    # every image is present, loaded, non-empty and not shrunk below 70 % of the width
    # it declares (a retina PNG declares half its pixel width)
    imgs = browser.execute_script(
        "return Array.from(document.querySelectorAll('main img')).map(i => [i.currentSrc || i.src, i.complete, i.naturalWidth, i.naturalHeight, i.getBoundingClientRect().width, parseFloat(i.style.width) || parseFloat(i.getAttribute('width')) || i.naturalWidth])"
    )
    for src, complete, w, h, shown, declared in imgs:
        name = src.rsplit("/", 1)[-1]
        if not (complete and w > 0 and h > 0):
            problems.append(f"image not loaded {name}")
        elif shown < 0.7 * declared:
            problems.append(
                f"image {name} shown at {shown:.0f} of {declared:.0f} px "
                f"({shown / declared:.0%}): its text shrinks"
            )
    problems += _figure_problems(browser)
    if page.startswith("notebooks/") and not imgs:
        problems.append("a chapter without any figure")

    # math: any TeX on the page has been typeset by the vendored MathJax ...
    has_math = browser.execute_script(
        "return document.querySelectorAll('.math').length"
    )
    if page == "conventions.html":
        assert has_math > 10, "the conventions page states its equations in TeX"
    if has_math:
        typeset = _wait_for(
            browser, "return document.querySelectorAll('mjx-container').length"
        )
        raw = browser.execute_script(
            "return Array.from(document.querySelectorAll('.math')).filter(e => !e.querySelector('mjx-container')).length"
        )
        if typeset < has_math or raw:
            problems.append(
                f"{has_math} math elements, {typeset} typeset, {raw} left raw"
            )
        errs = browser.execute_script(
            "return document.querySelectorAll('mjx-merror').length"
        )
        if errs:
            problems.append(f"{errs} MathJax errors")
    # ... and no TeX is left in the text around it (code cells are allowed TeX)
    prose = _text_outside(
        browser, "mjx-container, .math, .cell_input, pre, code, script, style"
    )
    for m in RAW_TEX.finditer(prose):
        problems.append(
            f"raw TeX in the text: …{prose[max(0, m.start() - 40) : m.end() + 20]!r}…"
        )

    # internal wording
    for pattern, what in INTERNAL:
        for m in re.finditer(pattern, text):
            problems.append(f"{what}: {text[max(0, m.start() - 30) : m.end() + 30]!r}")

    # chapters: the rendered number agrees with the file, and exercises have hidden solutions
    h1 = browser.execute_script(
        "const h = document.querySelector('main section > h1'); return h ? h.innerText : ''"
    )
    m = re.match(r"notebooks/(\d\d)_", page)
    if m:
        if not re.match(rf"^{int(m.group(1))}\.\s", h1):
            problems.append(f"rendered title {h1!r} is not chapter {int(m.group(1))}")
        hidden = browser.execute_script(
            """
            const sec = Array.from(document.querySelectorAll('main section'))
                .find(s => s.querySelector(':scope > h2') &&
                           /Exercises/.test(s.querySelector(':scope > h2').innerText));
            if (!sec) return -1;
            return Array.from(sec.querySelectorAll('details.hide, .toggle-hidden, details'))
                .filter(d => !d.open).length;
            """
        )
        if hidden < 2:
            problems.append(
                "no Exercises section"
                if hidden < 0
                else "fewer than 2 hidden solutions"
            )
        # every exercise has its answer in a closed "Solution N: the answer" dropdown
        n_ex, n_answers = browser.execute_script(
            """
            const sec = Array.from(document.querySelectorAll('main section'))
                .find(s => s.querySelector(':scope > h2') &&
                           /Exercises/.test(s.querySelector(':scope > h2').innerText));
            if (!sec) return [0, 0];
            const ol = sec.querySelector('ol');
            const answers = Array.from(sec.querySelectorAll('details.sd-dropdown'))
                .filter(d => !d.open && /^Solution \\d+: the answer/.test(
                    d.querySelector('summary').textContent.trim())).length;
            return [ol ? ol.querySelectorAll(':scope > li').length : 0, answers];
            """
        )
        if n_answers < n_ex:
            problems.append(
                f"{n_ex} exercises but {n_answers} closed 'Solution N: the answer' toggles"
            )
    elif page == "intro.html" and h1.strip() != "Introduction":
        problems.append(f"the home page is titled {h1!r}, not 'Introduction'")

    # the browser itself reported nothing wrong
    for entry in browser.get_log("browser"):
        if entry["level"] == "SEVERE":
            problems.append(f"console error: {entry['message'][:200]}")

    _screenshot(browser, page)
    assert not problems, f"{page}:\n  " + "\n  ".join(problems)


def test_bibliography_lists_every_cited_work(server, browser):
    """Every key cited with {cite} in a page of the book appears in the bibliography."""
    cited = set()
    for path in [*(ROOT / "notebooks").glob("*.ipynb"), *(ROOT / "book").glob("*.md")]:
        for group in re.findall(r"\{cite(?::\w+)?\}`([^`]+)`", path.read_text()):
            cited |= {k.strip() for k in group.replace("\\n", " ").split(",")}
    browser.get(f"{server}/bibliography.html")
    assert _wait_for(browser, "return document.readyState === 'complete'")
    entries = browser.execute_script(
        "return document.querySelectorAll('main div.citation').length"
    )
    # sphinxcontrib-bibtex lists cited works only, and a key missing from the .bib file
    # fails the build; so the page must hold exactly one entry per cited key
    assert entries == len(cited), (
        f"{len(cited)} works cited, {entries} listed in the bibliography"
    )
