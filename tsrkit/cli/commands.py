"""The built-in verbs, registered through ``register_commands`` exactly like a third-party verb.

The registry loads this module as an internal plugin (:data:`tsrkit.registry.INTERNAL`).
"""

from tsrkit.hookspecs import hookimpl


@hookimpl
def register_commands(cli):
    from tsrkit.cli.benchmark import benchmark_command, compare_command
    from tsrkit.cli.datasets import datasets_group
    from tsrkit.cli.detect import detect_command
    from tsrkit.cli.plugins_cmd import plugins_command
    from tsrkit.cli.presets_cmd import presets_command
    from tsrkit.cli.track import track_command
    from tsrkit.cli.train import train_command

    for command in (
        plugins_command,
        detect_command,
        train_command,
        datasets_group,
        benchmark_command,
        compare_command,
        presets_command,
        track_command,
    ):
        cli.add_command(command)
