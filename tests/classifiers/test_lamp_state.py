"""lamp-state: lamps of known colour and position, deterministic training, safe models."""

import cv2
import numpy as np
import pytest
from oracles.lamp_state_oracle import halved

import tsrkit
from tsrkit.core.types import Annotation, Candidate, Frame, Sample
from tsrkit.plugin.models import ModelError, load_model, save_model
from tsrkit_plugins.classifiers.lamp_state import STATES, colour_jitter, labelled_features
from tsrkit_plugins.classifiers.lamp_state.features import (
    N_FEATURES,
    N_LENS,
    TWO_LIT,
    area_resample,
    lamp_features,
    red_amber_rows,
    two_lit,
)
from tsrkit_plugins.classifiers.lamp_state.views import around_lights, quarter_turn

#: BGR of lit lamps as cameras record them (saturated, slightly orange red; amber; blue-green).
COLOURS = {"red": (40, 40, 230), "yellow": (20, 170, 250), "green": (170, 230, 40)}
SLOT = {"red": 0, "yellow": 1, "green": 2}
#: The other order: red at the far end (a Japanese head turned so that red is on the right).
REVERSED = {"red": 2, "yellow": 1, "green": 0}
#: Lit centroid along the housing axis among the features, 0 top .. 1 bottom.
POSITION = N_LENS + 6


def head(
    state: str, white_core: bool = False, size: int = 20, slot: dict[str, int] = SLOT
) -> tuple[np.ndarray, tuple]:
    """A road-grey image with a dark vertical 3-lamp housing whose ``state`` lamp is lit
    (``red_yellow``: the red and the amber one), each lamp at its ``slot`` (0 top, 2 bottom);
    returns the image and the housing box."""
    image = np.full((160, 120, 3), (120, 125, 130), np.uint8)
    x0, y0 = 40, 20
    box = (x0, y0, x0 + 2 * size, y0 + 6 * size)
    cv2.rectangle(image, box[:2], (box[2] - 1, box[3] - 1), (25, 25, 25), -1)
    for k in range(3):
        centre = (x0 + size, y0 + size + 2 * size * k)
        cv2.circle(image, centre, int(0.75 * size), (45, 45, 45), -1)
    for lit in state.split("_"):
        centre = (x0 + size, y0 + size + 2 * size * slot[lit])
        cv2.circle(image, centre, int(0.75 * size), COLOURS[lit], -1)
        if white_core:
            cv2.circle(image, centre, int(0.5 * size), (250, 250, 250), -1)
    return cv2.GaussianBlur(image, (3, 3), 0), box


@pytest.mark.parametrize("white_core", [False, True])
@pytest.mark.parametrize("state", ["red", "yellow", "green"])
def test_shipped_model_reads_rendered_heads(state, white_core):
    image, box = head(state, white_core)
    found = tsrkit.classifier("lamp-state").classify(
        Frame(image, "head"), [Candidate.from_box(box, 1.0)]
    )
    assert found[0].state == state
    assert found[0].state_scores[state] == max(found[0].state_scores.values())


def test_features_see_the_lit_position_and_the_rim():
    top, box = head("red", white_core=True)
    bottom, _ = head("green", white_core=True)
    a, b = (lamp_features(i, [Candidate.from_box(box, 1.0)])[0] for i in (top, bottom))
    assert a.shape == (N_FEATURES,)
    position = N_LENS + 6  # lit centroid along the housing axis, 0 top .. 1 bottom
    assert a[position] < 0.3 < 0.7 < b[position]
    assert a[N_LENS + 8] == 1.0  # has_housing
    # brightness at the slot centres, scaled to the housing's range: the lit slot is 1
    assert a[N_LENS + 9 : N_LENS + 12].tolist() == [1.0, 0.0, 0.0]
    assert b[N_LENS + 9 : N_LENS + 12].tolist() == [0.0, 0.0, 1.0]
    lens_box = [Candidate.from_circle(60, 40, 10, 1.0)]
    assert lamp_features(top, lens_box)[0][N_LENS + 8] == 0.0


def mirrored(image: np.ndarray, box: tuple) -> tuple[np.ndarray, tuple]:
    """``image`` mirrored left to right, and ``box`` with it."""
    width = image.shape[1]
    return np.ascontiguousarray(image[:, ::-1]), (width - box[2], box[1], width - box[0], box[3])


@pytest.mark.parametrize("white_core", [False, True])
@pytest.mark.parametrize("state", ["red", "yellow", "green", "red_yellow"])
@pytest.mark.parametrize("order", [SLOT, REVERSED], ids=["red left", "red right"])
def test_a_mirrored_horizontal_head_is_read_as_its_colour_places_it(state, white_core, order):
    """A horizontal head with red on the left (Europe, the US) or on the right (Japan) and its
    mirror image: the features are the same up to the rendering's one-pixel asymmetry (the
    redder end is put on top either way), the lit lamp sits where its colour puts it (red on
    top, green at the bottom, whichever end it was lit at), and the shipped model reads the
    lit state in both: a mirrored head never swaps red and green."""
    image, box = head(state, white_core, slot=order)
    image, (box,) = quarter_turn(image, [box], clockwise=False)  # top lamp to the left
    assert box[2] - box[0] > box[3] - box[1]
    views = [(image, box), mirrored(image, box)]
    rows = np.stack([lamp_features(i, [Candidate.from_box(b, 1.0)])[0] for i, b in views])
    assert np.abs(rows[0] - rows[1]).max() < 0.02
    if state in ("red", "red_yellow"):
        assert rows[:, POSITION].max() < 0.4  # red, or red and amber: the upper part
    elif state == "green":
        assert rows[:, POSITION].min() > 0.7
    classifier = tsrkit.classifier("lamp-state")
    for i, b in views:
        found = classifier.classify(Frame(i, "horizontal"), [Candidate.from_box(b, 1.0)])
        assert found[0].state == state


def test_training_views_keep_the_features_and_turn_heads_either_way():
    """The part of a frame the training views are made of gives the same features as the whole
    frame, and a quarter turn either way makes a vertical head horizontal with its lamp order
    reversed between the two turns (red on the left, then on the right)."""
    image, box = head("red")
    wide = np.concatenate([image, np.full_like(image, 90)], axis=1)
    part, (moved,) = around_lights(wide, [box])
    assert part.shape[1] < wide.shape[1]
    whole = lamp_features(wide, [Candidate.from_box(box, 1.0)])
    assert np.array_equal(lamp_features(part, [Candidate.from_box(moved, 1.0)]), whole)
    reds = []
    for clockwise in (False, True):
        turned, (at,) = quarter_turn(image, [box], clockwise)
        assert at[2] - at[0] == box[3] - box[1] and at[3] - at[1] == box[2] - box[0]
        x0, y0, x1, y1 = (int(v) for v in at)
        red = turned[y0:y1, x0:x1, 2].astype(int) - turned[y0:y1, x0:x1, 1]
        reds.append(np.argmax(red.mean(axis=0)) / (x1 - x0))
    assert reds[0] < 0.3 < 0.7 < reds[1]  # anticlockwise: red left; clockwise: red right


def test_training_turns_only_frames_without_horizontal_heads(tmp_path):
    """With every jittered view turned (``turned`` 1), a vertical head's views differ from
    those without turns in their housing features, and a frame holding a horizontal head is
    never turned (its views equal those of no turns)."""
    vertical, box = head("green")
    lying, (flat,) = quarter_turn(vertical, [box], clockwise=True)
    data = []
    for name, image, at in (("v", vertical, box), ("h", lying, flat)):
        path = tmp_path / f"{name}.png"
        cv2.imwrite(str(path), image)
        data.append([Sample(str(path), (Annotation(at, "green"),))])
    for sample, changed in zip(data, (True, False)):
        plain, _ = labelled_features(sample, copies=2, seed=4, turned=0.0)
        turned, _ = labelled_features(sample, copies=2, seed=4, turned=1.0)
        assert np.array_equal(plain[0], turned[0])  # the light itself is never turned
        assert (not np.array_equal(plain[1:], turned[1:])) is changed


@pytest.mark.parametrize("white_core", [False, True])
def test_two_lit_tells_red_amber_from_red(white_core):
    both, box = head("red_yellow", white_core)
    red, _ = head("red", white_core)
    amber, _ = head("yellow", white_core)
    scores = [
        lamp_features(i, [Candidate.from_box(box, 1.0)])[0, TWO_LIT] for i in (both, red, amber)
    ]
    assert scores[0] > 0.8 and scores[1] < 0.1 and scores[2] < 0.1


@pytest.mark.parametrize("white_core", [False, True])
def test_shipped_model_reads_red_amber_by_position(white_core):
    # the shipped model never saw red+amber (no open set labels it): the two-lit rule reads it;
    # without the rule it is read by one of its two lamps
    image, box = head("red_yellow", white_core)
    classifier = tsrkit.classifier("lamp-state")
    found = classifier.classify(Frame(image, "head"), [Candidate.from_box(box, 1.0)])
    assert found[0].state == "red_yellow"
    off = tsrkit.classifier("lamp-state", red_yellow_ratio=1.0)
    assert off.classify(Frame(image, "head"), [Candidate.from_box(box, 1.0)])[0].state in {
        "red",
        "yellow",
    }


@pytest.mark.parametrize("white_core", [False, True])
def test_red_amber_in_a_box_too_square_for_a_housing(white_core):
    # DTLD-like: the 40x120 head inside an 81x120 box (elongation 1.48, below ELONGATION): the
    # model reads no position there, the red+amber rule reads its band (the middle half across)
    both, (x0, y0, x1, y1) = head("red_yellow", white_core)
    red, _ = head("red", white_core)
    square = [Candidate.from_box((x0 - 20.5, y0, x1 + 20.5, y1), 1.0)]
    rows = [lamp_features(i, square) for i in (both, red)]
    assert rows[0][0, N_LENS + 8] == 0.0 and rows[0][0, TWO_LIT] == 0.0  # not read as a housing
    rule = [red_amber_rows(i, square, r)[0] for i, r in zip((both, red), rows)]
    assert rule[0][TWO_LIT] > 0.8 and rule[1][TWO_LIT] < 0.1
    assert np.array_equal(np.delete(rule[0], TWO_LIT), np.delete(rows[0][0], TWO_LIT))
    classifier = tsrkit.classifier("lamp-state")
    assert classifier.classify(Frame(both, "both"), square)[0].state == "red_yellow"
    assert classifier.classify(Frame(red, "red"), square)[0].state == "red"


def test_red_amber_rule_leaves_housings_lenses_and_wide_boxes_alone():
    both, (x0, y0, x1, y1) = head("red_yellow")
    candidates = [
        Candidate.from_box((x0, y0, x1, y1), 1.0),  # read as a housing: its own two_lit
        Candidate.from_circle(x0 + 20, y0 + 40, 15, 1.0),  # a lens: square box
        Candidate.from_box((x0 - 40, y0, x1 + 40, y1), 1.0),  # wider than tall
    ]
    rows = lamp_features(both, candidates)
    assert red_amber_rows(both, candidates, rows) is rows


def save(path, model):
    return save_model(path, model, plugin="lamp-state", plugin_version="0", params={}, training={})


def samples(tmp_path):
    out = []
    for i, state in enumerate(["red", "yellow", "green"] * 4):
        image, box = head(state, white_core=i % 2 == 1, size=16 + i % 3)
        path = tmp_path / f"{i}.png"
        cv2.imwrite(str(path), image)
        out.append(Sample(str(path), (Annotation(box, state),)))
    return out


def test_training_is_deterministic_and_round_trips(tmp_path):
    data = samples(tmp_path)
    first = tsrkit.classifier("lamp-state", iterations=20).fit(data)
    second = tsrkit.classifier("lamp-state", iterations=20).fit(data)
    assert first.info == second.info and first.info["states"] == ["red", "yellow", "green"]
    assert all(np.array_equal(first.arrays[k], second.arrays[k]) for k in first.arrays)
    path = tmp_path / "model"
    save(path, first)
    loaded = tsrkit.classifier("lamp-state", model=str(path))
    image, box = head("green")
    assert loaded.classify(Frame(image, "x"), [Candidate.from_box(box, 1.0)])[0].state == "green"
    assert set(STATES) >= set(load_model(path, "lamp-state").info["states"])


def test_corrupt_or_foreign_model_is_one_clear_error(tmp_path):
    path = tmp_path / "model"
    save(path, tsrkit.classifier("lamp-state", iterations=10).fit(samples(tmp_path)))
    npz = path.with_suffix(".npz")
    npz.write_bytes(npz.read_bytes()[:200])
    image, box = head("red")
    with pytest.raises(ModelError, match="model"):
        tsrkit.classifier("lamp-state", model=str(path)).classify(
            Frame(image, "x"), [Candidate.from_box(box, 1.0)]
        )
    with pytest.raises(ModelError):
        tsrkit.classifier("lamp-state", model=str(tmp_path / "missing")).classify(
            Frame(image, "x"), [Candidate.from_box(box, 1.0)]
        )


def test_one_state_is_not_enough(tmp_path):
    only_red = [s for s in samples(tmp_path) if s.annotations[0].state == "red"]
    with pytest.raises(tsrkit.TsrkitError, match="need at least two"):
        tsrkit.classifier("lamp-state").fit(only_red)


def test_colour_jitter_spans_other_cameras_exposure():
    grey = np.full((4, 4, 3), 100, np.uint8)
    rng = np.random.default_rng(0)
    views = np.stack([colour_jitter(grey, rng) for _ in range(200)])
    # gains 0.85-1.15 x exposure 0.8-3, gamma 0.8-1.25: 100 stays within these bounds
    low = 255 * (100 * 0.85 * 0.8 / 255) ** 1.25
    high = 255 * min(1.0, 100 * 1.15 * 3.0 / 255) ** 0.8
    assert low - 1 <= views.min() and views.max() <= high
    assert views.max() == 255  # some views clip, as an over-exposed lamp core does
    again = np.random.default_rng(0)
    assert np.array_equal(colour_jitter(grey, again), views[0])


@pytest.mark.parametrize("state", ["red", "yellow", "green"])
def test_fusion_with_ab_hist_reads_rendered_heads(state):
    image, box = head(state, white_core=True)
    found = tsrkit.classifier("lamp-state", ab_hist_weight=0.5).classify(
        Frame(image, "head"), [Candidate.from_box(box, 1.0)]
    )
    assert found[0].state == state
    assert set(found[0].state_scores) >= {"red", "yellow", "green"}
    assert abs(sum(found[0].state_scores.values()) - 1.0) < 1e-6


def test_two_lit_needs_two_lamps_and_a_red_top():
    # slot centres at rows 6, 18, 30 of 36, averaged over +-2 rows
    lamps = np.full((1, 36), 0.1)
    lamps[0, 4:9], lamps[0, 16:21] = 1.0, 0.8  # top and middle lamps, dark housing between
    glare = np.linspace(1.0, 0.1, 36)[None]  # one lamp's glare fading down the housing
    red, grey = np.full((1, 36), 0.2), np.zeros((1, 36))
    assert two_lit(lamps, red)[0] == pytest.approx((0.8 - 0.1) / (1.0 - 0.1))
    assert two_lit(lamps, grey)[0] == 0.0  # top not red: a backplate or unlit lens
    assert two_lit(glare, red)[0] == 0.0  # no dark gap between the two slots


@pytest.mark.parametrize(
    ("size", "first", "axis"),
    [((12, 36), 9, 1), ((36, 12), 9, 0), ((16, 16), 16, 1), ((12, 36), 12, 1)],
)
@pytest.mark.parametrize(("halve_from", "longest"), [(0, 1280), (2, 600), (4, 600)])
def test_area_resample_equals_opencv_whole_resampling(size, first, axis, halve_from, longest):
    """The wanted rows or columns (a housing's first 9 across, its band and a bit) equal those
    of OpenCV's whole resampling of the crop, bit for bit, at every length of the cut side up to
    ``longest`` (integer and fractional scales, enlarging and shrinking) and other sides short,
    long, even, odd, fractional and integer multiples of the output. Halved (``halve_from``
    > 0), the crop is first halved as ``tests/oracles/lamp_state_oracle.py``'s ``halved`` does
    (trimmed in numpy, averaged by OpenCV)."""
    rng = np.random.default_rng(3 + halve_from)
    image = rng.integers(0, 256, (longest + 1, longest + 1, 3), np.uint8)
    for length in range(1, longest + 1):
        for other in (1, 35, 36, 72, 73, int(rng.integers(37, longest))):
            shape = (length, other) if axis == 0 else (other, length)
            crop = image[: shape[0], : shape[1]]
            source = halved(crop, size, halve_from) if halve_from else crop
            whole = cv2.resize(source, size, interpolation=cv2.INTER_AREA)
            wanted = whole[:first] if axis == 0 else whole[:, :first]
            got = area_resample(crop, size, first, axis, halve_from)
            assert np.array_equal(got, wanted), shape


def test_area_resample_halving_averages_pixel_pairs_and_drops_an_odd_last_one():
    """Hand case: a 73 x 25 crop of 2 x 2 blocks of known colour (row 72 and column 24 white,
    past the last whole block) resampled to 12 x 36, halved first (sides from twice the
    output's): each block is one output cell, its colour exactly; the white rest is dropped,
    not averaged in. Sides under ``halve_from`` times the output's are not halved: the area
    rule alone, as without halving."""
    colours = np.arange(36 * 12 * 3, dtype=np.int64).reshape(36, 12, 3) % 200
    crop = np.full((73, 25, 3), 255, np.uint8)
    crop[:72, :24] = colours.repeat(2, axis=0).repeat(2, axis=1)
    assert np.array_equal(area_resample(crop, (12, 36), 9, 1, halve_from=2), colours[:, :9])
    whole = cv2.resize(crop, (12, 36), interpolation=cv2.INTER_AREA)[:, :9]
    assert np.array_equal(area_resample(crop, (12, 36), 9, 1, halve_from=4), whole)


@pytest.mark.parametrize("factors", [(2, 2), (2, 1), (1, 2)])
def test_opencv_integer_area_resampling_is_the_block_mean(factors):
    """OpenCV's area rule at integer scale factors (``halved``'s second step) gives each
    block's mean rounded to the nearest integer (exact ties go either way)."""
    kx, ky = factors
    crop = np.random.default_rng(kx * ky).integers(0, 256, (ky * 36, kx * 12, 3), np.uint8)
    means = crop.reshape(36, ky, 12, kx, 3).sum(axis=(1, 3)) / (kx * ky)
    got = cv2.resize(crop, (12, 36), interpolation=cv2.INTER_AREA)
    assert np.abs(got - means).max() <= 0.5
