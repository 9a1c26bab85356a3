"""Options shared by the verbs that run plugins (selection, ``--param``, ``--config``) and the
one-line user error. Building the chosen plugins is :func:`tsrkit.selection.build`."""

from __future__ import annotations

import math

import click

from tsrkit.selection import DEFAULT_DETECTOR


def plugin_options(func):
    """Add ``--detector``, ``--verifier``, ``--classifier``, ``--tracker``, ``--param``,
    ``--config``."""
    options = [
        click.option(
            "--detector", "-d", default=None, help=f"Detector plugin (default {DEFAULT_DETECTOR})."
        ),
        click.option(
            "--verifier",
            "-V",
            default=None,
            help="Verifier plugin: rescores, refines or rejects candidates.",
        ),
        click.option("--classifier", "-c", default=None, help="Classifier plugin."),
        click.option("--tracker", "-t", default=None, help="Tracker plugin (videos)."),
        click.option(
            "--param",
            "-p",
            "params",
            multiple=True,
            metavar="KEY=VALUE",
            help="Plugin parameter; repeatable. Prefix with detector., verifier., "
            "classifier. or tracker. when two plugins share a key.",
        ),
        click.option(
            "--config",
            type=click.Path(dir_okay=False),
            default=None,
            help="YAML run configuration (plugins and their params).",
        ),
    ]
    for option in reversed(options):
        func = option(func)
    return func


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


class FiniteFloatRange(click.FloatRange):
    """``click.FloatRange`` that also refuses ``nan`` (which every comparison lets through)
    and infinities."""

    def convert(self, value, param, ctx):
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number", param, ctx)
        return number
