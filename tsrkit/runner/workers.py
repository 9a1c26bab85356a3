"""Worker processes: how many a run may start, and their end when the run that started them
ends, even by ``kill -9`` (which runs no clean-up in the run itself).

Pools fork their workers from a fork server (:func:`tsrkit.runner.engine.pool_context`), which does
not
notice the run's end; each worker watches the run's process and ends, with its fork server,
within a second of it (:func:`end_with_run`).
"""

from __future__ import annotations

import os
import signal
import threading
import time
from pathlib import Path

from tsrkit.core.errors import TsrkitError

__all__ = [
    "WORKERS_PER_CORE",
    "alive",
    "check_workers",
    "end_with_run",
    "max_workers",
    "pool_broke",
]

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


def pool_broke(exc: BaseException) -> TsrkitError:
    """The one-line error for a worker pool whose processes died (``BrokenProcessPool``): most
    often a script that starts a run at import time, which each worker re-imports."""
    return TsrkitError(
        f"the worker processes died ({exc}); in a script, start the run under "
        "'if __name__ == \"__main__\":' (each worker imports the script), or use workers=1"
    )


def end_with_run(run: int, poll: float = 1.0) -> None:
    """In a worker process: end it (``os._exit``) once the run's process ``run`` is gone.

    A daemon thread looks every ``poll`` seconds. The fork server the worker came from serves
    that run only, and outlives it otherwise: while it is still this worker's parent it is
    ended too.
    """
    server = os.getppid()

    def watch() -> None:
        while alive(run):
            time.sleep(poll)
        if server != run and os.getppid() == server:
            os.kill(server, signal.SIGTERM)
        os._exit(1)

    threading.Thread(target=watch, name="tsrkit-end-with-run", daemon=True).start()


def alive(pid: int) -> bool:
    """Whether process ``pid`` runs: a zombie (ended, not yet reaped by its parent) does not."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except FileNotFoundError:
        return False
    except (OSError, IndexError):  # no /proc: ask the kernel
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return False
        except PermissionError:
            return True
        return True
    return state not in ("Z", "X")
