"""Metric results that render themselves: headline figures, remarks, tables and plots.

A :class:`~tsrkit.plugin.base.Metric`'s ``compute`` returns a :class:`MetricResult`: the report
sections it adds to ``report.json`` (``sections``) and, derived from them alone, what a reader
sees: :meth:`~MetricResult.headline` figures, :meth:`~MetricResult.remarks`,
:meth:`~MetricResult.tables` and :meth:`~MetricResult.plots`. Every report writer (Markdown,
HTML, CSV, plots) renders any result through these four methods, so a new metric reaches every
file without a writer edited.

Because a result is a function of its sections, ``tsrkit report`` rebuilds the same result from
``report.json`` (:func:`tsrkit.reporting.report.run_results`) and renders the same page again. The
base
class renders any sections generically (every scalar as a row of a table), which is also what
a metric returning a plain dictionary gets.
"""

from __future__ import annotations

import io
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar

if TYPE_CHECKING:
    from matplotlib.figure import Figure as MplFigure

__all__ = ["Figure", "MetricResult", "Plot", "Table", "fmt", "scalar_leaves"]


def fmt(value: Any, spec: str = ".3f") -> str:
    """A number for a table (``spec`` for floats), or a dash for a missing value.

    Examples
    --------
    >>> fmt(0.12345), fmt(None), fmt(3), fmt(2.5, ".1f")
    ('0.123', '-', '3', '2.5')
    """
    if value is None:
        return "-"
    return format(value, spec) if isinstance(value, float) else str(value)


@dataclass(frozen=True)
class Figure:
    """A headline figure: one number a reader compares between runs.

    Parameters
    ----------
    key : str
        Where the number is in ``report.json`` (``"per_frame.recall_mean"``); the column of
        ``headline.csv``.
    label : str
        The short column name of the tables (``"recall"``).
    value : float, int or None
    spec : str
        Format of a float (``".3f"``).
    interval : pair of float, optional
        A 95 % interval of the value.
    about : str
        What the figure is, in a few words (the caption of a table of runs).
    """

    key: str
    label: str
    value: float | int | None
    spec: str = ".3f"
    interval: tuple[float, float] | None = None
    about: str = ""

    @property
    def text(self) -> str:
        """The formatted value."""
        return fmt(self.value, self.spec)

    @property
    def interval_text(self) -> str:
        """The formatted interval, or an empty string."""
        if self.interval is None:
            return ""
        low, high = self.interval
        return f"{fmt(low, self.spec)} - {fmt(high, self.spec)}"


@dataclass(frozen=True)
class Table:
    """A table of formatted cells.

    ``ident`` names it in the HTML page (its element id, stable across runs); ``caption`` is
    printed below it.
    """

    ident: str
    title: str
    columns: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    caption: str = ""


@dataclass(frozen=True)
class Plot:
    """A plot: its file name under ``plots/``, the sentence that explains it, and how to draw it.

    ``draw`` receives an empty :class:`matplotlib.figure.Figure` of ``size`` inches and draws
    into it (axes, labels, legend); the writers own the backend, resolution and file.
    """

    name: str
    caption: str
    draw: Callable[[MplFigure], None] = field(repr=False, compare=False)
    size: tuple[float, float] = (5.0, 4.0)

    def png(self, dpi: int = 110) -> bytes:
        """The plot drawn and encoded as PNG (matplotlib's Agg canvas, no pyplot state)."""
        # matplotlib: only when a plot is drawn
        from matplotlib.figure import Figure as MplFigure

        figure = MplFigure(figsize=self.size)
        self.draw(figure)
        figure.tight_layout()
        buffer = io.BytesIO()
        figure.savefig(buffer, format="png", dpi=dpi)
        return buffer.getvalue()


@dataclass(frozen=True)
class MetricResult:
    """What a metric computed: its ``report.json`` sections and how they are shown.

    Subclasses read ``sections`` only (so that a result rebuilt from ``report.json`` renders
    alike) and override the methods below; this base class shows every scalar of every section
    in one table and has no headline figure and no plot.
    """

    sections: Mapping[str, Any]
    #: The metric that computed the result (its registry name); set by the evaluation.
    metric: str = ""
    #: Where the result's figures, tables and plots come among the others' (lower first; the
    #: run's description is 0, the built-in metrics 10-60, the run's timing 90).
    order: ClassVar[int] = 100

    def headline(self) -> list[Figure]:
        """The figures of the headline table and ``headline.csv``, in order."""
        return []

    def remarks(self) -> list[str]:
        """Sentences a reader must see beside the headline (what a figure leaves out)."""
        return []

    def tables(self) -> list[Table]:
        """The tables of the summary and the HTML page."""
        rows = tuple((path, fmt(value)) for path, value in scalar_leaves(self.sections))
        if not rows:
            return []
        title = self.metric or ", ".join(self.sections)
        return [Table(f"metric-{title}", title, ("figure", "value"), rows)]

    def plots(self) -> list[Plot]:
        """The plots (``plots/NAME`` and the HTML page)."""
        return []


def scalar_leaves(value: Any, path: str = "") -> Iterator[tuple[str, Any]]:
    """``(dotted path, value)`` of every number, string, boolean or None inside ``value``.

    Examples
    --------
    >>> list(scalar_leaves({"a": {"b": 1, "c": [2, {"d": None}]}}))
    [('a.b', 1), ('a.c.0', 2), ('a.c.1.d', None)]
    """
    if isinstance(value, Mapping):
        for key, item in value.items():
            yield from scalar_leaves(item, f"{path}.{key}" if path else str(key))
    elif isinstance(value, Sequence) and not isinstance(value, str):
        for k, item in enumerate(value):
            yield from scalar_leaves(item, f"{path}.{k}")
    else:
        yield path, value
