"""The bad-input matrix, third table: a fresh stranger's cases past the first two tables. Run
folders read back by ``tsrkit report`` (benchmark, compare and track folders with each file
missing, empty, damaged or special), numeric options at and past their limits (non-finite,
zero, negative, huge) on every verb that takes them, special files (FIFO, device, socket,
folder, dangling link) at every place a regular file is read or written, and video ranges.
Same runner as :mod:`test_bad_input_matrix`: exit code, message fragment, no traceback; rows
that could block run under an alarm.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import tempfile
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest
from click.testing import CliRunner
from test_bad_input_matrix import BASES, FAST, Row, check_row, convert, norm_dataset, png, write
from test_edge_matrix import FIXES, MAP, fifo, geo, link, tiny_drive, unix_socket, with_video

from tsrkit.cli.main import cli

# ---------------------------------------------------------------------------------------------
# run folders, made once per session and copied into each row's folder

_TEMPLATES: dict[str, Path] = {}

TRAVERSAL = {
    "traversal": 0,
    "intersection": 1,
    "movement": "through",
    "first_frame": 0,
    "last_frame": 20,
    "anchor_frame": 12,
    "short_range": [8, 14],
    "tracks": [],
    "start_utc": 1780315200.0,
}


def track_folder(folder: Path, gps: Path, osm: Path) -> Path:
    """A ``track VIDEO --out`` folder as the verb writes it (``report.json`` and one traversal
    in ``traversals.jsonl``), written by hand so that no video is decoded."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "traversals.jsonl").write_text(json.dumps(TRAVERSAL) + "\n")
    report = {
        "video": "drive.mp4",
        "gps": str(gps),
        "map": str(osm),
        "frames": 21,
        "fps": 10.0,
        "start_utc": 1780315200.0,
        "clip_frames": 21,
        "traversals": 1,
        "plugins": {},
        "settings": {"vicinity": 30.0},
        "files": [],
        "plots": [],
    }
    (folder / "report.json").write_text(json.dumps(report))
    return folder


def template(kind: str) -> Path:
    """The session's run folder of ``kind`` (``run``, ``compare`` or ``track``)."""
    if kind not in _TEMPLATES:
        root = Path(tempfile.mkdtemp(prefix=f"tsrkit-{kind}-"))
        if kind == "track":
            gps, osm = write(root / "g.csv", FIXES), write(root / "m.osm", MAP)
            _TEMPLATES[kind] = track_folder(root / "out", gps, osm)
        else:
            ds = norm_dataset(root)
            verb = (
                ["benchmark", "-d", "gray-tophat"]
                if kind == "run"
                else ["compare", "--detectors", "gray-tophat,tl-recognizer"]
            )
            args = [*verb, "--dataset", str(ds), "-q", "-w", "1", "--no-cache", "-o"]
            result = CliRunner().invoke(cli, [*args, str(root / "out")])
            assert result.exit_code == 0, result.output
            _TEMPLATES[kind] = root / "out"
    return _TEMPLATES[kind]


def report(kind: str, *damage: Callable[[Path], object], writer: str = "markdown"):
    """``tsrkit report --writer WRITER`` on a copy of the ``kind`` folder after ``damage``."""

    def build(tmp: Path) -> list[str]:
        folder = tmp / kind
        shutil.copytree(template(kind), folder, symlinks=True)
        for change in damage:
            change(folder)
        return ["report", str(folder), "--writer", writer]

    return build


def replace(name: str, content: str | bytes) -> Callable[[Path], object]:
    return lambda folder: write(folder / name, content)


def remove(name: str) -> Callable[[Path], object]:
    return lambda folder: (folder / name).unlink()


def edit(name: str, change: Callable[[dict], object], line: bool = False):
    """Change the JSON object of ``name`` (its first line when ``line``) in place."""

    def apply(folder: Path) -> None:
        path = folder / name
        lines = path.read_text().splitlines() if line else [path.read_text()]
        data = json.loads(lines[0])
        change(data)
        path.write_text("\n".join([json.dumps(data), *lines[1:]]) + "\n")

    return apply


def special(name: str, kind: str) -> Callable[[Path], object]:
    """Replace ``name`` in the folder by a special file of ``kind``."""

    def apply(folder: Path) -> None:
        path = folder / name
        path.unlink(missing_ok=True)
        make_special(path, kind)

    return apply


def make_special(path: Path, kind: str) -> Path:
    if kind == "fifo":
        return fifo(path)
    if kind == "device":
        return link(path, "/dev/zero")
    if kind == "socket":
        path.parent.mkdir(parents=True, exist_ok=True)
        return unix_socket(path)
    if kind == "dangling":
        return link(path, str(path.parent / "gone"))
    path.mkdir(parents=True)
    return path


REPORTS: list[Row] = [
    ("report-folder-empty", lambda tmp: ["report", str(tmp)], 2, "not a run folder"),
    ("report-path-is-a-file", lambda tmp: ["report", str(write(tmp / "r.json", "{}"))], 2, "file"),
    ("report-json-null", report("run", replace("report.json", "null")), 2, "not a tsrkit report"),
    ("report-json-string", report("run", replace("report.json", '"x"')), 2, "not a tsrkit rep"),
    ("report-json-number", report("run", replace("report.json", "3")), 2, "not a tsrkit report"),
    (
        "report-json-deep",
        report("run", replace("report.json", "[" * 5000 + "]" * 5000)),
        2,
        "report.json: nested deeper",
    ),
    (
        "report-json-not-utf8",
        report("run", replace("report.json", b'{"dataset": "\xff"}')),
        2,
        "report.json: line 1: not valid UTF-8",
    ),
    (
        "report-json-without-dataset",
        report("run", edit("report.json", lambda d: d.pop("dataset"))),
        2,
        "no 'dataset' entry",
    ),
    (
        "report-json-dataset-a-string",
        report("run", edit("report.json", lambda d: d.update(dataset="x"))),
        2,
        "report.json",
    ),
    (
        "report-json-per-frame-a-list",
        report("run", edit("report.json", lambda d: d.update(per_frame=[1]))),
        1,
        "writer 'markdown' failed and was left out",
    ),
    (
        "report-dataset-moved",
        report(
            "run",
            edit("report.json", lambda d: d["dataset"]["opened_as"].update(ref="/nowhere/a.json")),
        ),
        0,
        "summary.md",
    ),
    ("report-detections-empty", report("run", replace("detections.jsonl", "")), 0, "summary.md"),
    (
        "report-detections-not-utf8",
        report("run", replace("detections.jsonl", b"\xff\xfe\n")),
        2,
        "detections.jsonl: line 1: not valid UTF-8",
    ),
    (
        "report-detections-deep-line",
        report("run", replace("detections.jsonl", "[" * 5000 + "]" * 5000 + "\n")),
        2,
        "detections.jsonl: line 1",
    ),
    (
        "report-detections-width-a-string",
        report("run", edit("detections.jsonl", lambda d: d.update(width="64"), line=True)),
        2,
        "detections.jsonl: line 1: not a frame record",
    ),
    (
        "report-json-fifo",
        report("run", special("report.json", "fifo")),
        2,
        "report.json: not a regular file",
    ),
    (
        "report-json-device",
        report("run", special("report.json", "device")),
        2,
        "report.json: not a regular file",
    ),
    (
        "report-json-folder",
        report("run", special("report.json", "folder")),
        2,
        "report.json: not a regular file",
    ),
    (
        "report-json-dangling",
        report("run", special("report.json", "dangling")),
        2,
        "report.json",
    ),
    (
        "report-detections-fifo",
        report("run", special("detections.jsonl", "fifo")),
        2,
        "detections.jsonl: not a regular file",
    ),
    (
        "report-detections-device",
        report("run", special("detections.jsonl", "device")),
        2,
        "detections.jsonl: not a regular file",
    ),
    ("report-writer-unknown", report("run", writer="nope"), 2, "nope"),
    ("report-compare-ok", report("compare", writer="html"), 0, "compare.html"),
    ("report-compare-markdown", report("compare"), 2, "markdown write nothing for one"),
    (
        "report-compare-json-null",
        report("compare", replace("compare.json", "null")),
        2,
        "compare.json",
    ),
    (
        "report-compare-reports-empty",
        report("compare", edit("compare.json", lambda d: d.update(reports=[]))),
        2,
        "no 'reports' list",
    ),
    (
        "report-compare-report-without-dataset",
        report("compare", edit("compare.json", lambda d: d["reports"][0].pop("dataset"))),
        2,
        "a report without its dataset",
    ),
    (
        "report-compare-json-fifo",
        report("compare", special("compare.json", "fifo")),
        2,
        "compare.json: not a regular file",
    ),
    (
        "report-compare-json-device",
        report("compare", special("compare.json", "device")),
        2,
        "compare.json: not a regular file",
    ),
    (
        "report-compare-paired-tests-a-number",
        report("compare", edit("compare.json", lambda d: d.update(paired_tests=2)), writer="html"),
        1,
        "writer 'html' failed and was left out",
    ),
    ("report-track-ok", report("track"), 0, "summary.md"),
    ("report-track-no-traversal", report("track", replace("traversals.jsonl", "")), 0, "summary"),
    (
        "report-track-gps-moved",
        report("track", edit("report.json", lambda d: d.update(gps="/nowhere/g.csv"))),
        0,
        "summary.md",
    ),
    (
        "report-track-traversals-missing",
        report("track", remove("traversals.jsonl")),
        2,
        r"not a track run folder \(traversals.jsonl missing\)",
    ),
    (
        "report-track-traversals-garbage",
        report("track", replace("traversals.jsonl", "{oops\n")),
        2,
        "traversals.jsonl: line 1",
    ),
    (
        "report-track-traversal-a-list",
        report("track", replace("traversals.jsonl", "[1, 2]\n")),
        2,
        "line 1: not a traversal record",
    ),
    (
        "report-track-tracks-not-a-list",
        report("track", edit("traversals.jsonl", lambda d: d.update(tracks=3), line=True)),
        2,
        "no list of tracks",
    ),
    (
        "report-track-traversal-without-movement",
        report("track", edit("traversals.jsonl", lambda d: d.pop("movement"), line=True)),
        2,
        "missing movement",
    ),
    (
        "report-track-without-settings",
        report("track", edit("report.json", lambda d: d.pop("settings"))),
        2,
        "not a track report",
    ),
    (
        "report-track-fps-a-word",
        report("track", edit("report.json", lambda d: d.update(fps="fast"))),
        2,
        "not a track report",
    ),
    (
        "report-track-traversals-fifo",
        report("track", special("traversals.jsonl", "fifo")),
        2,
        "traversals.jsonl: not a regular file",
    ),
    (
        "report-track-traversals-device",
        report("track", special("traversals.jsonl", "device")),
        2,
        "traversals.jsonl: not a regular file",
    ),
    (
        "report-track-without-video",
        report("track", remove("report.json")),
        2,
        "a track run without a video",
    ),
]

# ---------------------------------------------------------------------------------------------
# numeric options at and past their limits


def detect(*extra: str):
    def build(tmp: Path) -> list[str]:
        png(tmp / "in" / "a.png", size=64)
        return ["detect", str(tmp / "in"), "-d", "gray-tophat", "-q", *extra]

    return build


def detect_video(*extra: str):
    def build(tmp: Path) -> list[str]:
        return ["detect", str(tiny_drive() / "drive.mp4"), "-d", "gray-tophat", "-q", *extra]

    return build


def drive(*extra: str):
    return lambda tmp: ["datasets", "drive", "--out", str(tmp / "d"), *extra]


def synth(*extra: str):
    return lambda tmp: ["datasets", "synth", "--out", str(tmp / "s"), "-q", *extra]


def bench(*extra: str):
    def build(tmp: Path) -> list[str]:
        ds = norm_dataset(tmp)
        return ["benchmark", "--dataset", str(ds), "-d", "gray-tophat", *FAST, *extra]

    return build


def compare(*extra: str):
    def build(tmp: Path) -> list[str]:
        ds = norm_dataset(tmp)
        args = ["compare", "--dataset", str(ds), "--detectors", "gray-tophat,lab-frst", *FAST]
        return [*args, *extra]

    return build


NUMBERS: list[Row] = [
    *(
        (f"drive-fps-{name}", drive("--fps", value), 2, "--fps")
        for name, value in (("nan", "nan"), ("inf", "inf"), ("zero", "0"), ("above-120", "121"))
    ),
    ("drive-width-below-64", drive("--width", "8"), 2, "--width"),
    ("drive-height-huge", drive("--height", "100000"), 2, "--height"),
    ("drive-seed-negative", drive("--seed", "-1"), 2, "--seed"),
    ("drive-route-unknown", drive("--route", "sideways"), 2, "sideways"),
    ("drive-route-empty", drive("--route", ","), 2, "route"),
    ("synth-width-zero", synth("--width", "0"), 2, "--width"),
    ("synth-height-huge", synth("--height", "100000"), 2, "--height"),
    ("synth-frames-zero", synth("--frames", "0"), 2, "--frames"),
    ("synth-frames-word", synth("--frames", "many"), 2, "--frames"),
    ("synth-seed-negative-named", synth("--seed", "-1"), 2, "--seed"),
    ("detect-every-negative", detect("--every", "-1"), 2, "--every"),
    ("detect-start-negative", detect("--start", "-1"), 2, "--start"),
    ("detect-end-negative", detect("--end", "-5"), 2, "--end"),
    ("detect-workers-negative", detect("-w", "-1"), 2, "--workers"),
    ("detect-every-word", detect("--every", "two"), 2, "--every"),
    ("video-key-every-with-tracker", detect_video("--key-every", "2", "-t", "meanshift"), 2, "one"),
    ("video-start-negative", detect_video("--start", "-3"), 2, "--start"),
    ("video-end-zero", detect_video("--end", "0"), 2, "--end|empty|no frame"),
    ("video-every-past-its-length", detect_video("--every", "1000"), 0, "1 frames"),
    *(
        (f"track-{option[2:]}-{name}", geo(FIXES, MAP, option, value), 2, option)
        for option, name, value in (
            ("--vicinity", "zero", "0"),
            ("--vicinity", "inf", "inf"),
            ("--vicinity", "huge", "1e9"),
            ("--upstream", "negative", "-1"),
            ("--upstream", "minus-inf", "-inf"),
            ("--downstream", "nan", "nan"),
            ("--downstream", "negative", "-0.5"),
            ("--slack", "inf", "inf"),
            ("--slack", "negative", "-1"),
            ("--roi-top", "zero", "0"),
            ("--roi-top", "above-one", "1.5"),
            ("--roi-top", "inf", "inf"),
            ("--top", "zero", "0"),
            ("--top", "word", "five"),
            ("--flow-margin", "negative", "-1"),
        )
    ),
    *(
        (f"track-start-utc-{name}", with_video("--start-utc", value), 2, "--start-utc")
        for name, value in (
            ("word", "yesterday"),
            ("year-10000", "10000-01-01T00:00:00"),
            ("minus-inf", "-inf"),
        )
    ),
    *(
        (f"track-{option[2:]}-without-video", geo(FIXES, MAP, option, value), 2, "need a VIDEO")
        for option, value in (("--start-utc", "0"), ("--top", "3"), ("--config", "recommended"))
    ),
    ("benchmark-iou-inf", bench("--iou-threshold", "inf"), 2, "--iou"),
    ("benchmark-iou-negative", bench("--iou-threshold", "-0.5"), 2, "--iou"),
    ("benchmark-iou-one", bench("--iou-threshold", "1"), 2, "--iou"),
    ("benchmark-workers-negative", bench("-w", "-2"), 2, "--workers"),
    ("compare-iou-nan", compare("--iou-threshold", "nan"), 2, "--iou"),
    ("compare-workers-zero", compare("-w", "0"), 2, "--workers"),
]

# ---------------------------------------------------------------------------------------------
# special files where a regular file is read or written


def at(where: str, kind: str):
    """A command that meets a special file of ``kind`` at ``where``."""

    def build(tmp: Path) -> list[str]:
        png(tmp / "in" / "a.png", size=64)
        g, m = write(tmp / "gps.csv", FIXES), write(tmp / "map.osm", MAP)
        path = make_special(tmp / "special" / NAMES[where], kind)
        if where == "config":
            return ["detect", str(tmp / "in"), "-d", "gray-tophat", "--config", str(path)]
        if where == "model":
            return ["detect", str(tmp / "in"), "-c", "ab-hist", "-p", f"model={path}"]
        if where == "gps":
            return ["track", "--gps", str(path), "--map", str(m)]
        if where == "map":
            return ["track", "--gps", str(g), "--map", str(path)]
        if where == "truth":
            d = tiny_drive()
            video = ["track", str(d / "drive.mp4"), "--gps", str(d / "gps.csv")]
            return [*video, "--map", str(d / "map.osm"), "-d", "gray-tophat", "--truth", str(path)]
        if where == "track-video":
            return ["track", str(path), "--gps", str(g), "--map", str(m), "-d", "gray-tophat"]
        if where == "annotations":
            return ["datasets", "info", str(path)]
        if where == "convert-source":
            return ["datasets", "convert", str(path), "--to", "coco", "--out", str(tmp / "o.json")]
        if where == "train-dataset":
            return ["train", "ab-hist", "--dataset", str(path), "--out", str(tmp / "m")]
        if where == "detect-out":
            return ["detect", str(tmp / "in"), "-d", "gray-tophat", "-q", "-o", str(path)]
        if where == "convert-out":
            ds = norm_dataset(tmp / "ds")
            return ["datasets", "convert", str(ds), "--to", "coco", "--out", str(path)]
        if where == "synth-video":
            return [
                "datasets",
                "synth",
                "--out",
                str(tmp / "s"),
                "--frames",
                "2",
                "--video",
                str(path),
            ]
        raise AssertionError(where)

    return build


NAMES = {
    "config": "run.yaml",
    "model": "m.npz",
    "gps": "g.csv",
    "map": "m.osm",
    "truth": "truth.jsonl",
    "track-video": "drive.mp4",
    "annotations": "annotations.json",
    "convert-source": "coco.json",
    "train-dataset": "annotations.json",
    "detect-out": "d.jsonl",
    "convert-out": "o.json",
    "synth-video": "s.mp4",
}
#: The special files each place already has a row for in the earlier tables.
EARLIER = {
    ("config", "fifo"),
    ("config", "device"),
    ("config", "folder"),
    ("model", "fifo"),
    ("model", "folder"),
    ("gps", "fifo"),
    ("gps", "device"),
    ("map", "fifo"),
    ("truth", "fifo"),
    ("annotations", "fifo"),
    ("annotations", "device"),
}
#: Left open: a model path that names nothing is only noticed once a candidate needs the model
#: (plugins load their model at the first candidate).
OPEN = {("model", "dangling")}
WRITTEN = ("detect-out", "convert-out", "synth-video")
KINDS = ("fifo", "device", "socket", "folder", "dangling")


def expected(where: str, kind: str) -> tuple[int, str]:
    """An output path: a special file is refused (a folder by what writes it; a dangling link
    is written through); an input: refused in one line naming the file."""
    if where in WRITTEN:
        if kind == "dangling":
            return 0, ""
        if kind == "folder":
            return 2, NAMES[where]
        return 2, "not a regular file"
    if kind == "dangling":
        return 2, "no such file|does not exist|nor an existing path"
    return 2, f"{NAMES[where]}|not a regular file|directory"


SPECIALS: list[Row] = [
    (f"{where}-{kind}", at(where, kind), *expected(where, kind))
    for where in NAMES
    for kind in KINDS
    if (where, kind) not in EARLIER | OPEN
]

PATHS: list[Row] = [
    (
        "model-named-without-suffix-ok",
        lambda tmp: [*detect("-c", "ab-hist")(tmp), "-p", f"model={model_copy(tmp)}"],
        0,
        "1 frames",
    ),
]


def model_copy(tmp: Path) -> Path:
    """The shipped ab-hist model copied to ``tmp/m.npz`` / ``.json``, named without suffix."""
    from tsrkit_plugins.classifiers.ab_hist import DEFAULT_MODEL

    for suffix in (".npz", ".json"):
        shutil.copy(DEFAULT_MODEL.with_suffix(suffix), tmp / f"m{suffix}")
    return tmp / "m"


def declared(tmp: Path, name: str, kind: str) -> list[str]:
    """``benchmark`` on a dataset whose first image, of declared size, is a special file (the
    reader opens no image then: the run meets it first)."""
    records = [
        {"file": name, "width": 32, "height": 32, "boxes": []},
        {"file": "a.png", "width": 32, "height": 32, "boxes": []},
    ]
    ds = norm_dataset(tmp, records)
    make_special(tmp / name, kind)
    out = ["-o", str(tmp / "o"), "--writer", "jsonl"]
    return ["benchmark", "--dataset", str(ds), "-d", "gray-tophat", *FAST, *out]


RUNS: list[Row] = [
    (
        "dataset-image-of-declared-size-fifo",
        lambda tmp: declared(tmp, "p.png", "fifo"),
        0,
        "report",
    ),
    (
        "dataset-image-of-declared-size-device",
        lambda tmp: declared(tmp, "z.png", "device"),
        0,
        "report",
    ),
    (
        "dataset-json-nested-too-deep-named",
        lambda tmp: ["datasets", "info", str(write(tmp / "a.json", "[" * 500 + "]" * 500))],
        2,
        "a.json: nested deeper than 100 levels",
    ),
    (
        "benchmark-out-holds-a-foreign-report-json",
        lambda tmp: (
            write(tmp / "o" / "report.json", '{"mine": true}'),
            [*bench("-o", str(tmp / "o"))(tmp)],
        )[1],
        2,
        "report.json: not a tsrkit run's report",
    ),
]

# ---------------------------------------------------------------------------------------------
# inputs once mishandled: valid input refused, damage passed over in silence, results changed


def damaged_video(tmp: Path, frames: int = 60) -> Path:
    """A ``frames``-frame MPEG-4 video of noise whose middle 8,000 bytes are inverted: FFmpeg
    cannot decode a few frames there, and decodes the ones after them."""
    path = tmp / "damaged.mp4"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter.fourcc(*"mp4v"), 10.0, (64, 64))
    rng = np.random.default_rng(0)
    for _ in range(frames):
        writer.write(rng.integers(0, 255, (64, 64, 3), dtype=np.uint8))
    writer.release()
    data = bytearray(path.read_bytes())
    middle = len(data) // 2
    data[middle : middle + 8000] = bytes(b ^ 0xFF for b in data[middle : middle + 8000])
    return write(path, bytes(data))


def on_damaged_video(*extra: str):
    return lambda tmp: ["detect", str(damaged_video(tmp)), "-d", "gray-tophat", "-q", *extra]


#: Frames decoded and lost in :func:`damaged_video` (each lost frame is one skipped line).
DAMAGED = r"51 frames, \d+ detections, 9 skipped.*\n.*damaged.mp4#20: frame could not be decoded"

FOUND: list[Row] = [
    ("video-damaged-middle", on_damaged_video(), 0, DAMAGED),
    ("video-damaged-middle-workers", on_damaged_video("-w", "2"), 0, DAMAGED),
    ("video-damaged-middle-every-2", on_damaged_video("--every", "2"), 0, "25 frames.*5 skipped"),
    ("detect-resume-without-out", detect("--resume"), 2, "--resume .* needs --out"),
    (
        "detect-resume-with-agree",
        lambda tmp: [*detect_video("--agree", "2", "--resume", "-o")(tmp), str(tmp / "o.jsonl")],
        2,
        "--resume: a tracker, --key-every and --agree carry lights",
    ),
    (
        "detect-resume-without-partial",
        lambda tmp: [*detect("--resume", "-o")(tmp), str(tmp / "o.jsonl")],
        0,
        "no .*o.jsonl.partial to resume: starting at the first frame",
    ),
    ("detect-lock-of-a-reused-process-id", lambda tmp: locked_by(tmp, "legacy"), 0, "1 frames"),
    ("detect-lock-of-another-start-time", lambda tmp: locked_by(tmp, "1"), 0, "1 frames"),
    (
        "detect-lock-of-a-live-run-named",
        lambda tmp: locked_by(tmp, "live"),
        2,
        r"another run .* \(lock file TMP/\.o\.jsonl\.tsrkit\.lock\)",
    ),
    (
        "image-gif-first-frame",
        lambda tmp: one_image(gif(tmp / "a.gif")),
        0,
        r'"width": 30, "height": 20',
    ),
    (
        "image-jpeg-exif-rotated-upright",
        lambda tmp: one_image(exif_jpeg(tmp / "phone.jpg")),
        0,
        r'"width": 20, "height": 40',
    ),
    (
        "coco-utf8-byte-order-mark",
        convert("coco", b"\xef\xbb\xbf" + BASES["coco"][1].encode()),
        0,
        "1 images|->",
    ),
    (
        "coco-one-zero-width-box-left-out",
        convert(
            "coco",
            None,
            (
                "[1, 1, 9, 9]}]",
                '[1, 1, 9, 9]}, {"id": 2, "image_id": 1, "category_id": 1, "bbox": [5, 5, 0, 4]}]',
            ),
        ),
        0,
        r"warning: .*coco.json: 1 box\(es\) of zero width or height left out: a.png box 1",
    ),
    (
        "track-gps-fix-repeated-exactly",
        geo("".join(FIXES.splitlines(keepends=True)[k] for k in (*range(6), 5, *range(6, 21)))),
        0,
        "warning: .*g.csv: line 7: exactly repeats the fix before: left out",
    ),
    (
        "track-gps-glitch-fix",
        geo(FIXES.replace(FIXES.splitlines()[9], "1780315208,48.5,-122.15")),
        0,
        r"warning: .*g.csv: line 10: a glitch: the fix 48.500000, -122.150000 is reached and left "
        "faster than 90 m/s: left out",
    ),
    (
        "track-gps-jump-of-1000-km",
        geo(
            "time,lat,lon\n"
            + "".join(
                f"{1780315200 + k},{47.599 + 0.0001 * k + 9 * (k >= 10):.7f},-122.15\n"
                for k in range(20)
            )
        ),
        0,
        "warning: .*g.csv: line 12: the log jumps 1,000,... m in 1 s .*split there",
    ),
    (
        "detect-agree-on-still-images-keeps-them",
        detect("--agree", "3"),
        0,
        "1 frames, 1 detections",
    ),
    ("benchmark-split-empty", bench("--split", ""), 2, "--split.*empty split name"),
    (
        "train-split-empty",
        lambda tmp: [
            "train",
            "ab-hist",
            "--dataset",
            str(norm_dataset(tmp)),
            "--split",
            " ",
            "--out",
            str(tmp / "m"),
        ],
        2,
        "--split.*empty split name",
    ),
    (
        "coco-two-images-of-one-id",
        convert(
            "coco", None, ('"height": 32}]', '"height": 32}, {"id": 1, "file_name": "b.png"}]')
        ),
        2,
        r"coco.json: images\[1\]: image id 1 is also the id of images\[0\]",
    ),
    (
        "compare-into-a-folder-a-live-compare-holds",
        lambda tmp: locked_by(tmp, "live", "o/.tsrkit.lock", compare("-o", str(tmp / "o"))),
        2,
        r"TMP/o: another run .* \(lock file TMP/o/\.tsrkit\.lock\)",
    ),
    (
        "config-yaml-merge-key",
        lambda tmp: (
            one_image(png(tmp / "a.png", size=64))[:2]
            + ["--config", str(write(tmp / "run.yaml", MERGED)), "-q"]
        ),
        0,
        "1 frames",
    ),
]

#: A run configuration whose detector merges a shared mapping (``<<: *tophat``) and overrides
#: one of its keys.
MERGED = """\
detector:
  <<: &tophat {name: gray-tophat, params: {h_peak: 0.1}}
  params: {h_peak: 0.2}
"""


def one_image(path: Path) -> list[str]:
    return ["detect", str(path), "-d", "gray-tophat", "-q"]


def gif(path: Path) -> Path:
    """A 30x20 GIF of two frames (the first is read)."""
    from PIL import Image

    frames = [Image.new("RGB", (30, 20), colour) for colour in ("red", "blue")]
    path.parent.mkdir(parents=True, exist_ok=True)
    frames[0].save(path, save_all=True, append_images=frames[1:])
    return path


def exif_jpeg(path: Path) -> Path:
    """A 40x20 JPEG whose EXIF orientation 6 turns it upright to 20x40, as phones write."""
    from PIL import Image

    image = Image.new("RGB", (40, 20), "gray")
    exif = image.getexif()
    exif[0x0112] = 6
    path.parent.mkdir(parents=True, exist_ok=True)
    image.save(path, exif=exif)
    return path


def locked_by(tmp: Path, started: str, lock: str = ".o.jsonl.tsrkit.lock", verb=None):
    """``verb`` (default ``detect -o o.jsonl``) beside the lock file ``lock`` of this test's
    parent process (alive, not this one): with its real start time (``live``), another one, or
    none in a lock written in 2000, before the process started (``legacy``: its id was reused
    since)."""
    from tsrkit.runner.outlock import _start_time

    parent = os.getppid()
    path = tmp / lock
    if started == "legacy":
        write(path, str(parent))
        os.utime(path, (946684800, 946684800))
    else:
        write(path, f"{parent} {_start_time(parent) if started == 'live' else started}")
    return (verb or detect("-o", str(tmp / "o.jsonl")))(tmp)


def without_ms(path: Path) -> list[dict]:
    records = [json.loads(line) for line in path.read_text().splitlines()]
    return [{k: v for k, v in r.items() if k != "ms"} for r in records]


@pytest.mark.parametrize("workers", ["1", "2"])
def test_resume_goes_on_after_the_frames_of_the_partial(tmp_path, workers):
    """``detect -o OUT --resume`` after a kill (OUT.partial holds the first 30 records and half
    of the 31st) writes the records of an uninterrupted run, and runs only the rest."""
    png(tmp_path / "in" / "a.png", size=48)
    png(tmp_path / "in" / "b.png", size=48, value=90)
    damaged_video(tmp_path / "in")
    args = ["detect", str(tmp_path / "in"), "-d", "gray-tophat", "-q", "-w", workers, "-o"]
    whole = CliRunner().invoke(cli, [*args, str(tmp_path / "whole.jsonl")])
    assert whole.exit_code == 0, whole.output
    lines = (tmp_path / "whole.jsonl").read_text().splitlines(keepends=True)
    assert len(lines) == 53
    write(tmp_path / "o.jsonl.partial", "".join(lines[:30]) + lines[30][:40])
    resumed = CliRunner().invoke(cli, [*args, str(tmp_path / "o.jsonl"), "--resume"])
    assert resumed.exit_code == 0, resumed.output
    assert "resuming after the 30 frames" in resumed.output
    assert "53 frames" in resumed.output and "0 skipped" in resumed.output
    assert without_ms(tmp_path / "o.jsonl") == without_ms(tmp_path / "whole.jsonl")
    assert not (tmp_path / "o.jsonl.partial").exists()


MORE = REPORTS + NUMBERS + SPECIALS + PATHS + RUNS + FOUND


def test_the_third_table_is_a_hundred_new_cases():
    from test_bad_input_matrix import MATRIX
    from test_edge_matrix import EDGES

    earlier = {row[0] for row in MATRIX + EDGES}
    assert len(MORE) >= 100
    assert len({row[0] for row in MORE}) == len(MORE) and not earlier & {r[0] for r in MORE}


@pytest.mark.parametrize("build,code,fragment", [pytest.param(*r[1:], id=r[0]) for r in MORE])
def test_more_edges(tmp_path, monkeypatch, build, code, fragment):
    monkeypatch.setenv("TSRKIT_CACHE_DIR", str(tmp_path / "cache"))

    def blocked(signum, frame):
        raise TimeoutError("the row blocked for 120 s")

    previous = signal.signal(signal.SIGALRM, blocked)
    signal.alarm(120)
    try:
        check_row(tmp_path, build, code, fragment)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


SOURCE_COCO = {
    "images": [
        {"id": 7, "file_name": "a.png", "width": 32, "height": 32},
        {"id": 3, "file_name": "b.png", "width": 32, "height": 32},
    ],
    "annotations": [
        {"id": 1, "image_id": 7, "category_id": 5, "bbox": [0.1, 0.7, 0.2, 0.1]},
        {"id": 2, "image_id": 3, "category_id": 2, "bbox": [1.23456789, 2.5, 3.1415926, 4.0001]},
        {"id": 3, "image_id": 3, "category_id": 5, "bbox": [10, 11, 12.5, 3]},
    ],
    "categories": [{"id": 5, "name": "red"}, {"id": 2, "name": "green"}],
}


def test_coco_to_coco_keeps_boxes_and_ids(tmp_path):
    """``datasets convert`` COCO -> COCO: every box number as written, image and category ids
    kept (not renumbered); through the normalised format (which has no category ids) too, the
    boxes and image ids."""
    png(tmp_path / "a.png")
    png(tmp_path / "b.png")
    source = write(tmp_path / "coco.json", json.dumps(SOURCE_COCO))
    norm, back, direct = tmp_path / "n" / "a.json", tmp_path / "back.json", tmp_path / "o.json"
    for src, to, out in (
        (source, "normalized", norm),
        (norm, "coco", back),
        (source, "coco", direct),
    ):
        result = CliRunner().invoke(
            cli, ["datasets", "convert", str(src), "--to", to, "--out", str(out)]
        )
        assert result.exit_code == 0, result.output
    expected = [(a["image_id"], a["bbox"]) for a in SOURCE_COCO["annotations"]]
    for path in (direct, back):
        written = json.loads(path.read_text())
        assert [(i["id"], i["file_name"]) for i in written["images"]] == [
            (7, "a.png"),
            (3, "b.png"),
        ]
        assert [(a["image_id"], a["bbox"]) for a in written["annotations"]] == expected
    written = json.loads(direct.read_text())
    assert written["categories"] == [{"id": 2, "name": "green"}, {"id": 5, "name": "red"}]
    assert [a["category_id"] for a in written["annotations"]] == [5, 2, 5]
