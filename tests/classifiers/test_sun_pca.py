"""``sun-pca``: Lee's Sun-compensated colour model (2017, 4.3) on hand-made pixels and rendered
Sun-lit scenes, its fallback without Sun facts, and the report's count of that fallback."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tsrkit.core.types import Candidate, Dataset
from tsrkit.plugin.models import Model, ModelError, save_model
from tsrkit.plugin.registry import get_registry
from tsrkit.reporting.benchmarking import run_benchmark
from tsrkit.runner.training import trainable_plugin
from tsrkit.synth.sunlit import sweep
from tsrkit_plugins.classifiers.sun_pca import FALLBACK_NOTE
from tsrkit_plugins.classifiers.sun_pca.model import (
    SPREAD_FLOOR,
    azimuth_bin,
    fit_line,
    lit_share,
    probability,
)

AXIS = np.array([1.0, 2.0, 2.0]) / 3.0
MEAN = np.array([40.0, 80.0, 120.0])


def line_pixels(rng, n=600):
    """Pixels on the line MEAN + s AXIS with s = 5 + 30 max(0, cos alpha), a little noise off it."""
    alpha = rng.uniform(0.0, 180.0, n)
    s = 5.0 + 30.0 * lit_share(alpha) + rng.normal(0.0, 2.0, n)
    off = rng.normal(0.0, 1.0, (n, 3))
    off -= np.outer(off @ AXIS, AXIS)  # perpendicular to the axis
    return MEAN + np.outer(s, AXIS) + off, alpha


def test_azimuth_bins_are_lees_30_degree_steps():
    assert [azimuth_bin(a) for a in (0.0, 29.9, 30.0, 95.0, 179.0, 180.0)] == [0, 0, 1, 3, 5, 5]


def test_fit_line_recovers_the_axis_and_the_cosine_law():
    pixels, alpha = line_pixels(np.random.default_rng(0))
    line = fit_line(pixels, alpha)
    assert abs(line["axis"] @ AXIS) == pytest.approx(1.0, abs=1e-3)
    assert line["axis"].sum() > 0
    # s is measured from the pixels' mean, so the intercept shifts by the mean of 30 cos(alpha).
    mean_s = 5.0 + 30.0 * np.mean(lit_share(alpha))
    assert line["coef"][1] == pytest.approx(30.0, abs=0.5)
    assert line["coef"][0] == pytest.approx(5.0 - mean_s, abs=0.5)
    # Spreads about the law are the noise (2 along, sqrt(2) across) plus the floor.
    assert line["v_a"] == pytest.approx(2.0 + SPREAD_FLOOR, abs=0.5)
    assert line["v_d"] == pytest.approx(np.sqrt(2.0) + SPREAD_FLOOR, abs=0.3)
    # Uncompensated: the spread along the axis holds the whole cosine swing.
    assert float(line["v_a0"]) > 10.0
    # The law holds beyond 90 degrees too, so no bin departs from it.
    assert np.all(line["offset"][:3] == 0.0) and np.abs(line["offset"]).max() < 0.5


def test_probability_is_one_on_the_target_colour_and_falls_off_it():
    pixels, alpha = line_pixels(np.random.default_rng(1))
    line = fit_line(pixels, alpha)
    target = {k: np.stack([v, v]) for k, v in line.items()}
    at_zero = line["mean"] + (line["coef"][0] + line["coef"][1]) * line["axis"]
    at_ninety = line["mean"] + line["coef"][0] * line["axis"]
    p = probability(np.array([at_zero, at_ninety]), target, 0.0, 256.0)
    assert p[0] == pytest.approx(1.0, abs=1e-3) and p[1] < 0.01
    # Without the angle, the mean colour is the target and v_a0 the spread.
    assert probability(line["mean"][None], target, None, 256.0)[0] == pytest.approx(1.0)
    assert probability(at_zero[None], target, None, 256.0)[0] > 0.3


def test_sun_pca_is_trained_as_a_classifier_and_detects_with_the_same_model():
    assert trainable_plugin("sun-pca").kind == "classifier"
    registry = get_registry()
    assert registry.create("detector", "sun-pca", {}).name == "sun-pca"


@pytest.fixture(scope="module")
def scenes():
    return sweep([0.0, 30.0, 60.0], frames_each=3, seed=7)


def test_classifier_tells_orange_from_red_on_rendered_signs(scenes):
    classifier = get_registry().create("classifier", "sun-pca", {})
    right = total = 0
    for sample in scenes:
        frame = sample.load()
        boxes = [Candidate.from_box(a.bbox, 1.0) for a in sample.annotations]
        states = [d.state for d in classifier.classify(frame, boxes)]
        assert classifier.notes == ()
        right += sum(s == a.state for s, a in zip(states, sample.annotations))
        total += len(states)
    assert right / total >= 0.9


def test_detector_finds_orange_signs_with_the_sun_behind(scenes):
    from tsrkit.eval.overlap import match_by_iou

    detector = get_registry().create("detector", "sun-pca", {})
    found = signs = 0
    for sample in scenes:
        candidates = detector.detect(sample.load())
        orange = [a.bbox for a in sample.annotations if a.state == "orange"]
        pairs = match_by_iou([c.bbox for c in candidates], [c.score for c in candidates], orange)
        found, signs = found + len(pairs), signs + len(orange)
        assert all(c.state == "orange" for c in candidates)
    assert found / signs >= 0.6


def without_sun(dataset: Dataset) -> Dataset:
    samples = tuple(replace(s, metadata={}) for s in dataset.samples)
    return replace(dataset, samples=samples)


def test_frames_without_sun_facts_fall_back_and_the_report_counts_them(scenes):
    data = without_sun(scenes)
    classifier = get_registry().create("classifier", "sun-pca", {})
    run = run_benchmark(data, classifier=classifier, cache=False)
    assert run.report["frame_notes"] == {"frames": len(data), "counts": {FALLBACK_NOTE: len(data)}}
    assert all(r.notes == (FALLBACK_NOTE,) for r in run.records)
    assert f"{len(data)} of {len(data)} frames: {FALLBACK_NOTE}" in run.report["notes"]
    # With the facts, nothing to note and no section.
    assert "frame_notes" not in run_benchmark(scenes, classifier=classifier, cache=False).report
    # Settings stand in for missing metadata (here the relative azimuth itself).
    given = get_registry().create("classifier", "sun-pca", {"relative_azimuth_deg": 30.0})
    assert "frame_notes" not in run_benchmark(data, classifier=given, cache=False).report


def test_training_without_sun_facts_gives_an_uncompensated_model(scenes):
    classifier = get_registry().create("classifier", "sun-pca", {})
    model = classifier.fit(without_sun(scenes).samples)
    assert model.info["compensated"] is False
    assert model.info["frames_without_sun"] == len(scenes)
    assert not np.any(model.arrays["coef"][:, :, 1])
    with pytest.raises(ValueError, match="target 'green'"):
        get_registry().create("classifier", "sun-pca", {"targets": "orange,green"}).fit(
            scenes.samples
        )


def test_a_model_of_the_wrong_shape_is_one_clear_error(tmp_path, scenes):
    path = save_model(tmp_path / "m", Model({"mean": np.zeros((1, 2, 3))}, {"targets": ["x"]}),
                      plugin="sun-pca", plugin_version="1", params={}, training={})  # fmt: skip
    classifier = get_registry().create("classifier", "sun-pca", {"model": str(path)})
    with pytest.raises(ModelError, match="not a sun-pca model"):
        classifier.classify(scenes.samples[0].load(), [Candidate.from_circle(5, 5, 3, 1.0)])


def test_a_gps_log_and_a_start_time_give_every_video_frame_its_sun(tmp_path, scenes):
    log = tmp_path / "drive.csv"
    rows = [f"2016-06-20T15:04:{i:02d}Z,40.4433,{-79.9436 + 1e-4 * i:.6f}" for i in range(10)]
    log.write_text("time,lat,lon\n" + "\n".join(rows) + "\n")
    params = {"gps": str(log), "start_utc": "2016-06-20T15:04:00Z"}
    detector = get_registry().create("detector", "sun-pca", params)
    frame = scenes.samples[0].load()
    for timestamp in (0.0, 4.5, 9.0):
        detector.detect(replace(frame, metadata={}, timestamp=timestamp))
        assert detector.notes == ()
    detector.detect(replace(frame, metadata={}, timestamp=60.0))  # past the log's end
    assert detector.notes == (FALLBACK_NOTE,)
