"""Atomic output: all or nothing, with ordinary permissions; JSON without non-finite tokens."""

import json
import os
import stat

import pytest

from tsrkit.core.atomic import atomic_open, json_line, write_json


def test_success_replaces_and_uses_umask_permissions(tmp_path):
    target = tmp_path / "sub" / "out.json"
    write_json(target, {"a": 1})
    assert target.read_text() == '{\n  "a": 1\n}\n'
    mask = os.umask(0)
    os.umask(mask)
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~mask


def test_failure_leaves_the_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError), atomic_open(target) as fh:
        fh.write("new, half written")
        raise RuntimeError("interrupted")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]


def strict(text: str):
    """Parse ``text`` as JSON, refusing the ``NaN`` / ``Infinity`` tokens Python accepts."""

    def refuse(token):
        raise AssertionError(f"{token} is not JSON")

    return json.loads(text, parse_constant=refuse)


def test_non_finite_numbers_are_written_as_null(tmp_path):
    data = {"p": float("nan"), "rows": [[1.5, float("inf")], (float("-inf"),)], "n": 2}
    write_json(tmp_path / "r.json", data)
    expected = {"p": None, "rows": [[1.5, None], [None]], "n": 2}
    assert strict((tmp_path / "r.json").read_text()) == expected
    assert strict(json_line(data)) == expected
