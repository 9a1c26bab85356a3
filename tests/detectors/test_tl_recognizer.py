"""Tests for the TL-recognizer detector (Mascetti 2016) on synthetic frames and real data."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest
from oracles.tl_recognizer_loop import scored_loop

import tsrkit
from tsrkit.core.types import Annotation, Frame, Sample
from tsrkit.datasets import open_dataset
from tsrkit.plugin.models import load_model, save_model
from tsrkit.plugin.registry import get_registry
from tsrkit_plugins.detectors.tl_recognizer import (
    TlRecognizer,
    enclosed_cores,
    red_or_yellow,
    tl_geometry as geo,
)
from tsrkit_plugins.detectors.tl_recognizer.tl_recognizer import image_boxes, levelled_boxes
from tsrkit_plugins.detectors.tl_recognizer.tl_templates import (
    disc_template,
    extract_patch,
    ncc,
    warp_matrices,
)
from tsrkit_plugins.detectors.tl_recognizer.tl_tuning import (
    patch_scores,
    smallest_ranges,
    tune_threshold,
)

#: Lit-lens colours as a camera records them (BGR), distinct from the templates' own colours.
LIT = {"green": (170, 250, 40), "red": (50, 30, 235), "yellow": (20, 180, 245)}
SODIUM = (0, 120, 255)  # low-pressure sodium: saturated orange, hue about 14
WARM_WHITE = (150, 230, 255)  # warm-white lamp: S about 105, passes the yellowRed filter


def scene(height=240, width=320, background=(30, 30, 30)):
    return np.full((height, width, 3), background, np.uint8)


def lit_disc(image, centre, radius, colour):
    cv2.circle(image, centre, radius, colour, thickness=-1, lineType=cv2.LINE_AA)
    return image


def detector(**params) -> TlRecognizer:
    """Housing-context validation (``context=housing``), unless the test says otherwise."""
    return tsrkit.detector("tl-recognizer", **{"context": "housing", **params})


def lens_detector(**params) -> TlRecognizer:
    """The paper's bare-MBR validation against a lit disc (the plugin's default): the bare discs
    drawn below are lenses without housing, which the housing context rightly does not accept."""
    return detector(context="lens", **params)


def test_default_context_is_the_papers_bare_lens():
    assert tsrkit.detector("tl-recognizer").params["context"] == "lens"


@pytest.mark.parametrize("state", ["green", "red", "yellow"])
def test_lit_disc_found_with_its_state(state):
    image = lit_disc(scene(), (160, 100), 12, LIT[state])
    found = lens_detector(resize_factor=1).detect(Frame(image, "synthetic"))
    assert len(found) == 1
    c = found[0]
    assert c.state == state
    assert abs(c.x - 160) <= 1.5 and abs(c.y - 100) <= 1.5 and 10 <= c.radius <= 14
    assert c.score > 0.586


def test_three_lights_in_one_frame_each_get_their_state():
    image = scene()
    for x, state in zip((60, 160, 260), ("red", "yellow", "green")):
        lit_disc(image, (x, 120), 10, LIT[state])
    found = lens_detector(resize_factor=2).detect(Frame(image, "synthetic"))
    assert sorted((round(c.x / 100), c.state) for c in found) == [
        (1, "red"),
        (2, "yellow"),
        (3, "green"),
    ]


def test_lamps_pass_extraction_but_fail_validation():
    image = scene()
    cv2.rectangle(image, (40, 60), (100, 100), SODIUM, thickness=-1)  # sodium luminaire
    cv2.rectangle(image, (200, 60), (250, 95), WARM_WHITE, thickness=-1)  # white lamp panel
    det = lens_detector(resize_factor=1)
    scored = det.scored(Frame(image, "synthetic"))
    assert len(scored) == 2  # both survive extraction and pruning...
    assert all(c.score <= det.threshold for c in scored)  # ...and validation rejects them
    assert det.detect(Frame(image, "synthetic")) == []


DUSK_SKY = (90, 60, 50)
LAMPS = {"sodium": SODIUM, "warm white": WARM_WHITE}


def signal_head(image, centre, radius, state, horizontal=False):
    """A 3-lens head (red top/left, green bottom/right) with ``state`` lit, pitch 1.3 diameters."""
    k = ("red", "yellow", "green").index(state)
    pitch, border = int(round(2.6 * radius)), radius // 2 - 1
    first = np.array(centre) - (k * pitch if horizontal else 0, 0 if horizontal else k * pitch)
    step = np.array((pitch, 0) if horizontal else (0, pitch))
    end = first + 2 * step
    cv2.rectangle(
        image,
        tuple(int(v) for v in first - radius - border),
        tuple(int(v) for v in end + radius + border),
        (20, 20, 20),
        -1,
    )
    for j in range(3):
        lit_disc(image, tuple(int(v) for v in first + j * step), radius, (40, 40, 40))
    return lit_disc(image, centre, radius, LIT[state])


def street_lamp(image, centre, radius, colour):
    """A round lamp on a thin dark pole."""
    cv2.rectangle(
        image, (centre[0] - 2, centre[1]), (centre[0] + 2, image.shape[0]), (50, 50, 50), -1
    )
    return lit_disc(image, centre, radius, colour)


@pytest.mark.parametrize("horizontal", [False, True])
@pytest.mark.parametrize("state", ["green", "red", "yellow"])
def test_lit_lens_in_its_housing_is_accepted(state, horizontal):
    image = signal_head(scene(background=DUSK_SKY), (160, 120), 10, state, horizontal)
    det = detector(resize_factor=1, orientation="both" if horizontal else "vertical")
    found = det.detect(Frame(image, "synthetic"))
    assert [c.state for c in found] == [state]
    assert abs(found[0].x - 160) <= 1.5 and abs(found[0].y - 120) <= 1.5
    assert found[0].score > det.threshold + 0.1
    # the vertical template does not fit a horizontal head
    vertical = detector(resize_factor=1).scored(Frame(image, "synthetic"))
    assert (vertical[0].score > det.threshold) != horizontal


@pytest.mark.parametrize("lamp", sorted(LAMPS))
def test_round_street_lamps_are_rejected_by_housing_validation(lamp):
    hsv = cv2.cvtColor(np.uint8([[LAMPS[lamp]]]), cv2.COLOR_BGR2HSV)[0, 0]
    assert hsv[0] <= 25 and hsv[1] >= 100 and hsv[2] >= 80  # inside the yellowRed filter
    image = street_lamp(scene(background=DUSK_SKY), (160, 80), 10, LAMPS[lamp])
    frame = Frame(image, "synthetic")
    for orientation in ("vertical", "both"):
        det = detector(resize_factor=1, orientation=orientation)
        scored = det.scored(frame)
        assert len(scored) == 1 and abs(scored[0].x - 160) <= 1.5  # extracted and pruned...
        assert scored[0].score < det.threshold - 0.1  # ...but not a lens
        assert det.detect(frame) == []
    # the bare-lens reading of 3.5 scores the same lamp as high as a lens
    assert lens_detector(resize_factor=1).scored(frame)[0].score > 0.586


def test_housing_template_layout():
    from tsrkit_plugins.detectors.tl_recognizer.tl_templates import (
        Layout,
        housing_template,
        patch_box,
    )

    layout = Layout(True, 20, pitch=1.5, margin=0.5)
    t = housing_template("red", "vertical", layout)
    assert t.shape == (20 * 5 // 2, 20, 3)  # along (2 * 1.5 + 1 + 1) / across 2
    lens_row = 20 // 2  # red lens centred 1 diameter from the top
    assert t[lens_row, 10, 2] > 200 and t[lens_row + 15, 10, 2] < 80  # lit red, dim yellow
    assert t[1, 1].min() > 150 and t[lens_row, 3].max() < 40  # surround, screen
    assert np.array_equal(housing_template("red", "horizontal", layout), t.transpose(1, 0, 2))
    # green at the bottom: the patch reaches two pitches above the lens
    assert patch_box((-5, -5, 5, 5), "green", "vertical", layout) == (-10, -40, 10, 10)
    assert patch_box((-5, -5, 5, 5), "red", "horizontal", layout) == (-10, -10, 40, 10)


def test_white_lamp_without_tint_never_passes_the_range_filter():
    image = lit_disc(scene(), (160, 120), 15, (250, 250, 250))
    assert detector(resize_factor=1).scored(Frame(image, "synthetic")) == []


def test_ncc_of_template_with_itself_and_with_flat_patch():
    t = disc_template("green", 32)
    assert ncc(t, t) == pytest.approx(1.0)
    assert ncc(np.full_like(t, 90), t) == 0.0
    with pytest.raises(ValueError):
        ncc(t[:16], t)


def test_ncc_matches_the_textbook_formula():
    rng = np.random.default_rng(1)
    p = rng.integers(0, 256, (16, 16, 3), dtype=np.uint8)
    t = rng.integers(0, 256, (16, 16, 3), dtype=np.uint8)
    a = p.astype(float) - p.reshape(-1, 3).mean(axis=0)
    b = t.astype(float) - t.reshape(-1, 3).mean(axis=0)
    expected = (a * b).sum() / np.sqrt((a * a).sum() * (b * b).sum())
    assert ncc(p, t) == pytest.approx(expected, abs=1e-4)


def test_red_yellow_split_counts_pure_hues():
    red_patch = lit_disc(scene(32, 32), (16, 16), 14, LIT["red"])
    yellow_patch = lit_disc(scene(32, 32), (16, 16), 14, LIT["yellow"])
    assert red_or_yellow(red_patch, 100, 80, (160, 179), (10, 30)) == "red"
    assert red_or_yellow(yellow_patch, 100, 80, (160, 179), (10, 30)) == "yellow"


def test_horizon_hand_worked_case():
    # f = 500 px, pitch 10 deg up, roll 30 deg, centre (320, 240).
    # P = C + f tan(10 deg) (sin 30, cos 30) = (320 + 44.081, 240 + 76.351) and the line's
    # direction is (cos 30, -sin 30): both P and P + 100 (cos 30, -sin 30) lie on it.
    a, b, c = geo.horizon_line(np.radians(10), np.radians(30), (320, 240), 500)
    d = 500 * np.tan(np.radians(10))
    assert d == pytest.approx(88.163, abs=1e-3)
    p = np.array([320 + d * 0.5, 240 + d * np.sqrt(3) / 2])
    q = p + 100 * np.array([np.sqrt(3) / 2, -0.5])
    for x, y in (p, q):
        assert a * x + b * y + c == pytest.approx(0, abs=1e-9)
    # levelled coordinates put the horizon at v = f tan(pitch)
    uv = geo.level_coordinates(np.array([p, q]), np.radians(30), (320, 240))
    assert uv[:, 1] == pytest.approx([d, d])
    back = geo.image_coordinates(uv, np.radians(30), (320, 240))
    assert back == pytest.approx(np.array([p, q]))
    # level camera, no roll: the horizon is the centre row
    a, b, c = geo.horizon_line(0.0, 0.0, (320, 240), 500)
    assert (a, b, -c / b) == pytest.approx((0, 1, 240))


def test_property2_distances_against_a_pinhole_projection():
    f, pitch, lens = 800.0, np.radians(5), 0.2
    d_h, height = 10.0, 2.0  # light 10 m ahead, lens bottom 2 m above camera
    # project lens bottom and top into a camera pitched up by 5 degrees
    d1 = f * np.tan(np.arctan2(height, d_h) - pitch)
    d2 = f * np.tan(np.arctan2(height + lens, d_h) - pitch)
    assert geo.horizontal_distance(d1, d2, f, pitch, lens) == pytest.approx(d_h, rel=1e-9)
    assert geo.vertical_distance(d_h, d1, f, pitch) == pytest.approx(height, rel=1e-9)
    assert geo.object_width(10.0, 16.0, 800.0, 0.0) == pytest.approx(0.2)
    assert geo.object_width(10.0, 16.0, 800.0, np.radians(60)) == pytest.approx(0.4)


def metric_frame(distance_m, height_m, state, focal=800.0, pitch_deg=5.0, roll_deg=0.0):
    """A frame holding a 0.2 m lens at a known distance, with camera metadata."""
    image = scene(480, 640)
    pitch = np.radians(pitch_deg)
    centre_angle = np.arctan2(height_m + 0.1, distance_m) - pitch
    radius = int(round(f_over(focal, distance_m) * 0.1))
    y = int(round((480 - 1) / 2 - focal * np.tan(centre_angle)))
    lit_disc(image, (320, y), radius, LIT[state])
    if roll_deg:
        rot = cv2.getRotationMatrix2D((319.5, 239.5), roll_deg, 1.0)
        image = cv2.warpAffine(image, rot, (640, 480), borderValue=(30, 30, 30))
    return Frame(
        image,
        "synthetic",
        metadata={"focal_px": focal, "pitch_deg": pitch_deg, "roll_deg": roll_deg},
    )


def f_over(focal, distance):
    return focal / distance


@pytest.mark.parametrize(
    "distance, height, kept",
    [
        (8.0, 2.0, True),  # inside 2.5-20 m and 0.5-4 m
        (40.0, 2.0, False),  # too far
        (8.0, 6.0, False),  # too high
        (8.0, -0.5, False),  # below the camera
    ],
)
def test_metadata_pruning_by_distance(distance, height, kept):
    frame = metric_frame(distance, height, "green")
    found = lens_detector(resize_factor=1).detect(frame)
    assert (len(found) == 1) == kept


def test_rolled_frame_is_levelled_before_pruning():
    frame = metric_frame(8.0, 2.0, "red", roll_deg=20.0)
    found = lens_detector(resize_factor=1).detect(frame)
    assert [c.state for c in found] == ["red"]


def test_width_property_prunes_a_wide_blob_with_metadata():
    frame = metric_frame(8.0, 2.0, "green")
    image = frame.image.copy()
    cv2.ellipse(image, (100, 150), (30, 10), 0, 0, 360, LIT["green"], -1)
    found = lens_detector(resize_factor=1).detect(Frame(image, "s", metadata=frame.metadata))
    assert len(found) == 1 and abs(found[0].x - 320) < 2


def test_patch_follows_the_roll():
    image = scene(200, 200)
    cv2.rectangle(image, (90, 60), (110, 140), (255, 255, 255), -1)  # a tall bar
    rot = cv2.getRotationMatrix2D((99.5, 99.5), 30, 1.0)  # turned 30 deg ccw
    rotated = cv2.warpAffine(image, rot, (200, 200), borderValue=(30, 30, 30))
    upright = extract_patch(image, (-10.5, -40.5, 11.5, 41.5), 0.0, (99.5, 99.5), 16)
    levelled = extract_patch(rotated, (-10.5, -40.5, 11.5, 41.5), np.radians(30), (99.5, 99.5), 16)
    assert np.abs(upright.astype(int) - levelled.astype(int)).mean() < 12


@pytest.mark.parametrize("factor", [1, 2, 3, 4])
def test_resize_factor_keeps_large_lights(factor):
    image = scene(480, 640)
    for x, state in zip((120, 320, 520), ("red", "yellow", "green")):
        lit_disc(image, (x, 200), 18, LIT[state])
    found = sorted(
        lens_detector(resize_factor=factor).detect(Frame(image, "synthetic")), key=lambda c: c.x
    )
    assert [c.state for c in found] == ["red", "yellow", "green"]
    for c, x in zip(found, (120, 320, 520)):
        assert abs(c.x - x) <= 1.5 and abs(c.y - 200) <= 1.5 and abs(c.radius - 18.5) <= 2


def test_two_threads_give_the_same_result():
    image = scene()
    for x, state in zip((60, 160, 260), ("red", "yellow", "green")):
        lit_disc(image, (x, 120), 10, LIT[state])
    frame = Frame(image, "synthetic")
    assert lens_detector(threads=2).detect(frame) == lens_detector(threads=1).detect(frame)


def synthetic_samples(n=6, seed=0):
    rng = np.random.default_rng(seed)
    samples = []
    for i in range(n):
        image = scene()
        state = ("red", "yellow", "green")[i % 3]
        x, y = int(rng.integers(40, 280)), int(rng.integers(40, 200))
        lit_disc(image, (x, y), 9, LIT[state])
        cv2.rectangle(image, (10, 10), (40, 30), SODIUM, -1)  # a non-light
        samples.append(
            Sample(f"s{i}", (Annotation((x - 9, y - 9, x + 10, y + 10), state),), image=image)
        )
    return samples


def test_patch_scores_split_lights_from_others():
    det = lens_detector(resize_factor=1)
    samples = synthetic_samples()
    lights, others = patch_scores(det, samples)
    assert len(lights) == len(others) == len(samples)  # one lens and one sodium panel each
    assert lights.min() > others.max()
    assert tune_threshold(det, samples) == (others.max(), 6, 6)


def overexposed_lens(colour, arc, centre=(160, 120), radius=12):
    """A white lens core with a 2 px coloured fringe only on an arc (degrees, 0 = right)."""
    image = lit_disc(scene(), centre, radius, (255, 255, 255))
    cv2.ellipse(image, centre, (radius + 1, radius + 1), 0, arc[0], arc[1], colour, thickness=2)
    return image


def test_enclosed_cores_joins_ringed_white_blobs_only():
    hsv = np.zeros((9, 9, 3), np.uint8)
    hsv[2:5, 2:5] = (0, 0, 250)  # white core, fully ringed
    hsv[6:8, 6:8] = (0, 0, 250)  # white blob with no coloured border
    mask = np.zeros((9, 9), np.uint8)
    mask[1:6, 1:6] = 255
    mask[2:5, 2:5] = 0
    out = enclosed_cores(hsv, mask, 230, 0.5)
    assert out[2:5, 2:5].all() and not out[6:8, 6:8].any()
    assert np.array_equal(enclosed_cores(hsv, mask, 251, 0.5), mask)  # core too dark


def test_fill_cores_recovers_the_whole_overexposed_lens():
    # a fringe on the left 200 degrees: the range filter keeps a C whose box misses the right
    # part of the lens; with the white core added the box is the whole lens
    frame = Frame(overexposed_lens(LIT["red"], arc=(80, 280)), "synthetic")
    (plain,) = lens_detector(resize_factor=1).scored(frame)
    (filled,) = lens_detector(resize_factor=1, fill_cores=True).scored(frame)
    assert filled.state == "red"
    assert abs(filled.x - 159) <= 1 and abs(filled.radius - 13) <= 1
    assert plain.x <= 156 and plain.radius <= 11
    assert filled.score > plain.score


def test_fit_tunes_threshold_and_ranges(tmp_path):
    det = lens_detector(resize_factor=1)
    model = det.fit(synthetic_samples())
    ranges, threshold = model.arrays["ranges"], float(model.arrays["threshold"])
    # T is the best score of the sodium rectangle, which is below every light's score
    lamp = det.scored(Frame(synthetic_samples(1)[0].image, "s"))
    assert threshold == pytest.approx(max(c.score for c in lamp if c.x < 50))
    # the green hue range shrinks from the broad one around the lit green disc's hue
    hue = int(cv2.cvtColor(np.uint8([[LIT["green"]]]), cv2.COLOR_BGR2HSV)[0, 0, 0])
    assert 50 < ranges[0, 0, 0] <= hue <= ranges[0, 1, 0] < 115
    path = save_model(
        tmp_path / "m",
        model,
        plugin="tl-recognizer",
        plugin_version="t",
        params=det.params,
        training={},
    )
    # T holds for the resize factor it was tuned at
    loaded = lens_detector(model=str(path), resize_factor=1)
    assert loaded.threshold == pytest.approx(threshold)
    assert np.array_equal(loaded.ranges, ranges)
    assert load_model(path, "tl-recognizer").info["threshold_from_data"] is True
    for sample in synthetic_samples(6, seed=1):
        found = loaded.detect(sample.load())
        assert [c.state for c in found] == [sample.annotations[0].state]


def test_fit_without_ranges_tunes_t_alone():
    det = lens_detector(resize_factor=1, fit_ranges=False)
    table6 = det.ranges.copy()
    model = det.fit(synthetic_samples())
    assert np.array_equal(model.arrays["ranges"], table6)
    assert float(model.arrays["threshold"]) == pytest.approx(
        tune_threshold(lens_detector(resize_factor=1), synthetic_samples())[0]
    )
    assert model.info["lens_pixels"] == {"green": 0, "yellowred": 0}


def test_smallest_ranges_cover_all_pixels():
    pixels = {
        "green": np.array([[72, 120, 90], [90, 200, 254], [80, 150, 255]], np.uint8),
        "yellowred": np.array([[5, 110, 100], [170, 130, 200], [20, 255, 130]], np.uint8),
    }
    fallback = np.zeros((3, 2, 3))
    r = smallest_ranges(pixels, fallback, 1.0)
    assert r[0, :, 0].tolist() == [72, 90]
    assert r[1, :, 0].tolist() == [0, 20] and r[2, :, 0].tolist() == [170, 180]
    assert r[0, 0, 1:].tolist() == [110, 90]  # the V=255 pixel is excluded


def test_templates_folder_is_used_and_checked(tmp_path):
    with pytest.raises(ValueError, match="red"):
        detector(templates=str(tmp_path))
    for state in ("red", "yellow", "green"):
        cv2.imwrite(str(tmp_path / f"{state}.png"), disc_template(state, 20))
    det = detector(templates=str(tmp_path), template_size=24)
    assert det.templates["green", "vertical"].shape == (24 * 23 // 10, 24, 3)
    assert det.templates["green", "horizontal"].shape == (24, 24 * 23 // 10, 3)
    det = detector(templates=str(tmp_path), template_size=24, context="lens")
    assert det.templates["green", "vertical"].shape == (24, 24, 3)


def test_registered_and_listed_as_trainable():
    info = [i for i in get_registry().plugins() if i.name == "tl-recognizer"]
    assert info and info[0].kind == "detector"
    assert json.dumps(info[0].to_json())


def test_real_frames_run_and_states_are_valid(shared_datasets):
    from tsrkit.runner.inputs import read_image

    images = sorted((shared_datasets / "roboflow_cinta_v2_id").rglob("*.jpg"))[:8]
    assert images
    det = detector(resize_factor=1)
    for path in images:
        for c in det.detect(Frame(read_image(path), str(path))):
            assert c.state in ("red", "yellow", "green") and c.score > det.threshold


def test_levelled_boxes_hand_worked_and_like_one_contour_at_a_time():
    # Reduced pixel (0, 0) at factor 2 covers full-resolution pixels 0-1: edges -0.5 .. 1.5.
    single = [np.array([[[0, 0]]], np.int32), np.array([[[3, 1]], [[4, 2]]], np.int32)]
    boxes = levelled_boxes(single, (2.0, 2.0), 0.0, (0.0, 0.0))
    assert boxes.tolist() == [[-0.5, -0.5, 1.5, 1.5], [5.5, 1.5, 9.5, 5.5]]
    assert image_boxes(boxes, 0.0, (10.0, 5.0)).tolist() == [
        [9.5, 4.5, 11.5, 6.5],
        [15.5, 6.5, 19.5, 10.5],
    ]
    rng = np.random.default_rng(3)
    contours = [rng.integers(0, 90, (n, 1, 2)).astype(np.int32) for n in (1, 4, 9, 2)]
    roll, centre, scale = 0.3, (44.5, 30.0), (3.0, 2.5)
    boxes = levelled_boxes(contours, scale, roll, centre)
    for contour, box in zip(contours, boxes):
        uv = geo.level_coordinates((contour.reshape(-1, 2) + 0.5) * scale - 0.5, roll, centre)
        (u0, v0), (u1, v1) = uv.min(axis=0), uv.max(axis=0)
        assert box.tolist() == [u0 - 1.5, v0 - 1.25, u1 + 1.5, v1 + 1.25]
    assert levelled_boxes([], scale, roll, centre).shape == (0, 4)


#: Real frames with many contours that survive pruning (a city street in Indonesia, a Korean
#: road at dusk, two Japanese junctions), stretched to Mascetti's 1413x1884 as the benchmarks do.
CLUTTERED = (
    ("roboflow_cinta_v2_id", "traffic-light--524-_jpg"),
    ("roboflow_traffic_light_kr", "KakaoTalk_20240226_182814713_05_jpg"),
    ("iwai_japan_tl", "im198.jpg"),
    ("iwai_japan_tl", "im105.jpg"),
)


@pytest.fixture(scope="module")
def cluttered_frames(shared_datasets):
    frames = []
    for name, stem in CLUTTERED:
        samples = open_dataset(shared_datasets / name, format="normalized")
        sample = next(s for s in samples if Path(s.source).name.startswith(stem))
        image = cv2.resize(sample.load().image, (1413, 1884), interpolation=cv2.INTER_LINEAR)
        frames.append(Frame(image, sample.source))
    rng = np.random.default_rng(5)
    image = cv2.GaussianBlur(rng.integers(60, 140, (720, 1280, 3), dtype=np.uint8), (0, 0), 3)
    for _ in range(600):
        hsv = np.uint8([[[rng.choice([5, 20, 80, 175]), rng.integers(150, 256), 200]]])
        colour = tuple(int(c) for c in cv2.cvtColor(hsv, cv2.COLOR_HSV2BGR)[0, 0])
        centre = (int(rng.integers(0, 1280)), int(rng.integers(0, 720)))
        axes = (int(rng.integers(1, 12)), int(rng.integers(1, 12)))
        cv2.ellipse(image, centre, axes, float(rng.uniform(0, 180)), 0, 360, colour, -1)
    return frames + [Frame(image, "rendered clutter")]


@pytest.mark.parametrize(
    "params",
    [{}, {"context": "housing", "orientation": "both", "fill_cores": True, "resize_factor": 2}],
)
def test_candidates_equal_those_of_contour_by_contour_validation(cluttered_frames, params):
    """Scored and detected candidates (boxes, NCC, states) equal those of validating each
    contour on its own with OpenCV's NCC, on cluttered real frames and a rendered one."""
    det = tsrkit.detector("tl-recognizer", **params)
    for frame in cluttered_frames:
        expected = scored_loop(det, frame)
        assert len(expected) > 20
        assert det.scored(frame) == expected
        assert det.detect(frame) == [c for c in expected if c.score > det.threshold]


@pytest.mark.parametrize("roll", [0.0, 0.3])
def test_warp_matrices_equal_the_product_of_the_two_maps(roll):
    """Unrolled maps are written out for all boxes at once; they must be the numbers the
    product levelled -> image times patch -> levelled gives, as rolled ones are computed."""
    rng = np.random.default_rng(3)
    corner = rng.uniform(-700, 700, (200, 2))
    boxes = np.column_stack([corner, corner + rng.uniform(0.5, 90, (200, 2))])
    centre = (706.0, 941.5)
    for size in ((32, 32), (32, 96)):
        found = warp_matrices(boxes, roll, centre, size)
        for (u0, v0, u1, v1), matrix in zip(boxes, found):
            su, sv = (u1 - u0) / size[0], (v1 - v0) / size[1]
            c, s = np.cos(roll), np.sin(roll)
            to_uv = np.array([[su, 0.0, u0 + su / 2], [0.0, sv, v0 + sv / 2]])
            to_xy = np.array([[c, s], [-s, c]])
            expected = np.hstack([to_xy @ to_uv[:, :2], (to_xy @ to_uv[:, 2] + centre)[:, None]])
            assert np.array_equal(matrix, expected)
