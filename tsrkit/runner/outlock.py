"""One run at a time per output folder or file: a lock file holding the writer's process id
and start time (``PID START``, START from ``/proc/PID/stat``, in clock ticks after boot).

A second run into the same ``--out`` while the first is alive refuses with one clear line
naming the lock file; a lock left by a killed run (its process is gone, or its process id now
belongs to a process started at another time, or, in a lock holding no start time, after the
lock was written) is taken over, and the temporary files a killed
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
    """Create ``lock`` holding this process id and start time, taking over one whose process
    is gone (and running ``clean`` then); ``busy`` (with ``{}`` for the owner) is the refusal."""
    for _ in range(2):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            try:
                text = lock.read_text().strip()
                written = lock.stat().st_mtime
            except OSError:
                continue  # released meanwhile: try again
            owner, _, started = text.partition(" ")
            pid = int(owner) if owner.isdigit() else 0
            live = pid != 0 and pid != os.getpid() and _runs(pid, started, written)
            if live or (not text and time.time() - written < _FRESH):
                raise OutputBusy(
                    busy.format(pid or "starting")
                    + f" (lock file {lock}); wait for it or choose another --out"
                ) from None
            lock.unlink(missing_ok=True)  # left by a killed run: take it over
            clean()
            continue
        with os.fdopen(fd, "w") as fh:
            fh.write(f"{os.getpid()} {_start_time(os.getpid())}".strip())
        break
    else:
        raise OutputBusy(f"cannot take the output lock {lock}")
    try:
        yield
    finally:
        lock.unlink(missing_ok=True)


def _start_time(pid: int) -> str:
    """Process ``pid``'s start time in clock ticks after boot (``/proc/PID/stat`` field 22), or
    ``""`` where there is no ``/proc``."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[19]
    except (OSError, IndexError):
        return ""


def _runs(pid: int, started: str, written: float) -> bool:
    """Whether the lock's owner, process ``pid`` started at ``started``, still runs: a live
    process under a reused id does not count. A lock of an older version holds no start time:
    then a process that started after the lock was ``written`` (a time stamp) is not its owner.
    """
    if not alive(pid):
        return False
    now = _start_time(pid)
    if started or not now:
        return now in ("", started)
    try:
        boot = next(
            float(line.split()[1])
            for line in Path("/proc/stat").read_text().splitlines()
            if line.startswith("btime ")
        )
    except (OSError, StopIteration, IndexError, ValueError):
        return True
    return boot + int(now) / os.sysconf("SC_CLK_TCK") <= written + 1.0  # 1 s: clock ticks
