"""The HTML report in a real browser: Debian's chromium driven by Playwright (no browser download).

Skipped, with the reason, where chromium or Playwright is missing (``apt-get install -y
chromium`` and the ``test`` extra install them); CI installs both and sets
``TSRKIT_REQUIRE_BROWSER=1``, which turns the skip into a failure.
"""

import json
import os
import shutil
from pathlib import Path

import pytest

import tsrkit
from tsrkit.reporting.report import fmt

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
REFERENCE = Path(__file__).resolve().parents[1] / "data" / "reference_reports"


def browser_api():
    """Playwright's sync API, or a skip (a failure under ``TSRKIT_REQUIRE_BROWSER=1``)."""
    missing = None
    try:
        from playwright import sync_api
    except ImportError:
        missing = "playwright is not installed"
    if CHROMIUM is None:
        missing = "chromium is not installed (apt-get install -y chromium)"
    if missing:
        if os.environ.get("TSRKIT_REQUIRE_BROWSER") == "1":
            pytest.fail(f"{missing}, and TSRKIT_REQUIRE_BROWSER=1")
        pytest.skip(missing)
    return sync_api


def open_page(pw, path: Path, errors: list):
    """A chromium page showing ``path``, recording console errors into ``errors``."""
    browser = pw.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(path.as_uri())
    return browser, page


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("html-run")
    tsrkit.benchmark(tsrkit.dataset("sample"), tsrkit.detector("gray-tophat"), out=out, cache=False)
    return out


def test_the_page_is_self_contained(run_dir):
    page = (run_dir / "report.html").read_text()
    assert "http://" not in page and "https://" not in page  # no CDN, nothing fetched
    assert page.count("data:image/") >= 3  # plots and gallery embedded


def test_page_loads_in_chromium_with_the_report_numbers(run_dir, tmp_path):
    sync_api = browser_api()
    report = json.loads((run_dir / "report.json").read_text())
    errors: list = []
    with sync_api.sync_playwright() as pw:
        browser, page = open_page(pw, run_dir / "report.html", errors)
        headline = page.inner_text("#headline")
        assert fmt(report["per_frame"]["recall_mean"]) in headline
        assert fmt(report["iou50"]["ap"]) in headline
        run = page.inner_text("#run")
        assert "sample" in run and "gray-tophat" in run and "all" in run  # dataset, split
        assert min(report["params"]["detector"]) in page.inner_text("#params")
        assert report["versions"]["numpy"] in page.inner_text("#versions")
        assert fmt(report["iou50"]["precision"]) in page.inner_text("#iou")
        assert page.locator('a[href="report.json"]').count() == 1
        captions = page.eval_on_selector_all("figure > figcaption", "c => c.map(x => x.innerText)")
        plots = [c for c in captions if len(c) > 40]  # the plots' sentences, not crop labels
        assert len(plots) == len(report["plots"]) and not any(c.endswith(".png") for c in plots)
        widths = page.eval_on_selector_all("img", "imgs => imgs.map(i => i.naturalWidth)")
        assert widths and min(widths) > 0
        assert page.locator("img.gallery").count() > 0
        crops = page.eval_on_selector_all(
            "figure.crop img", "imgs => imgs.map(i => [i.naturalWidth, i.width])"
        )
        assert crops and all(natural == 160 and shown >= 160 for natural, shown in crops)
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


def test_compare_page_loads_in_chromium_with_readable_p_values(tmp_path):
    from click.testing import CliRunner

    from tsrkit.cli.main import cli

    sync_api = browser_api()
    stored = json.loads((REFERENCE / "compare_sample.compare.json").read_text())
    stored["paired_tests"][0]["p_value"] = 7.430843875383497e-14
    (tmp_path / "compare.json").write_text(json.dumps(stored))
    assert CliRunner().invoke(cli, ["report", str(tmp_path)]).exit_code == 0
    errors: list = []
    with sync_api.sync_playwright() as pw:
        browser, page = open_page(pw, tmp_path / "compare.html", errors)
        tests = page.inner_text("#tests")
        assert "7.4e-14" in tests and "e-14" in tests and "7.43084" not in tests
        runs = page.inner_text("#runs")
        assert all(name in runs for name in stored["detectors"])
        page.screenshot(path=str(tmp_path / "compare.png"), full_page=True)
        browser.close()
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
