"""The one exception family for user-facing mistakes, and the warning for input read past.

The CLI turns any :class:`TsrkitError` into a single line on stderr and exit status 2; anything
else is a bug and keeps its traceback. A :class:`TsrkitWarning` becomes one ``warning:`` line
and the run goes on.
"""

__all__ = ["TsrkitError", "TsrkitWarning"]


class TsrkitError(ValueError):
    """A problem the user can fix: bad parameter, unknown plugin, unreadable file..."""


class TsrkitWarning(UserWarning):
    """Input read past rather than refused (a box with no area, a repeated GPS fix...), said
    with ``warnings.warn(message, TsrkitWarning)``: the command line prints every one."""
