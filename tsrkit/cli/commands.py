"""The built-in verbs, registered through ``register_commands`` exactly like a third-party verb.

The registry loads this module as an internal plugin (:data:`tsrkit.registry.INTERNAL`); the
command line itself imports a built-in verb only when it runs (:mod:`tsrkit.cli.verbs`).
"""

import importlib

from tsrkit.cli.verbs import VERBS
from tsrkit.hookspecs import hookimpl


@hookimpl
def register_commands(cli):
    for name, verb in VERBS.items():
        if not verb.module.startswith("tsrkit_plugins."):  # plugins register their own verbs
            cli.add_command(getattr(importlib.import_module(verb.module), verb.attribute), name)
