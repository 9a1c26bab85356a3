"""The one-line user error of the command line, and how a file-system error reads as one.

Light on purpose: :mod:`tsrkit.cli.main` imports it before any verb is loaded.
"""

from __future__ import annotations

import click

__all__ = ["UserError", "describe_os_error"]


class UserError(click.ClickException):
    """Raised by commands for mistakes that need no traceback."""

    exit_code = 2


def describe_os_error(exc: OSError) -> str:
    """One line for a file-system error: the path(s) and the reason.

    Examples
    --------
    >>> describe_os_error(NotADirectoryError(20, "Not a directory", "out/x"))
    'cannot use out/x: Not a directory'
    """
    paths = " -> ".join(str(p) for p in (exc.filename, exc.filename2) if p is not None)
    reason = exc.strerror or str(exc)
    return f"cannot use {paths}: {reason}" if paths else f"file system error: {reason}"
