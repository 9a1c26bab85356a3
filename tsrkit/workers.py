"""Worker processes: how many a run may start, and their end when the run that started them
ends, even by ``kill -9`` (which runs no clean-up in the run itself).

Pools fork their workers from a fork server (:func:`tsrkit.engine.pool_context`), which exits
when the run's process is gone; a worker then finds itself re-parented and ends within a second
(:func:`end_with_parent`).
"""

from __future__ import annotations

import os
import threading
import time

from tsrkit.errors import TsrkitError

#: Worker processes per core at most: more only adds memory and switching.
WORKERS_PER_CORE = 4


def max_workers() -> int:
    """The most worker processes one run may start on this machine."""
    return WORKERS_PER_CORE * (os.cpu_count() or 1)


def check_workers(workers: int, option: str = "--workers") -> int:
    """``workers`` when it is at least 1 and at most :func:`max_workers`.

    Raises
    ------
    TsrkitError
        Naming the option, the value and the bound.
    """
    limit = max_workers()
    if not 1 <= workers <= limit:
        raise TsrkitError(
            f"{option} {workers}: must be between 1 and {limit} "
            f"({WORKERS_PER_CORE} per core of this machine's {os.cpu_count() or 1})"
        )
    return workers


def end_with_parent(poll: float = 1.0) -> None:
    """In a worker process: end it (``os._exit``) once its parent process is gone.

    The parent is the fork server or the run itself; when it ends the worker is re-parented,
    which a daemon thread notices within ``poll`` seconds.
    """
    parent = os.getppid()

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(poll)
        os._exit(1)

    threading.Thread(target=watch, name="tsrkit-end-with-parent", daemon=True).start()
