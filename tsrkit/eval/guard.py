"""Metrics run so that one that fails cannot take the report with it.

A metric that raises (in ``reset``, ``update`` or ``compute``), returns something that is not its
declared result type, renders badly (a headline figure that is not a :class:`Figure`, a table
row of the wrong width) or writes a report section another metric already wrote is left out of
the report and listed in its :class:`Failure` list; every other metric's sections and renderings
are kept. The report says which failed and why (``notes`` and ``failures`` of ``report.json``,
and every summary shows the notes).
"""

from __future__ import annotations

import dataclasses
import functools
import json
import re
from collections import Counter
from collections.abc import Callable, Mapping, Set
from dataclasses import dataclass
from typing import Any

from tsrkit.core.records import FrameRecord
from tsrkit.core.results import Figure, MetricResult, Plot, Table
from tsrkit.core.types import Sample
from tsrkit.eval.settings import EvalSettings
from tsrkit.plugin.base import Metric, Plugin

__all__ = [
    "MESSAGE_CHARS",
    "PLOT_NAME",
    "Failure",
    "GuardedMetrics",
    "MetricFault",
    "check_rendering",
    "checked",
    "clashes",
    "merge_into",
]

#: What a plot's file name may be (it is written under ``plots/``).
PLOT_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*\.png")
#: Longest error message kept in a failure (a message can be a whole traceback or data dump).
MESSAGE_CHARS = 300


@dataclass(frozen=True)
class Failure:
    """A plugin that failed during a run: which (``metric 'x'``, ``writer 'y'``) and why."""

    plugin: str
    error: str

    @classmethod
    def of(cls, plugin: str, exc: BaseException) -> Failure:
        """The failure of ``plugin`` raising ``exc``: the exception's type and first line."""
        text = " ".join(str(exc).split())
        if len(text) > MESSAGE_CHARS:
            text = text[: MESSAGE_CHARS - 3] + "..."
        return cls(plugin, f"{type(exc).__name__}: {text}" if text else type(exc).__name__)

    @property
    def note(self) -> str:
        """The sentence of the report's notes."""
        return f"{self.plugin} failed and was left out ({self.error})"

    def to_json(self) -> dict[str, str]:
        return {"plugin": self.plugin, "error": self.error}


class MetricFault(Exception):
    """A metric's result breaks the result contract (wrong type, bad rendering, clashing key)."""


class GuardedMetrics:
    """Metrics fed together; one that fails is dropped and recorded in :attr:`failures`.

    Parameters
    ----------
    factories : mapping
        ``{name: make}``: each metric's name and what creates it, in the order their sections
        enter ``report.json``.
    settings : EvalSettings
        Every metric is reset with them.
    """

    def __init__(self, factories: Mapping[str, Callable[[], Plugin]], settings: EvalSettings):
        self.failures: list[Failure] = []
        self.metrics: list[Metric] = []
        for name, make in factories.items():
            ok, metric = self._attempt(name, functools.partial(_made, make))
            if ok and self._attempt(name, functools.partial(metric.reset, settings))[0]:
                self.metrics.append(metric)

    def _attempt(self, name: str, step: Callable[[], Any]) -> tuple[bool, Any]:
        """``(True, step())``; or, when metric ``name``'s step raises, the failure recorded and
        ``(False, None)``."""
        try:
            return True, step()
        except MetricFault as exc:
            self.failures.append(Failure(f"metric '{name}'", str(exc)))
        except Exception as exc:
            self.failures.append(Failure.of(f"metric '{name}'", exc))
        return False, None

    def update(self, sample: Sample, record: FrameRecord) -> None:
        """Fold one frame into every metric still running."""
        self.metrics = [
            m
            for m in self.metrics
            if self._attempt(m.name, functools.partial(m.update, sample, record))[0]
        ]

    def compute(
        self, reserved: Set[str] = frozenset()
    ) -> tuple[dict[str, Any], list[MetricResult], dict[str, list[str]]]:
        """The merged report sections, the results (in the metrics' order) and which report
        entries each metric wrote (``{"name": ["section", "shared_section.key"]}``: a section
        that several metrics fill is listed key by key). ``reserved`` are the report's own keys,
        which no metric may write."""
        sections: dict[str, Any] = {}
        results: list[MetricResult] = []
        for metric in self.metrics:
            taken = {p.name for r in results for p in r.plots()}
            ok, result = self._attempt(
                metric.name, functools.partial(checked, metric, sections, taken, reserved)
            )
            if ok:
                merge_into(sections, result)
                results.append(result)
        claims = Counter(section for r in results for section in r.sections)
        written = {
            r.metric: [
                f"{section}.{key}" if claims[section] > 1 else section
                for section, value in r.sections.items()
                for key in (value if claims[section] > 1 else [None])
            ]
            for r in results
        }
        return sections, results, written


def _made(make: Callable[[], Plugin]) -> Metric:
    """``make()``, which must be a metric."""
    metric = make()
    if not isinstance(metric, Metric):
        raise MetricFault(f"registered as a metric but is a {type(metric).__name__}")
    return metric


def clashes(sections: Mapping[str, Any], result: MetricResult) -> str | None:
    """What of ``result`` another metric already wrote into ``sections``, or None.

    A section two metrics fill (``iou50``) is merged key by key, so two mappings clash only on
    a common key.
    """
    for section, value in result.sections.items():
        if section not in sections:
            continue
        if not (isinstance(value, Mapping) and isinstance(sections[section], Mapping)):
            return f"report section '{section}'"
        common = sorted(value.keys() & sections[section].keys())
        if common:
            return f"report key '{section}.{common[0]}'"
    return None


def merge_into(sections: dict[str, Any], result: MetricResult) -> None:
    """Add ``result``'s sections (checked by :func:`clashes`) to ``sections``."""
    for section, value in result.sections.items():
        if section in sections:
            sections[section].update(value)
        else:
            sections[section] = dict(value) if isinstance(value, Mapping) else value


def checked(
    metric: Metric,
    sections: Mapping[str, Any],
    plots: Set[str] = frozenset(),
    reserved: Set[str] = frozenset(),
) -> MetricResult:
    """``metric.compute()`` as its declared result type, named, its rendering checked against
    the writers' types, its sections against those already in ``sections`` and the report's
    own keys (``reserved``), and its plots' names against ``plots`` (those of other metrics).

    A plain mapping is taken as the sections of the metric's ``result_type``.

    Raises
    ------
    MetricFault
        The result is not the declared type, its sections are not JSON or clash with
        ``sections``, or a rendering method returns something a writer cannot show.
    """
    result = metric.compute()
    kind = type(metric).result_type
    if isinstance(result, Mapping):
        result = kind(dict(result))
    if type(result) is not kind:
        raise MetricFault(
            f"compute returned {type(result).__name__}, not its result_type {kind.__name__}"
        )
    result = dataclasses.replace(result, metric=metric.name)
    check_rendering(result)
    own = sorted(result.sections.keys() & reserved)
    if own:
        raise MetricFault(f"report section '{own[0]}' is the report's own")
    clash = clashes(sections, result)
    if clash:
        raise MetricFault(f"{clash} is already written by another metric")
    for plot in result.plots():
        if plot.name in plots:
            raise MetricFault(f"plot '{plot.name}' is already drawn by another metric")
    return result


def check_rendering(result: MetricResult) -> None:
    """Raise :class:`MetricFault` unless ``result`` is JSON and renders into the writers' types."""
    if not all(isinstance(key, str) and "." not in key for key in result.sections):
        raise MetricFault("report sections must be named by strings without a dot")
    try:
        json.dumps(result.sections, allow_nan=True)
    except (TypeError, ValueError) as exc:
        raise MetricFault(f"sections are not JSON: {exc}") from None
    for method, kind in (
        (result.headline, Figure),
        (result.remarks, str),
        (result.tables, Table),
        (result.plots, Plot),
    ):
        items = method()
        if not isinstance(items, list) or not all(isinstance(i, kind) for i in items):
            raise MetricFault(f"{method.__name__}() must return a list of {kind.__name__}")
    for table in result.tables():
        if any(len(row) != len(table.columns) for row in table.rows):
            raise MetricFault(f"table '{table.ident}' has rows of the wrong width")
    for plot in result.plots():
        if not PLOT_NAME.fullmatch(plot.name):
            raise MetricFault(f"plot name '{plot.name}' is not a plain file name ending in .png")
