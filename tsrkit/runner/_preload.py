"""What the fork server of the worker pools does once, before it forks any worker.

Every worker pool forks its workers from one server process
(:func:`tsrkit.runner.engine.pool_context`),
and a forked worker starts with the server's memory, so nothing done here is done again by a
worker: the engine and every installed plugin are imported (a worker then unpickles its job
without importing anything), and numba's compiler is initialised (its typing and target
registries: about 0.3 s of CPU in every process before its first compiled function runs, even
one loaded from the on-disk cache). :func:`tsrkit.runner.engine.start_pool_server` starts the server
while the command is still starting, so this runs on another core meanwhile.
"""

from __future__ import annotations

import contextlib

from numba import njit

from tsrkit.plugin.registry import get_registry


@njit(cache=True)
def _first_compiled_call(value: int) -> int:
    return value + 1


# A failure here costs only the head start: each worker then imports what it needs itself.
with contextlib.suppress(Exception):
    get_registry()
    _first_compiled_call(1)
