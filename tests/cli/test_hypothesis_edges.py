"""Property-based tests (hypothesis) of the edges the bad-input matrix's second table covers by
example: run configurations (keys, nesting, aliases), the ``track`` options, cache entries,
video frame ranges, JSON nesting and output paths that name an input. Whatever the input,
the answer is a valid result or tsrkit's own one-line error, never an uncaught exception, a
hang, or an input replaced.

Bounded like ``test_hypothesis_inputs.py`` (``TSRKIT_HYPOTHESIS_EXAMPLES`` searches harder).
"""

from __future__ import annotations

import json
import os
import string
from pathlib import Path

import pytest
import yaml
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings, strategies as st

from tsrkit.cli.main import cli
from tsrkit.core.errors import TsrkitError
from tsrkit.core.files import MAX_DEPTH, InputFileError, loads_json, loads_yaml
from tsrkit.core.outputs import OutputIsInput, reading, refuse_input
from tsrkit.core.records import FrameRecord
from tsrkit.plugin.params import CONFIG_KEYS, ParamError, load_config
from tsrkit.runner.engine import read_cached
from tsrkit.runner.inputs import check_range, plan_work

BOUNDED = settings(
    max_examples=int(os.environ.get("TSRKIT_HYPOTHESIS_EXAMPLES", "40")),
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
FEW = settings(BOUNDED, max_examples=min(BOUNDED.max_examples, 12))

KEYS = st.one_of(
    st.sampled_from([*CONFIG_KEYS, "name", "params", "clasifier", "detecter", "Detector"]),
    st.text(alphabet=string.ascii_lowercase + "_-", min_size=1, max_size=10),
)
LEAVES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**40), 2**40),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from(["gray-tophat", "lab-frst", "ab-hist", "housing", "nope", ""]),
)
TREES = st.recursive(
    LEAVES,
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(KEYS, inner, max_size=3),
    max_leaves=12,
)


@pytest.fixture(scope="module")
def work(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("edges")


def nested(depth: int, kind: str) -> str:
    return "[" * depth + "]" * depth if kind == "list" else "{a: " * depth + "1" + "}" * depth


@BOUNDED
@given(
    content=st.one_of(
        TREES.map(yaml.safe_dump),
        st.dictionaries(KEYS, TREES, max_size=4).map(yaml.safe_dump),
        st.tuples(st.integers(1, 400), st.sampled_from(["list", "map"])).map(
            lambda t: "detector: " + nested(*t)
        ),
        st.tuples(st.integers(1, 12), st.integers(1, 12)).map(
            lambda t: (
                "a: &a [x]\n"
                + "".join(
                    f"a{k}: &a{k} [{', '.join(['*a' + (str(k - 1) if k > 1 else '')] * t[1])}]\n"
                    for k in range(1, t[0] + 1)
                )
            )
        ),
    )
)
def test_configs_are_read_or_refused_in_one_line(work, content):
    """Unknown keys, deep nesting and alias chains of any width and depth: a config is either
    all known keys of the right shape, or one ParamError line."""
    path = work / "run.yaml"
    path.write_text(content)
    try:
        config = load_config(path)
    except ParamError as exc:
        assert "\n" not in str(exc) and len(str(exc)) < 1000
        return
    assert set(config) <= set(CONFIG_KEYS)
    for kind in ("detector", "verifier", "classifier", "tracker"):
        if config.get(kind) is not None:
            assert set(config[kind]) == {"name", "params"}


@BOUNDED
@given(depth=st.integers(1, 3000), kind=st.sampled_from(["[", '{"a": ']))
def test_json_nesting_is_bounded(depth, kind):
    text = kind * depth + ("1" if kind != "[" else "") + ("]" if kind == "[" else "}") * depth
    try:
        loads_json(text, "x.json")
    except InputFileError as exc:
        assert depth > MAX_DEPTH - 1 and "nested deeper" in str(exc)
        return
    assert depth <= MAX_DEPTH


@BOUNDED
@given(width=st.integers(1, 40), depth=st.integers(1, 12))
def test_yaml_alias_chains_are_bounded_by_their_expanded_size(width, depth):
    text = "a0: &a0 [x]\n" + "".join(
        f"a{k}: &a{k} [{', '.join([f'*a{k - 1}'] * width)}]\n" for k in range(1, depth + 1)
    )
    try:
        data = loads_yaml(text, "c.yaml")
    except InputFileError as exc:
        assert "expands to more than" in str(exc)
        assert width**depth > 10_000  # only documents that really expand are refused
        return
    assert len(data) == depth + 1


FLOATS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from(["nan", "inf", "-inf", "1e308", "-0", "0", "30", "abc", ""]),
)


@FEW
@given(option=st.sampled_from(["--vicinity"]), value=FLOATS)
def test_track_distance_options_never_crash(work, option, value):
    gps = work / "g.csv"
    gps.write_text(
        "time,lat,lon\n"
        + "".join(f"{1780315200 + k},{47.599 + 1e-4 * k},-122.15\n" for k in range(9))
    )
    osm = work / "m.osm"
    osm.write_text(
        '<osm version="0.6"><node id="1" lat="47.5994" lon="-122.15">'
        '<tag k="highway" v="traffic_signals"/></node></osm>'
    )
    result = CliRunner().invoke(
        cli, ["track", "--gps", str(gps), "--map", str(osm), option, str(value)]
    )
    assert result.exception is None or isinstance(result.exception, SystemExit), result.output
    assert result.exit_code in (0, 2), result.output
    if result.exit_code == 0:
        assert "nan" not in str(value).lower() and "inf" not in str(value).lower()


@BOUNDED
@given(content=st.one_of(st.binary(max_size=80), TREES.map(json.dumps)))
def test_a_cache_entry_is_a_record_or_ignored(work, content):
    path = work / "entry.json"
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    record = read_cached(path)
    assert record is None or isinstance(record, FrameRecord)


@BOUNDED
@given(
    every=st.integers(-3, 10**15),
    start=st.integers(-3, 10**15),
    end=st.one_of(st.none(), st.integers(-3, 10**15)),
)
def test_video_ranges_are_checked_before_use(work, every, start, end):
    """Any --every/--start/--end either plans work (a bounded number of units, however large
    the numbers) or is refused with the options named."""
    try:
        check_range(every, start, end)
    except TsrkitError as exc:
        assert str(exc).startswith("--")
        return
    units = list(plan_work([work / "missing.mp4"], every, start, end, chunk=64))
    assert len(units) == 1  # a missing file: one skip, no iteration over the range


@BOUNDED
@given(
    name=st.text(alphabet=string.ascii_letters + "._-", min_size=1, max_size=12).filter(
        lambda n: n not in (".", "..")
    ),
    spelling=st.sampled_from(["{}", "./{}", "sub/../{}"]),
)
def test_an_output_naming_an_input_is_refused(work, name, spelling):
    (work / "sub").mkdir(exist_ok=True)
    source = work / name
    source.write_text("input")
    with reading([source]):
        with pytest.raises(OutputIsInput):
            refuse_input(work / spelling.format(name))
        refuse_input(work / f"{name}.out")  # another path is fine
    assert source.read_text() == "input"
