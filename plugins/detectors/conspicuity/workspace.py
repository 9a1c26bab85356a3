"""Scratch arrays of the conspicuity map reused from frame to frame, one set per thread.

A 1280x720 map needs about 17 MB of intermediate arrays (the L and S channels, their mirrored
copies, two prefix-table stacks and the running maximum). Allocated afresh for every frame,
they went back to the operating system and were faulted in again: 8-16 ms of system time per
frame in a plain ``detect`` loop. :class:`Workspace` keeps them instead. It is a
``threading.local``, so concurrent threads never share a buffer, and ``conspicuity_map`` uses
it only for arrays that never leave the call: what it returns is always freshly allocated.
"""

from __future__ import annotations

import threading

import numpy as np


class Workspace(threading.local):
    """Named scratch buffers of the calling thread, each grown to the largest size asked for."""

    def __init__(self) -> None:
        self.buffers: dict[str, np.ndarray] = {}

    def array(self, key: str, shape: tuple[int, ...], dtype: type) -> np.ndarray:
        """An uninitialised C-contiguous array of ``shape`` and ``dtype`` over buffer ``key``
        (valid until the same thread asks for ``key`` again)."""
        kind = np.dtype(dtype)
        size = int(np.prod(shape)) * kind.itemsize
        buffer = self.buffers.get(key)
        if buffer is None or buffer.size < size:
            buffer = np.empty(size, np.uint8)
            self.buffers[key] = buffer
        return buffer[:size].view(kind).reshape(shape)
