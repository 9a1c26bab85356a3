"""Options shared by the verbs that run plugins (selection, ``--param``, ``--config``) and a
float option type that refuses NaN. Building the chosen plugins is
:func:`tsrkit.plugin.selection.build`."""

from __future__ import annotations

import math

import click

from tsrkit.cli.completion import plugin_names, preset_or_file
from tsrkit.plugin.selection import DEFAULT_DETECTOR

__all__ = ["FiniteFloatRange", "plugin_options", "split_name"]


def plugin_options(func=None, *, tracker: bool = True):
    """Add ``--detector``, ``--verifier``, ``--classifier``, ``--tracker`` (unless
    ``tracker=False``: a verb that cannot use one does not offer it), ``--param``,
    ``--config``."""
    if func is None:
        return lambda f: plugin_options(f, tracker=tracker)
    options = [
        click.option(
            "--detector",
            "-d",
            default=None,
            help=f"Detector plugin (default {DEFAULT_DETECTOR}).",
            shell_complete=plugin_names("detector"),
        ),
        click.option(
            "--verifier",
            "-V",
            default=None,
            help="Verifier plugin: rescores, refines or rejects candidates.",
            shell_complete=plugin_names("verifier"),
        ),
        click.option(
            "--classifier",
            "-c",
            default=None,
            help="Classifier plugin.",
            shell_complete=plugin_names("classifier"),
        ),
        *(
            [
                click.option(
                    "--tracker",
                    "-t",
                    default=None,
                    help="Tracker plugin (videos).",
                    shell_complete=plugin_names("tracker"),
                )
            ]
            if tracker
            else []
        ),
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
            help="YAML run configuration (plugins and their params) or a preset name "
            "(tsrkit presets). A file when it holds a / or ends in .yaml or .yml, else a preset "
            "(./NAME for a file NAME).",
            shell_complete=preset_or_file,
        ),
    ]
    for option in reversed(options):
        func = option(func)
    return func


def split_name(ctx: click.Context, param: click.Parameter, value: str | None) -> str | None:
    """The ``--split`` callback: refuse the empty name, which would keep every split."""
    if value is not None and not value.strip():
        raise click.BadParameter("empty split name (leave --split out for every split)")
    return value


class FiniteFloatRange(click.FloatRange):
    """``click.FloatRange`` that also refuses ``nan`` (which every comparison lets through)
    and infinities."""

    def convert(self, value, param, ctx):
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number", param, ctx)
        return number
