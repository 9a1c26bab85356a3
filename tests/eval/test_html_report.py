"""The HTML report in a real browser: Debian's chromium driven by Playwright (no browser download).

Skipped, with the reason, where chromium or Playwright is missing (``apt-get install -y
chromium`` and the ``test`` extra install them).
"""

import json
import shutil

import pytest

import tsrkit
from tsrkit.report import fmt

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("html-run")
    tsrkit.benchmark(tsrkit.dataset("sample"), tsrkit.detector("gray-tophat"), out=out, cache=False)
    return out


def test_the_page_is_self_contained(run_dir):
    page = (run_dir / "report.html").read_text()
    assert "http://" not in page and "https://" not in page  # no CDN, nothing fetched
    assert page.count("data:image/") >= 3  # plots and gallery embedded


@pytest.mark.skipif(
    CHROMIUM is None, reason="chromium is not installed (apt-get install -y chromium)"
)
def test_page_loads_in_chromium_with_the_report_numbers(run_dir, tmp_path):
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed")
    report = json.loads((run_dir / "report.json").read_text())
    with sync_api.sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
        page = browser.new_page()
        errors = []
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto((run_dir / "report.html").as_uri())
        headline = page.inner_text("#headline")
        assert fmt(report["per_frame"]["recall_mean"]) in headline
        assert fmt(report["iou50"]["ap"]) in headline
        widths = page.eval_on_selector_all("img", "imgs => imgs.map(i => i.naturalWidth)")
        assert widths and min(widths) > 0
        assert page.locator("img.gallery").count() > 0
        column = "#categories tbody tr td:nth-child(3)"
        page.click("#categories th:nth-child(3)")
        frames = [int(v) for v in page.eval_on_selector_all(column, "c => c.map(x => x.innerText)")]
        assert frames == sorted(frames)
        page.click("#categories th:nth-child(3)")
        frames = [int(v) for v in page.eval_on_selector_all(column, "c => c.map(x => x.innerText)")]
        assert frames == sorted(frames, reverse=True)
        page.fill('input[data-table="categories"]', "night")
        shown = page.eval_on_selector_all(
            "#categories tbody tr", "rows => rows.filter(r => r.style.display !== 'none').length"
        )
        assert 0 < shown < len(report["categories"])
        page.screenshot(path=str(tmp_path / "report.png"), full_page=True)
        browser.close()
    assert (tmp_path / "report.png").stat().st_size > 10_000
    assert errors == []


def test_report_verb_re_renders_a_run_and_a_compare_folder(run_dir, tmp_path):
    from click.testing import CliRunner

    from tsrkit.cli.main import cli

    before = (run_dir / "report.html").read_text()
    (run_dir / "report.html").unlink()
    result = CliRunner().invoke(cli, ["report", str(run_dir)])
    assert result.exit_code == 0, result.output
    assert (run_dir / "report.html").read_text() == before  # same run, same page
    out = tmp_path / "cmp"
    detectors = [tsrkit.detector("gray-tophat"), tsrkit.detector("conspicuity")]
    tsrkit.compare(tsrkit.dataset("sample"), detectors, out=out, cache=False)
    assert CliRunner().invoke(cli, ["report", str(out)]).exit_code == 0
    page = (out / "compare.html").read_text()
    assert "gray-tophat" in page and 'href="conspicuity/report.html"' in page
    bad = CliRunner().invoke(cli, ["report", str(tmp_path)])
    assert bad.exit_code != 0 and "not a run folder" in bad.output


def test_compare_html_flag_writes_the_compare_page(tmp_path):
    from click.testing import CliRunner

    from tsrkit.cli.main import cli

    out = tmp_path / "cmp"
    args = ["compare", "--detectors", "gray-tophat,conspicuity", "--html", "-q", "-w", "1"]
    result = CliRunner().invoke(cli, [*args, "-o", str(out), "--no-cache"])
    assert result.exit_code == 0, result.output
    assert 'href="gray-tophat/report.html"' in (out / "compare.html").read_text()
