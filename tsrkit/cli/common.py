"""Options shared by the verbs that run plugins (selection, ``--param``, ``--config``) and a
float option type that refuses NaN. Building the chosen plugins is
:func:`tsrkit.selection.build`."""

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


class FiniteFloatRange(click.FloatRange):
    """``click.FloatRange`` that also refuses ``nan`` (which every comparison lets through)
    and infinities."""

    def convert(self, value, param, ctx):
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number", param, ctx)
        return number
