"""The one exception family for user-facing mistakes.

The CLI turns any :class:`TsrkitError` into a single line on stderr and exit status 2; anything
else is a bug and keeps its traceback.
"""

__all__ = ["TsrkitError"]


class TsrkitError(ValueError):
    """A problem the user can fix: bad parameter, unknown plugin, unreadable file..."""
