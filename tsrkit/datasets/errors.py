"""The error a dataset reader raises for a file it cannot use, naming file, entry and problem.

Also the YAML reading that registry and format readers share, so its errors read alike.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from tsrkit.core.errors import TsrkitError
from tsrkit.core.files import InputFileError, loads_json, loads_yaml, read_bytes

__all__ = ["DatasetError", "read_json", "read_text", "read_yaml"]


class DatasetError(TsrkitError):
    """A dataset file that is missing, malformed or inconsistent.

    Parameters
    ----------
    path : path-like
        The file (or folder) at fault.
    problem : str
        What is wrong, in words.
    where : str, optional
        The line or entry, e.g. ``"line 12"`` or ``"images[3]"``.

    Examples
    --------
    >>> str(DatasetError("a.csv", "expected 8 fields, got 3", "line 4"))
    'a.csv: line 4: expected 8 fields, got 3'
    """

    def __init__(self, path: str | os.PathLike, problem: str, where: str = ""):
        self.path = str(path)
        self.where = where
        self.problem = problem
        super().__init__(": ".join(part for part in (self.path, where, problem) if part))


def read_text(path: str | os.PathLike, missing: str = "file not found") -> str:
    """The whole text of a UTF-8 file (a byte-order mark, which Windows tools write, is
    dropped).

    Raises
    ------
    DatasetError
        ``missing`` when the file does not exist, the reason when it cannot be read (not a
        regular file, larger than :data:`tsrkit.core.files.MAX_TEXT_BYTES`...), and "not valid
        UTF-8" with the line and the offending byte when it does not decode.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.NamedTemporaryFile(suffix=".csv", delete=False) as fh:
    ...     _ = fh.write(b"a,b\\nc,\\xff\\n")
    >>> read_text(fh.name)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    tsrkit.datasets.errors.DatasetError: ...csv: line 2: not valid UTF-8 (byte 0xff at offset 6)
    """
    path = Path(path)
    try:
        data = read_bytes(path)
    except InputFileError as exc:
        raise DatasetError(
            path, missing if exc.problem == "no such file" else exc.problem
        ) from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        problem = f"not valid UTF-8 (byte 0x{data[exc.start]:02x} at offset {exc.start})"
        raise DatasetError(path, problem, f"line {line}") from None


def read_yaml(path: str | os.PathLike, missing: str = "file not found") -> Any:
    """Parse a YAML file (:func:`tsrkit.core.files.loads_yaml`: the C loader when available, bounded
    nesting and aliases, no repeated key).

    Raises
    ------
    DatasetError
        ``missing`` when the file does not exist; "not valid UTF-8" or "not valid YAML" with
        the line otherwise.
    """
    try:
        return loads_yaml(read_text(path, missing), path)
    except InputFileError as exc:
        raise DatasetError(path, exc.problem) from None


def read_json(path: str | os.PathLike, missing: str = "file not found") -> Any:
    """Parse a JSON file (:func:`tsrkit.core.files.loads_json`: nesting bounded).

    Raises
    ------
    DatasetError
        ``missing`` when the file does not exist; "not valid UTF-8" or "not valid JSON" with
        the line and column otherwise, or "nested deeper than ...".
    """
    try:
        return loads_json(read_text(path, missing), path)
    except InputFileError as exc:
        raise DatasetError(path, exc.problem) from None
