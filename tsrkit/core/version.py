"""The installed tsrkit's version (``0+unknown`` in a source tree that is not installed)."""

from importlib import metadata

__all__ = ["__version__"]

try:
    __version__ = metadata.version("tsrkit")
except metadata.PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"
