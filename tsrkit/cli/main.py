"""The ``tsrkit`` click group; every verb, built-in or not, is added via ``register_commands``.

Start-up is lazy: ``tsrkit --help`` lists the verbs shipped with tsrkit from
:data:`tsrkit.cli.verbs.VERBS` without importing them, and a verb's module (with NumPy, OpenCV
and the plugins) is imported only when that verb runs. The plugin registry is loaded for a verb
that is not one of tsrkit's own, or to list the verbs when a package other than tsrkit declares
``tsrkit`` entry points (its verbs come through the ``register_commands`` hook).
"""

from __future__ import annotations

import atexit
import contextlib
import importlib
import os
import sys
import warnings
from importlib import metadata

import click

from tsrkit.cli.errors import UserError, describe_os_error
from tsrkit.cli.verbs import VERBS
from tsrkit.core.errors import TsrkitError, TsrkitWarning
from tsrkit.plugin.hookspecs import ENTRY_POINT_GROUP

__all__ = ["TsrkitGroup", "cli", "main"]


class TsrkitGroup(click.Group):
    """A click group that loads verbs on demand, reports :class:`TsrkitError` and
    operating-system errors (an unwritable ``--out``, a full disk) as one line and exit
    status 2, and each :class:`TsrkitWarning` as one ``warning:`` line on stderr."""

    def main(self, *args, **kwargs):
        """Run the command line, each :class:`TsrkitWarning` (plugins load while ``--help``
        is parsed, too) printed as one ``warning:`` line."""
        shown = warnings.showwarning

        def show(message, category, *rest, **options):
            if issubclass(category, TsrkitWarning):
                click.echo(f"warning: {message}", err=True)
            else:
                shown(message, category, *rest, **options)

        with warnings.catch_warnings():
            warnings.simplefilter("always", TsrkitWarning)
            warnings.showwarning = show
            return super().main(*args, **kwargs)

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except TsrkitError as exc:
            raise UserError(str(exc)) from None
        except OSError as exc:
            raise UserError(describe_os_error(exc)) from None

    def list_commands(self, ctx: click.Context) -> list[str]:
        if _foreign_entry_points():
            _add_commands()
        return sorted({*self.commands, *VERBS})

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        if cmd_name not in self.commands:
            verb = VERBS.get(cmd_name)
            if verb is not None:
                module = importlib.import_module(verb.module)
                self.add_command(getattr(module, verb.attribute), cmd_name)
            else:
                _add_commands()
        return self.commands.get(cmd_name)

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        """The verb list, with the summaries of :data:`VERBS` for verbs not loaded yet."""
        names = [
            name
            for name in self.list_commands(ctx)
            if name not in self.commands or not self.commands[name].hidden
        ]
        limit = formatter.width - 6 - max(map(len, names), default=0)
        rows = []
        for name in names:
            command = self.commands.get(name)
            summary = (
                command.get_short_help_str(limit)
                if command is not None
                else click.Command(name, help=VERBS[name].summary).get_short_help_str(limit)
            )
            rows.append((name, summary))
        if rows:
            with formatter.section("Commands"):
                formatter.write_dl(rows)


@click.group(
    cls=TsrkitGroup,
    invoke_without_command=True,
    context_settings={"help_option_names": ["-h", "--help"]},
)
@click.version_option(package_name="tsrkit")
@click.pass_context
def cli(ctx: click.Context) -> None:
    """Traffic signal recognition: detect, classify, track and benchmark methods side by side.

    With no verb, compares the built-in detectors on the bundled synthetic sample.

    \b
    Examples:
      tsrkit detect frames/ -o detections.jsonl
      tsrkit benchmark --dataset roboflow_traffic_light_kr --split test -d lab-frst
      tsrkit plugins
    """
    if ctx.invoked_subcommand is None:
        # when needed: ``tsrkit --help`` loads no verb and no plugin
        from tsrkit.cli.benchmark import run_default

        ctx.invoke(run_default)


def _foreign_entry_points() -> bool:
    """Whether a package other than tsrkit declares ``tsrkit`` plugins (which may add verbs)."""
    return any(
        ep.dist is not None and ep.dist.name != "tsrkit"
        for ep in metadata.entry_points(group=ENTRY_POINT_GROUP)
    )


#: The name the built-in verbs (:mod:`tsrkit.cli.commands`) are registered under.
BUILTIN_VERBS = "tsrkit-commands"


def _add_commands() -> None:
    """Every verb registered through ``register_commands``: the built-in ones (the CLI
    registers :mod:`tsrkit.cli.commands` as an internal plugin) and the plugins'; runs once."""
    # when needed: ``tsrkit --help`` loads no verb and no plugin
    from tsrkit.cli import commands
    from tsrkit.plugin.registry import PluginFailure, get_registry

    if getattr(cli, "_hooks_done", False):
        return
    cli._hooks_done = True  # type: ignore[attr-defined]
    registry = get_registry()
    if registry.pm.get_plugin(BUILTIN_VERBS) is None:
        registry.add(commands, BUILTIN_VERBS, "tsrkit")
    for impl in registry.pm.hook.register_commands.get_hookimpls():
        try:
            impl.function(cli=cli)
        except (Exception, SystemExit) as exc:  # one broken plugin must not break the command line
            registry.failures.append(
                PluginFailure(
                    impl.plugin_name, "?", f"register_commands: {type(exc).__name__}: {exc}"
                )
            )
            if impl.plugin_name == BUILTIN_VERBS:  # the core's own verbs must not fail silently
                raise


def main() -> None:
    """Console-script entry point: run the command, then end the process without the
    interpreter's teardown.

    A benchmark imports about 2,300 modules (NumPy, SciPy, scikit-learn, matplotlib, numba, the
    plugins); the teardown frees them one by one, about a second of CPU after the command's work
    is done (``benchmarks/bench_run_tail.py``). Exit handlers still run and the standard streams
    are flushed before :func:`os._exit`; files are written and closed inside the command. Under
    a profiler or tracer (``python -m cProfile``, coverage), which write their results after
    the program returns, the process ends the usual way.
    """
    try:
        cli.main(prog_name="tsrkit")
        status = 0
    except SystemExit as exc:
        status = exit_status(exc.code)
    if sys.getprofile() is not None or sys.gettrace() is not None:
        raise SystemExit(status)
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):  # a closed pipe has nothing left to flush
            stream.flush()
    os._exit(status)


def exit_status(code: object) -> int:
    """The process status of ``SystemExit(code)``, as Python's own exit gives it (a message is
    printed on stderr and counts as 1).

    >>> exit_status(None), exit_status(2), exit_status("no such file")
    (0, 2, 1)
    """
    if code is None:
        return 0
    if isinstance(code, int):
        return code
    print(code, file=sys.stderr)
    return 1


if __name__ == "__main__":
    main()
