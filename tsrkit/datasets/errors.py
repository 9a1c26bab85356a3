"""The error a dataset reader raises for a file it cannot use, naming file, entry and problem."""
from __future__ import annotations

import os

from tsrkit.errors import TsrkitError


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
