"""A run's folder: the report writers write it (:func:`write_run`), and it is read back to be
written again without recomputing (:func:`load_run`, for ``tsrkit report``).

A writer that raises, or a plot that cannot be drawn, is left out and does not stop the others:
when anything failed, the writers that succeeded write again with a report that lists the failure
(``notes`` and ``failures``) and no longer lists the failed writer's files, so that every summary
says what is missing.
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from tsrkit.core.errors import TsrkitError
from tsrkit.core.files import loads_json, read_text
from tsrkit.core.outputs import refuse_input
from tsrkit.core.records import FrameRecord
from tsrkit.core.types import Dataset
from tsrkit.datasets import open_dataset
from tsrkit.eval.guard import Failure
from tsrkit.eval.settings import eval_settings
from tsrkit.plugin.base import ReportWriter
from tsrkit.plugin.registry import get_registry
from tsrkit.reporting.report import RunResult, run_results, with_outputs
from tsrkit.reporting.track import TrackFacts, TraversalsResult, is_track_report, load_track_run

__all__ = [
    "ReportBuilder",
    "load_run",
    "read_comparison",
    "read_object",
    "read_records",
    "read_report",
    "refuse_foreign_report",
    "remove_stale_files",
    "reopen",
    "write_run",
    "write_track_run",
    "writers_for",
]

#: Builds the run's report from the files the writers write and the failures so far.
ReportBuilder = Callable[[Sequence[str], Sequence[Failure]], dict[str, Any]]


def write_run(
    run: RunResult, writers: Sequence[ReportWriter], folder: Path, report: ReportBuilder
) -> RunResult:
    """Let every writer write ``folder``; return the run as finally written.

    ``report(files, failures)`` builds ``report.json`` from the files the writers declare and
    the failures so far (:attr:`RunResult.failures`). A writer whose ``files`` or ``write``
    raises, or a plot that cannot be drawn, is added to the failures; when ``write`` added any,
    the writers that did not fail write once more, so that their files say so.
    """
    listed: dict[str, list[str]] = {}
    for writer in writers:
        try:
            listed[writer.name] = list(writer.files(run))
        except Exception as exc:
            run.failures.append(Failure.of(f"writer '{writer.name}'", exc))
    chosen = [w for w in writers if listed.get(w.name)]  # a writer with nothing to write is idle
    remove_stale_files(folder, {f for names in listed.values() for f in names})
    known = len(run.failures)
    run = _with_report(run, report, [listed[w.name] for w in chosen])
    failed = _write_all(run, chosen, folder)
    if len(run.failures) == known:
        return run
    kept = [w for w in chosen if w.name not in failed]
    run = _with_report(run, report, [listed[w.name] for w in kept])
    _write_all(run, kept, folder)
    return run


def refuse_foreign_report(folder: Path) -> None:
    """Refuse an output folder holding a ``report.json`` that no tsrkit run wrote: the run
    would replace it (a rerun into a run's own folder replaces that run's report, as it
    should).

    Raises
    ------
    TsrkitError
        When ``folder/report.json`` exists and is an input of this run or not a run's report.
    """
    path = folder / "report.json"
    if not os.path.lexists(path):
        return
    refuse_input(path, "the run's report")
    try:
        report = read_object(path)
    except TsrkitError:
        report = {}
    if not isinstance(report.get("dataset"), dict):
        raise TsrkitError(
            f"{path}: not a tsrkit run's report, and the run would replace it; choose another --out"
        )


def remove_stale_files(folder: Path, keep: set[str]) -> list[str]:
    """Delete the files an earlier run's ``report.json`` in ``folder`` lists and this run will
    not write (a rerun with fewer writers or plots replaces the old report completely).

    Only names the old report lists, inside ``folder``, are touched; an unreadable old report
    removes nothing. Returns the names removed.
    """
    try:
        old = json.loads((folder / "report.json").read_text(encoding="utf-8"))
        listed = [*old.get("files", []), *old.get("plots", [])]
    except (OSError, ValueError, AttributeError, TypeError):
        return []
    root = folder.resolve()
    removed = []
    for name in listed:
        if not isinstance(name, str) or name in keep:
            continue
        path = (folder / name).resolve()
        if path.is_relative_to(root) and path != root and path.is_file():
            path.unlink()
            removed.append(name)
    return removed


def _with_report(
    run: RunResult, report: ReportBuilder, files: Sequence[Sequence[str]]
) -> RunResult:
    """``run`` with its report listing ``files`` and the failures so far."""
    listed = [name for names in files for name in names]
    return dataclasses.replace(run, report=report(listed, run.failures))


def _write_all(run: RunResult, writers: Sequence[ReportWriter], folder: Path) -> set[str]:
    """Run every writer; record the failures of those that raise; return their names."""
    failed = set()
    for writer in writers:
        try:
            writer.write(run, folder)
        except Exception as exc:
            run.failures.append(Failure.of(f"writer '{writer.name}'", exc))
            failed.add(writer.name)
    return failed


def load_run(folder: Path) -> RunResult:
    """The :class:`RunResult` of a benchmark folder, from its ``report.json`` and
    ``detections.jsonl``, with the dataset opened again as the run opened it (by registry name
    or path, format and image folder, and split); or of a ``tsrkit track VIDEO`` folder
    (:func:`tsrkit.reporting.track.load_track_run`).

    A dataset that cannot be opened again (moved, or several concatenated) leaves the run
    without ground truth: its results and tables are complete, the frames' overlays are not.

    Raises
    ------
    TsrkitError
        Not a run folder, or a ``report.json`` / ``detections.jsonl`` that is not what a run
        writes (naming the file, the line and the problem).
    """
    report = read_object(folder / "report.json")

    if is_track_report(report):
        return load_track_run(folder, report)
    if not isinstance(report.get("dataset"), dict):
        raise TsrkitError(f"{folder / 'report.json'}: not a tsrkit report (no 'dataset' entry)")
    records = read_records(folder / "detections.jsonl")
    try:
        results = run_results(report)
    except (KeyError, TypeError, AttributeError, ValueError) as exc:
        raise TsrkitError(f"{folder / 'report.json'}: not a tsrkit report ({exc!r})") from None
    dataset = reopen(report.get("dataset") or {})
    if dataset is None:
        return RunResult(report, results=results)
    index = {s.source: k for k, s in enumerate(dataset.samples)}
    kept = [
        dataclasses.replace(r, index=index[r.source])
        for r in records
        if r.skipped is None and r.source in index
    ]
    settings = eval_settings(dataset, True, 0.5, report.get("evaluated_box") or "auto")
    return RunResult(report, dataset, settings, tuple(kept), results)


def read_report(path: Path) -> dict[str, Any]:
    """A run's ``report.json`` (or a compare folder's ``compare.json``) as a dictionary.

    Raises
    ------
    TsrkitError
        Missing, empty, not JSON, or not a JSON object with the run's ``dataset``.
    """
    data = read_object(path)
    if "dataset" not in data:
        raise TsrkitError(f"{path}: not a tsrkit report (no 'dataset' entry)")
    return data


def read_object(path: Path) -> dict[str, Any]:
    """The JSON object of a run folder's ``report.json`` or ``compare.json``.

    Raises
    ------
    TsrkitError
        Missing (the folder is then not a run folder), empty, not JSON, or not an object.
    """
    if not path.exists() and (path.parent / "traversals.jsonl").is_file():
        raise TsrkitError(
            f"{path.parent}: a track run without a video (traversals.jsonl only) has no "
            "report to write again; tsrkit report reads the folders of benchmark, compare "
            "and track VIDEO --out"
        )
    if not os.path.lexists(path):
        raise TsrkitError(
            f"{path.parent}: not a run folder ({path.name} missing; tsrkit report reads the "
            "folders of benchmark, compare and track VIDEO --out)"
        )
    text = read_text(path)  # a special, unreadable or huge file: one line naming it
    if not text.strip():
        raise TsrkitError(f"{path}: empty file (the run did not finish writing it)")
    data = loads_json(text, path)
    if not isinstance(data, dict):
        raise TsrkitError(f"{path}: not a tsrkit report (not a JSON object)")
    return data


def read_comparison(folder: Path) -> dict[str, Any]:
    """A compare folder's ``compare.json``: the runs' reports side by side and the tests.

    Raises
    ------
    TsrkitError
        Missing, empty or not JSON, or without its ``reports`` (a list of run reports).
    """
    path = folder / "compare.json"
    data = read_report(path)
    reports = data.get("reports")
    if not isinstance(reports, list) or not reports:
        raise TsrkitError(f"{path}: not a tsrkit comparison (no 'reports' list)")
    if not all(isinstance(r, dict) and isinstance(r.get("dataset"), dict) for r in reports):
        raise TsrkitError(f"{path}: not a tsrkit comparison (a report without its dataset)")
    return data


def read_records(path: Path) -> list[FrameRecord]:
    """The records of a run's ``detections.jsonl``.

    Raises
    ------
    TsrkitError
        Missing file, or a line that is not a record (naming the line).
    """
    if not os.path.lexists(path):
        raise TsrkitError(f"{path.parent}: not a run folder ({path.name} missing)")
    lines = read_text(path).splitlines()
    records = []
    for number, line in enumerate(lines, 1):
        if not line.strip():
            continue
        try:
            data = loads_json(line, f"{path}: line {number}")
            records.append(FrameRecord.from_json(data))
        except (ValueError, KeyError, TypeError, AttributeError) as exc:
            problem = f"missing {exc}" if isinstance(exc, KeyError) else str(exc)
            raise TsrkitError(f"{path}: line {number}: not a frame record ({problem})") from None
    return records


def reopen(described: Mapping[str, Any]) -> Dataset | None:
    """The dataset a report's ``dataset`` entry describes, opened again; None when it cannot be
    (no ``opened_as``, or the files moved)."""
    opened = described.get("opened_as")
    if not isinstance(opened, Mapping) or not opened.get("ref"):
        return None
    try:
        dataset = open_dataset(
            opened["ref"], format=opened.get("format"), images=opened.get("images")
        )
    except (TsrkitError, OSError):
        return None
    name = str(described.get("name", ""))
    if name.startswith(dataset.name + ":"):  # the run used one split
        return dataset.split(name[len(dataset.name) + 1 :])
    return dataset


def writers_for(names: Sequence[str] | None) -> list[ReportWriter]:
    """The named report writers, or every registered writer that runs by default."""
    registry = get_registry()
    if names is None:
        names = [
            info.name for info in registry.plugins("writer") if getattr(info.cls, "default", False)
        ]
    return [registry.create("writer", name) for name in names]


def write_track_run(
    out: Path,
    report: Mapping[str, Any],
    records: Sequence[Mapping[str, Any]],
    profile: tuple[np.ndarray, np.ndarray],
    vicinity: float,
) -> RunResult:
    """Write a track run's folder with the default report writers (``report.json``,
    ``summary.md``, ``report.html``, ``headline.csv``, ``plots/``...)."""
    counted = {k: report[k] for k in ("traversals", "temporal") if k in report}
    frames, distance = profile
    traversals = TraversalsResult(counted, "traversals", tuple(records), frames, distance, vicinity)
    run = RunResult(dict(report), results=(TrackFacts(report, "run"), traversals))

    def build(files: Sequence[str], failures: Sequence[Failure]) -> dict[str, Any]:
        return with_outputs(report, files, failures=failures)

    return write_run(run, writers_for(None), out, build)
