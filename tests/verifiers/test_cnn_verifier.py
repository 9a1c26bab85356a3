"""The CNN verifier: its windows and labels on hand-worked cases, a real (tiny) training run
exported to ONNX and read back through the plugin, the CLI's training, and bad model files."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest
from click.testing import CliRunner

from tsrkit.cli.main import cli
from tsrkit.core.types import Candidate, Frame
from tsrkit.plugin.base import Detector
from tsrkit.plugin.models import ModelError, save_model
from tsrkit.plugin.registry import get_registry
from tsrkit_plugins.verifiers.cnn.augment import geometry
from tsrkit_plugins.verifiers.cnn.data import Scene, collect, housing_target, label
from tsrkit_plugins.verifiers.cnn.windows import TRAIN_MARGIN, Window, crops, cut
from tsrkit_plugins.verifiers.mining import Heads, head_frames
from tsrkit_plugins.verifiers.unlit import no_light_frames

pytest.importorskip("torch")


def make(**params):
    return get_registry().create("verifier", "cnn-verifier", params)


def test_a_window_is_twelve_radii_wide_and_maps_boxes_both_ways():
    window = Window.around(Candidate.from_circle(100.0, 60.0, 4.0, 1.0))
    assert window == Window(76, 36, 48)  # 12 x 4 px, centred on the lens
    box = (90.0, 40.0, 110.0, 84.0)
    assert np.allclose(window.to_frame(window.to_unit(box)), box)
    wide = Window.around(Candidate.from_circle(100.0, 60.0, 4.0, 1.0), TRAIN_MARGIN)
    assert wide.side == 72 and wide.x0 + wide.side / 2 == pytest.approx(window.x0 + 24)


def test_a_cut_repeats_the_edge_outside_the_frame_and_resizes():
    image = np.zeros((10, 10, 3), np.uint8)
    image[:, 0] = 200  # the left column is bright
    out = cut(image, Window(-4, 0, 8), 8)
    assert (out[:, :5, 0] == 200).all() and (out[:, 5:, 0] == 0).all()
    batch, windows = crops(image, [Candidate.from_circle(5, 5, 1, 1.0)])
    assert batch.shape == (1, 32, 32, 3) and windows[0].side == 16


def test_labels_follow_zhengs_rule_and_spare_unboxed_lights_of_partial_sets():
    frame = Frame(np.zeros((100, 100, 3), np.uint8), "f")
    on = Candidate.from_circle(20, 20, 2, 1.0)
    high = Candidate.from_circle(60, 20, 2, 1.0)  # unboxed, high in the frame
    low = Candidate.from_circle(60, 90, 2, 1.0)  # unboxed, in the lowest rows
    box = [(15, 10, 25, 40)]
    light, hit = label(Scene(frame, box, ["red"], True), [on, high, low])
    assert light.tolist() == [1, 0, 0] and hit.tolist() == [0, -1, -1]
    light, _ = label(Scene(frame, box, ["red"], False), [on, high, low])
    assert light.tolist() == [1, -1, 0]  # the high unboxed one may be an unlabelled light


def test_a_housing_target_is_in_units_of_the_inner_window_and_lens_boxes_give_none():
    wide = Window(0, 0, 48)  # inner window: (8, 8) to (40, 40), side 32
    assert housing_target(wide, (8, 8, 24, 40)).tolist() == [0.0, 0.0, 0.5, 1.0]
    assert np.isnan(housing_target(wide, (8, 8, 20, 20))).all()  # square: a lens box


def test_the_geometric_augmentation_moves_the_box_with_the_pixels():
    crop = np.zeros((48, 48, 3), np.uint8)
    crop[14:34, 20:28] = 255  # a bright bar: 8 x 20 px, inner-window units below
    box = np.array([(20 - 8) / 32, (14 - 8) / 32, (28 - 8) / 32, (34 - 8) / 32], np.float32)
    rng = np.random.default_rng(3)
    for _ in range(20):
        out, moved = geometry(crop, box, 32, rng, turn=0.5)
        ys, xs = np.nonzero(out[..., 0] > 127)
        seen = np.array([xs.min(), ys.min(), xs.max() + 1, ys.max() + 1]) / 32
        assert np.abs(seen - moved).max() < 3 / 32  # within the resampling blur


class LampDetector(Detector):
    """Candidates at the centre of every head's box (by the frame's source) and on a fixed grid
    of background points: what a detector gives a verifier to sort."""

    name = "lamps-and-grid"

    def __init__(self, boxes=None):
        super().__init__()
        self.boxes = boxes or {}

    def detect(self, frame):
        on = [
            Candidate.from_circle((x0 + x1) / 2, (y0 + y1) / 2, min(x1 - x0, y1 - y0) / 2, 1.0)
            for x0, y0, x1, y1 in self.boxes.get(frame.source, [])
        ]
        grid = [
            Candidate.from_circle(x, y, 4.0, 0.5)
            for x in range(100, 1280, 150)
            for y in (100, 300, 500)
        ]
        return on + grid


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    """A tiny network trained for real (two epochs) on rendered heads and no-light scenes."""
    scenes = [Scene(f, b, [None] * len(b)) for f, b in head_frames(Heads(4, 0.5, 0.0))]
    scenes += [Scene(f, [], []) for f in no_light_frames(2)]
    detector = LampDetector({s.frame.source: s.boxes for s in scenes})
    data = collect(scenes, detector)
    assert (data.light == 1).sum() >= 10 and (data.light == 0).sum() >= 10
    trainer = make(width=4, epochs=2, seed=1)
    model = trainer.fit_crops(data)
    path = tmp_path_factory.mktemp("cnn") / "tiny"
    where = save_model(
        path, model, plugin="cnn-verifier", plugin_version="0", params={}, training={}
    )
    return path, where, scenes, model, detector


def test_a_trained_network_runs_through_the_plugin_as_onnx(trained):
    path, where, scenes, model, detector = trained
    assert where.suffix == ".npz" and path.with_suffix(".onnx").is_file()  # weights + network
    assert model.info["onnx_vs_torch_max_difference"] <= 1e-4
    verifier = make(model=str(path), threshold=0.0, overlap=1.0)
    frame = scenes[0].frame
    candidates = detector.detect(frame)
    kept = verifier.verify(frame, candidates)
    assert len(kept) == len(candidates)  # threshold 0 and no suppression keep every one
    assert all(0.0 <= c.score <= 1.0 and c.housing is not None for c in kept)
    assert {c.state for c in kept} <= {"red", "yellow", "green", "red_yellow", "off"}
    height, width = frame.image.shape[:2]
    for c in kept:
        x0, y0, x1, y1 = c.housing
        assert 0 <= x0 < x1 <= width and 0 <= y0 < y1 <= height
    strict = make(model=str(path), threshold=1.0).verify(frame, candidates)
    assert all(c.score >= 1.0 for c in strict)


def test_training_is_repeatable_from_its_seed(trained):
    _, _, scenes, model, detector = trained
    again = make(width=4, epochs=2, seed=1).fit_crops(collect(scenes, detector))
    assert again.files["onnx"] == model.files["onnx"]


def test_bad_model_files_are_one_clear_line(trained, tmp_path):
    path, _, scenes, _, _ = trained
    card = json.loads(path.with_suffix(".json").read_text())
    frame, candidates = scenes[0].frame, [Candidate.from_circle(50, 50, 3, 1.0)]

    damaged = tmp_path / "damaged"
    data = bytearray(path.with_suffix(".onnx").read_bytes())
    data[len(data) // 2] ^= 0xFF
    damaged.with_suffix(".onnx").write_bytes(bytes(data))
    damaged.with_suffix(".json").write_text(json.dumps(card))
    for copy in (damaged, tmp_path / "garbage", tmp_path / "other"):
        copy.with_suffix(".npz").write_bytes(path.with_suffix(".npz").read_bytes())
    with pytest.raises(ModelError, match="checksum"):
        make(model=str(damaged)).verify(frame, candidates)

    import hashlib

    garbage = tmp_path / "garbage"
    garbage.with_suffix(".onnx").write_bytes(b"not a network at all")
    card_g = json.loads(json.dumps(card))
    card_g["files"]["onnx"]["sha256"] = hashlib.sha256(b"not a network at all").hexdigest()
    garbage.with_suffix(".json").write_text(json.dumps(card_g))
    with pytest.raises(ModelError, match="not an ONNX model"):
        make(model=str(garbage)).verify(frame, candidates)

    other = tmp_path / "other"
    other.with_suffix(".onnx").write_bytes(path.with_suffix(".onnx").read_bytes())
    card_o = json.loads(json.dumps(card))
    card_o["info"]["layout"]["input"] = [3, 64, 64]
    other.with_suffix(".json").write_text(json.dumps(card_o))
    with pytest.raises(ModelError, match="another input"):
        make(model=str(other)).verify(frame, candidates)

    image = tmp_path / "frame.png"
    cv2.imwrite(str(image), frame.image)
    for bad, words in ((damaged, "checksum"), (tmp_path / "missing", "no such file")):
        result = CliRunner().invoke(
            cli,
            [
                "detect",
                str(image),
                "-d",
                "gray-tophat",
                "-V",
                "cnn-verifier",
                "-p",
                f"verifier.model={bad}",
            ],
        )
        assert result.exit_code == 2, result.output
        assert words in result.output and "Traceback" not in result.output


def test_tsrkit_train_cnn_verifier_writes_a_model_the_plugin_reads(tmp_path):
    out = tmp_path / "m"
    result = CliRunner().invoke(
        cli,
        [
            "train",
            "cnn-verifier",
            "--dataset",
            "sample",
            "--split",
            "train",
            "--detector",
            "conspicuity",
            "--out",
            str(out),
            "-p",
            "width=4",
            "-p",
            "epochs=1",
            "-p",
            "synthetic_frames=1",
            "-p",
            "head_frames=2",
            "-p",
            "crop_frames=0",
        ],
    )
    assert result.exit_code == 0, result.output
    card = json.loads(out.with_suffix(".json").read_text())
    assert card["plugin"] == "cnn-verifier" and card["info"]["crops"]["positives"] > 0
    assert card["training"]["licences"]
    frame = Frame(np.full((64, 64, 3), 90, np.uint8), "grey")
    kept = make(model=str(out), threshold=0.0).verify(frame, [Candidate.from_circle(30, 30, 3, 1)])
    assert len(kept) == 1


def test_adapting_to_a_camera_re_estimates_only_the_normalisation(trained):
    from tsrkit.plugin.models import load_model
    from tsrkit_plugins.verifiers.cnn.training import adapt

    path, _, scenes, _, detector = trained
    model = load_model(path, "cnn-verifier")
    frame = scenes[0].frame
    batch, _ = crops(frame.image, detector.detect(frame))
    darker = (batch * 0.5).astype(np.uint8)  # the same scene, a darker camera
    onnx, arrays = adapt(dict(model.arrays), model.info["width"], darker)
    changed = {k for k in arrays if not np.array_equal(arrays[k], model.arrays[k])}
    assert changed and all("running" in k or "num_batches" in k for k in changed)
    assert onnx != model.files["onnx"]
