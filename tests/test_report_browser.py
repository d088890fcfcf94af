"""The class report in a real browser: headless Chromium (Debian's ``chromium``, which ``.ci/run``
installs where it can) opens the demo's ``report.html``, takes a screenshot into ``tests/artifacts/``
and logs no console message (the page has no script, so any message is an error: a blocked load, a
script that got in). Where Chromium is absent these tests skip, saying so."""

from __future__ import annotations

import shutil
import struct
import subprocess
from pathlib import Path

import pytest

from tests.demo_output import ROOT, DemoRun
from tests.test_class_report import ALLOWED_TAGS, HOSTILE, Page, make_class

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
ARTIFACTS = ROOT / "tests" / "artifacts"
WINDOW = (1200, 2400)

pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="headless Chromium is not installed (Debian: apt-get install chromium; .ci/run "
                             "installs it where apt is available): the report's browser tests are skipped")


def chromium(page: Path, profile: Path, *options: str) -> subprocess.CompletedProcess[str]:
    """Chromium run headless on ``page`` with a profile of its own (tests may run side by side)."""
    assert CHROMIUM is not None
    return subprocess.run([CHROMIUM, "--headless", "--disable-gpu", "--no-sandbox", "--hide-scrollbars",
                           "--no-first-run", "--disable-extensions", f"--user-data-dir={profile}",
                           "--enable-logging=stderr", "--v=0", *options, page.resolve().as_uri()],
                          capture_output=True, text=True, timeout=180)


def screenshot(page: Path, target: Path, profile: Path) -> list[str]:
    """Take a screenshot of ``page`` into ``target``; returns the console messages the page logged."""
    target.unlink(missing_ok=True)
    result = chromium(page, profile, f"--screenshot={target}", f"--window-size={WINDOW[0]},{WINDOW[1]}")
    assert target.is_file(), result.stderr[-2000:]
    return [line for line in result.stderr.splitlines() if ":CONSOLE" in line]


def png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    width, height = struct.unpack(">II", data[16:24])
    return width, height


def test_the_demo_report_loads_in_chromium_with_no_console_message(demo_run: DemoRun, tmp_path: Path) -> None:
    """The screenshot is ``tests/artifacts/report.png``: look at it after a change to the report."""
    ARTIFACTS.mkdir(exist_ok=True)
    target = ARTIFACTS / "report.png"
    messages = screenshot(demo_run.out / "grades" / "report.html", target, tmp_path / "profile")
    assert messages == []
    assert png_size(target) == WINDOW
    from PIL import Image

    with Image.open(target) as image:  # a page was drawn: not one color, and its figures' blue is there
        colors = image.convert("RGB").getcolors(maxcolors=1 << 20) or []
    assert len(colors) > 50
    assert any(abs(r - 0x1F) < 8 and abs(g - 0x4E) < 8 and abs(b - 0x99) < 8 for _, (r, g, b) in colors)


def test_a_page_with_an_error_is_caught(tmp_path: Path) -> None:
    """The check above can fail: a script error, and a load the page's policy blocks, are both logged."""
    page = tmp_path / "broken.html"
    page.write_text("<!DOCTYPE html><html><head><meta http-equiv=\"Content-Security-Policy\" "
                    "content=\"default-src 'none'\"></head><body><p>x</p><script>nope()</script></body></html>",
                    encoding="utf-8")
    assert len(screenshot(page, tmp_path / "broken.png", tmp_path / "profile")) == 1
    page.write_text("<!DOCTYPE html><html><body><script>nope()</script></body></html>", encoding="utf-8")
    assert "Uncaught ReferenceError" in screenshot(page, tmp_path / "broken.png", tmp_path / "profile")[0]


def test_names_that_look_like_markup_are_text_in_the_browser(tmp_path: Path) -> None:
    """Chromium's own reading of a report whose roster, key and answers hold markup: no element of
    theirs, their text shown as typed, and nothing logged."""
    from grader.grade.class_report import class_report

    graded = make_class({"1a": ["invalid"] * 3, "1b": ["correct", "incorrect", "correct"]},
                        params=[{"e": 1.0}, {"e": 2.0}, {"e": 3.0}],
                        names=HOSTILE[:3], typed=HOSTILE[2], title=HOSTILE[3])
    page = tmp_path / "report.html"
    page.write_text(class_report(graded), encoding="utf-8")
    dom = Page(chromium(page, tmp_path / "profile", "--dump-dom").stdout)
    assert "svg" in dom.tags and dom.tags <= ALLOWED_TAGS, dom.tags - ALLOWED_TAGS
    assert not [name for name, _ in dom.attributes if name.startswith("on")]
    text = "".join(dom.text)
    assert all(hostile in text for hostile in HOSTILE[:4])
    assert screenshot(page, tmp_path / "report.png", tmp_path / "profile") == []
