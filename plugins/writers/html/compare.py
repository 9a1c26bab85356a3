"""``compare.html``: a compare folder's runs side by side (every headline figure any run has),
the paired tests with their p-values formatted for a reader, the AP50 of each evaluated box, and
links to each run's page and to the comparison's files, from its ``compare.json``."""

from __future__ import annotations

import html
from pathlib import Path

from tsrkit.api import figure_notes, fmt, format_p, headline_rows, read_comparison, title

#: The columns of the paired-test table: (key of a test, column label).
TEST_COLUMNS = (
    ("a", "A"),
    ("b", "B"),
    ("metric", "figure"),
    ("frames", "frames"),
    ("mean_difference", "mean A - B"),
    ("p_value", "p"),
    ("verdict", "verdict"),
)


def _test_row(test: dict) -> list[str]:
    cells = []
    for key, _ in TEST_COLUMNS:
        value = test.get(key)
        cells.append(format_p(value) if key == "p_value" else fmt(value))
    return cells


def compare_page(folder: Path) -> str:
    """``compare.html``: the runs side by side, the paired tests, links to each run's page."""
    from tsrkit_plugins.writers.html import SCRIPT, STYLE, table

    data = read_comparison(folder)
    reports = data["reports"]
    columns, values = headline_rows(reports)
    notes = figure_notes(columns)
    header = [label for _, label in TEST_COLUMNS]
    runs = [str(r) for r in data.get("runs") or data.get("detectors") or []]
    name = f"Comparison on {data.get('dataset', '-')}"
    parts = [
        f"<h1>{html.escape(name)}</h1>",
        '<p class="files">Files: <a href="compare.json">compare.json</a> '
        '<a href="compare.md">compare.md</a></p>',
        "<h2>Runs</h2>",
        table(
            "runs",
            ["run", *(f.label for f in columns)],
            [[title(r), *row] for r, row in zip(reports, values)],
        ),
        f'<p class="caption">{html.escape(notes)}</p>',
        "<h2>Paired tests on the same frames (Wilcoxon signed-rank)</h2>",
        table("tests", header, [_test_row(t) for t in data.get("paired_tests", [])]),
    ]
    if data.get("verifier_tests"):
        parts += [
            "<h2>With vs without the verifier (Wilcoxon signed-rank on the same frames)</h2>",
            table("verifier-tests", header, [_test_row(t) for t in data["verifier_tests"]]),
        ]
    if data.get("box_ap50"):
        parts += [
            "<h2>AP50 by evaluated box (pycocotools): the lens circle's box vs the housing</h2>",
            table(
                "box-ap50",
                ["run", "lens AP50", "housing AP50"],
                [
                    [str(b.get("run")), fmt(b.get("lens")), fmt(b.get("housing"))]
                    for b in data["box_ap50"]
                ],
            ),
        ]
    links = "".join(
        f'<li><a href="{html.escape(run)}/report.html">{html.escape(run)}</a></li>'
        for run in runs
        if (folder / run / "report.html").is_file()
    )
    if links:
        parts.append(f"<h2>Each run</h2><ul>{links}</ul>")
    return (
        f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>{html.escape(name)}'
        f"</title><style>{STYLE}</style></head><body>{''.join(parts)}<script>{SCRIPT}</script>"
        "</body></html>"
    )
