"""The hooks a tsrkit plugin may implement (pluggy specifications).

Each ``register_*`` hook receives a ``register`` callable; call it once per plugin class.
``register_commands`` receives the root click group so a plugin can add a verb. The built-in
methods, metrics, report writers and verbs are registered through these same hooks.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import pluggy

if TYPE_CHECKING:
    import click

    from tsrkit.plugin.base import (
        Classifier,
        DatasetFormat,
        Detector,
        Metric,
        ReportWriter,
        Tracker,
        Verifier,
    )

__all__ = [
    "ENTRY_POINT_GROUP",
    "hookimpl",
    "hookspec",
    "register_classifiers",
    "register_commands",
    "register_dataset_formats",
    "register_detectors",
    "register_metrics",
    "register_report_writers",
    "register_trackers",
    "register_verifiers",
]

#: The entry-point group a package declares its tsrkit plugins in (``pyproject.toml``:
#: ``[project.entry-points.tsrkit]``).
ENTRY_POINT_GROUP = "tsrkit"

hookspec = pluggy.HookspecMarker(ENTRY_POINT_GROUP)
hookimpl = pluggy.HookimplMarker(ENTRY_POINT_GROUP)


@hookspec
def register_detectors(register: Callable[[type[Detector]], None]) -> None:
    """Register :class:`tsrkit.Detector` subclasses: ``register(MyDetector)``."""


@hookspec
def register_verifiers(register: Callable[[type[Verifier]], None]) -> None:
    """Register :class:`tsrkit.Verifier` subclasses."""


@hookspec
def register_classifiers(register: Callable[[type[Classifier]], None]) -> None:
    """Register :class:`tsrkit.Classifier` subclasses."""


@hookspec
def register_trackers(register: Callable[[type[Tracker]], None]) -> None:
    """Register :class:`tsrkit.Tracker` subclasses."""


@hookspec
def register_dataset_formats(register: Callable[[type[DatasetFormat]], None]) -> None:
    """Register :class:`tsrkit.DatasetFormat` subclasses."""


@hookspec
def register_metrics(register: Callable[[type[Metric]], None]) -> None:
    """Register :class:`tsrkit.Metric` subclasses; each adds its sections to ``report.json``."""


@hookspec
def register_report_writers(register: Callable[[type[ReportWriter]], None]) -> None:
    """Register :class:`tsrkit.ReportWriter` subclasses; each writes files of a run's folder."""


@hookspec
def register_commands(cli: click.Group) -> None:
    """Add click commands to the ``tsrkit`` group ``cli``."""
