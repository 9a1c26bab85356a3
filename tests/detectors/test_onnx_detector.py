"""onnx-detector on tiny hand-built ONNX models: boxes exactly where the model put them
(letterbox included), both layouts, NMS, class names and states, tiles, bad models."""

from __future__ import annotations

import json
import pickle
import re
from pathlib import Path

import cv2
import numpy as np
import onnx
import pytest
from click.testing import CliRunner
from oracles.onnx_models import brightest_model, constant_model, rtdetr_model, yolo_output

import tsrkit
from tsrkit.api import Frame, ModelError
from tsrkit.cli.main import cli
from tsrkit_plugins.detectors.onnx_detector.layouts import decode_yolo
from tsrkit_plugins.detectors.onnx_detector.letterbox import letterbox

RYG = "{0: 'red', 1: 'yellow', 2: 'green'}"


def blank(width: int, height: int) -> Frame:
    return Frame(np.zeros((height, width, 3), np.uint8), "blank.png")


def yolo_model(tmp_path: Path, boxes, size=(640, 640), names=RYG, transpose=False) -> Path:
    out = yolo_output(boxes, 3)
    out = out.transpose(0, 2, 1) if transpose else out
    metadata = {"names": names} if names else None
    return constant_model(tmp_path / "yolo.onnx", {"output0": out}, size, metadata)


def detector(model: Path, **params):
    return tsrkit.detector("onnx-detector", model=str(model), **params)


def boxes_of(found) -> list[tuple[float, ...]]:
    return [tuple(round(v, 6) for v in c.bbox) for c in found]


# --- where the boxes land --------------------------------------------------------------------


def test_a_yolo_box_is_reported_where_the_model_put_it(tmp_path):
    model = yolo_model(tmp_path, [(100, 200, 20, 40, 0, 0.9)])
    (found,) = detector(model).detect(blank(640, 640))
    assert found.bbox == (90.0, 180.0, 110.0, 220.0)
    assert (found.x, found.y) == (100.0, 200.0)
    assert found.radius == 10.0  # half the shorter side
    assert found.score == pytest.approx(0.9)
    assert found.state == "red"


@pytest.mark.parametrize(
    ("frame_wh", "model_hw", "box", "expected"),
    [
        # landscape into a square input: scale 0.5, 140 grey rows above
        ((1280, 720), (640, 640), (320, 240, 20, 40), (620, 160, 660, 240)),
        # portrait: scale 1, 140 grey columns on the left
        ((360, 640), (640, 640), (240, 100, 20, 40), (90, 80, 110, 120)),
        # a non-square input (H=384, W=640): scale 0.5, 12 grey rows above
        ((1280, 720), (384, 640), (320, 192, 20, 40), (620, 320, 660, 400)),
        # 1000 x 333 into 64: resized to 64 x 21 (not 21.312), 21 rows above and 22 below;
        # a box over the image rows maps back to exactly 0..333 (1 / 0.064 would give 328.1)
        ((1000, 333), (64, 64), (32, 31.5, 8, 21), (437.5, 0, 562.5, 333)),
    ],
)
def test_letterbox_is_undone_exactly_on_any_frame(tmp_path, frame_wh, model_hw, box, expected):
    model = yolo_model(tmp_path, [(*box, 2, 0.8)], size=model_hw)
    (found,) = detector(model).detect(blank(*frame_wh))
    assert found.bbox == pytest.approx(expected, abs=1e-9)
    assert found.state == "green"


def test_the_input_is_ultralytics_letterbox_in_rgb():
    image = np.random.default_rng(0).integers(0, 256, (103, 200, 3), np.uint8)
    tensor, placed = letterbox(image, (64, 64))
    assert tensor.shape == (1, 3, 64, 64) and tensor.dtype == np.float32
    # 200 x 103 -> 64 x 33: 31 grey rows, 15 above and 16 below (round(15.5 -+ 0.1))
    assert (placed.left, placed.top) == (0, 15)
    resized = cv2.resize(image, (64, 33), interpolation=cv2.INTER_LINEAR)
    rgb = resized[:, :, ::-1].transpose(2, 0, 1).astype(np.float32) / np.float32(255)
    assert np.array_equal(tensor[0, :, 15:48], rgb)
    grey = np.float32(114) / np.float32(255)
    assert (tensor[0, :, :15] == grey).all() and (tensor[0, :, 48:] == grey).all()


def test_a_transposed_yolo_output_reads_the_same(tmp_path):
    model = yolo_model(tmp_path, [(100, 200, 20, 40, 1, 0.9)], transpose=True)
    (found,) = detector(model).detect(blank(640, 640))
    assert found.bbox == (90.0, 180.0, 110.0, 220.0) and found.state == "yellow"


@pytest.mark.parametrize("classes", [None, 3])
def test_a_square_yolo_output_is_refused(classes):
    with pytest.raises(ModelError, match="is square: cannot tell classes from anchors"):
        decode_yolo(np.zeros((1, 7, 7), np.float32), 0.25, classes)


# --- filtering, NMS, names -------------------------------------------------------------------

OVERLAPPING = [
    (100, 100, 20, 20, 0, 0.9),
    (102, 100, 20, 20, 0, 0.8),  # IoU 0.82 with the first, same class: suppressed
    (102, 100, 20, 20, 1, 0.7),  # same place, other class: kept
    (300, 300, 10, 10, 0, 0.2),  # below conf
]


def test_confidence_and_class_aware_nms(tmp_path):
    model = yolo_model(tmp_path, OVERLAPPING)
    found = detector(model).detect(blank(640, 640))
    assert [(round(c.score, 3), c.state) for c in found] == [(0.9, "red"), (0.7, "yellow")]
    assert len(detector(model, iou=0.9).detect(blank(640, 640))) == 3
    assert len(detector(model, conf=0.1).detect(blank(640, 640))) == 3
    assert len(detector(model, max_det=1).detect(blank(640, 640))) == 1


def test_classes_keeps_only_the_chosen_class_ids(tmp_path):
    model = yolo_model(tmp_path, OVERLAPPING)
    (found,) = detector(model, classes=(1,)).detect(blank(640, 640))
    assert found.state == "yellow"


def test_names_parameter_wins_and_names_say_states(tmp_path):
    model = yolo_model(tmp_path, [(50, 50, 10, 10, i, 0.9 - 0.1 * i) for i in range(3)])
    found = detector(model, names="tl_red_yellow,traffic light,Off").detect(blank(640, 640))
    assert [c.state for c in found] == ["red_yellow", None, "off"]


@pytest.mark.parametrize(
    ("name", "text"),
    [
        ("yolo.yaml", "names:\n  0: stop\n  1: warning\n  2: go\n"),
        ("yolo.yml", "names: [RedLeft, amber, GreenStraight]\n"),
        ("yolo.json", '{"names": ["red", "yellow", "green"]}'),
    ],
)
def test_names_file_beside_the_model(tmp_path, name, text):
    model = yolo_model(tmp_path, [(50, 50, 10, 10, 2, 0.9)], names=None)
    (tmp_path / name).write_text(text)
    assert [c.state for c in detector(model).detect(blank(640, 640))] == ["green"]


def test_without_names_there_is_no_state(tmp_path):
    model = yolo_model(tmp_path, [(50, 50, 10, 10, 0, 0.9)], names=None)
    assert [c.state for c in detector(model).detect(blank(640, 640))] == [None]


def test_names_that_do_not_fit_the_classes_are_refused(tmp_path):
    model = yolo_model(tmp_path, [(50, 50, 10, 10, 0, 0.9)])
    with pytest.raises(ModelError, match="scores 3 classes but 2 class names"):
        detector(model, names="red,green").detect(blank(640, 640))


# --- the boxes layout ------------------------------------------------------------------------

POST_NMS = {
    "boxes": np.array([[[300.0, 220.0, 340.0, 260.0], [305.0, 220.0, 345.0, 260.0]]], np.float32),
    "scores": np.array([[0.6, 0.9]], np.float32),
    "labels": np.array([[0, 2]], np.int64),
}


def test_boxes_layout_keeps_the_models_own_boxes_best_first(tmp_path):
    model = constant_model(tmp_path / "m.onnx", POST_NMS, (640, 640), {"names": RYG})
    found = detector(model).detect(blank(1280, 720))  # scale 0.5, 140 rows above
    assert boxes_of(found) == [(610, 160, 690, 240), (600, 160, 680, 240)]  # no NMS after NMS
    assert [c.state for c in found] == ["green", "red"]
    assert len(detector(model, conf=0.7).detect(blank(1280, 720))) == 1


def test_boxes_layout_by_shapes_with_a_count_and_normalised_boxes(tmp_path):
    outputs = {
        "out_a": np.array([2], np.int64),  # the count: the third row is padding
        "out_b": np.array([[0.5, 0.5, 0.75, 1.0], [0, 0, 0.25, 0.25], [0, 0, 1, 1]], np.float32),
        "out_c": np.array([0.9, 0.8, 0.99], np.float32),
        "out_d": np.array([1, 0, 0], np.int64),
    }
    model = constant_model(tmp_path / "m.onnx", outputs, (64, 64), {"names": RYG})
    found = detector(model, layout="boxes", normalized=True).detect(blank(128, 128))
    assert boxes_of(found) == [(64, 64, 96, 128), (0, 0, 32, 32)]
    assert [c.state for c in found] == ["yellow", "red"]


def test_rtdetr_style_model_is_fed_its_input_size(tmp_path):
    fractions = np.array([[[0.25, 0.5, 0.5, 0.75]]], np.float32)
    model = rtdetr_model(
        tmp_path / "m.onnx", fractions, np.array([[0.8]], np.float32), np.array([[2]], np.int64)
    )
    (found,) = detector(model, names="red,yellow,green").detect(blank(128, 64))
    assert found.bbox == (32.0, 32.0, 64.0, 64.0) and found.state == "green"  # 16 rows above


def test_normalised_yolo_layout_as_ultralytics_rtdetr_exports_it(tmp_path):
    out = yolo_output([(0.5, 0.5, 0.25, 0.5, 1, 0.9)], 3, anchors=10).transpose(0, 2, 1)
    model = constant_model(tmp_path / "m.onnx", {"output0": out}, (64, 64), {"names": RYG})
    (found,) = detector(model, normalized=True).detect(blank(64, 64))
    assert found.bbox == (24.0, 16.0, 40.0, 48.0) and found.state == "yellow"


def test_non_finite_rows_are_left_out_and_noted(tmp_path):
    out = yolo_output([(100, 100, 20, 20, 0, 0.9), (200, 200, 20, 20, 1, 0.8)], 3)
    out[0, 0, 1] = np.nan
    out[0, 4, 2] = np.inf  # a third anchor scoring infinity
    model = constant_model(tmp_path / "nan.onnx", {"output0": out}, (640, 640))
    plugin = detector(model)
    assert boxes_of(plugin.detect(blank(640, 640))) == [(90, 90, 110, 110)]
    assert plugin.notes == ("onnx-detector: 2 boxes with values that are not finite left out",)


# --- tiles, sessions, sizes ------------------------------------------------------------------


def test_tiles_find_a_light_the_whole_frame_loses_and_merge_duplicates(tmp_path):
    model = brightest_model(tmp_path / "bright.onnx")  # 100 x 100 input
    frame = blank(300, 100)
    frame.image[50, 129] = 255  # the whole frame, at a third, never samples column 129
    assert detector(model, conf=0.5).detect(frame) == []
    # tiles at x = 0, 50, 100, 150, 200: two of them hold the pixel, NMS keeps one box
    (found,) = detector(model, conf=0.5, tile=100, tile_overlap=0.5).detect(frame)
    assert found.bbox == (127.0, 48.0, 132.0, 53.0) and (found.x, found.y) == (129.5, 50.5)


def test_one_cpu_thread_and_a_session_that_is_not_pickled(tmp_path):
    model = yolo_model(tmp_path, [(100, 200, 20, 40, 0, 0.9)])
    plugin = detector(model)
    first = plugin.detect(blank(640, 640))
    runtime = plugin.session().runtime
    assert runtime.get_providers() == ["CPUExecutionProvider"]
    assert runtime.get_session_options().intra_op_num_threads == 1
    copy = pickle.loads(pickle.dumps(plugin))
    assert copy._session is None and copy.detect(blank(640, 640)) == first


def test_dynamic_input_size_from_the_parameter_or_the_metadata(tmp_path):
    out = {"output0": yolo_output([(32, 32, 8, 8, 0, 0.9)], 3)}
    model = constant_model(tmp_path / "dyn.onnx", out, ("height", "width"))
    with pytest.raises(ModelError, match="dynamic; give it with -p size"):
        detector(model).detect(blank(128, 128))
    assert boxes_of(detector(model, size=(64,)).detect(blank(128, 128))) == [(56, 56, 72, 72)]
    with pytest.raises(ModelError, match=r"input is \(64, 64\), not size=\(32,\)"):
        detector(constant_model(tmp_path / "fixed.onnx", out), size=(32,)).detect(blank(9, 9))
    meta = constant_model(tmp_path / "meta.onnx", out, ("h", "w"), {"imgsz": "[64, 64]"})
    assert boxes_of(detector(meta).detect(blank(128, 128))) == [(56, 56, 72, 72)]


# --- the command line ------------------------------------------------------------------------


def write_image(path: Path, width: int = 80, height: int = 60) -> Path:
    cv2.imwrite(str(path), np.zeros((height, width, 3), np.uint8))
    return path


def test_detect_verb_writes_the_models_boxes(tmp_path):
    model = yolo_model(tmp_path, [(32, 32, 8, 16, 2, 0.9)], size=(64, 64))
    image = write_image(tmp_path / "f.png", 128, 64)  # scale 0.5, 16 grey rows above
    args = ["detect", str(image), "-d", "onnx-detector", "-p", f"detector.model={model}"]
    result = CliRunner().invoke(cli, [*args, "-o", str(tmp_path / "d.jsonl")])
    assert result.exit_code == 0, result.output
    (record,) = [json.loads(line) for line in (tmp_path / "d.jsonl").read_text().splitlines()]
    (det,) = record["detections"]
    assert det["bbox"] == [56, 16, 72, 48] and det["state"] == "green"


def not_onnx(tmp: Path) -> Path:
    (tmp / "m.onnx").write_bytes(b"this is not a protobuf \x00\xff")
    return tmp / "m.onnx"


def rank3_input(tmp: Path) -> Path:
    return constant_model(tmp / "m.onnx", {"output0": yolo_output([], 3)}, size=(64,))


def unreadable_outputs(tmp: Path) -> Path:
    return constant_model(tmp / "m.onnx", {"out": np.zeros((1, 10), np.float32)})


def mismatched_names(tmp: Path) -> Path:
    model = constant_model(tmp / "m.onnx", {"output0": yolo_output([(8, 8, 4, 4, 0, 1.0)], 3)})
    (tmp / "m.yaml").write_text("names: [red, green]\n")
    return model


def unknown_second_input(tmp: Path) -> Path:
    model = onnx.load(str(constant_model(tmp / "m.onnx", {"output0": yolo_output([], 3)})))
    extra = onnx.helper.make_tensor_value_info("mask", onnx.TensorProto.FLOAT, [1, 64, 64])
    model.graph.input.append(extra)
    onnx.save(model, str(tmp / "m.onnx"))
    return tmp / "m.onnx"


def bad_names_file(tmp: Path) -> Path:
    model = constant_model(tmp / "m.onnx", {"output0": yolo_output([], 3)})
    (tmp / "m.json").write_text('{"classes": 3}')
    return model


@pytest.mark.parametrize(
    ("build", "fragment"),
    [
        (lambda tmp: tmp / "missing.onnx", "no such file"),
        (not_onnx, "not an ONNX model"),
        (rank3_input, r"input 'images' is tensor\(float\) \[1, 3, 64\]; expected a float image"),
        (unreadable_outputs, r"cannot read outputs out\[1, 10\] by any layout"),
        (unknown_second_input, "inputs are images, mask; expected an image, optionally"),
        (mismatched_names, "scores 3 classes but 2 class names"),
        (bad_names_file, "no 'names' in this class-names file"),
    ],
)
def test_a_bad_model_is_one_line_and_exit_status_2(tmp_path, build, fragment):
    model = build(tmp_path)
    image = write_image(tmp_path / "f.png")
    args = ["detect", str(image), "-d", "onnx-detector", "-p", f"detector.model={model}"]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    (line,) = result.output.strip().splitlines()
    assert re.search(fragment, line), line


def test_the_model_parameter_is_required():
    result = CliRunner().invoke(cli, ["detect", "x.png", "-d", "onnx-detector"])
    assert result.exit_code == 2 and "parameter 'model' is required" in result.output


def test_compare_runs_the_model_beside_conspicuity(tmp_path):
    model = brightest_model(tmp_path / "bright.onnx")
    args = ["compare", "--dataset", "sample", "--detectors", "onnx-detector,conspicuity"]
    params = ["-p", f"onnx-detector.model={model}", "-p", "onnx-detector.conf=0.5"]
    out = tmp_path / "out"
    result = CliRunner().invoke(cli, [*args, *params, "-o", str(out), "-w", "2", "-q"])
    assert result.exit_code == 0, result.output
    comparison = json.loads((out / "compare.json").read_text())
    assert comparison["detectors"] == ["onnx-detector", "conspicuity"]
    report = json.loads((out / "onnx-detector" / "report.json").read_text())
    assert report["params"]["detector"]["model"] == str(model) and not report["skipped"]
    assert "onnx-detector vs conspicuity" in result.output
