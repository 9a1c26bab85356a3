"""The bad-input matrix, continued: the edges a stranger's audit found past the first table
(special files, sizes and counts, configs, video ranges, output paths that name inputs, cache
entries, GPS and map options), one row each, run through the command line like
:mod:`test_bad_input_matrix` (same runner: exit code, message fragment, no traceback).

Rows that would block (a FIFO, a device) run under an alarm, so a regression fails the row
instead of hanging the suite. Concurrency and ``kill -9`` cases, which need processes, are in
``test_concurrent_runs.py``.
"""

from __future__ import annotations

import json
import os
import signal
import socket
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest
from test_bad_input_matrix import FAST, Row, check_row, norm_dataset, png, write

GOOD_SIZE = 32


def folder(tmp: Path, *extra: Callable[[Path], object]) -> Path:
    """``tmp/in`` with one good image, then whatever ``extra`` adds."""
    inputs = tmp / "in"
    png(inputs / "g.png", size=64)  # 64 px: gray-tophat finds its spot
    for add in extra:
        add(inputs)
    return inputs


def detect_in(*add: Callable[[Path], object], args: tuple[str, ...] = ()):
    def build(tmp: Path) -> list[str]:
        return ["detect", str(folder(tmp, *add)), "-d", "gray-tophat", *args]

    return build


def fifo(path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    os.mkfifo(path)
    return path


def link(path: Path, target: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    os.symlink(target, path)
    return path


def unix_socket(path: Path) -> Path:
    sock = socket.socket(socket.AF_UNIX)
    sock.bind(str(path))
    sock.close()
    return path


def trailing(kind: str, size: int) -> Callable[[Path], object]:
    """An image followed by ``size`` bytes after its end marker (as phones write them)."""

    def add(inputs: Path) -> None:
        _ok, data = cv2.imencode(f".{kind}", np.full((16, 16, 3), 120, np.uint8))
        write(inputs / f"phone.{kind}", data.tobytes() + bytes(range(256)) * (size // 256))

    return add


def sparse(path: Path, size: int, head: bytes) -> Path:
    with open(path, "wb") as fh:
        fh.write(head)
        fh.truncate(size)
    return path


SPECIAL: list[Row] = [
    ("fifo-among-images", detect_in(lambda d: fifo(d / "p.png")), 0, "(?s)1 skipped.*FIFO"),
    (
        "fifo-named",
        lambda tmp: ["detect", str(fifo(tmp / "p.jpg")), "-d", "gray-tophat"],
        1,
        "not a regular file \\(a FIFO\\)",
    ),
    ("device-as-jpg", detect_in(lambda d: link(d / "z.jpg", "/dev/zero")), 0, "character device"),
    ("socket-as-png", detect_in(lambda d: unix_socket(d / "s.png")), 0, "socket"),
    ("symlink-to-itself", detect_in(lambda d: link(d / "l.png", "l.png")), 0, "1 skipped"),
    ("symlink-to-parent-folder", detect_in(lambda d: link(d / "up", "..")), 0, "1 frames"),
    ("dangling-symlink", detect_in(lambda d: link(d / "x.png", "/nonexistent")), 0, "1 skipped"),
    ("folder-named-png", detect_in(lambda d: (d / "f.png").mkdir()), 0, "1 frames, .* 0 skipped"),
    (
        "huge-sparse-jpg",
        detect_in(lambda d: sparse(d / "h.jpg", 3 * 2**30, b"\xff\xd8\xff\xe0")),
        0,
        "h.jpg: .*bytes, more than the limit",
    ),
    ("fifo-video", lambda tmp: ["detect", str(fifo(tmp / "v.mp4"))], 1, "FIFO"),
    (
        "fifo-config",
        lambda tmp: ["detect", str(folder(tmp)), "--config", str(fifo(tmp / "c.yaml"))],
        2,
        "c.yaml: not a regular file",
    ),
    (
        "device-config",
        lambda tmp: [
            "detect",
            str(folder(tmp)),
            "--config",
            str(link(tmp / "c.yaml", "/dev/zero")),
        ],
        2,
        "c.yaml: not a regular file",
    ),
    (
        "fifo-model",
        lambda tmp: [
            "detect",
            str(folder(tmp)),
            "-c",
            "ab-hist",
            "-p",
            f"model={fifo(tmp / 'm.npz')}",
        ],
        2,
        "not a regular file \\(a FIFO\\)",
    ),
    (
        "device-verifier-model",
        lambda tmp: [
            "detect",
            str(folder(tmp)),
            "-V",
            "verifier",
            "-p",
            f"verifier.model={link(tmp / 'v.npz', '/dev/zero')}",
        ],
        2,
        "not a regular file \\(a character device\\)",
    ),
    (
        "fifo-annotations",
        lambda tmp: [
            "benchmark",
            "--dataset",
            str(fifo(tmp / "a.json")),
            "--format",
            "normalized",
            *FAST,
            "-o",
            str(tmp / "o"),
        ],
        2,
        "a.json: not a regular file",
    ),
    (
        "device-annotations",
        lambda tmp: [
            "datasets",
            "info",
            str(link(tmp / "a.json", "/dev/zero")),
        ],
        2,
        "not a regular file",
    ),
    (
        "fifo-dataset-image",
        lambda tmp: (
            fifo(tmp / "p.png"),
            [
                "benchmark",
                "--dataset",
                str(
                    norm_dataset(
                        tmp, [{"file": "p.png", "boxes": []}, {"file": "a.png", "boxes": []}]
                    )
                ),
                "-d",
                "gray-tophat",
                *FAST,
                "-o",
                str(tmp / "o"),
            ],
        )[1],
        0,
        "report",
    ),
    (
        "fifo-in-voc-folder",
        lambda tmp: (
            write(tmp / "v" / "a.xml", "<annotation><filename>a.png</filename></annotation>"),
            fifo(tmp / "v" / "b.xml"),
            ["datasets", "info", str(tmp / "v")],
        )[2],
        2,
        "b.xml: not a regular file",
    ),
    (
        "fifo-gps",
        lambda tmp: ["track", "--gps", str(fifo(tmp / "g.csv")), "--map", str(tmp / "m.osm")],
        2,
        "g.csv: not a regular file",
    ),
    (
        "fifo-map",
        lambda tmp: (
            write(tmp / "g.csv", "time,lat,lon\n0,47.6,-122.1\n1,47.6001,-122.1\n"),
            ["track", "--gps", str(tmp / "g.csv"), "--map", str(fifo(tmp / "m.osm"))],
        )[1],
        2,
        "m.osm: not a regular file",
    ),
]

IMAGES: list[Row] = [
    ("jpeg-bytes-after-end-8k", detect_in(trailing("jpg", 8192)), 0, "2 frames"),
    ("png-bytes-after-end-8k", detect_in(trailing("png", 8192)), 0, "2 frames"),
    ("jpeg-bytes-after-end-1m", detect_in(trailing("jpg", 2**20)), 0, "2 frames"),
    (
        "jpeg-cut-inside-scan-with-thumbnail",
        detect_in(lambda d: write(d / "cut.jpg", _thumbnail_jpeg()[:-300])),
        0,
        "truncated JPEG",
    ),
    (
        "png-cut-after-idat",
        detect_in(
            lambda d: write(
                d / "cut.png", png(d.parent / "x.png").read_bytes()[:-12] + b"\0" * 5000
            )
        ),
        0,
        "truncated PNG",
    ),
    (
        "newline-in-file-name",
        detect_in(lambda d: write(d / "a\nb.png", b"junk")),
        0,
        "a\\\\nb.png",
    ),
    ("empty-path-argument", lambda tmp: ["detect", "", "-d", "gray-tophat"], 2, "empty path"),
    (
        "max-pixels-not-a-number",
        detect_in(),
        2,
        "TSRKIT_MAX_PIXELS",
    ),
]


def _thumbnail_jpeg() -> bytes:
    """A JPEG whose EXIF block holds a complete thumbnail (with its own end marker)."""
    _ok, thumb = cv2.imencode(".jpg", np.full((8, 8, 3), 200, np.uint8))
    _ok, main = cv2.imencode(
        ".jpg", np.random.default_rng(0).integers(0, 255, (64, 64, 3), np.uint8)
    )
    body = b"Exif\0\0" + thumb.tobytes()
    app1 = b"\xff\xe1" + (len(body) + 2).to_bytes(2, "big") + body
    data = main.tobytes()
    return data[:2] + app1 + data[2:]


VIDEO: list[Row] = []


def clip(tmp: Path) -> str:
    """A 4-frame 64x64 video of the synthetic sample's kind."""
    path = tmp / "clip.mp4"
    if not path.exists():
        from tsrkit.synth.video import video_writer

        with video_writer(path, 10.0, (64, 64)) as put:
            for k in range(4):
                put(np.full((64, 64, 3), 40 * k, np.uint8))
    return str(path)


def video(*args: str):
    return lambda tmp: ["detect", clip(tmp), "-d", "gray-tophat", *args]


VIDEO += [
    (
        "video-end-before-start",
        video("--start", "3", "--end", "1"),
        2,
        "--end 1 is before --start 3",
    ),
    (
        "video-end-before-start-workers",
        video("--start", "3", "--end", "1", "-w", "2"),
        2,
        "--end 1 is before --start 3",
    ),
    ("video-empty-range", video("--start", "2", "--end", "2"), 2, "empty"),
    ("video-start-past-its-end", video("--start", "100", "--end", "900"), 1, "has 4 frames"),
    ("video-every-huge", video("--every", "1000000000000"), 0, "1 frames"),
    ("video-end-huge-workers", video("--end", "1" + "0" * 30, "-w", "2"), 0, "4 frames"),
    ("video-every-huge-workers", video("--every", "1" + "0" * 30, "-w", "2"), 0, "1 frames"),
    (
        "video-truncated-half",
        lambda tmp: [
            "detect",
            str(
                write(
                    tmp / "half.mp4",
                    Path(clip(tmp)).read_bytes()[: Path(clip(tmp)).stat().st_size // 2],
                )
            ),
            "-d",
            "gray-tophat",
        ],
        1,
        "skipped|frames",
    ),
]


def cfg(text: str | bytes, verb: str = "detect"):
    def build(tmp: Path) -> list[str]:
        path = write(tmp / "run.yaml", text)
        if verb == "detect":
            return ["detect", str(folder(tmp)), "--config", str(path)]
        dataset = str(norm_dataset(tmp))
        args = ["--dataset", dataset, "--config", str(path), *FAST, "-o", str(tmp / "o")]
        if verb == "compare":
            return ["compare", "--detectors", "gray-tophat,lab-frst", *args]
        return ["benchmark", *args]

    return build


ALIASES = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{chr(98 + k)}: &{chr(98 + k)} [{', '.join([f'*{chr(97 + k)}'] * 9)}]\n" for k in range(8)
)

CONFIGS: list[Row] = [
    ("config-misspelt-kind", cfg("clasifier: ab-hist\n"), 2, "unknown key 'clasifier'.*classifier"),
    (
        "config-unknown-key",
        cfg("detector: gray-tophat\ntresholds: 1\n"),
        2,
        "unknown key 'tresholds'",
    ),
    (
        "config-misspelt-params",
        cfg("detector: {name: gray-tophat, parms: {h_peak: 0.2}}\n"),
        2,
        "unknown key 'parms'.*params",
    ),
    ("config-repeated-key", cfg("detector: gray-tophat\ndetector: lab-frst\n"), 2, "appears twice"),
    (
        "config-alias-bomb",
        cfg(ALIASES + "detector: {name: gray-tophat, params: {h_peak: *i}}\n"),
        2,
        "aliases",
    ),
    ("config-alias-bomb-unused", cfg(ALIASES + "detector: gray-tophat\n"), 2, "aliases"),
    ("config-deep-lists", cfg("detector: " + "[" * 5000 + "]" * 5000 + "\n"), 2, "nest"),
    (
        "config-deep-mappings",
        cfg("detector: " + "{a: " * 3000 + "1" + "}" * 3000 + "\n"),
        2,
        "nested deeper",
    ),
    ("config-huge", cfg("# " + "x" * (2**20 + 10) + "\n"), 2, "more than the limit"),
    ("config-tracker-on-benchmark", cfg("tracker: meanshift\n", "benchmark"), 2, "tracker"),
    ("config-misspelt-compare", cfg("verifer: housing\n", "compare"), 2, "unknown key 'verifer'"),
    ("config-byte-order-mark-ok", cfg(b"\xef\xbb\xbfdetector: gray-tophat\n"), 0, "1 frames"),
    ("config-empty-ok", cfg(""), 0, "1 frames"),
    ("config-params-null-ok", cfg("detector: {name: gray-tophat, params: null}\n"), 0, "1 frames"),
    ("config-description-ok", cfg("description: my run\ndetector: gray-tophat\n"), 0, "1 frames"),
]

PARAMS: list[Row] = [
    (
        "param-ints-range-billion",
        detect_in(args=("-d", "lab-frst", "-p", "radii=1..1000000000")),
        2,
        "radii",
    ),
    (
        "param-int-in-e-notation",
        detect_in(args=("-d", "conspicuity", "-p", "n_top=1e3")),
        2,
        "n_top",
    ),
    (
        "param-model-folder",
        lambda tmp: [
            "detect",
            str(folder(tmp)),
            "-d",
            "gray-tophat",
            "-c",
            "ab-hist",
            "-p",
            f"model={tmp}",
        ],
        2,
        "model",
    ),
    ("workers-past-the-limit", detect_in(args=("-w", "100000")), 2, "--workers 100000"),
    (
        "compare-detectors-comma",
        lambda tmp: ["compare", "--dataset", str(norm_dataset(tmp)), "--detectors", ",", *FAST],
        2,
        "--detectors",
    ),
    (
        "compare-detectors-blank",
        lambda tmp: ["compare", "--dataset", str(norm_dataset(tmp)), "--detectors", " ", *FAST],
        2,
        "--detectors",
    ),
    (
        "scheduler-without-dask",
        lambda tmp: [
            "benchmark",
            "--dataset",
            str(norm_dataset(tmp)),
            "-d",
            "gray-tophat",
            *FAST,
            "--scheduler",
            "tcp://127.0.0.1:1",
            "-o",
            str(tmp / "o"),
        ],
        2,
        "--engine dask",
    ),
]


def dataset_copy(tmp: Path) -> Path:
    """A normalised dataset (two 32x32 frames) whose annotation file is ``tmp/annotations.json``."""
    return norm_dataset(tmp)


OUTPUTS: list[Row] = [
    (
        "detect-out-is-the-input-image",
        lambda tmp: [
            "detect",
            str(folder(tmp) / "g.png"),
            "-d",
            "gray-tophat",
            "-o",
            str(tmp / "in" / "g.png"),
        ],
        2,
        "is an input of this run",
    ),
    (
        "detect-out-inside-the-input-folder",
        lambda tmp: [
            "detect",
            str(folder(tmp)),
            "-d",
            "gray-tophat",
            "-o",
            str(tmp / "in" / "d.jsonl"),
        ],
        0,
        "1 frames, \\d+ detections, 0 skipped",
    ),
    (
        "detect-draw-inside-the-input-folder",
        lambda tmp: [
            "detect",
            str(folder(tmp)),
            "-d",
            "gray-tophat",
            "--draw",
            str(tmp / "in" / "ov"),
        ],
        0,
        "1 frames",
    ),
    (
        "detect-draw-is-the-input-folder",
        lambda tmp: ["detect", str(folder(tmp)), "-d", "gray-tophat", "--draw", str(tmp / "in")],
        2,
        "is an input of this run",
    ),
    (
        "train-out-names-the-annotations",
        lambda tmp: [
            "train",
            "ab-hist",
            "--dataset",
            str(dataset_copy(tmp)),
            "--out",
            str(tmp / "annotations"),
        ],
        2,
        "annotations.json is an input of this run",
    ),
    (
        "convert-in-place",
        lambda tmp: [
            "datasets",
            "convert",
            str(dataset_copy(tmp)),
            "--to",
            "normalized",
            "--out",
            str(tmp / "annotations.json"),
        ],
        2,
        "is an input of this run",
    ),
    (
        "convert-out-is-an-image",
        lambda tmp: [
            "datasets",
            "convert",
            str(dataset_copy(tmp)),
            "--to",
            "normalized",
            "--out",
            str(tmp / "a.png"),
        ],
        2,
        "is an input of this run",
    ),
    (
        "benchmark-out-holds-a-file-it-would-replace",
        lambda tmp: (
            write(tmp / "run" / "report.json", "[]"),
            [
                "benchmark",
                "--dataset",
                str(
                    write(
                        tmp / "run" / "report.json", json.dumps([{"file": "../a.png", "boxes": []}])
                    )
                ),
                "--format",
                "normalized",
                "-d",
                "gray-tophat",
                *FAST,
                "-o",
                str(tmp / "run"),
            ],
        )[1],
        2,
        "report.json is an input of this run",
    ),
    (
        "synth-video-over-its-own-annotations",
        lambda tmp: [
            "datasets",
            "synth",
            "--out",
            str(tmp / "s"),
            "--frames",
            "2",
            "--width",
            "64",
            "--height",
            "64",
            "--video",
            str(tmp / "s" / "annotations.json"),
        ],
        2,
        "annotations.json",
    ),
    (
        "track-out-is-the-gps-log",
        lambda tmp: (
            write(tmp / "g.csv", "time,lat,lon\n0,47.6,-122.1\n1,47.6001,-122.1\n"),
            write(
                tmp / "m.osm",
                '<osm version="0.6"><node id="1" lat="47.6" lon="-122.1">'
                '<tag k="highway" v="traffic_signals"/></node></osm>',
            ),
            [
                "track",
                "--gps",
                str(tmp / "g.csv"),
                "--map",
                str(tmp / "m.osm"),
                "--out",
                str(tmp / "g.csv"),
            ],
        )[2],
        2,
        "g.csv",
    ),
]


def records(boxes: list[dict], **sample) -> list[dict]:
    return [{"file": f, "split": "test", **sample, "boxes": boxes} for f in ("a.png", "b.png")]


def bench_records(data, *extra: str):
    def build(tmp: Path) -> list[str]:
        ds = (
            norm_dataset(tmp, data)
            if not isinstance(data, str)
            else (norm_dataset(tmp), write(tmp / "annotations.json", data))[1]
        )
        return [
            "benchmark",
            "--dataset",
            str(ds),
            "--format",
            "normalized",
            "-d",
            "gray-tophat",
            *FAST,
            "-o",
            str(tmp / "o"),
            *extra,
        ]

    return build


BOX = {"label": "red", "x_min": 4, "y_min": 4, "x_max": 10, "y_max": 10}
DATASETS: list[Row] = [
    ("dataset-empty", bench_records([]), 1, "no samples"),
    (
        "dataset-box-outside-the-image",
        bench_records(records([{**BOX, "x_min": 500, "x_max": 600}], width=32, height=32)),
        2,
        "outside the 32x32 image",
    ),
    (
        "dataset-declared-size-differs",
        bench_records(records([BOX], width=640, height=480)),
        0,
        "declare.*640x480.*32x32",
    ),
    ("dataset-deeply-nested-json", bench_records("[" * 100000 + "]" * 100000), 2, "nested deeper"),
    (
        "dataset-nan-coordinate",
        bench_records(json.dumps(records([BOX])).replace('"x_min": 4', '"x_min": NaN')),
        2,
        "finite",
    ),
    (
        "dataset-huge-coordinate",
        bench_records(json.dumps(records([BOX])).replace('"x_max": 10', '"x_max": 1e400')),
        2,
        "finite",
    ),
    (
        "train-empty-dataset",
        lambda tmp: [
            "train",
            "ab-hist",
            "--dataset",
            str(norm_dataset(tmp, [])),
            "--out",
            str(tmp / "m"),
        ],
        1,
        "no samples",
    ),
    (
        "info-empty-dataset-ok",
        lambda tmp: ["datasets", "info", str(norm_dataset(tmp, []))],
        0,
        "samples",
    ),
    (
        "synth-frames-past-the-limit",
        lambda tmp: ["datasets", "synth", "--out", str(tmp / "s"), "--frames", "1000000000"],
        2,
        "--frames",
    ),
    (
        "synth-lighting-empty",
        lambda tmp: [
            "datasets",
            "synth",
            "--out",
            str(tmp / "s"),
            "--frames",
            "2",
            "--lighting",
            ",",
        ],
        2,
        "lighting",
    ),
]


def cached_run(corrupt: Callable[[Path], object]):
    """``benchmark`` twice into one folder, one cache entry corrupted in between: the second
    run recomputes that frame."""

    def build(tmp: Path) -> list[str]:
        from click.testing import CliRunner

        from tsrkit.cli.main import cli

        args = [
            "benchmark",
            "--dataset",
            str(norm_dataset(tmp)),
            "-d",
            "gray-tophat",
            "-q",
            "-w",
            "1",
            "--writer",
            "json",
            "-o",
            str(tmp / "o"),
        ]
        assert CliRunner().invoke(cli, args).exit_code == 0
        corrupt(sorted((tmp / "o" / "cache").rglob("*.json"))[0])
        return args

    return build


CACHE: list[Row] = [
    ("cache-entry-broken-json", cached_run(lambda p: p.write_text("{")), 0, "report"),
    ("cache-entry-empty", cached_run(lambda p: p.write_text("")), 0, "report"),
    ("cache-entry-a-list", cached_run(lambda p: p.write_text("[]")), 0, "report"),
    (
        "cache-entry-missing-fields",
        cached_run(lambda p: p.write_text('{"source": 5}')),
        0,
        "report",
    ),
    ("cache-entry-binary", cached_run(lambda p: p.write_bytes(b"\xff\xfe\0")), 0, "report"),
    ("cache-entry-fifo", cached_run(lambda p: (p.unlink(), os.mkfifo(p))), 0, "report"),
    (
        "cache-entry-bad-detection",
        cached_run(
            lambda p: p.write_text(
                json.dumps({**json.loads(p.read_text()), "detections": [{"x": "a"}]})
            )
        ),
        0,
        "report",
    ),
]


MAP = (
    '<?xml version="1.0"?><osm version="0.6"><node id="1" lat="47.6" lon="-122.15">'
    '<tag k="highway" v="traffic_signals"/></node></osm>'
)
FIXES = "time,lat,lon\n" + "".join(
    f"{1780315200 + k},{47.5990 + 0.0001 * k:.7f},-122.15\n" for k in range(20)
)


def geo(
    gps: str = FIXES, osm: str = MAP, *extra: str, gps_name: str = "g.csv", map_name: str = "m.osm"
):
    def build(tmp: Path) -> list[str]:
        g = write(tmp / gps_name, gps)
        m = write(tmp / map_name, osm)
        return ["track", "--gps", str(g), "--map", str(m), *extra]

    return build


def tiny_drive() -> Path:
    """A rendered test drive (video, GPS, map), made once per test session."""
    import tempfile

    from tsrkit.synth.drive import DriveOptions, render_drive

    global _DRIVE
    if _DRIVE is None:
        options = DriveOptions(
            width=96, height=72, fps=4, route=("left",), lead_m=30, tail_m=10, trucks=False
        )
        _DRIVE = render_drive(Path(tempfile.mkdtemp(prefix="tsrkit-drive-")), options, seed=3)
    return _DRIVE


_DRIVE: Path | None = None


def with_video(*extra: str):
    def build(tmp: Path) -> list[str]:
        d = tiny_drive()
        return [
            "track",
            str(d / "drive.mp4"),
            "--gps",
            str(d / "gps.csv"),
            "--map",
            str(d / "map.osm"),
            "-d",
            "gray-tophat",
            "-q",
            *extra,
        ]

    return build


GEO: list[Row] = [
    ("track-vicinity-nan", geo(FIXES, MAP, "--vicinity", "nan"), 2, "not a finite number"),
    ("track-upstream-inf", with_video("--upstream", "inf"), 2, "--upstream"),
    ("track-upstream-nan", with_video("--upstream", "nan"), 2, "not a finite number"),
    ("track-downstream-huge", with_video("--downstream", "1e308"), 2, "--downstream"),
    ("track-roi-top-nan", with_video("--roi-top", "nan"), 2, "not a finite number"),
    ("track-slack-nan", with_video("--slack", "nan"), 2, "not a finite number"),
    ("track-start-utc-nan", with_video("--start-utc", "nan"), 2, "--start-utc"),
    ("track-start-utc-inf", with_video("--start-utc", "inf"), 2, "--start-utc"),
    ("track-start-utc-1e20", with_video("--start-utc", "1e20"), 2, "--start-utc"),
    (
        "track-start-utc-far-from-the-log",
        with_video("--start-utc", "1000"),
        2,
        "outside the GPS log",
    ),
    ("track-one-fix", geo("time,lat,lon\n1780315200,47.6,-122.15\n"), 2, "two GPS fixes"),
    (
        "track-gps-time-1e20",
        geo("time,lat,lon\n1e20,47.6,-122.15\n1.00000000001e20,47.6001,-122.15\n"),
        2,
        "time",
    ),
    (
        "track-gps-time-before-year-1",
        geo("time,lat,lon\n-1e15,47.6,-122.15\n-0.9e15,47.6001,-122.15\n"),
        2,
        "time",
    ),
    (
        "track-map-without-signals",
        geo(FIXES, '<osm version="0.6"><node id="1" lat="47.6" lon="-122.15"/></osm>'),
        2,
        "no traffic signal",
    ),
    (
        "track-geojson-without-features",
        geo(FIXES, '{"type": "FeatureCollection", "features": []}', map_name="m.geojson"),
        2,
        "no traffic signal",
    ),
    (
        "track-geojson-deep",
        geo(FIXES, "[" * 100000 + "]" * 100000, map_name="m.geojson"),
        2,
        "nested deeper|m.geojson",
    ),
    (
        "track-gps-device",
        lambda tmp: [
            "track",
            "--gps",
            str(link(tmp / "g.csv", "/dev/zero")),
            "--map",
            str(write(tmp / "m.osm", MAP)),
        ],
        2,
        "not a regular file",
    ),
    (
        "track-truth-fifo",
        lambda tmp: [*with_video()(tmp), "--truth", str(fifo(tmp / "t.jsonl"))],
        2,
        "t.jsonl: not a regular file",
    ),
]

EDGES = SPECIAL + IMAGES + VIDEO + CONFIGS + PARAMS + OUTPUTS + DATASETS + CACHE + GEO
ENV = {"max-pixels-not-a-number": {"TSRKIT_MAX_PIXELS": "lots"}}


def test_the_edges_are_a_hundred_new_cases():
    from test_bad_input_matrix import MATRIX

    assert len(EDGES) >= 100
    assert len({row[0] for row in EDGES + MATRIX}) == len(EDGES) + len(MATRIX)


@pytest.mark.parametrize("build,code,fragment", [pytest.param(*r[1:], id=r[0]) for r in EDGES])
def test_edge(tmp_path, monkeypatch, build, code, fragment, request):
    for key, value in ENV.get(request.node.callspec.id, {}).items():
        monkeypatch.setenv(key, value)
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
