"""One run at a time per output folder: a lock file holding the writer's process id.

A second run into the same ``--out`` while the first is alive refuses with one clear line; a
lock left by a killed run (its process is gone) is taken over, and the temporary files a killed
run left (``.NAME.*.tmp`` of :func:`tsrkit.atomic.atomic_open`) are removed then.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path

from tsrkit.errors import TsrkitError

__all__ = ["LOCK", "OutputBusy", "locked"]

LOCK = ".tsrkit.lock"


class OutputBusy(TsrkitError):
    """Another live run is writing the same output folder."""


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


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
    lock = folder / LOCK
    for _ in range(2):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            try:
                owner = int(lock.read_text().strip() or 0)
            except (OSError, ValueError):
                owner = 0
            if owner and owner != os.getpid() and _alive(owner):
                raise OutputBusy(
                    f"{folder}: another run (process {owner}) is writing here; wait for it or "
                    "choose another --out"
                ) from None
            lock.unlink(missing_ok=True)  # left by a killed run: take it over
            for leftover in folder.rglob(".*.tmp"):
                leftover.unlink(missing_ok=True)
            continue
        with os.fdopen(fd, "w") as fh:
            fh.write(str(os.getpid()))
        break
    else:
        raise OutputBusy(f"{folder}: cannot take the output lock {lock}")
    try:
        yield folder
    finally:
        lock.unlink(missing_ok=True)
