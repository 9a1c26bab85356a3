"""Where each verb shipped with tsrkit lives, so ``tsrkit --help`` lists them without importing
any of them (or NumPy, OpenCV and the plugins they pull in).

A verb's module is imported when the verb runs; the summary is what ``--help`` shows until then
(``tests/cli/test_cli_startup.py`` checks it against the command's own help). Verbs of other
installed packages come through the ``register_commands`` hook (:mod:`tsrkit.cli.main`).
"""

from __future__ import annotations

from typing import NamedTuple

__all__ = ["VERBS", "Verb"]


class Verb(NamedTuple):
    """A verb's module, the click command's attribute in it, and its one-line summary."""

    module: str
    attribute: str
    summary: str


VERBS = {
    "benchmark": Verb(
        "tsrkit.cli.benchmark",
        "benchmark_command",
        "Run a detector (and classifier) over a dataset and write an evaluated report.",
    ),
    "compare": Verb(
        "tsrkit.cli.benchmark",
        "compare_command",
        "Benchmark several detectors (or whole pipelines: --configs) on the same frames; one "
        "report side by side.",
    ),
    "datasets": Verb(
        "tsrkit.cli.datasets",
        "datasets_group",
        "The dataset registry (datasets.yaml): list, info NAME, verify NAME, convert SRC.",
    ),
    "detect": Verb(
        "tsrkit.cli.detect",
        "detect_command",
        "Detect lit signal lenses in images, folders (recursive) or videos.",
    ),
    "plugins": Verb(
        "tsrkit.cli.plugins_cmd",
        "plugins_command",
        "List installed plugins: name, kind, package, version and summary.",
    ),
    "presets": Verb(
        "tsrkit.cli.presets_cmd",
        "presets_command",
        "List the shipped presets; use one with --config NAME on detect, benchmark or compare.",
    ),
    "report": Verb(
        "tsrkit.cli.report",
        "report_command",
        "Write RUN_DIR/report.html (a benchmark or `track VIDEO --out` folder) or "
        "RUN_DIR/compare.html (a compare folder) from the files the run left, without "
        "recomputing.",
    ),
    "study": Verb(
        "tsrkit.cli.study",
        "study_command",
        "Run `tsrkit track VIDEO --gps LOG --map MAP` on every drive of MANIFEST (CSV or YAML: "
        "video, gps, map, optional name and start_utc) into OUT/drives/NAME/, skipping drives "
        "finished before (a killed study resumes), then write the combined timelines.csv and "
        "events.csv (a `drive` column first) and traversals.geojson into OUT.",
    ),
    "track": Verb(
        "tsrkit.cli.track",
        "track_command",
        "List the traversals of the GPS track through the map's signalised intersections; "
        "with VIDEO, recognise the signal states of each traversal on its clip "
        "(Zheng 2016, 3.4).",
    ),
    "train": Verb(
        "tsrkit.cli.train",
        "train_command",
        "Fit PLUGIN (a trainable detector, verifier or classifier) and save the model for "
        "--param model=.",
    ),
}
