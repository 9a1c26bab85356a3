"""Never write over an input, nor read an output back as one: a run declares the files it reads
and the files it writes once, and outputs are checked against inputs before anything is
written.

A verb wraps its work in :func:`reading` with the files it reads (images, annotation files,
configs, models, GPS logs); :func:`tsrkit.core.atomic.atomic_open` and the verbs' own output checks
call :func:`refuse_input`, so ``train --out D/annotations`` or ``datasets convert a.json --out
a.json`` refuse with one line instead of replacing the user's data.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import stat
from collections.abc import Iterable, Iterator

from tsrkit.core.errors import TsrkitError
from tsrkit.core.files import not_regular

__all__ = [
    "OutputIsInput",
    "OutputIsSpecial",
    "is_input",
    "is_output",
    "reading",
    "refuse_input",
    "refuse_special",
    "writing",
]

_INPUTS: contextvars.ContextVar[frozenset[str]] = contextvars.ContextVar(
    "tsrkit_inputs", default=frozenset()
)
_OUTPUTS: contextvars.ContextVar[frozenset[str]] = contextvars.ContextVar(
    "tsrkit_outputs", default=frozenset()
)


class OutputIsInput(TsrkitError):
    """An output path that names one of the run's inputs."""


class OutputIsSpecial(TsrkitError):
    """An output path that names a device, FIFO or socket."""


def _key(path: str | os.PathLike) -> str:
    return os.path.realpath(path)


@contextlib.contextmanager
def reading(paths: Iterable[str | os.PathLike]) -> Iterator[None]:
    """Declare ``paths`` (files or folders) as inputs of the run for the block's duration."""
    keys = {_key(p) for p in paths if p is not None and str(p)}
    token = _INPUTS.set(_INPUTS.get() | keys)
    try:
        yield
    finally:
        _INPUTS.reset(token)


@contextlib.contextmanager
def writing(paths: Iterable[str | os.PathLike | None]) -> Iterator[None]:
    """Declare ``paths`` (files or folders) as the run's outputs for the block's duration:
    :func:`tsrkit.runner.inputs.expand_paths` leaves them out of the inputs it lists."""
    keys = {_key(p) for p in paths if p is not None and str(p)}
    token = _OUTPUTS.set(_OUTPUTS.get() | keys)
    try:
        yield
    finally:
        _OUTPUTS.reset(token)


def is_output(path: str | os.PathLike) -> bool:
    """Whether ``path`` is one of the run's declared outputs (:func:`writing`)."""
    outputs = _OUTPUTS.get()
    return bool(outputs) and _key(path) in outputs


def is_input(path: str | os.PathLike) -> bool:
    """Whether ``path`` names a file or folder declared with :func:`reading`."""
    return _key(path) in _INPUTS.get()


def refuse_input(path: str | os.PathLike, option: str = "the output") -> None:
    """Raise :class:`OutputIsInput` when ``path`` is one of the run's inputs.

    Examples
    --------
    >>> with reading(["data/a.json"]):
    ...     refuse_input("data/./a.json", "--out")
    Traceback (most recent call last):
    ...
    tsrkit.core.outputs.OutputIsInput: --out data/./a.json is an input of this run; choose another \
path
    """
    if is_input(path):
        raise OutputIsInput(f"{option} {path} is an input of this run; choose another path")


def refuse_special(
    path: str | os.PathLike, option: str = "the output", follow: bool = True
) -> None:
    """Raise :class:`OutputIsSpecial` when ``path`` exists and is neither a regular file nor a
    folder (``follow``: after symbolic links; else only a device node itself). Outputs are
    written beside their path and renamed over it: that would replace a device (``-o
    /dev/null`` run as root would replace ``/dev/null`` itself) and never reach a FIFO's
    reader.

    Examples
    --------
    >>> refuse_special("/dev/null", "--out")
    Traceback (most recent call last):
    ...
    tsrkit.core.outputs.OutputIsSpecial: --out /dev/null: not a regular file (a character device); \
outputs are written beside their path and renamed over it: choose a file
    """
    try:
        mode = os.stat(path).st_mode if follow else os.lstat(path).st_mode
    except OSError:  # missing (to be made) or unreachable: the writer says so
        return
    special = (
        not (stat.S_ISREG(mode) or stat.S_ISDIR(mode))
        if follow
        else stat.S_ISCHR(mode) or stat.S_ISBLK(mode)
    )
    if special:
        raise OutputIsSpecial(
            f"{option} {path}: {not_regular(path)}; outputs are written beside their path "
            "and renamed over it: choose a file"
        )
