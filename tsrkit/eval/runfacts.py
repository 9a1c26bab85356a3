"""The results of a benchmark run that no metric computes: what was run on what, its timing,
and the inputs it skipped. They render like a metric's results, first and last."""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

from tsrkit.core.results import Figure, MetricResult, Table, fmt

__all__ = ["STAGES", "RunFacts", "RunTiming", "SkippedInputs", "description_tables", "run_facts"]

#: The plugin stages of a benchmark report, in pipeline order.
STAGES = ("detector", "verifier", "classifier")


@dataclass(frozen=True)
class RunFacts(MetricResult):
    """The run's description: dataset and split, the evaluated box, the plugins with their
    versions and parameters, and the library versions."""

    order: ClassVar[int] = 0

    def tables(self) -> list[Table]:
        dataset = self.sections.get("dataset") or {}
        name = str(dataset.get("name", "-"))
        base, _, split = name.partition(":")
        rows = [
            ("dataset", base),
            ("split", split or "all"),
            *((key, fmt(dataset.get(key))) for key in ("format", "samples", "root")),
            ("box convention", fmt(dataset.get("box_convention"))),
            ("evaluated box", fmt(self.sections.get("evaluated_box"))),
            ("frames evaluated", fmt(self.sections.get("frames"))),
        ]
        plugins = {k: self.sections[k] for k in STAGES if self.sections.get(k)}
        return description_tables(rows, plugins, (), {}, self.sections.get("versions") or {})


def description_tables(
    rows: Sequence[tuple[str, str]],
    plugins: Mapping[str, Mapping[str, Any]],
    settings: Sequence[tuple[str, str, str]],
    timing: Mapping[str, Any],
    versions: Mapping[str, Any],
) -> list[Table]:
    """A run's description as tables: ``Run`` (``rows``, then each plugin's name and version),
    ``Parameters`` (each plugin's, then ``settings`` rows), ``Timing`` and ``Versions`` (those
    that are not empty)."""
    rows = [
        *rows,
        *((k, f"{p['name']} {p.get('version', '')}".strip()) for k, p in plugins.items()),
    ]
    parameters = [
        (kind, key, json.dumps(value))
        for kind, plugin in plugins.items()
        for key, value in sorted((plugin.get("params") or {}).items())
    ]
    parts: list[tuple[str, str, tuple[str, ...], list[tuple[str, ...]]]] = [
        ("params", "Parameters", ("stage", "parameter", "value"), [*parameters, *settings]),
        ("timing", "Timing", ("", "value"), [(k, fmt(v, ".2f")) for k, v in timing.items()]),
        (
            "versions",
            "Versions",
            ("package", "version"),
            [(k, str(v)) for k, v in versions.items()],
        ),
    ]
    return [Table("run", "Run", ("", "value"), tuple(rows))] + [
        Table(ident, title, columns, tuple(body)) for ident, title, columns, body in parts if body
    ]


@dataclass(frozen=True)
class RunTiming(MetricResult):
    """``timing``: the median milliseconds per frame as a headline figure, and the details."""

    order: ClassVar[int] = 90

    @property
    def timing(self) -> Mapping[str, Any]:
        return self.sections.get("timing") or {}

    def headline(self) -> list[Figure]:
        return [
            Figure(
                "timing.ms_per_frame_median",
                "ms",
                self.timing.get("ms_per_frame_median"),
                ".1f",
                about="median compute time per frame",
            )
        ]

    def tables(self) -> list[Table]:
        rows = tuple((key, fmt(value, ".2f")) for key, value in self.timing.items())
        if not rows:
            return []
        return [
            Table(
                "timing",
                "Timing",
                ("", "value"),
                rows,
                "ms per frame: the detector's and classifier's compute time of a frame, "
                "decoding and I/O excluded (cached frames keep the time they were computed in).",
            )
        ]


@dataclass(frozen=True)
class SkippedInputs(MetricResult):
    """``skipped``: every input that could not be read, with the reason."""

    order: ClassVar[int] = 95

    def tables(self) -> list[Table]:
        skipped = self.sections.get("skipped") or []
        if not skipped:
            return []
        rows = tuple((str(s.get("source")), str(s.get("reason"))) for s in skipped)
        return [Table("skipped", "Skipped", ("source", "reason"), rows)]


def run_facts(report: Mapping[str, Any]) -> list[MetricResult]:
    """The run's own results (description, timing, skipped inputs) from its report."""
    described = ("dataset", *STAGES, "evaluated_box", "frames", "versions")
    return [
        RunFacts({k: report[k] for k in described if k in report}, "run"),
        RunTiming({"timing": report.get("timing") or {}}, "timing"),
        SkippedInputs({"skipped": report.get("skipped") or []}, "skipped"),
    ]
