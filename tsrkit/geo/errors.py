"""The one error of GPS logs and maps (file, place in the file, problem), and reading them as
text."""

from __future__ import annotations

import os
from pathlib import Path

from tsrkit.core import files
from tsrkit.core.errors import TsrkitError

__all__ = ["GeoError", "read_text"]


class GeoError(TsrkitError):
    """A GPS log or map that is missing or malformed.

    ``line`` is a line number, or the label of a place that has none (a GPX track point, a
    GeoJSON feature, an OSM node of a binary file).

    Examples
    --------
    >>> str(GeoError("drive.csv", "latitude 123.0 out of range", 7))
    'drive.csv: line 7: latitude 123.0 out of range'
    >>> str(GeoError("drive.gpx", "no time", "track point 3"))
    'drive.gpx: track point 3: no time'
    """

    def __init__(
        self, path: str | os.PathLike, problem: str, line: int | str | None = None
    ) -> None:
        where = f"line {line}: " if isinstance(line, int) else f"{line}: " if line else ""
        super().__init__(f"{path}: {where}{problem}")


def read_text(path: Path) -> str:
    """The UTF-8 text of ``path`` (a byte order mark dropped), or a :class:`GeoError`: missing,
    not a regular file, larger than :data:`tsrkit.core.files.MAX_TEXT_BYTES`, not UTF-8."""
    try:
        return files.read_text(path)
    except files.InputFileError as exc:
        raise GeoError(path, exc.problem) from None


def check_file(path: Path) -> None:
    """Raise a :class:`GeoError` unless ``path`` is a regular file of at most
    :data:`tsrkit.core.files.MAX_TEXT_BYTES` (a FIFO or device would block the reader)."""
    try:
        files.file_size(path, files.MAX_TEXT_BYTES)
    except files.InputFileError as exc:
        raise GeoError(path, exc.problem) from None
