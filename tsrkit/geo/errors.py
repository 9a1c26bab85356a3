"""The one error of GPS logs and maps: file, line and problem."""

from __future__ import annotations

import os

from tsrkit.errors import TsrkitError


class GeoError(TsrkitError):
    """A GPS log or map that is missing or malformed.

    Examples
    --------
    >>> str(GeoError("drive.csv", "latitude 123.0 out of range", 7))
    'drive.csv: line 7: latitude 123.0 out of range'
    """

    def __init__(self, path: str | os.PathLike, problem: str, line: int | None = None):
        where = f"line {line}: " if line is not None else ""
        super().__init__(f"{path}: {where}{problem}")
