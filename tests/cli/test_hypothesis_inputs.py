"""Property-based tests (hypothesis) of every input surface: whatever the
bytes, image decoding, each format reader, model loading, configs and parameters either return
valid typed data or raise tsrkit's own one-line error, and a reader names the problem itself
(its message is not the generic "malformed ... data" of ``read_dataset``'s safety net).

Bounded to a few dozen examples per property, without deadlines, so the file stays fast
(``TSRKIT_HYPOTHESIS_EXAMPLES=1000`` searches harder).
"""

from __future__ import annotations

import json
import math
import os
import string
from pathlib import Path

import cv2
import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings, strategies as st

from tsrkit.core.errors import TsrkitError
from tsrkit.core.images import ImageReadError, read_image
from tsrkit.datasets import open_dataset
from tsrkit.plugin.models import Model, ModelError, load_model, save_model
from tsrkit.plugin.params import TYPES, Param, ParamError, load_config, validate

BOUNDED = settings(
    max_examples=int(os.environ.get("TSRKIT_HYPOTHESIS_EXAMPLES", "40")),
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)


@pytest.fixture(scope="module")
def work(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("hypothesis")
    image = np.full((24, 24, 3), 90, np.uint8)
    for name in ("a.png", "images/a.png", "Lara3D_UrbanSeq1_JPG/frame_000000.jpg"):
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        cv2.imwrite(str(folder / name), image)
    return folder


# --- values that break parsers: wrong types, non-finite numbers, huge and negative values ---
SCALARS = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**40), 2**40),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from(["", "a.png", "red", "nan", "-1", "1e999", "0", "images", "\x00"]),
    st.text(max_size=6),
)
JSON = st.recursive(
    SCALARS,
    lambda inner: (
        st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=8), inner, max_size=3)
    ),
    max_leaves=12,
)


def _check_dataset(dataset) -> None:
    """What every reader promises: finite boxes with area, and typed samples."""
    for sample in dataset:
        assert isinstance(sample.source, str)
        assert sample.split is None or isinstance(sample.split, str)
        assert isinstance(sample.metadata, dict)
        for ann in sample.annotations:
            x0, y0, x1, y1 = ann.bbox
            assert all(math.isfinite(v) for v in ann.bbox) and x1 > x0 and y1 > y0
            assert isinstance(ann.attributes, dict)


def check_reader_total(path: Path, fmt: str) -> None:
    """Reading ``path`` gives a valid dataset or one reader-specific line, never a traceback."""
    try:
        dataset = open_dataset(path, format=fmt)
    except TsrkitError as exc:
        assert "\n" not in str(exc)
        assert "malformed" not in str(exc), f"the safety net, not the reader, caught: {exc}"
        return
    _check_dataset(dataset)


def _mutated(record: dict, data) -> dict:
    """``record`` with one key's value replaced by an arbitrary JSON value, or deleted."""
    key = data.draw(st.sampled_from(sorted(record)))
    out = dict(record)
    if data.draw(st.booleans()):
        del out[key]
    else:
        out[key] = data.draw(JSON)
    return out


BOX = {"label": "red", "x_min": 1, "y_min": 1, "x_max": 9, "y_max": 9}


@BOUNDED
@given(data=st.data())
def test_normalized_reader_is_total(work, data):
    box = _mutated(BOX, data) if data.draw(st.booleans()) else BOX
    record = {"file": "a.png", "split": "test", "width": 24, "height": 24, "boxes": [box]}
    record = _mutated(record, data) if data.draw(st.booleans()) else record
    path = work / "annotations.json"
    path.write_text(json.dumps([record], allow_nan=True))
    check_reader_total(path, "normalized")


@BOUNDED
@given(data=st.data())
def test_coco_reader_is_total(work, data):
    image = {"id": 1, "file_name": "a.png", "width": 24, "height": 24}
    ann = {"id": 1, "image_id": 1, "category_id": 1, "bbox": [1, 1, 8, 8]}
    category = {"id": 1, "name": "red"}
    top = {"images": [image], "annotations": [ann], "categories": [category]}
    part = data.draw(st.sampled_from(["images", "annotations", "categories", "top"]))
    if part == "top":
        top = _mutated(top, data)
    else:
        top[part] = [_mutated(top[part][0], data)]
    path = work / "coco.json"
    path.write_text(json.dumps(top, allow_nan=True))
    check_reader_total(path, "coco")


@BOUNDED
@given(data=st.data())
def test_dtld_reader_is_total(work, data):
    label = {"x": 1, "y": 1, "w": 8, "h": 8, "attributes": {"state": "red"}}
    entry = {"image_path": "a.png", "labels": [label]}
    if data.draw(st.booleans()):
        entry["labels"] = [_mutated(label, data)]
    else:
        entry = _mutated(entry, data) | {"image_path": entry["image_path"]}
    path = work / "dtld.json"
    path.write_text(json.dumps({"images": [entry]}, allow_nan=True))
    check_reader_total(path, "dtld")


@BOUNDED
@given(data=st.data())
def test_bosch_reader_is_total(work, data):
    box = {"label": "Red", "occluded": False, "x_min": 1, "y_min": 1, "x_max": 9, "y_max": 9}
    entry = {"path": "a.png", "boxes": [_mutated(box, data)]}
    if data.draw(st.booleans()):
        entry = _mutated(entry, data)
    path = work / "bosch.yaml"
    path.write_text(yaml.safe_dump([entry]))
    check_reader_total(path, "bosch")


# --- line formats: rows of tokens drawn from a tricky alphabet ---
TOKENS = st.sampled_from(["0", "1", "9", "-1", "0.5", "nan", "inf", "", "x", "a.png", "go", "'go'"])


def _line(data, count: int, sep: str) -> str:
    return sep.join(data.draw(st.lists(TOKENS, min_size=0, max_size=count + 2)))


@BOUNDED
@given(data=st.data())
def test_yolo_reader_is_total(work, data):
    root = work / "yolo"
    (root / "images").mkdir(parents=True, exist_ok=True)
    (root / "labels").mkdir(exist_ok=True)
    cv2.imwrite(str(root / "images" / "a.png"), np.zeros((24, 24, 3), np.uint8))
    names = data.draw(st.one_of(st.just(["red"]), JSON))
    (root / "data.yaml").write_text(yaml.safe_dump({"names": names, "train": "images"}))
    (root / "labels" / "a.txt").write_text(_line(data, 5, " ") + "\n" + _line(data, 5, " "))
    check_reader_total(root / "data.yaml", "yolo")


@pytest.mark.parametrize("names", [{"\u00b2": "red"}, ["red"]])
def test_yolo_superscript_digits_are_not_class_ids(work, names):
    """Found by the test above: ``'\u00b2'.isdigit()`` is true but ``int('\u00b2')`` raises."""
    root = work / "yolo_sup"
    (root / "images").mkdir(parents=True, exist_ok=True)
    (root / "labels").mkdir(exist_ok=True)
    cv2.imwrite(str(root / "images" / "a.png"), np.zeros((24, 24, 3), np.uint8))
    (root / "data.yaml").write_text(yaml.safe_dump({"names": names, "train": "images"}))
    (root / "labels" / "a.txt").write_text("\u00b2 0.5 0.5 0.1 0.1\n")
    with pytest.raises(TsrkitError, match="not an"):
        open_dataset(root / "data.yaml", format="yolo")


HEADERS = {
    "gtsrb": ("GT-00000.csv", "Filename;Width;Height;Roi.X1;Roi.Y1;Roi.X2;Roi.Y2;ClassId", ";", 8),
    "lisa": (
        "frameAnnotationsBOX.csv",
        "Filename;Annotation tag;Upper left corner X;Upper left corner Y;Lower right corner X;"
        "Lower right corner Y;Origin file;Origin frame number;Origin track;Origin track frame "
        "number",
        ";",
        10,
    ),
    "crops": ("labels.csv", "file,label,split,width,height", ",", 5),
    "lara": ("gt.txt", "# LaRA ground truth", " ", 10),
}


@BOUNDED
@pytest.mark.parametrize("fmt", sorted(HEADERS))
@given(data=st.data())
def test_line_readers_are_total(work, fmt, data):
    name, header, sep, count = HEADERS[fmt]
    lines = [header] + [_line(data, count, sep) for _ in range(data.draw(st.integers(1, 3)))]
    if fmt == "lara" and data.draw(st.booleans()):
        lines.append("0.5 / 0 " + _line(data, 4, " ") + " 0 'Traffic Light' 'go'")
    path = work / fmt / name
    path.parent.mkdir(exist_ok=True)
    path.write_text("\n".join(lines) + "\n")
    if fmt != "lara":
        cv2.imwrite(str(path.parent / "a.png"), np.zeros((24, 24, 3), np.uint8))
    check_reader_total(path, fmt)


@BOUNDED
@pytest.mark.parametrize(
    "fmt,name",
    [
        ("normalized", "annotations.json"),
        ("coco", "coco.json"),
        ("dtld", "dtld.json"),
        ("bosch", "b.yaml"),
        ("voc", "a.xml"),
        ("gtsrb", "GT-00001.csv"),
        ("lisa", "frameAnnotationsBOX.csv"),
        ("crops", "labels.csv"),
        ("lara", "gt.txt"),
    ],
)
@given(content=st.binary(max_size=200))
def test_readers_are_total_on_arbitrary_bytes(work, fmt, name, content):
    path = work / f"bytes-{fmt}" / name
    path.parent.mkdir(exist_ok=True)
    path.write_bytes(content)
    check_reader_total(path, fmt)


# --- images ---


def _encoded(ext: str) -> bytes:
    ok, buffer = cv2.imencode(ext, np.arange(16 * 16 * 3, dtype=np.uint8).reshape(16, 16, 3))
    assert ok
    return buffer.tobytes()


SEEDS = [_encoded(".png"), _encoded(".jpg"), _encoded(".bmp")]


@BOUNDED
@given(
    seed=st.sampled_from(SEEDS),
    edits=st.lists(st.tuples(st.integers(0, 400), st.integers(0, 255)), max_size=6),
    cut=st.integers(0, 500),
)
def test_image_decoding_is_total(work, seed, edits, cut):
    data = bytearray(seed)
    for at, value in edits:
        data[at % len(data)] = value
    path = work / "mutated.img"
    path.write_bytes(bytes(data[: max(cut, 1)] if cut < len(data) else data))
    try:
        image = read_image(path)
    except ImageReadError as exc:
        assert "\n" not in str(exc)
        return
    assert image.dtype == np.uint8 and image.ndim == 3 and image.shape[2] == 3


# --- model files ---


@BOUNDED
@given(meta=JSON, archive=st.binary(max_size=64), keep_archive=st.booleans())
def test_model_loading_is_total(work, meta, archive, keep_archive):
    base = work / "model"
    save_model(
        base, Model({"w": np.ones(3)}), plugin="p", plugin_version="1", params={}, training={}
    )
    (work / "model.json").write_text(json.dumps(meta, allow_nan=True))
    if not keep_archive:
        (work / "model.npz").write_bytes(archive)
    try:
        model = load_model(base, plugin="p")
    except ModelError:
        return
    assert set(model.arrays) == {"w"}


@BOUNDED
@given(
    edits=st.lists(
        st.tuples(st.floats(0, 1, exclude_max=True), st.integers(0, 255)), min_size=1, max_size=4
    )
)
def test_a_damaged_model_archive_is_a_model_error(work, edits):
    base = work / "zipped"
    save_model(
        base, Model({"w": np.arange(64.0)}), plugin="p", plugin_version="1", params={}, training={}
    )
    data = bytearray((work / "zipped.npz").read_bytes())
    for where, value in edits:  # a relative position: uniform over the whole file
        data[int(where * len(data))] = value
    (work / "zipped.npz").write_bytes(bytes(data))
    try:
        model = load_model(base, plugin="p")
    except ModelError as exc:
        assert "\n" not in str(exc)
        return
    assert np.array_equal(model.arrays["w"], np.arange(64.0))  # the checksum guards the values


# --- configs and parameters ---


@BOUNDED
@given(
    content=st.one_of(
        JSON.map(lambda v: yaml.safe_dump(v)),
        st.dictionaries(
            st.sampled_from(["detector", "classifier", "verifier", "tracker", 1]),
            JSON | st.fixed_dictionaries({"name": SCALARS, "params": JSON}),
            max_size=3,
        ).map(lambda v: yaml.safe_dump(v)),
        st.binary(max_size=60),
    )
)
def test_config_loading_is_total(work, content):
    path = work / "run.yaml"
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    try:
        config = load_config(path)
    except ParamError as exc:
        assert "\n" not in str(exc)
        return
    assert isinstance(config, dict) and all(isinstance(k, str) for k in config)
    for kind in ("detector", "verifier", "classifier", "tracker"):
        if config.get(kind) is not None:
            assert isinstance(config[kind]["name"], str)
            assert isinstance(config[kind]["params"], dict)


@BOUNDED
@given(
    kind=st.sampled_from(sorted(TYPES)),
    value=st.one_of(JSON, st.text(alphabet=string.printable, max_size=12)),
)
def test_parameters_are_validated_or_refused(kind, value):
    schema = (
        [Param("k", kind, None, min=0, max=10)] if kind in ("int", "float") else [Param("k", kind)]
    )
    try:
        out = validate(schema, {"k": value}, "plugin")["k"]
    except ParamError as exc:
        assert "\n" not in str(exc) or "\n" in repr(value)
        return
    if value is None:  # "not set": the plugin's default applies
        assert out is None
        return
    items = out if isinstance(out, tuple) else (out,)
    for item in items:
        if kind in ("int", "float", "ints", "floats"):
            assert isinstance(item, (int, float)) and not isinstance(item, bool)
            assert math.isfinite(item)
