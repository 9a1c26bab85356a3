"""``compare.html``: a compare folder's runs side by side, the paired tests, and links to each
run's page, from its ``compare.json``."""

from __future__ import annotations

import json
from pathlib import Path

from tsrkit.api import headline, title


def compare_page(folder: Path) -> str:
    """``compare.html``: the runs side by side, the paired tests, links to each run's page."""
    from tsrkit_plugins.writers.html import SCRIPT, STYLE, table

    data = json.loads((folder / "compare.json").read_text(encoding="utf-8"))
    reports = data["reports"]
    labels = list(headline(reports[0]))
    rows = [[title(r), *headline(r).values()] for r in reports]
    tests = [
        [str(t.get(k, "")) for k in ("a", "b", "metric", "verdict", "p_value", "frames")]
        for t in data.get("paired_tests", [])
    ]
    links = "".join(
        f'<li><a href="{d}/report.html">{d}</a></li>'
        for d in data["detectors"]
        if (folder / d / "report.html").is_file()
    )
    body = (
        f"<h1>compare on {data['dataset']}</h1>"
        + table("runs", ["run", *labels], rows)
        + "<h2>Paired tests</h2>"
        + table("tests", ["a", "b", "metric", "verdict", "p", "frames"], tests)
        + f"<h2>Each run</h2><ul>{links}</ul>"
    )
    return (
        f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>compare</title>'
        f"<style>{STYLE}</style></head><body>{body}<script>{SCRIPT}</script></body></html>"
    )
