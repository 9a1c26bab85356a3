"""Property-based tests (hypothesis) of the edges past the run itself: run folders read back by
``tsrkit report`` (benchmark, compare and track folders, one file damaged at random), a
third-party metric or report writer that returns anything or raises, a track run's cache
entries, and special files (FIFOs, devices, folders, dangling links, sockets) given where a
regular file is read. Whatever happens, the answer is a report, tsrkit's own one-line error or
a failure named in the report, never an uncaught exception, a hang, or JSON that a strict
reader refuses.

Bounded like ``test_hypothesis_inputs.py`` (``TSRKIT_HYPOTHESIS_EXAMPLES`` searches harder).
"""

from __future__ import annotations

import dataclasses
import json
import os
import shutil
import signal
import socket
import string
from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings, strategies as st
from test_edge_matrix_more import track_folder

import tsrkit
from tsrkit.api import Metric, ReportWriter, hookimpl
from tsrkit.cli.main import cli
from tsrkit.spatiotemporal.run import read_cached
from tsrkit.synth import sample_path

BOUNDED = settings(
    max_examples=int(os.environ.get("TSRKIT_HYPOTHESIS_EXAMPLES", "40")),
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
FEW = settings(BOUNDED, max_examples=min(BOUNDED.max_examples, 10))

KEYS = st.text(alphabet=string.ascii_lowercase + "_", min_size=1, max_size=8)
LEAVES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**70), 2**70),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=6),
)
TREES = st.recursive(
    LEAVES,
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(KEYS, inner, max_size=3),
    max_leaves=10,
)
ERRORS = st.sampled_from(
    [ValueError, KeyError, ZeroDivisionError, RuntimeError, TypeError, OSError, MemoryError]
)


def strict(text: str):
    """Parse JSON, refusing the ``NaN`` / ``Infinity`` tokens Python accepts."""

    def refuse(token):
        raise AssertionError(f"{token} written into JSON")

    return json.loads(text, parse_constant=refuse)


def no_traceback(result) -> None:
    """The command ended with an exit status of its own: no uncaught exception."""
    assert result.exception is None or isinstance(result.exception, SystemExit), (
        f"uncaught {type(result.exception).__name__}: {result.exception}\n{result.output}"
    )
    assert "Traceback" not in result.output
    assert result.exit_code in (0, 1, 2), result.output


def sample(frames: int):
    data = tsrkit.dataset("sample")
    return dataclasses.replace(data, samples=data.samples[:frames])


# ---------------------------------------------------------------------------------------------
# run folders read back


@pytest.fixture(scope="module")
def folders(tmp_path_factory) -> dict[str, Path]:
    """A benchmark folder, a compare folder and a track folder (as the track verb writes it,
    written by hand)."""
    root = tmp_path_factory.mktemp("folders")
    tsrkit.benchmark(sample(4), tsrkit.detector("gray-tophat"), out=root / "run", cache=False)
    tsrkit.compare(
        sample(4),
        [tsrkit.detector("gray-tophat"), tsrkit.detector("lab-frst")],
        out=root / "compare",
        cache=False,
    )
    track = track_folder(root / "track", root / "missing.csv", root / "missing.osm")
    return {"run": root / "run", "compare": root / "compare", "track": track}


def damaged(path: Path, data, key: int | None) -> str:
    """``path``'s text with one key of its object (the first line's in JSON Lines) set to
    ``data`` (removed when ``data`` is ``"<removed>"``), or, with no ``key``, replaced whole."""
    text = path.read_text()
    lines = text.splitlines() if path.suffix == ".jsonl" else [text]
    first = json.loads(lines[0]) if lines and lines[0].strip() else None
    if key is None or not isinstance(first, dict) or not first:
        return data if isinstance(data, str) else json.dumps(data, allow_nan=True)
    chosen = list(first)[key % len(first)]
    if data == "<removed>":
        del first[chosen]
    else:
        first[chosen] = data
    return "\n".join([json.dumps(first, allow_nan=True), *lines[1:]])


@BOUNDED
@given(
    kind=st.sampled_from(["run", "compare", "track"]),
    which=st.integers(0, 10),
    data=st.one_of(TREES, st.just("<removed>"), st.text(max_size=30)),
    key=st.one_of(st.none(), st.integers(0, 30)),
)
def test_a_damaged_run_folder_is_reported_or_refused_in_one_line(
    folders, tmp_path_factory, kind, which, data, key
):
    folder = tmp_path_factory.mktemp("damaged") / kind
    shutil.copytree(folders[kind], folder)
    files = sorted(
        p for p in folder.rglob("*") if p.suffix in (".json", ".jsonl") and "cache" not in p.parts
    )
    target = files[which % len(files)]
    target.write_text(damaged(target, data, key))
    result = CliRunner().invoke(cli, ["report", str(folder), "--writer", "markdown"])
    no_traceback(result)
    if result.exit_code == 2:
        lines = [line for line in result.output.splitlines() if line.strip()]
        assert len(lines) == 1, result.output


# ---------------------------------------------------------------------------------------------
# third-party metrics and writers

#: What the registered metric and writer do in the current example.
BEHAVIOUR: dict = {}


class Drawn(Metric):
    """Returns the drawn sections, or raises the drawn error in the drawn method."""

    name = "drawn"

    def reset(self, settings):
        self._maybe_raise("reset")

    def update(self, sample, record):
        self._maybe_raise("update")

    def compute(self):
        self._maybe_raise("compute")
        return BEHAVIOUR["sections"]

    def _maybe_raise(self, method: str) -> None:
        if BEHAVIOUR.get("raise_in") == method:
            raise BEHAVIOUR["error"]("drawn failure")


class DrawnWriter(ReportWriter):
    """Declares the drawn files, or raises the drawn error in the drawn method."""

    name = "drawn-writer"

    def files(self, run):
        if BEHAVIOUR.get("writer_raise_in") == "files":
            raise BEHAVIOUR["error"]("drawn writer failure")
        return BEHAVIOUR["files"]

    def write(self, run, folder):
        if BEHAVIOUR.get("writer_raise_in") == "write":
            raise BEHAVIOUR["error"]("drawn writer failure")


class DrawnPlugins:
    @hookimpl
    def register_metrics(register):
        register(Drawn)

    @hookimpl
    def register_report_writers(register):
        register(DrawnWriter)


@FEW
@given(
    sections=st.one_of(st.dictionaries(KEYS, TREES, max_size=3), TREES),
    raise_in=st.sampled_from([None, "reset", "update", "compute"]),
    writer_raise_in=st.sampled_from([None, "files", "write"]),
    files=st.lists(
        st.one_of(st.sampled_from(["x.txt", "../escape.txt", "/abs.txt", "", "plots/a.png"])),
        max_size=2,
    ),
    error=ERRORS,
)
def test_a_third_party_metric_or_writer_never_breaks_the_run(
    registry, tmp_path_factory, sections, raise_in, writer_raise_in, files, error
):
    if "drawn" not in {info.name for info in registry.plugins("metric")}:
        registry.add(DrawnPlugins, "drawn")
    BEHAVIOUR.clear()
    BEHAVIOUR.update(
        sections=sections,
        raise_in=raise_in,
        writer_raise_in=writer_raise_in,
        files=files,
        error=error,
    )
    out = tmp_path_factory.mktemp("third-party")
    args = ["benchmark", "--dataset", "sample", "-d", "gray-tophat", "-w", "1", "-q"]
    writers = ["--writer", "json", "--writer", "drawn-writer", "--no-cache", "-o", str(out)]
    result = CliRunner().invoke(cli, [*args, *writers])
    no_traceback(result)
    report = strict((out / "report.json").read_text())
    failed = [f["plugin"] for f in report.get("failures", [])]
    if raise_in is not None:
        assert "metric 'drawn'" in failed and "drawn failure" in result.output
    if writer_raise_in is not None:
        assert "writer 'drawn-writer'" in failed
    assert not (out.parent / "escape.txt").exists() and not Path("/abs.txt").exists()


# ---------------------------------------------------------------------------------------------
# track cache entries


@BOUNDED
@given(content=st.one_of(st.binary(max_size=80), TREES.map(lambda t: json.dumps(t))))
def test_a_track_cache_entry_is_a_record_or_ignored(tmp_path_factory, content):
    path = tmp_path_factory.mktemp("entry") / "entry.json"
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    record = read_cached(path)
    assert record is None or (isinstance(record, dict) and isinstance(record["tracks"], list))


# ---------------------------------------------------------------------------------------------
# special files where a regular file is read


def special(path: Path, kind: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "device":
        os.symlink("/dev/zero", path)
    elif kind == "folder":
        path.mkdir()
    elif kind == "dangling":
        os.symlink(path.parent / "nowhere", path)
    else:
        sock = socket.socket(socket.AF_UNIX)
        sock.bind(str(path))
        sock.close()
    return path


GPS = "time,lat,lon\n0,47.6,-122.15\n10,47.6009,-122.15\n"
MAP = (
    '<osm version="0.6"><node id="1" lat="47.6005" lon="-122.15">'
    '<tag k="highway" v="traffic_signals"/></node></osm>'
)


def command(tmp: Path, where: str, kind: str) -> list[str]:
    """A command that reads a special file of ``kind`` at ``where``."""
    (tmp / "in").mkdir(exist_ok=True)
    shutil.copy(sample_path().parent / "images" / "000000.jpg", tmp / "in" / "a.jpg")
    (tmp / "gps.csv").write_text(GPS)
    (tmp / "map.osm").write_text(MAP)
    if where == "image":
        special(tmp / "in" / "b.jpg", kind)
        return ["detect", str(tmp / "in"), "-d", "gray-tophat", "-q"]
    if where == "config":
        return ["detect", str(tmp / "in"), "--config", str(special(tmp / "run.yaml", kind))]
    if where == "model":
        model = str(special(tmp / "m.npz", kind))
        return ["detect", str(tmp / "in"), "-c", "ab-hist", "-p", f"model={model}"]
    if where == "annotations":
        return ["datasets", "info", str(special(tmp / "annotations.json", kind))]
    if where == "gps":
        return ["track", "--gps", str(special(tmp / "g.csv", kind)), "--map", str(tmp / "map.osm")]
    if where == "map":
        return ["track", "--gps", str(tmp / "gps.csv"), "--map", str(special(tmp / "m.osm", kind))]
    special(tmp / "run" / "report.json", kind)
    return ["report", str(tmp / "run")]


@FEW
@given(
    where=st.sampled_from(["image", "config", "model", "annotations", "gps", "map", "report"]),
    kind=st.sampled_from(["fifo", "device", "folder", "dangling", "socket"]),
)
def test_a_special_file_is_skipped_or_refused_never_read(tmp_path_factory, where, kind):
    tmp = tmp_path_factory.mktemp("special")
    args = command(tmp, where, kind)

    def blocked(signum, frame):
        raise TimeoutError(f"{where} as a {kind} blocked for 60 s")

    previous = signal.signal(signal.SIGALRM, blocked)
    signal.alarm(60)
    try:
        result = CliRunner().invoke(cli, args)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    no_traceback(result)
    if where == "image":  # one good image and one special file: the run goes on
        assert result.exit_code == 0 and "skipped" in result.output
    else:
        assert result.exit_code == 2, result.output
