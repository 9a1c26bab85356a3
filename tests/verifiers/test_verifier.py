"""The learned verifier: features on known geometry, training, determinism, model files."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from click.testing import CliRunner
from skimage.feature import hog

from tsrkit.cli.main import cli
from tsrkit.core.types import Annotation, Candidate, Dataset, Frame, Sample
from tsrkit.plugin.models import ModelError, load_model, model_paths
from tsrkit.plugin.registry import get_registry
from tsrkit.runner.training import train
from tsrkit.synth import SynthOptions, render_frame
from tsrkit_plugins.verifiers import features as F
from tsrkit_plugins.verifiers.mining import centre_labels, no_light_frames


def lamp_scene() -> np.ndarray:
    """A grey frame with a dark 20x60 housing whose top lamp (radius 6) is lit red."""
    image = np.full((120, 160, 3), 150, np.uint8)
    image[20:80, 70:90] = 25
    yy, xx = np.mgrid[0:120, 0:160]
    image[np.hypot(xx - 80, yy - 30) <= 6] = (40, 40, 255)
    return image


def sample_boxes(image, boxes, size, upright=False):
    """The (N, height, width, 3) samples of ``boxes`` at ``size`` = (width, height)."""
    width, height = size
    points = F.remap_points(image, *F.box_maps(boxes, size, upright))
    return points.reshape(len(boxes), height, width, -1)


def test_stacked_hog_equals_skimage_hog_of_each_patch():
    import cv2

    rng = np.random.default_rng(1)
    patches = rng.uniform(0, 255, (4, 22, 12)).astype(np.float32)
    got = F.stacked_hog(patches, 3)
    alone = F.stacked_hog(patches[2:3], 3)
    assert np.array_equal(got[2], alone[0])  # a patch's HOG does not depend on its neighbours
    for i, patch in enumerate(patches):
        half = cv2.resize(patch / 255.0, (6, 11), interpolation=cv2.INTER_AREA)
        expected = hog(
            np.pad(half, ((2, 2), (0, 0))),  # framed by two black rows
            orientations=F.ORIENTATIONS,
            pixels_per_cell=(5, 6),
            cells_per_block=(1, 1),
            block_norm="L1",
        )
        assert np.array_equal(got[i], expected.astype(np.float32))  # to the bit


def test_stacked_hog_is_skimage_hog_of_the_stack_on_real_patches(shared_datasets):
    """The one-pass normalisation gives exactly what ``hog`` gives on the stacked patches."""
    import cv2

    from tsrkit.datasets import open_dataset

    sample = next(iter(open_dataset(shared_datasets / "dtld_fridtjofs", format="normalized")))
    image = sample.load().image
    rng = np.random.default_rng(4)
    candidates = [
        Candidate.from_circle(rng.uniform(0, image.shape[1]), rng.uniform(0, image.shape[0]), r, 1)
        for r in rng.uniform(1, 20, 60)
    ]
    samples = sample_boxes(image, F.context_boxes(F.candidate_table(candidates))[0], (16, 16))
    planes = F.colour_planes(samples.reshape(-1, 3), len(samples), [16 * 16])[0]
    lens = planes[..., 0].T.reshape(-1, 16, 16)
    for rows, patches in ((1, lens), (3, lens[:, :, 2:14].repeat(2, axis=1)[:, :22])):
        n, height, width = patches.shape
        small = cv2.resize(
            patches.reshape(n * height, width) / np.float32(255.0),
            (width // 2, n * height // 2),
            interpolation=cv2.INTER_AREA,
        ).reshape(n, height // 2, width // 2)
        framed = np.pad(small, ((0, 0), (2, 2), (0, 0))).reshape(-1, width // 2)
        expected = hog(
            framed,
            orientations=F.ORIENTATIONS,
            pixels_per_cell=(framed.shape[0] // (n * rows), width // 2),
            cells_per_block=(1, 1),
            block_norm="L1",
            feature_vector=False,
        )
        got = F.stacked_hog(patches, rows)
        assert np.array_equal(got, expected.reshape(n, -1).astype(np.float32))


def test_sample_boxes_reads_the_box_and_turns_wide_boxes_upright():
    image = np.zeros((50, 80, 3), np.uint8)
    image[:, :, 0] = np.arange(80)[None, :]  # blue grows to the right
    tall = sample_boxes(image, np.array([[10, 0, 22, 22]], np.float32), (12, 22))
    assert np.array_equal(tall[0, 0, :, 0], np.arange(10, 22))
    wide = sample_boxes(image, np.array([[10, 0, 32, 12]], np.float32), (12, 22), upright=True)
    # the box's x axis now runs down the sample
    assert np.array_equal(wide[0, :, 0, 0], np.arange(10, 32))
    assert np.all(wide[0, 5, :, 0] == 15)


def test_colour_and_geometry_features_of_a_lit_red_lamp_in_its_housing():
    image = lamp_scene()
    lamp = dataclasses.replace(
        Candidate.from_circle(80, 30, 6, 2.0), housing=(70, 20, 90, 80), housing_score=0.9
    )
    bare = Candidate.from_circle(80, 30, 6, 1.0)
    rows = F.candidate_features(image, [lamp, bare])
    names = F.feature_names()
    assert rows.shape == (2, len(names))
    col = {n: rows[0, i] for i, n in enumerate(names)}
    assert col["lens_L"] > col["annulus_L"] + 20  # the lit lens is brighter than its ring
    assert col["lens_a"] > 150  # red: Lab a well above neutral 128
    assert col["lens_hue_cos"] > 0.5  # hue near 0 (red), weighted by saturation
    assert col["housing_along_radii"] == pytest.approx(10.0)
    assert col["housing_across_radii"] == pytest.approx(20 / 6)
    assert col["lens_along_in_housing"] == pytest.approx(1 / 6)
    assert col["housing_fit"] == pytest.approx(0.9)
    assert col["score_rank"] == 0 and rows[1, names.index("score_rank")] == 1
    # without a housing stage the lens context stands in: a 6-radius square
    assert rows[1, names.index("has_housing")] == 0
    assert rows[1, names.index("housing_along_radii")] == pytest.approx(F.CONTEXT)
    assert F.candidate_features(image, []).shape == (0, len(names))


def test_a_horizontal_head_reads_as_the_same_head_hung_vertically():
    # the frame mirrored across its diagonal turns the vertical head horizontal (lamp at the
    # left): the housing is read upright, so its geometry and colour columns are unchanged
    image = lamp_scene()
    lamp = dataclasses.replace(
        Candidate.from_circle(80, 30, 6, 2.0), housing=(70, 20, 90, 80), housing_score=0.9
    )
    turned = dataclasses.replace(
        Candidate.from_circle(30, 80, 6, 2.0), housing=(20, 70, 80, 90), housing_score=0.9
    )
    names = F.feature_names()
    upright = F.candidate_features(image, [lamp])[0]
    lying = F.candidate_features(np.ascontiguousarray(image.transpose(1, 0, 2)), [turned])[0]
    same = [n for n in names if n.startswith("housing_") or n.startswith("lens_a")]
    same += ["lens_across_in_housing", "lens_along_in_housing", "radius"]
    for name in same:
        assert lying[names.index(name)] == pytest.approx(upright[names.index(name)]), name
    assert lying[names.index("x_over_width")] != upright[names.index("x_over_width")]


def test_centre_labels_follow_zheng_and_no_light_frames_are_unlit():
    cands = [Candidate.from_circle(x, 10, 2, 1.0) for x in (10, 20.7, 20.8)]
    # box 8x20: enclosing circle of radius sqrt(4^2 + 10^2) = 10.77 around (10, 10)
    assert centre_labels(cands, [(6, 0, 14, 20)]).tolist() == [1, 1, 0]
    assert centre_labels(cands, []).tolist() == [0, 0, 0]
    frames = list(no_light_frames(2, seed=5))
    assert len(frames) == 2 and frames[0].image.shape == (720, 1280, 3)
    assert frames[0].source != frames[1].source


def tiny_dataset(n: int = 6) -> Dataset:
    """Rendered 320x180 scenes with their lit lenses (in memory)."""
    samples = []
    for i in range(n):
        image, annotations, _ = render_frame(i, 3, 320, 180, SynthOptions())
        samples.append(Sample(f"tiny{i}", tuple(annotations), 320, 180, "train", image=image))
    return Dataset("tiny", tuple(samples))


def make(**params):
    return get_registry().create("verifier", "verifier", params)


FAST = dict(iterations=20, synthetic_frames=1, head_frames=1, crop_frames=0, negative_ratio=2.0)


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    folder = tmp_path_factory.mktemp("verifier")
    detector = get_registry().create("detector", "gray-tophat")
    paths = [
        train("verifier", tiny_dataset(), folder / f"model{k}", FAST, detector) for k in (1, 2)
    ]
    return paths


def test_training_is_deterministic(trained):
    a, b = (load_model(p, "verifier") for p in trained)
    assert a.arrays.keys() == b.arrays.keys()
    for key in a.arrays:
        assert np.array_equal(a.arrays[key], b.arrays[key])
    assert a.info["positives"] > 0 and a.info["negatives"] > 0


def test_model_round_trip_scores_like_the_fitted_estimator(trained):
    dataset = tiny_dataset()
    detector = get_registry().create("detector", "gray-tophat")
    fitted = make(**FAST).fit(dataset, detector=detector)
    loaded = make(model=str(trained[0]), threshold=0.0)
    frame = dataset.samples[0].load()
    candidates = detector.detect(frame)
    assert candidates
    from tsrkit_plugins.shared.persistence import load_estimator

    expected = load_estimator(fitted, "memory").predict_proba(
        F.candidate_features(frame.image, candidates)
    )[:, 1]
    assert np.allclose(loaded.probabilities(frame, candidates), expected)
    kept = loaded.verify(frame, candidates)
    assert len(kept) == len(candidates)
    # verify scores the candidates after its housing stage (after=housing)
    housed = get_registry().create("verifier", "housing").verify(frame, candidates)
    expected = loaded.probabilities(frame, housed)
    assert [c.score for c in kept] == sorted(expected.tolist(), reverse=True)
    assert make(model=str(trained[0]), threshold=1.0).verify(frame, candidates) == [
        c for c in kept if c.score >= 1.0
    ]


def test_prior_blends_the_detectors_score_with_the_probability(trained):
    frame = tiny_dataset(1).samples[0].load()
    candidates = get_registry().create("detector", "gray-tophat").detect(frame)[:4]
    own = [0.0, 0.5, 1.0, 7.0][: len(candidates)]  # detector scores, clipped to [0, 1]
    candidates = [dataclasses.replace(c, score=s) for c, s in zip(candidates, own)]
    # the verifier fits housings first (after=housing): read the probability after that stage
    candidates = get_registry().create("verifier", "housing").verify(frame, candidates)
    plain = make(model=str(trained[0]), threshold=0.0)
    probability = plain.probabilities(frame, candidates)
    blended = make(model=str(trained[0]), threshold=0.0, prior=0.7).verify(frame, candidates)
    expected = {
        (c.x, c.y): 0.3 * p + 0.7 * min(c.score, 1.0) for c, p in zip(candidates, probability)
    }
    assert blended  # the housing stage may merge duplicates; the survivors are blended
    assert [c.score for c in blended] == pytest.approx([expected[c.x, c.y] for c in blended])
    alone = make(model=str(trained[0]), prior=1.0).verify(frame, candidates)  # threshold 0.5
    assert alone and {c.score for c in alone} <= {0.5, 1.0}


def test_relative_drops_what_scores_below_a_share_of_the_frames_best(trained):
    frame = tiny_dataset(1).samples[0].load()
    candidates = get_registry().create("detector", "gray-tophat").detect(frame)
    candidates = get_registry().create("verifier", "housing").verify(frame, candidates)
    own = [1.0, 0.4]  # prior 1: the score is the detector's own
    candidates = [dataclasses.replace(c, score=s) for c, s in zip(candidates, own)]
    assert len(candidates) == 2

    def scores(**params):
        verifier = make(model=str(trained[0]), prior=1.0, **params)
        return [c.score for c in verifier.verify(frame, candidates)]

    assert scores(threshold=0.0) == [1.0, 0.4]
    assert scores(threshold=0.0, relative=0.5) == [1.0]
    assert scores(threshold=0.0, relative=0.4) == [1.0, 0.4]
    assert scores(threshold=0.5, relative=0.1) == [1.0]


def test_corrupt_foreign_or_mismatched_models_are_one_clear_error(trained, tmp_path):
    npz, meta = model_paths(trained[0])
    frame = Frame(lamp_scene(), "x")
    cand = [Candidate.from_circle(80, 30, 6, 1.0)]

    corrupt = tmp_path / "corrupt"
    data = bytearray(npz.read_bytes())
    data[len(data) // 2] ^= 0xFF
    (tmp_path / "corrupt.npz").write_bytes(bytes(data))
    (tmp_path / "corrupt.json").write_text(meta.read_text())
    with pytest.raises(ModelError, match="corrupt"):
        make(model=str(corrupt)).verify(frame, cand)

    layout = tmp_path / "layout"
    (tmp_path / "layout.npz").write_bytes(npz.read_bytes())
    info = json.loads(meta.read_text())
    info["info"]["layout"]["housing_px"] = [16, 32]
    (tmp_path / "layout.json").write_text(json.dumps(info))
    with pytest.raises(ModelError, match="feature layout"):
        make(model=str(layout)).verify(frame, cand)

    foreign = tmp_path / "foreign"
    (tmp_path / "foreign.npz").write_bytes(npz.read_bytes())
    info = json.loads(meta.read_text())
    info["plugin"] = "ab-hist"
    (tmp_path / "foreign.json").write_text(json.dumps(info))
    with pytest.raises(ModelError, match="ab-hist"):
        make(model=str(foreign)).verify(frame, cand)

    result = CliRunner().invoke(
        cli,
        [
            "detect",
            str(write_png(tmp_path)),
            "-d",
            "gray-tophat",
            "-V",
            "verifier",
            "-p",
            f"verifier.model={corrupt}",
            "-p",
            "detector.h_peak=0.1",
        ],
    )
    assert result.exit_code == 2, result.output
    assert "corrupt" in result.output and "Traceback" not in result.output


def write_png(folder):
    import cv2

    path = folder / "lamp.png"
    cv2.imwrite(str(path), lamp_scene())
    return path


def test_untrusted_types_in_the_estimator_bytes_are_refused():
    import skops.io as sio
    from sklearn.preprocessing import FunctionTransformer

    from tsrkit.plugin.models import Model
    from tsrkit_plugins.shared.persistence import ARRAY, load_estimator

    blob = np.frombuffer(sio.dumps(FunctionTransformer(func=print)), np.uint8)
    with pytest.raises(ModelError, match="untrusted"):
        load_estimator(Model({ARRAY: blob}), "x")


def test_fit_needs_a_detector_and_both_classes():
    from tsrkit.core.errors import TsrkitError

    with pytest.raises(TsrkitError, match="detector"):
        make().fit(tiny_dataset(1))
    empty = Dataset(
        "none", (Sample("blank", (), 64, 64, "train", image=np.zeros((64, 64, 3), np.uint8)),)
    )
    detector = get_registry().create("detector", "gray-tophat")
    with pytest.raises(TsrkitError, match="positive"):
        make(synthetic_frames=0, head_frames=0, crop_frames=0).fit(empty, detector=detector)


def test_a_annotation_is_used_by_its_box():
    ann = Annotation((6, 0, 14, 20), "red")
    assert centre_labels([Candidate.from_circle(10, 10, 1, 1)], [ann.bbox]).tolist() == [1]


def test_the_shipped_model_reads_this_feature_layout_and_open_data_only():
    verifier = make(threshold=0.0)
    frame = Frame(lamp_scene(), "lamp")
    kept = verifier.verify(frame, [Candidate.from_circle(80, 30, 6, 1.0)])
    assert len(kept) == 1 and 0.0 <= kept[0].score <= 1.0
    from tsrkit_plugins.verifiers.learned import DEFAULT_MODEL

    training = load_model(DEFAULT_MODEL, "verifier").meta["training"]
    # shipped models learn from openly licensed sets only (never dtld_fridtjofs)
    assert "dtld" not in training["dataset"]
    assert set(training["dataset"].replace("+", " ").split()) <= {
        "roboflow_traffic_light_kr:valid",
        "roboflow_cinta_v2_id:valid",
    }


def test_the_verifier_runs_its_housing_stage_and_its_model_must_match_it():
    frame = Frame(lamp_scene(), "lamp")
    kept = make(threshold=0.0).verify(frame, [Candidate.from_circle(80, 30, 6, 1.0)])
    x0, y0, x1, y1 = kept[0].housing  # the housing stage ran first (after=housing)
    assert (x1 - x0) < (y1 - y0) and (kept[0].x, kept[0].y, kept[0].radius) == (80.0, 30.0, 6.0)
    with pytest.raises(ModelError, match="trained after the stage 'housing'"):
        make(after="").verify(frame, [Candidate.from_circle(80, 30, 6, 1.0)])
