"""The hooks a tsrkit plugin may implement (pluggy specifications).

Each ``register_*`` hook receives a ``register`` callable; call it once per plugin class.
``register_commands`` receives the root click group so a plugin can add a verb.
"""
import pluggy

hookspec = pluggy.HookspecMarker("tsrkit")
hookimpl = pluggy.HookimplMarker("tsrkit")


@hookspec
def register_detectors(register):
    """Register :class:`tsrkit.plugin.Detector` subclasses: ``register(MyDetector)``."""


@hookspec
def register_verifiers(register):
    """Register :class:`tsrkit.plugin.Verifier` subclasses."""


@hookspec
def register_classifiers(register):
    """Register :class:`tsrkit.plugin.Classifier` subclasses."""


@hookspec
def register_trackers(register):
    """Register :class:`tsrkit.plugin.Tracker` subclasses."""


@hookspec
def register_dataset_formats(register):
    """Register :class:`tsrkit.plugin.DatasetFormat` subclasses."""


@hookspec
def register_commands(cli):
    """Add click commands to the ``tsrkit`` group ``cli``."""
