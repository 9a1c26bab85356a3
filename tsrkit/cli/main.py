"""The ``tsrkit`` click group; every verb, built-in or not, is added via ``register_commands``."""

from __future__ import annotations

import click

from tsrkit.cli.common import UserError, describe_os_error
from tsrkit.errors import TsrkitError
from tsrkit.registry import INTERNAL, PluginFailure, get_registry


class TsrkitGroup(click.Group):
    """A click group that reports :class:`TsrkitError` and operating-system errors (an
    unwritable ``--out``, a full disk) as one line and exit status 2."""

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except TsrkitError as exc:
            raise UserError(str(exc)) from None
        except OSError as exc:
            raise UserError(describe_os_error(exc)) from None


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
    """
    if ctx.invoked_subcommand is None:
        from tsrkit.cli.benchmark import run_default

        ctx.invoke(run_default)


def _add_commands() -> None:
    """Every verb: the built-in ones (:mod:`tsrkit.cli.commands`) and the plugins'."""
    registry = get_registry()
    for impl in registry.pm.hook.register_commands.get_hookimpls():
        try:
            impl.function(cli=cli)
        except Exception as exc:  # one broken plugin must not break the command line
            registry.failures.append(
                PluginFailure(
                    impl.plugin_name, "?", f"register_commands: {type(exc).__name__}: {exc}"
                )
            )
            if impl.plugin_name in INTERNAL:  # the core's own verbs must not fail silently
                raise


_add_commands()


def main() -> None:
    """Console-script entry point."""
    cli.main(prog_name="tsrkit")


if __name__ == "__main__":
    main()
