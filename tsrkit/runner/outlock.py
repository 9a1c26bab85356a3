"""One run at a time per output folder or file: a lock file holding the writer's process id.

A second run into the same ``--out`` while the first is alive refuses with one clear line; a
lock left by a killed run (its process is gone) is taken over, and the temporary files a killed
run left (``.NAME.*.tmp`` of :func:`tsrkit.core.atomic.atomic_open`, the writers' ``.writing-*``
folder of :func:`tsrkit.reporting.benchmarking.staged`) are removed then.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import time
from collections.abc import Iterator
from pathlib import Path

from tsrkit.core.errors import TsrkitError
from tsrkit.runner.workers import alive

__all__ = ["LOCK", "OutputBusy", "locked", "locked_file"]

LOCK = ".tsrkit.lock"


class OutputBusy(TsrkitError):
    """Another live run is writing the same output folder."""


@contextlib.contextmanager
def locked(folder: str | os.PathLike) -> Iterator[Path]:
    """Hold ``folder``'s lock while the block runs.

    Raises
    ------
    OutputBusy
        When a live process (not this one) holds it.
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)

    def clean() -> None:
        for leftover in folder.rglob(".*.tmp"):
            leftover.unlink(missing_ok=True)
        for staging in folder.glob(".writing-*"):  # a killed run's unfinished report files
            shutil.rmtree(staging, ignore_errors=True)

    with _held(folder / LOCK, f"{folder}: another run (process {{}}) is writing here", clean):
        yield folder


@contextlib.contextmanager
def locked_file(path: str | os.PathLike) -> Iterator[Path]:
    """Hold the lock of the output file ``path`` (``.NAME.tsrkit.lock`` beside it) while the
    block runs: two runs writing one file would mix or lose each other's lines.

    Raises
    ------
    OutputBusy
        When a live process (not this one) holds it.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    lock = path.with_name(f".{path.name}{LOCK}")
    with _held(lock, f"{path}: another run (process {{}}) is writing it", lambda: None):
        yield path


#: Seconds a lock file may stay empty (its owner between creating and writing it).
_FRESH = 5.0


@contextlib.contextmanager
def _held(lock: Path, busy: str, clean) -> Iterator[None]:
    """Create ``lock`` holding this process id, taking over one whose process is gone (and
    running ``clean`` then); ``busy`` (with ``{}`` for the owner) is the refusal."""
    for _ in range(2):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            try:
                text = lock.read_text().strip()
                age = time.time() - lock.stat().st_mtime
            except OSError:
                continue  # released meanwhile: try again
            owner = int(text) if text.isdigit() else 0
            if (owner and owner != os.getpid() and alive(owner)) or (not text and age < _FRESH):
                raise OutputBusy(
                    busy.format(owner or "starting") + "; wait for it or choose another --out"
                ) from None
            lock.unlink(missing_ok=True)  # left by a killed run: take it over
            clean()
            continue
        with os.fdopen(fd, "w") as fh:
            fh.write(str(os.getpid()))
        break
    else:
        raise OutputBusy(f"cannot take the output lock {lock}")
    try:
        yield
    finally:
        lock.unlink(missing_ok=True)
