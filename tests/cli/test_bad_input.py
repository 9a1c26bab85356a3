"""Bad input never stops a run: header bombs, invalid annotation files, NaN parameters and
detectors returning invalid boxes give one clear reason and the run goes on."""

import json
import struct
import zlib

import cv2
import numpy as np
import pytest
from click.testing import CliRunner

from tsrkit.cli.main import cli
from tsrkit.core.images import ImageReadError, read_image
from tsrkit.core.types import Candidate, Sample
from tsrkit.datasets import open_dataset
from tsrkit.datasets.errors import DatasetError
from tsrkit.plugin.base import Detector
from tsrkit.plugin.params import Param, ParamError, validate
from tsrkit.runner.engine import Job, process_sample


def png_header_lie(path, width, height):
    """A tiny valid PNG whose IHDR declares ``width`` x ``height``."""

    def chunk(kind, data):
        return (
            struct.pack(">I", len(data))
            + kind
            + data
            + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
        )

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    body = zlib.compress(b"\x00" * 16)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", body) + chunk(b"IEND", b"")
    )
    return path


def test_an_image_declaring_too_many_pixels_is_refused_before_decoding(tmp_path, monkeypatch):
    bomb = png_header_lie(tmp_path / "bomb.png", 30000, 30000)
    with pytest.raises(ImageReadError, match="refused"):
        read_image(bomb)
    small = tmp_path / "small.png"
    cv2.imwrite(str(small), np.zeros((20, 30, 3), np.uint8))
    monkeypatch.setenv("TSRKIT_MAX_PIXELS", "500")
    with pytest.raises(ImageReadError, match="600 pixels, more than the limit of 500"):
        read_image(small)


def test_a_header_lie_in_a_folder_of_good_images_skips_only_that_frame(tmp_path):
    folder = tmp_path / "in"
    folder.mkdir()
    for k in range(3):
        cv2.imwrite(str(folder / f"good{k}.png"), np.full((40, 40, 3), 30 * k, np.uint8))
    png_header_lie(folder / "lie.png", 40000, 40000)
    out = tmp_path / "d.jsonl"
    result = CliRunner().invoke(cli, ["detect", str(folder), "-d", "gray-tophat", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert len(out.read_text().splitlines()) == 3
    assert "lie.png" in result.output and "refused" in result.output


@pytest.mark.parametrize(
    "content,fragment",
    [
        (b"\xff\xfe not utf-8 \x80", "line 1: not valid UTF-8 \\(byte 0xff at offset 0\\)"),
        (json.dumps({"images": 5}).encode(), "expected a list of image records"),
        (
            json.dumps(
                [
                    {
                        "file": "a.png",
                        "boxes": [{"label": "red", "x_min": 6, "y_min": 5, "x_max": 5, "y_max": 9}],
                    }
                ]
            ).encode(),
            "no area|min > max",
        ),
        (
            json.dumps(
                [
                    {
                        "file": "a.png",
                        "boxes": [
                            {"label": "red", "x_min": "nan", "y_min": 5, "x_max": 2, "y_max": 9}
                        ],
                    }
                ]
            ).encode(),
            "nan|finite|number",
        ),
    ],
)
def test_malformed_annotation_files_are_one_dataset_error(tmp_path, content, fragment):
    path = tmp_path / "annotations.json"
    path.write_bytes(content)
    with pytest.raises(DatasetError, match=fragment):
        open_dataset(path, format="normalized")


@pytest.mark.parametrize("text", ["nan", "inf", "-inf", "1,nan,1"])
def test_non_finite_numbers_are_refused_by_every_numeric_parameter(text):
    schema = [Param("h", "float", 0.5), Param("w", "floats", (1.0, 1.0, 1.0))]
    key = "w" if "," in text else "h"
    with pytest.raises(ParamError, match="finite"):
        validate(schema, {key: text}, "plugin")


class NaNDetector(Detector):
    name = "nan-boxes"

    def detect(self, frame):
        return [Candidate(float("nan"), 3.0, 1.0, (float("nan"), 2.0, 4.0, 4.0), 1.0)]


def test_a_detector_returning_an_invalid_box_costs_the_frame_not_the_run():
    sample = Sample("x", image=np.zeros((10, 10, 3), np.uint8))
    record = process_sample(0, sample, Job(NaNDetector(), None, "nan", None))
    assert record.skipped is not None and "invalid detection box" in record.skipped


def test_a_run_whose_inputs_were_all_skipped_exits_non_zero(tmp_path):
    folder = tmp_path / "bad"
    folder.mkdir()
    (folder / "a.png").write_bytes(b"not an image")
    png_header_lie(folder / "b.png", 40000, 40000)
    result = CliRunner().invoke(cli, ["detect", str(folder), "-d", "gray-tophat"])
    assert result.exit_code == 1 and "all 2 inputs were skipped" in result.output
    good = tmp_path / "good"
    good.mkdir()
    cv2.imwrite(str(good / "g.png"), np.zeros((20, 20, 3), np.uint8))
    (good / "a.png").write_bytes(b"not an image")
    assert CliRunner().invoke(cli, ["detect", str(good), "-d", "gray-tophat"]).exit_code == 0


def test_a_benchmark_whose_frames_were_all_skipped_exits_non_zero(tmp_path):
    (tmp_path / "a.png").write_bytes(b"not an image")
    boxes = [{"label": "red", "x_min": 1, "y_min": 1, "x_max": 5, "y_max": 5}]
    entries = [{"file": "a.png", "width": 20, "height": 20, "boxes": boxes}]
    (tmp_path / "annotations.json").write_text(json.dumps(entries))
    args = ["benchmark", "--dataset", str(tmp_path / "annotations.json"), "-d", "gray-tophat"]
    result = CliRunner().invoke(cli, [*args, "-q", "-o", str(tmp_path / "out"), "--no-cache"])
    assert result.exit_code == 1 and "all 1 inputs were skipped" in result.output
