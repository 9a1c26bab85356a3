"""Reading a user's input files without hanging, exhausting memory or crashing on their shape.

One policy for every file tsrkit reads (images, annotation files, configs, GPS logs, maps,
models, cache entries): only regular files are opened (a FIFO, device or socket would block or
never end), the size is checked before a byte is read, JSON and YAML nesting is bounded, and a
YAML document may not expand aliases past a bound (an "alias bomb") nor repeat a key. Each
refusal is an :class:`InputFileError` naming the file and the problem, which each surface turns
into its own error type.
"""

from __future__ import annotations

import json
import os
import stat
from typing import Any

import yaml

from tsrkit.core.errors import TsrkitError

__all__ = [
    "MAX_DEPTH",
    "MAX_TEXT_BYTES",
    "MAX_VALUES",
    "InputFileError",
    "deeper_than",
    "file_size",
    "loads_json",
    "loads_yaml",
    "not_regular",
    "read_bytes",
    "read_json",
    "read_text",
    "read_yaml",
]

#: The largest text file read (annotation files, GPS logs, maps), in bytes.
MAX_TEXT_BYTES = 2 * 2**30
#: The deepest nesting of lists and mappings accepted in JSON and YAML.
MAX_DEPTH = 100
#: The most values (scalars and collections, aliases expanded) one YAML document may hold.
MAX_VALUES = 1_000_000

_KINDS = (
    (stat.S_ISFIFO, "a FIFO"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
    (stat.S_ISDIR, "a folder"),
)


class InputFileError(TsrkitError):
    """An input file that cannot be read safely: ``path`` and ``problem`` are kept apart so
    that each surface can wrap them in its own error.

    Examples
    --------
    >>> str(InputFileError("a.json", "nested deeper than 100 levels"))
    'a.json: nested deeper than 100 levels'
    """

    def __init__(self, path: str | os.PathLike, problem: str) -> None:
        self.path = str(path)
        self.problem = problem
        super().__init__(f"{path}: {problem}")


def not_regular(path: str | os.PathLike) -> str | None:
    """Why ``path`` is not a regular file that can be read (after symbolic links), or None.

    Examples
    --------
    >>> not_regular("/dev/null")
    'not a regular file (a character device)'
    >>> not_regular("/nonexistent/x") is not None
    True
    """
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return "no such file"
    except OSError as exc:
        return f"cannot read ({exc.strerror or exc})"
    if stat.S_ISREG(mode):
        return None
    kind = next((name for test, name in _KINDS if test(mode)), "a special file")
    return f"not a regular file ({kind})"


def file_size(path: str | os.PathLike, limit: int) -> int:
    """The size of the regular file ``path``, refused when it is not one or exceeds ``limit``.

    Raises
    ------
    InputFileError
    """
    problem = not_regular(path)
    if problem:
        raise InputFileError(path, problem)
    size = os.stat(path).st_size
    if size > limit:
        raise InputFileError(
            path, f"{size:,} bytes, more than the limit of {limit:,} for this kind of file"
        )
    return size


def read_bytes(path: str | os.PathLike, limit: int = MAX_TEXT_BYTES) -> bytes:
    """The bytes of a regular file no larger than ``limit``.

    Raises
    ------
    InputFileError
        Missing, not a regular file, too large or unreadable.
    """
    file_size(path, limit)
    try:
        with open(path, "rb") as fh:
            return fh.read(limit + 1)[:limit]
    except OSError as exc:
        raise InputFileError(path, f"cannot read ({exc.strerror or exc})") from None


def read_text(path: str | os.PathLike, limit: int = MAX_TEXT_BYTES) -> str:
    """The UTF-8 text of a regular file (a byte order mark dropped).

    Raises
    ------
    InputFileError
        As :func:`read_bytes`, or "not valid UTF-8" with the line and byte.
    """
    data = read_bytes(path, limit)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise InputFileError(
            path,
            f"line {line}: not valid UTF-8 (byte 0x{data[exc.start]:02x} at offset {exc.start})",
        ) from None


def loads_json(text: str | bytes, path: str | os.PathLike) -> Any:
    """Parse JSON text, refusing nesting deeper than :data:`MAX_DEPTH`.

    Raises
    ------
    InputFileError
        Not valid JSON (with line and column) or nested too deeply.

    Examples
    --------
    >>> loads_json('{"a": [1, 2]}', "x.json")
    {'a': [1, 2]}
    >>> loads_json("[" * 200 + "]" * 200, "x.json")
    Traceback (most recent call last):
    ...
    tsrkit.core.files.InputFileError: x.json: nested deeper than 100 levels
    """
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputFileError(
            path, f"line {exc.lineno} column {exc.colno}: not valid JSON ({exc.msg})"
        ) from None
    except RecursionError:
        data = None
        deep = True
    else:
        deep = deeper_than(data, MAX_DEPTH)
    if deep:
        raise InputFileError(path, f"nested deeper than {MAX_DEPTH} levels")
    return data


def deeper_than(data: Any, limit: int) -> bool:
    """Whether lists and mappings nest in ``data`` more than ``limit`` deep (no recursion).

    Examples
    --------
    >>> deeper_than({"a": [[1]]}, 3), deeper_than({"a": [[1]]}, 2)
    (False, True)
    """
    stack = [(data, 1)] if isinstance(data, (dict, list)) else []
    while stack:
        item, depth = stack.pop()
        children = item.values() if isinstance(item, dict) else item
        if depth > limit:
            return True
        stack.extend((child, depth + 1) for child in children if isinstance(child, (dict, list)))
    return False


def read_json(path: str | os.PathLike, limit: int = MAX_TEXT_BYTES) -> Any:
    """:func:`read_text` then :func:`loads_json`."""
    return loads_json(read_text(path, limit), path)


class _UniqueKeyLoader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):  # type: ignore[misc]
    """The safe YAML loader, refusing a mapping that repeats a key (YAML leaves it undefined;
    PyYAML silently keeps the last). Merge keys (``<<: *base``) are YAML 1.1's: the keys a
    mapping writes itself override the merged ones without counting as repeated."""

    def construct_mapping(self, node, deep=False):
        seen: set = set()
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":
                continue
            key = self.construct_object(key_node, deep=deep)
            try:
                repeated = key in seen
                seen.add(key)
            except TypeError:  # an unhashable key: the constructor's own error follows
                break
            if repeated:
                raise yaml.constructor.ConstructorError(
                    None, None, f"key {key!r} appears twice", key_node.start_mark
                )
        return super().construct_mapping(node, deep=deep)


def loads_yaml(text: str, path: str | os.PathLike) -> Any:
    """Parse a YAML document safely: no Python objects, nesting at most :data:`MAX_DEPTH`, at
    most :data:`MAX_VALUES` values once its aliases are expanded, no repeated key.

    The bounds are checked on the parser's events before anything is built (each anchor's
    expanded size is counted once), so an alias bomb or a deeply nested document costs one
    linear pass.

    Raises
    ------
    InputFileError
        Not valid YAML (with its line), or past a bound.

    Examples
    --------
    >>> loads_yaml("a: [1, 2]", "c.yaml")
    {'a': [1, 2]}
    >>> loads_yaml("a: 1\\na: 2", "c.yaml")
    Traceback (most recent call last):
    ...
    tsrkit.core.files.InputFileError: c.yaml: line 2: not valid YAML (key 'a' appears twice)
    """
    loader = _UniqueKeyLoader
    depth, sizes, counts = 0, {}, [0]  # values per open collection; anchors' expanded sizes
    anchors: list[str | None] = []
    try:
        for event in yaml.parse(text, Loader=loader):
            if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
                depth += 1
                if depth > MAX_DEPTH:
                    raise InputFileError(path, f"nested deeper than {MAX_DEPTH} levels")
                counts.append(0)
                anchors.append(event.anchor)
            elif isinstance(event, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
                depth -= 1
                size = counts.pop() + 1
                anchor = anchors.pop()
                if anchor is not None:
                    sizes[anchor] = size
                counts[-1] += size
            elif isinstance(event, yaml.ScalarEvent):
                counts[-1] += 1
                if event.anchor is not None:
                    sizes[event.anchor] = 1
            elif isinstance(event, yaml.AliasEvent):
                counts[-1] += sizes.get(event.anchor, 1)
            if counts[-1] > MAX_VALUES:
                raise InputFileError(
                    path, f"expands to more than {MAX_VALUES:,} values (through YAML aliases?)"
                )
        return yaml.load(text, Loader=loader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        reason = " ".join(str(getattr(exc, "problem", None) or exc).split())
        where = f"line {mark.line + 1}: " if mark else ""
        raise InputFileError(path, f"{where}not valid YAML ({reason[:200]})") from None


def read_yaml(path: str | os.PathLike, limit: int = MAX_TEXT_BYTES) -> Any:
    """:func:`read_text` then :func:`loads_yaml`."""
    return loads_yaml(read_text(path, limit), path)
