"""The built-in verbs, registered through ``register_commands`` exactly like a third-party verb.

The command line registers this module as an internal plugin when it needs every verb
(:func:`tsrkit.cli.main._add_commands`); it imports a built-in verb only when that verb runs
(:mod:`tsrkit.cli.verbs`).
"""

import importlib

from tsrkit.cli.verbs import VERBS
from tsrkit.plugin.hookspecs import hookimpl

__all__ = ["register_commands"]


@hookimpl
def register_commands(cli):
    for name, verb in VERBS.items():
        cli.add_command(getattr(importlib.import_module(verb.module), verb.attribute), name)
