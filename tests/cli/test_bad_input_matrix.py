"""The bad-input matrix as a table: one row per hand-made bad input, run through the
command line, with the exit code and a fragment of the one-line message it must give.

Every row also asserts that no Python traceback (no uncaught exception) came out. Inputs are
tiny files built in ``tmp_path``; the rows that run a detector use 32x32 images.
Exit codes: 0 success, 1 a run whose inputs were all skipped, 2 a usage or input error.
"""

from __future__ import annotations

import json
import re
import struct
import zlib
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest
from click.testing import CliRunner

from tsrkit.cli.main import cli

# ---------------------------------------------------------------------------------------------
# tiny inputs


def png(path: Path, size: int = 32, value: int = 40) -> Path:
    """A valid ``size`` x ``size`` PNG with a bright spot."""
    path.parent.mkdir(parents=True, exist_ok=True)
    image = np.full((size, size, 3), value, np.uint8)
    cv2.circle(image, (size // 2, size // 2), 3, (40, 40, 230), -1)
    cv2.imwrite(str(path), image)
    return path


def jpeg(path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(path), np.full((32, 32, 3), 90, np.uint8))
    return path


def _chunk(kind: bytes, data: bytes) -> bytes:
    crc = struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    return struct.pack(">I", len(data)) + kind + data + crc


def png_declaring(path: Path, width: int, height: int, body: bytes = b"\x00" * 16) -> Path:
    """A PNG whose IHDR declares ``width`` x ``height`` over a tiny pixel stream."""
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + _chunk(b"IHDR", ihdr)
        + _chunk(b"IDAT", zlib.compress(body))
        + _chunk(b"IEND", b"")
    )
    return path


def jpeg_declaring(path: Path, width: int, height: int) -> Path:
    """A valid small JPEG whose SOF0 marker is rewritten to declare ``width`` x ``height``."""
    data = bytearray(jpeg(path).read_bytes())
    sof = data.find(b"\xff\xc0")
    data[sof + 5 : sof + 9] = struct.pack(">HH", height, width)
    path.write_bytes(bytes(data))
    return path


BAD_UTF8 = b"\xff\xfe\x80"


def write(path: Path, content: str | bytes) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    if isinstance(content, str):
        content = content.encode()
    path.write_bytes(content)
    return path


# Each format's smallest valid annotation file (one 32x32 image ``a.png`` with one box); a row
# corrupts it with ``old -> new`` replacements or replaces it whole.
BASES: dict[str, tuple[str, str]] = {
    "yolo": ("labels/a.txt", "0 0.5 0.5 0.25 0.25\n"),
    "yolo-yaml": ("data.yaml", "names: [red]\ntrain: images\n"),
    "gtsrb": (
        "GT-00000.csv",
        "Filename;Width;Height;Roi.X1;Roi.Y1;Roi.X2;Roi.Y2;ClassId\na.png;32;32;1;1;20;20;0\n",
    ),
    "lisa": (
        "frameAnnotationsBOX.csv",
        "Filename;Annotation tag;Upper left corner X;Upper left corner Y;Lower right corner X;"
        "Lower right corner Y;Origin file;Origin frame number;Origin track;Origin track frame "
        "number\na.png;go;1;1;10;10;x;0;x;0\n",
    ),
    "bosch": (
        "test.yaml",
        "- path: a.png\n  boxes:\n  - {label: Red, occluded: false, x_min: 1, y_min: 1, "
        "x_max: 10, y_max: 10}\n",
    ),
    "bosch-json": (
        "test.json",
        '[{"path": "a.png", "boxes": [{"label": "Red", "occluded": false, "x_min": 1, '
        '"y_min": 1, "x_max": 10, "y_max": 10}]}]',
    ),
    "crops": ("labels.csv", "file,label,width,height\na.png,red,32,32\n"),
    "coco": (
        "coco.json",
        '{"images": [{"id": 1, "file_name": "a.png", "width": 32, "height": 32}], '
        '"annotations": [{"id": 1, "image_id": 1, "category_id": 1, "bbox": [1, 1, 9, 9]}], '
        '"categories": [{"id": 1, "name": "red"}]}',
    ),
    "voc": (
        "a.xml",
        "<annotation><filename>a.png</filename><size><width>32</width><height>32</height>"
        "</size><object><name>red</name><bndbox><xmin>1</xmin><ymin>1</ymin><xmax>10</xmax>"
        "<ymax>10</ymax></bndbox></object></annotation>",
    ),
    "normalized": (
        "annotations.json",
        '[{"file": "a.png", "split": "test", "width": 32, "height": 32, "boxes": '
        '[{"label": "red", "x_min": 1, "y_min": 1, "x_max": 10, "y_max": 10}]}]',
    ),
    "dtld": (
        "dtld.json",
        '{"images": [{"image_path": "a.png", "labels": [{"x": 1, "y": 1, "w": 9, "h": 9, '
        '"attributes": {"state": "red"}}]}]}',
    ),
    "lara": ("gt.txt", "# LaRA\n0.5 / 0 1 1 10 10 0 'Traffic Light' 'go'\n"),
}
#: The --format name and the path convert reads, per base.
READ_AS = {
    "yolo": ("yolo", "data.yaml"),
    "yolo-yaml": ("yolo", "data.yaml"),
    "bosch-json": ("bosch", "test.json"),
}


def dataset_files(tmp: Path, base: str, content: str | bytes | None = None) -> Path:
    """Write a valid dataset of ``base``'s format, its annotation file replaced by
    ``content``; return the path to read."""
    if base.startswith("yolo"):
        png(tmp / "images" / "a.png")
        write(tmp / "data.yaml", BASES["yolo-yaml"][1])
        write(tmp / "labels" / "a.txt", BASES["yolo"][1])
    elif base == "lara":
        png(tmp / "Lara3D_UrbanSeq1_JPG" / "frame_000000.jpg")
    else:
        png(tmp / "a.png")
    name, text = BASES[base]
    write(tmp / name, text if content is None else content)
    read = READ_AS.get(base, ("", name))[1]
    return tmp / read


def convert(base: str, content: str | bytes | None = None, *replace: tuple[str, str]):
    """A row reading a corrupted ``base`` file with ``datasets convert`` (to normalized)."""

    def build(tmp: Path) -> list[str]:
        text = BASES[base][1] if content is None else content
        for old, new in replace:
            assert isinstance(text, str) and old in text, (base, old)
            text = text.replace(old, new)
        path = dataset_files(tmp, base, text)
        fmt = READ_AS.get(base, (base.split("-")[0],))[0]
        out = str(tmp / "out" / "o.json")
        return [
            "datasets",
            "convert",
            str(path),
            "--format",
            fmt,
            "--to",
            "normalized",
            "--out",
            out,
        ]

    return build


def utf8(base: str, at: str):
    """A row whose annotation file holds invalid UTF-8 bytes right after ``at``."""
    text = BASES[base][1]
    assert at in text
    head, tail = text.split(at, 1)
    return convert(base, head.encode() + at.encode() + BAD_UTF8 + tail.encode())


def norm_dataset(tmp: Path, records: list | None = None) -> Path:
    """A valid normalised dataset of two 32x32 frames (or ``records`` as given)."""
    png(tmp / "a.png")
    png(tmp / "b.png", value=60)
    boxes = [
        {"label": state, "x_min": 4 + 8 * k, "y_min": 12, "x_max": 10 + 8 * k, "y_max": 18}
        for k, state in enumerate(("red", "yellow", "green"))
    ]
    if records is None:
        records = [
            {"file": f, "split": "test", "width": 32, "height": 32, "boxes": boxes}
            for f in ("a.png", "b.png")
        ]
    return write(tmp / "annotations.json", json.dumps(records))


FAST = ["-q", "-w", "1", "--no-cache", "--writer", "json"]


def bench(*extra: str, records=None):
    def build(tmp: Path) -> list[str]:
        ds = norm_dataset(tmp, records)
        out = str(tmp / "out")
        return ["benchmark", "--dataset", str(ds), "-d", "gray-tophat", *FAST, "-o", out, *extra]

    return build


def compare(*extra: str):
    def build(tmp: Path) -> list[str]:
        ds = norm_dataset(tmp)
        out = str(tmp / "out")
        args = ["compare", "--dataset", str(ds), "--detectors", "gray-tophat,tl-recognizer", *FAST]
        return [*args, "-o", out, *extra]

    return build


def detect(*extra: str, files: Callable[[Path], object] | None = None):
    """A ``detect`` row over the folder ``in`` (``files`` fills it; default one good image)."""

    def build(tmp: Path) -> list[str]:
        folder = tmp / "in"
        folder.mkdir()
        (files or (lambda d: png(d / "g.png")))(folder)
        chosen = [] if "--config" in extra else ["-d", "gray-tophat"]
        return ["detect", str(folder), *chosen, *extra]

    return build


def train(*extra: str):
    def build(tmp: Path) -> list[str]:
        ds = norm_dataset(tmp)
        return ["train", "ab-hist", "--dataset", str(ds), "--out", str(tmp / "m" / "model"), *extra]

    return build


def config(text: str | bytes, verb: str = "detect"):
    """A ``--config`` row: the YAML ``text`` given to ``verb``."""

    def build(tmp: Path) -> list[str]:
        cfg = write(tmp / "run.yaml", text)
        if verb == "detect":
            return detect("--config", str(cfg))(tmp)
        return compare("--config", str(cfg))(tmp)

    return build


def image(maker: Callable[[Path], object], *extra: str):
    """``detect`` on a folder holding only the image(s) ``maker`` writes."""
    return detect(*extra, files=maker)


def under_a_file(verb: Callable[[Path, str], list[str]]):
    """A writing verb whose output path lies below a regular file (unwritable, even as root)."""

    def build(tmp: Path) -> list[str]:
        blocker = write(tmp / "blocker", "a file, not a folder")
        return verb(tmp, str(blocker / "sub" / "out"))

    return build


def model_files(arrays: bytes | None, meta: str | None):
    """``detect`` with ab-hist whose ``model`` is the given (corrupt) npz and json."""

    def build(tmp: Path) -> list[str]:
        if arrays is not None:
            write(tmp / "m.npz", arrays)
        if meta is not None:
            write(tmp / "m.json", meta)
        return detect("-c", "ab-hist", "-p", f"model={tmp / 'm.npz'}")(tmp)

    return build


def good_npz() -> bytes:
    import io

    buffer = io.BytesIO()
    np.savez_compressed(buffer, histograms=np.zeros((3, 4)))
    return buffer.getvalue()


def damaged_npz(part: str) -> bytes:
    """:func:`good_npz` with its deflate stream overwritten (``"deflate"``) or its central
    directory naming an unknown compression method (``"method"``): cases fuzz.py found."""
    import io
    import zipfile

    data = bytearray(good_npz())
    with zipfile.ZipFile(io.BytesIO(bytes(data))) as archive:
        info = archive.infolist()[0]
    if part == "deflate":
        at = info.header_offset  # the local header's own name and extra lengths
        start = at + 30 + int.from_bytes(data[at + 26 : at + 28], "little")
        start += int.from_bytes(data[at + 28 : at + 30], "little")
        data[start : start + 8] = b"\xff" * 8  # BTYPE 11: an invalid deflate block
    else:
        central = data.rfind(b"PK\x01\x02")
        data[central + 10 : central + 12] = (99).to_bytes(2, "little")
    return bytes(data)


def model_meta(**overrides) -> str:
    meta = {"format_version": 1, "plugin": "ab-hist", "arrays": {"histograms": {"sha256": "x"}}}
    meta.update(overrides)
    return json.dumps(meta)


# ---------------------------------------------------------------------------------------------
# the matrix

Row = tuple[str, Callable[[Path], list[str]], int, str]

IMAGES: list[Row] = [
    ("image-empty", image(lambda d: write(d / "a.png", b"")), 1, "empty file"),
    ("image-text-as-png", image(lambda d: write(d / "a.png", "hello")), 1, "not a decodable"),
    ("image-random-bytes", image(lambda d: write(d / "a.jpg", bytes(range(256)))), 1, "decod"),
    (
        "image-truncated-png",
        image(lambda d: write(d / "a.png", png(d.parent / "x.png").read_bytes()[:60])),
        1,
        "truncated PNG",
    ),
    (
        "image-truncated-jpeg",
        image(lambda d: write(d / "a.jpg", jpeg(d.parent / "x.jpg").read_bytes()[:200])),
        1,
        "truncated JPEG",
    ),
    (
        "image-png-header-30000",
        image(lambda d: png_declaring(d / "a.png", 30000, 30000)),
        1,
        "refused",
    ),
    (
        "image-png-header-65535",
        image(lambda d: png_declaring(d / "a.png", 65535, 65535)),
        1,
        "refused",
    ),
    (
        "image-png-header-wide",
        image(lambda d: png_declaring(d / "a.png", 2**31 - 1, 1)),
        1,
        "refused|decod",
    ),
    (
        "image-jpeg-header-30000",
        image(lambda d: jpeg_declaring(d / "a.jpg", 30000, 30000)),
        1,
        "refused",
    ),
    (
        "image-png-header-lie-small",
        image(lambda d: png_declaring(d / "a.png", 2000, 2000)),
        1,
        "decod",
    ),
    ("image-png-zero-size", image(lambda d: png_declaring(d / "a.png", 0, 0)), 1, "decod"),
    (
        "image-png-bad-crc",
        image(
            lambda d: write(
                d / "a.png",
                png(d.parent / "x.png").read_bytes()[:29]
                + b"\0\0\0\0"
                + png(d.parent / "y.png").read_bytes()[33:],
            )
        ),
        1,
        "decod",
    ),
    (
        "image-bmp-header-lie",
        image(
            lambda d: write(
                d / "a.bmp",
                b"BM"
                + struct.pack("<IHHI", 70, 0, 0, 54)
                + struct.pack("<IiiHHIIiiII", 40, 40000, 40000, 1, 24, 0, 0, 0, 0, 0, 0)
                + b"\0" * 16,
            )
        ),
        1,
        "refused",
    ),
    ("image-max-pixels-env", image(lambda d: png(d / "a.png")), 1, "more than the limit of 100"),
    (
        "image-missing-path",
        lambda tmp: ["detect", str(tmp / "nope.png"), "-d", "gray-tophat"],
        1,
        "no such file",
    ),
    (
        "image-header-lie-among-good",
        image(lambda d: (png(d / "g.png"), png_declaring(d / "lie.png", 40000, 40000))),
        0,
        "1 skipped",
    ),
    ("image-video-garbage", image(lambda d: write(d / "a.mp4", b"\0" * 100)), 1, "skipped"),
    ("image-video-empty", image(lambda d: write(d / "a.mp4", b"")), 1, "skipped"),
    ("image-not-an-image-file", image(lambda d: write(d / "notes.txt", "x")), 1, "skipped"),
    (
        "image-16-bit-png-ok",
        image(lambda d: cv2.imwrite(str(d / "a.png"), np.full((9, 9), 60000, np.uint16))),
        0,
        "1 frames",
    ),
    (
        "image-rgba-png-ok",
        image(lambda d: cv2.imwrite(str(d / "a.png"), np.full((9, 9, 4), 200, np.uint8))),
        0,
        "1 frames",
    ),
    (
        "image-gray-png-ok",
        image(lambda d: cv2.imwrite(str(d / "a.png"), np.full((9, 9), 200, np.uint8))),
        0,
        "1 frames",
    ),
    ("image-empty-folder", image(lambda d: None), 1, "no input"),
]

READERS: list[Row] = [
    # invalid UTF-8 in every reader
    ("yolo-labels-utf8", utf8("yolo", "0 "), 2, "not valid UTF-8"),
    ("yolo-data-yaml-utf8", utf8("yolo-yaml", "names: [red"), 2, "not valid UTF-8"),
    ("gtsrb-utf8", utf8("gtsrb", "a.png;"), 2, "not valid UTF-8"),
    ("lisa-utf8", utf8("lisa", "a.png;go"), 2, "not valid UTF-8"),
    ("bosch-yaml-utf8", utf8("bosch", "label: Red"), 2, "not valid UTF-8"),
    ("bosch-json-utf8", utf8("bosch-json", '"Red'), 2, "not valid UTF-8"),
    ("crops-utf8", utf8("crops", "a.png,red"), 2, "not valid UTF-8"),
    ("coco-utf8", utf8("coco", '"red'), 2, "not valid UTF-8"),
    ("voc-utf8", utf8("voc", "<name>red"), 2, "not well-formed|UTF-8"),
    ("normalized-utf8", utf8("normalized", '"red'), 2, "not valid UTF-8"),
    ("dtld-utf8", utf8("dtld", '"red'), 2, "not valid UTF-8"),
    ("lara-utf8", utf8("lara", "'go"), 2, "not valid UTF-8"),
    # empty and truncated files
    ("yolo-yaml-empty", convert("yolo-yaml", ""), 2, "names"),
    ("gtsrb-empty", convert("gtsrb", ""), 2, "missing column"),
    ("lisa-empty", convert("lisa", ""), 2, "missing column"),
    ("bosch-empty", convert("bosch", ""), 2, "expected a list"),
    ("crops-empty", convert("crops", ""), 2, "missing column"),
    ("coco-empty", convert("coco", ""), 2, "not valid JSON"),
    ("coco-truncated", convert("coco", BASES["coco"][1][:70]), 2, "not valid JSON"),
    ("voc-truncated", convert("voc", BASES["voc"][1][:60]), 2, "not well-formed"),
    (
        "normalized-truncated",
        convert("normalized", BASES["normalized"][1][:50]),
        2,
        "not valid JSON",
    ),
    ("dtld-truncated", convert("dtld", BASES["dtld"][1][:50]), 2, "not valid JSON"),
    ("lara-truncated", convert("lara", "0.5 / 0 1 1 10\n"), 2, "10 fields"),
    ("bosch-yaml-broken", convert("bosch", "- path: [a.png\n"), 2, "not valid YAML"),
    # wrong types
    ("yolo-class-word", convert("yolo", "red 0.5 0.5 0.2 0.2\n"), 2, "is not an id"),
    ("yolo-class-unknown", convert("yolo", "7 0.5 0.5 0.2 0.2\n"), 2, "is not an id"),
    ("yolo-value-word", convert("yolo", "0 0.5 half 0.2 0.2\n"), 2, "expected 4 numbers"),
    ("yolo-value-nan", convert("yolo", "0 0.5 nan 0.2 0.2\n"), 2, "finite"),
    ("yolo-value-count", convert("yolo", "0 0.5 0.5 0.2\n"), 2, "got 3"),
    ("yolo-negative-size", convert("yolo", "0 0.5 0.5 -0.2 0.2\n"), 2, "negative size|no area"),
    ("yolo-zero-size", convert("yolo", "0 0.5 0.5 0 0.2\n"), 0, "warning: .*zero width"),
    ("yolo-names-int", convert("yolo-yaml", "names: 5\ntrain: images\n"), 2, "names"),
    ("yolo-names-bad-key", convert("yolo-yaml", "names: {red: a}\ntrain: images\n"), 2, "class id"),
    (
        "yolo-train-list",
        convert("yolo-yaml", "names: [red]\ntrain: [images]\n"),
        0,
        "wrote 1 images",
    ),
    (
        "yolo-path-int",
        convert("yolo-yaml", "names: [red]\npath: 5\ntrain: images\n"),
        2,
        "no images|path",
    ),
    ("yolo-no-images", convert("yolo-yaml", "names: [red]\ntrain: nowhere\n"), 2, "no images"),
    ("gtsrb-roi-word", convert("gtsrb", None, (";1;1;20", ";x;1;20")), 2, "expected 4 numbers"),
    ("gtsrb-roi-reversed", convert("gtsrb", None, (";1;1;20;20", ";20;1;1;20")), 2, "min > max"),
    ("gtsrb-class-negative", convert("gtsrb", None, (";20;0\n", ";20;-1\n")), 2, "class id"),
    ("gtsrb-width-word", convert("gtsrb", None, ("a.png;32", "a.png;wide")), 2, "Width/Height"),
    ("gtsrb-short-row", convert("gtsrb", None, (";20;20;0", "")), 2, "8 .;.-separated fields"),
    ("lisa-coord-word", convert("lisa", None, (";go;1", ";go;x")), 2, "expected 4 numbers"),
    ("lisa-empty-tag", convert("lisa", None, (";go;", ";;")), 2, "empty or missing"),
    ("lisa-reversed", convert("lisa", None, (";1;1;10;10", ";10;1;1;10")), 2, "min > max"),
    ("lisa-inf", convert("lisa", None, (";10;10;x", ";inf;10;x")), 2, "finite"),
    (
        "bosch-label-unknown",
        convert("bosch", None, ("label: Red", "label: Purple")),
        2,
        "unknown label",
    ),
    (
        "bosch-label-list",
        convert("bosch", None, ("label: Red", "label: [Red]")),
        2,
        "'label' must be",
    ),
    ("bosch-coord-word", convert("bosch", None, ("x_min: 1", "x_min: one")), 2, "'x_min' must be"),
    (
        "bosch-boxes-dict",
        convert("bosch", "- path: a.png\n  boxes: {a: 1}\n"),
        2,
        "'boxes' must be",
    ),
    ("bosch-entry-int", convert("bosch", "- 5\n"), 2, "expected an object"),
    ("bosch-path-int", convert("bosch", None, ("path: a.png", "path: 5")), 2, "'path' must be"),
    ("bosch-top-dict", convert("bosch", "a: 1\n"), 2, "expected a list"),
    ("bosch-coord-nan", convert("bosch", None, ("x_min: 1", "x_min: .nan")), 2, "finite"),
    ("crops-width-word", convert("crops", None, ("red,32", "red,wide")), 2, "width/height"),
    (
        "crops-empty-label",
        convert("crops", None, ("a.png,red", "a.png,")),
        2,
        "empty file or label",
    ),
    (
        "crops-missing-image",
        convert("crops", "file,label\nmissing.png,red\n"),
        2,
        "image not found",
    ),
    (
        "crops-negative-size",
        convert("crops", None, ("red,32,32", "red,-5,32")),
        2,
        "positive|no area",
    ),
    (
        "crops-split-list-free",
        convert("crops", "file,label,split\na.png,red,[1]\n"),
        0,
        "wrote 1 images",
    ),
    ("voc-coord-word", convert("voc", None, ("<xmin>1<", "<xmin>one<")), 2, "expected 4 numbers"),
    ("voc-missing-name", convert("voc", None, ("<name>red</name>", "")), 2, "missing <name>"),
    (
        "voc-missing-bndbox",
        convert("voc", None, ("<bndbox>", "<bbx>"), ("</bndbox>", "</bbx>")),
        2,
        "missing <bndbox>",
    ),
    ("voc-reversed", convert("voc", None, ("<xmin>1<", "<xmin>99<")), 2, "min > max"),
    ("voc-root", convert("voc", "<other/>"), 2, "expected <annotation>"),
    (
        "voc-entity",
        convert("voc", '<!DOCTYPE a [<!ENTITY x "y">]><annotation>&x;</annotation>'),
        2,
        "forbidden",
    ),
    (
        "voc-state-bad",
        convert("voc", None, ("<name>red</name>", "<name>red</name><state>blue</state>")),
        2,
        "state 'blue'",
    ),
    ("dtld-images-int", convert("dtld", '{"images": 5}'), 2, "expected"),
    (
        "dtld-labels-dict",
        convert("dtld", None, ('"labels": [', '"labels": {"a": ['), ("]}]}", "]}}]}")),
        2,
        "'labels' must be",
    ),
    ("dtld-x-word", convert("dtld", None, ('"x": 1', '"x": "one"')), 2, "'x' must be"),
    ("dtld-state-unknown", convert("dtld", None, ('"red"', '"blue"')), 2, "unknown state"),
    (
        "dtld-attributes-list",
        convert("dtld", None, ('{"state": "red"}', '["red"]')),
        2,
        "'attributes' must be",
    ),
    ("dtld-negative-w", convert("dtld", None, ('"w": 9', '"w": -9')), 2, "min > max"),
    ("dtld-path-int", convert("dtld", None, ('"a.png"', "5")), 2, "expected|'image_path' must be"),
    (
        "dtld-timestamp-list",
        convert("dtld", None, ('"labels"', '"time_stamp": [1], "labels"')),
        0,
        "wrote 1 images",
    ),
    ("lara-subtype", convert("lara", None, ("'go'", "'purple'")), 2, "unknown subtype"),
    ("lara-frame-word", convert("lara", None, ("/ 0 ", "/ x ")), 2, "must be numbers"),
    ("lara-quote", convert("lara", None, ("'go'", "'go")), 2, "cannot split"),
    ("lara-reversed", convert("lara", None, (" 1 1 10 10 ", " 10 1 1 10 ")), 2, "min > max"),
    ("lara-nan", convert("lara", None, (" 1 1 10 10 ", " nan 1 10 10 ")), 2, "finite"),
]

COCO: list[Row] = [
    (
        "coco-images-int",
        convert(
            "coco",
            None,
            (
                '"images": [{"id": 1, "file_name": "a.png", "width": 32, "height": 32}]',
                '"images": 5',
            ),
        ),
        2,
        "'images' must be",
    ),
    (
        "coco-annotations-int",
        convert("coco", None, ('"annotations": [', '"annotations": 5, "x": [')),
        2,
        "'annotations' must be",
    ),
    (
        "coco-categories-str",
        convert("coco", None, ('"categories": [{"id": 1, "name": "red"}]', '"categories": "red"')),
        2,
        "'categories' must be",
    ),
    ("coco-top-list", convert("coco", "[1, 2]"), 2, "expected an object"),
    (
        "coco-attributes-list",
        convert("coco", None, ('"bbox"', '"attributes": [1], "bbox"')),
        2,
        "'attributes' must be",
    ),
    (
        "coco-attributes-int",
        convert("coco", None, ('"bbox"', '"attributes": 5, "bbox"')),
        2,
        "'attributes' must be",
    ),
    (
        "coco-attributes-str",
        convert("coco", None, ('"bbox"', '"attributes": "x", "bbox"')),
        2,
        "'attributes' must be",
    ),
    (
        "coco-metadata-list",
        convert("coco", None, ('"width": 32,', '"metadata": [1], "width": 32,')),
        2,
        "'metadata' must be",
    ),
    (
        "coco-metadata-int",
        convert("coco", None, ('"width": 32,', '"metadata": 5, "width": 32,')),
        2,
        "'metadata' must be",
    ),
    (
        "coco-split-list",
        convert("coco", None, ('"width": 32,', '"split": ["test"], "width": 32,')),
        2,
        "'split' must be",
    ),
    (
        "coco-split-int",
        convert("coco", None, ('"width": 32,', '"split": 3, "width": 32,')),
        2,
        "'split' must be",
    ),
    ("coco-bbox-three", convert("coco", None, ("[1, 1, 9, 9]", "[1, 1, 9]")), 2, "expected 4"),
    (
        "coco-bbox-strings",
        convert("coco", None, ("[1, 1, 9, 9]", '["a", 1, 9, 9]')),
        2,
        "expected 4 numbers",
    ),
    (
        "coco-bbox-negative",
        convert("coco", None, ("[1, 1, 9, 9]", "[1, 1, -9, 9]")),
        2,
        "min > max",
    ),
    ("coco-bbox-zero", convert("coco", None, ("[1, 1, 9, 9]", "[1, 1, 0, 9]")), 0, "0 boxes"),
    ("coco-bbox-dict", convert("coco", None, ("[1, 1, 9, 9]", '{"x": 1}')), 2, "'bbox' must be"),
    ("coco-bbox-huge", convert("coco", None, ("[1, 1, 9, 9]", "[1, 1, 1e400, 9]")), 2, "finite"),
    (
        "coco-category-unknown",
        convert("coco", None, ('"category_id": 1', '"category_id": 9')),
        2,
        "unknown category_id",
    ),
    (
        "coco-category-str",
        convert("coco", None, ('"category_id": 1', '"category_id": "1"')),
        2,
        "'category_id' must be",
    ),
    (
        "coco-image-id-unknown",
        convert("coco", None, ('"image_id": 1', '"image_id": 4')),
        2,
        "unknown image ids",
    ),
    (
        "coco-image-id-bool",
        convert("coco", None, ('"image_id": 1', '"image_id": true')),
        2,
        "'image_id' must be",
    ),
    (
        "coco-file-name-int",
        convert("coco", None, ('"file_name": "a.png"', '"file_name": 5')),
        2,
        "'file_name' must be",
    ),
    (
        "coco-image-str",
        convert(
            "coco",
            None,
            ('[{"id": 1, "file_name": "a.png", "width": 32, "height": 32}]', '["a.png"]'),
        ),
        2,
        "expected an object",
    ),
    (
        "coco-state-bad",
        convert("coco", None, ('"bbox"', '"state": "blue", "bbox"')),
        2,
        "state 'blue'",
    ),
    (
        "coco-category-name-list",
        convert("coco", None, ('"name": "red"', '"name": ["red"]')),
        2,
        "'name' must be",
    ),
    (
        "coco-width-str-ignored",
        convert("coco", None, ('"width": 32', '"width": "32"')),
        0,
        "wrote 1 images",
    ),
    (
        "normalized-split-list",
        convert("normalized", None, ('"split": "test"', '"split": ["test"]')),
        2,
        "'split' must be",
    ),
    (
        "normalized-metadata-list",
        convert("normalized", None, ('"width"', '"metadata": [1], "width"')),
        2,
        "'metadata' must be",
    ),
    (
        "normalized-attributes-list",
        convert("normalized", None, ('"x_min"', '"attributes": [1], "x_min"')),
        2,
        "'attributes' must be",
    ),
    (
        "normalized-boxes-dict",
        convert("normalized", None, ('"boxes": [', '"boxes": {"a": ['), ("}]}]", "}]}}]")),
        2,
        "'boxes' must be",
    ),
    (
        "normalized-record-int",
        convert("normalized", "[5]"),
        2,
        "expected a list|expected an object",
    ),
    ("normalized-top-dict", convert("normalized", '{"images": 5}'), 2, "expected a list"),
    (
        "normalized-x-str",
        convert("normalized", None, ('"x_min": 1', '"x_min": "1"')),
        2,
        "'x_min' must be",
    ),
    (
        "normalized-label-list",
        convert("normalized", None, ('"label": "red"', '"label": ["red"]')),
        2,
        "'label' must be",
    ),
    (
        "normalized-negative",
        convert("normalized", None, ('"x_max": 10', '"x_max": -10')),
        2,
        "min > max",
    ),
]

PARAMS: list[Row] = [
    ("param-nan-float", detect("-p", "h_peak=nan"), 2, "finite"),
    ("param-inf-float", detect("-p", "h_peak=inf"), 2, "finite"),
    ("param-minus-inf", detect("-p", "h_peak=-inf"), 2, "finite"),
    ("param-nan-in-list", detect("-d", "conspicuity", "-p", "weights=nan,1,1"), 2, "finite"),
    ("param-inf-in-list", detect("-d", "conspicuity", "-p", "weights=1,inf,1"), 2, "finite"),
    ("param-word-for-float", detect("-p", "h_peak=big"), 2, "must be a number"),
    ("param-list-length", detect("-d", "conspicuity", "-p", "weights=1,1"), 2, "length 3"),
    ("param-no-equals", detect("-p", "min_radius"), 2, "key=value"),
    ("param-empty-key", detect("-p", "=1"), 2, "key=value"),
    ("param-unknown-detect", detect("-p", "bogus=1"), 2, "unknown parameter 'bogus'"),
    ("param-unknown-benchmark", bench("-p", "bogus=1"), 2, "unknown parameter 'bogus'"),
    ("param-unknown-compare", compare("-p", "bogus=1"), 2, "unknown parameter 'bogus'"),
    (
        "param-unknown-compare-prefixed",
        compare("-p", "gray-tophat.bogus=1"),
        2,
        "unknown parameter 'bogus'",
    ),
    ("param-unknown-train", train("-p", "bogus=1"), 2, "unknown parameter 'bogus'"),
    ("param-nan-compare", compare("-p", "gray-tophat.h_peak=nan"), 2, "finite"),
    ("param-nan-benchmark", bench("-p", "h_peak=nan"), 2, "finite"),
    ("param-nan-train", train("-p", "bins=nan"), 2, "integer|finite"),
    ("param-detector-prefix-train", train("-p", "detector.x=1"), 2, "need --detector"),
    (
        "param-classifier-prefix-unselected",
        detect("-p", "classifier.model=x"),
        2,
        "unknown parameter",
    ),
    ("plugin-unknown-detector", detect("-d", "nope"), 2, "no detector called 'nope'"),
    ("plugin-unknown-classifier", detect("-c", "nope"), 2, "no classifier called 'nope'"),
    ("plugin-unknown-verifier", detect("-V", "nope"), 2, "no verifier called 'nope'"),
    ("plugin-unknown-tracker", detect("-t", "nope"), 2, "no tracker called 'nope'"),
    ("plugin-unknown-compare", compare("--detectors", "nope"), 2, "no detector called 'nope'"),
    ("plugin-benchmark-tracker", bench("-t", "meanshift"), 2, "No such option '-t'"),
    (
        "plugin-train-not-trainable",
        lambda tmp: train()(tmp)[:1] + ["gray-tophat"] + train()(tmp)[2:],
        2,
        "trainable|cannot be trained|not",
    ),
    ("plugin-train-unknown", lambda tmp: train()(tmp)[:1] + ["nope"] + train()(tmp)[2:], 2, "nope"),
    ("writer-unknown", bench("--writer", "nope"), 2, "nope"),
    ("compare-without-verifier-alone", compare("--without-verifier"), 2, "needs a verifier"),
    ("detect-draw-with-workers", detect("--draw", "ov", "-w", "2"), 2, "--workers 1"),
]

CONFIGS: list[Row] = [
    ("config-int-key", config("1: conspicuity\n"), 2, "config"),
    (
        "config-int-key-in-params",
        config("detector: {name: gray-tophat, params: {1: 2}}\n"),
        2,
        "unknown parameter|config",
    ),
    ("config-list", config("- a\n- b\n"), 2, "expected a mapping"),
    ("config-broken-yaml", config("detector: [\n"), 2, "config"),
    ("config-utf8", config(b"detector: gray\xff\xfe"), 2, "UTF-8|config"),
    ("config-detector-int", config("detector: 5\n"), 2, "must be a name"),
    ("config-name-int", config("detector: {name: 5}\n"), 2, "name"),
    (
        "config-params-list",
        config("detector: {name: gray-tophat, params: [1]}\n"),
        2,
        "must be a mapping",
    ),
    ("config-unknown-plugin", config("detector: nope\n"), 2, "no detector called 'nope'"),
    (
        "config-unknown-param",
        config("detector: {name: gray-tophat, params: {bogus: 1}}\n"),
        2,
        "unknown parameter 'bogus'",
    ),
    (
        "config-nan-param",
        config("detector: {name: gray-tophat, params: {h_peak: .nan}}\n"),
        2,
        "finite",
    ),
    (
        "config-inf-param",
        config("detector: {name: gray-tophat, params: {h_peak: .inf}}\n"),
        2,
        "finite",
    ),
    ("config-compare-int-key", config("1: x\nclassifier: ab-hist\n", verb="compare"), 2, "config"),
    (
        "config-missing",
        detect("--config", "/nonexistent/run.yaml"),
        2,
        "no such|not found|nonexistent",
    ),
    ("config-folder", lambda tmp: detect("--config", str(tmp))(tmp), 2, "config|directory"),
    ("config-unknown-preset", detect("--config", "no-such-preset"), 2, "no-such-preset"),
]


def _detect_out(tmp: Path, out: str) -> list[str]:
    return detect("-o", out)(tmp)


def _bench_out(tmp: Path, out: str) -> list[str]:
    args = bench()(tmp)
    return [*args[: args.index("-o")], "-o", out]


def _compare_out(tmp: Path, out: str) -> list[str]:
    args = compare()(tmp)
    return [*args[: args.index("-o")], "-o", out]


def _train_out(tmp: Path, out: str) -> list[str]:
    args = train()(tmp)
    return [*args[: args.index("--out")], "--out", out]


def _synth_out(tmp: Path, out: str) -> list[str]:
    return ["datasets", "synth", "--out", out, "--frames", "2", "--width", "64", "--height", "64"]


def _convert_out(tmp: Path, out: str) -> list[str]:
    return ["datasets", "convert", str(norm_dataset(tmp)), "--to", "coco", "--out", out]


def _report_out(tmp: Path, out: str) -> list[str]:
    return ["report", out]


OUTPUTS: list[Row] = [
    (
        f"out-under-a-file-{name}",
        under_a_file(verb),
        2,
        "cannot write|not a directory|Not a directory",
    )
    for name, verb in [
        ("detect", _detect_out),
        ("benchmark", _bench_out),
        ("compare", _compare_out),
        ("train", _train_out),
        ("synth", _synth_out),
        ("convert", _convert_out),
    ]
] + [
    (
        "out-is-a-file-benchmark",
        lambda tmp: _bench_out(tmp, str(write(tmp / "f", "x"))),
        2,
        "file|exists",
    ),
    (
        "out-is-a-file-compare",
        lambda tmp: _compare_out(tmp, str(write(tmp / "f", "x"))),
        2,
        "file|exists",
    ),
    (
        "out-is-a-file-synth",
        lambda tmp: _synth_out(tmp, str(write(tmp / "f", "x"))),
        2,
        "file|exists",
    ),
    ("out-is-a-folder-detect", lambda tmp: _detect_out(tmp, str(tmp)), 2, "directory|folder"),
    ("out-is-a-folder-train", lambda tmp: _train_out(tmp, str(tmp / "m")), 0, "trained ab-hist"),
    ("report-not-a-run", lambda tmp: ["report", str(tmp)], 2, "report.json|compare.json"),
    ("report-missing", lambda tmp: ["report", str(tmp / "nope")], 2, "does not exist|no such"),
    (
        "report-broken-json",
        lambda tmp: ["report", str(write(tmp / "r" / "report.json", "{").parent)],
        2,
        "report.json",
    ),
]

RUNS: list[Row] = [
    (
        "bench-all-skipped",
        bench(records=[{"file": "missing.png", "boxes": []}]),
        1,
        "all 1 inputs were skipped",
    ),
    (
        "bench-header-lie-frame",
        lambda tmp: (
            png_declaring(tmp / "lie.png", 40000, 40000),
            bench(records=[{"file": "lie.png", "boxes": []}, {"file": "a.png", "boxes": []}])(tmp),
        )[1],
        0,
        "report",
    ),
    (
        "bench-unknown-dataset",
        lambda tmp: ["benchmark", "--dataset", "no-such-set", *FAST, "-o", str(tmp / "o")],
        2,
        "neither a registered dataset",
    ),
    (
        "bench-unknown-format",
        lambda tmp: bench("--format", "nope")(tmp),
        2,
        "no format called 'nope'",
    ),
    ("bench-wrong-format", lambda tmp: bench("--format", "coco")(tmp), 2, "expected an object"),
    ("bench-missing-split", bench("--split", "train"), 2, "no samples in split 'train'"),
    ("bench-iou-out-of-range", bench("--iou", "1.5"), 2, "1.5 is not in the range"),
    ("bench-iou-nan", bench("--iou", "nan"), 2, "'nan' is not a finite number"),
    ("bench-workers-zero", bench("-w", "0"), 2, "0 is not in the range x>=1"),
    ("detect-every-zero", detect("--every", "0"), 2, "0 is not in the range x>=1"),
    (
        "detect-key-every-zero",
        detect("--key-every", "0"),
        2,
        "'--key-every': 0 is not in the range",
    ),
    ("detect-agree-zero", detect("--agree", "0"), 2, "'--agree': 0 is not in the range x>=1"),
    ("detect-agree-word", detect("--agree", "two"), 2, "'two' is not a valid integer"),
    (
        "convert-unknown-to",
        lambda tmp: [
            "datasets",
            "convert",
            str(norm_dataset(tmp)),
            "--to",
            "nope",
            "--out",
            str(tmp / "o"),
        ],
        2,
        "no format called 'nope'",
    ),
    (
        "convert-to-read-only-format",
        lambda tmp: [
            "datasets",
            "convert",
            str(norm_dataset(tmp)),
            "--to",
            "lisa",
            "--out",
            str(tmp / "o"),
        ],
        2,
        "has no writer",
    ),
    (
        "convert-ambiguous",
        lambda tmp: ["datasets", "convert", str(tmp), "--to", "coco", "--out", str(tmp / "o.json")],
        2,
        "no format recognises",
    ),
    *(
        (
            f"sniff-utf8-{name}",
            lambda tmp, name=name: ["datasets", "info", str(write(tmp / name, BAD_UTF8))],
            2,
            "no format recognises it",
        )
        for name in ("a.json", "labels.csv", "GT-1.csv", "a.xml", "data.yaml", "gt.txt")
    ),
    (
        "info-unknown",
        lambda tmp: ["datasets", "info", "no-such-set"],
        2,
        "neither a registered dataset",
    ),
    (
        "verify-unknown",
        lambda tmp: ["datasets", "verify", "no-such-set"],
        2,
        "no registered dataset",
    ),
    (
        "synth-bad-lighting",
        lambda tmp: [*_synth_out(tmp, str(tmp / "s")), "--lighting", "purple"],
        2,
        "purple",
    ),
    (
        "synth-nan-width",
        lambda tmp: [*_synth_out(tmp, str(tmp / "s")), "--width", "nan"],
        2,
        "'nan' is not a valid integer",
    ),
    ("train-no-dataset", lambda tmp: ["train", "ab-hist", "--out", str(tmp / "m")], 2, "--dataset"),
    ("train-missing-split", train("--split", "nope"), 2, "nope"),
    ("model-missing", model_files(None, None), 2, "no such file"),
    ("model-npz-garbage", model_files(b"garbage", model_meta()), 2, "corrupt archive"),
    (
        "model-npz-bad-deflate",
        model_files(damaged_npz("deflate"), model_meta()),
        2,
        "corrupt archive \\(error",
    ),
    (
        "model-npz-unknown-method",
        model_files(damaged_npz("method"), model_meta()),
        2,
        "corrupt archive \\(NotImplementedError",
    ),
    ("model-json-garbage", model_files(good_npz(), "{"), 2, "unreadable metadata"),
    ("model-json-utf8", model_files(good_npz(), b'{"plugin": "\xff"}'), 2, "unreadable metadata"),
    ("model-json-list", model_files(good_npz(), "[1]"), 2, "not tsrkit model metadata"),
    (
        "model-other-plugin",
        model_files(good_npz(), model_meta(plugin="lamp-state")),
        2,
        "trained for 'lamp-state'",
    ),
    (
        "model-arrays-list",
        model_files(good_npz(), model_meta(arrays=["histograms"])),
        2,
        "metadata",
    ),
    (
        "model-arrays-int-entry",
        model_files(good_npz(), model_meta(arrays={"histograms": 5})),
        2,
        "metadata",
    ),
    ("model-checksum", model_files(good_npz(), model_meta()), 2, "checksum"),
    (
        "model-plugin-list",
        model_files(good_npz(), model_meta(plugin=["ab-hist"])),
        2,
        "trained for|metadata",
    ),
]

MATRIX = IMAGES + READERS + COCO + PARAMS + CONFIGS + OUTPUTS + RUNS


def test_the_matrix_has_the_issues_142_cases():
    assert len(MATRIX) >= 142
    assert len({row[0] for row in MATRIX}) == len(MATRIX)


@pytest.mark.parametrize(
    "build,code,fragment", [pytest.param(*row[1:], id=row[0]) for row in MATRIX]
)
def test_bad_input(tmp_path, monkeypatch, build, code, fragment, request):
    if request.node.callspec.id == "image-max-pixels-env":
        monkeypatch.setenv("TSRKIT_MAX_PIXELS", "100")
    check_row(tmp_path, build, code, fragment)


def check_row(tmp_path: Path, build: Callable[[Path], list[str]], code: int, fragment: str) -> None:
    """Run one row through the command line: exit ``code``, ``fragment`` in the output (with
    the row's folder hidden, so that a fragment cannot match the path), no traceback."""
    args = build(tmp_path)
    result = CliRunner().invoke(cli, args)
    output = result.output.replace(str(tmp_path), "TMP")  # fragments must not match the path
    assert result.exception is None or isinstance(result.exception, SystemExit), (
        f"uncaught {type(result.exception).__name__}: {result.exception}\n{output}"
    )
    assert "Traceback" not in output
    assert result.exit_code == code, output
    assert re.search(fragment, output, re.IGNORECASE), output
