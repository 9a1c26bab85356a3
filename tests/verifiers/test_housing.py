"""The housing stage: fits on rendered heads of known geometry, every layout; plugin behaviour."""

import cv2
import numpy as np
import pytest

import tsrkit
from tsrkit.core.geometry import iou_matrix
from tsrkit.core.types import Candidate, Frame
from tsrkit.plugin.pipeline import Pipeline
from tsrkit.plugin.registry import get_registry
from tsrkit.synth.heads import LAMP_COLOURS, background, render_head
from tsrkit_plugins.verifiers.housing.fit import fit_housings

LAYOUTS = [(v, n, lit) for v in (True, False) for n in (3, 4) for lit in range(n)]


def fit_iou(vertical, lenses, lit, radius, given):
    """IoU of the fit with a rendered head's housing, the detector's radius being ``given``."""
    image = background(300, 420, seed=lenses * 10 + lit)
    colour = list(LAMP_COLOURS.values())[lit % 3]
    head = render_head(image, (210.3, 150.6), radius, lenses, lit, vertical, colour, lit == 1)
    gray = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    boxes, scores, _ = fit_housings(gray, [(*head.lens[:2], given)])
    assert scores[0] > 0.5
    return iou_matrix([head.housing], boxes)[0, 0]


@pytest.mark.parametrize("vertical,lenses,lit", LAYOUTS)
@pytest.mark.parametrize("radius", [5, 8, 13])
def test_fit_recovers_rendered_heads_of_every_layout(vertical, lenses, lit, radius):
    assert fit_iou(vertical, lenses, lit, radius, radius) >= 0.8


def test_fit_without_a_lens_radius_searches_the_scale():
    # FRST-like detectors give a centre only: the radius ladder finds the scale; 40 of 42
    # rendered heads fit with IoU >= 0.8 (two 4-lens heads are taken for shorter ones)
    ious = [fit_iou(*layout, radius, 0.5) for layout in LAYOUTS for radius in (5, 8, 13)]
    assert np.mean(np.array(ious) >= 0.8) >= 0.9


def test_stage_adds_the_housing_and_drops_duplicates():
    image = background(200, 300)
    head = render_head(image, (150, 100), 8)
    lens = Candidate.from_circle(150, 100, 8, 0.9)
    twin = Candidate.from_circle(151, 101, 7, 0.5)  # the same light found twice
    sky = Candidate.from_circle(40, 20, 6, 0.7)
    stage = get_registry().create("verifier", "housing")
    out = stage.verify(Frame(image, "x"), [twin, sky, lens])
    assert [c.score for c in out] == [0.9, 0.7]
    weigh = get_registry().create("verifier", "housing", {"rescore": True})
    weighed = weigh.verify(Frame(image, "x"), [lens, sky])
    assert [c.score for c in weighed] == [c.score * c.housing_score for c in out]  # x fit
    best = out[0]
    assert (best.x, best.y, best.radius, best.score) == (lens.x, lens.y, lens.radius, lens.score)
    assert iou_matrix([head.housing], [best.housing])[0, 0] >= 0.8
    assert best.housing_score > out[1].housing_score
    strict = get_registry().create("verifier", "housing", {"min_score": 0.5})
    assert [c.score for c in strict.verify(Frame(image, "x"), [lens, sky])] == [0.9]


@pytest.mark.parametrize("given", [3.0, 8.0, 40.0])
def test_the_lens_box_becomes_the_lens_the_housing_was_fitted_around(given):
    # a detector's lens may be a blob five times the lamp (union's largest radius) or a point
    # (FRST): the candidate keeps its circle, and its lens box becomes the lit lens measured
    # for the fit, inside its housing
    image = background(200, 300)
    render_head(image, (150, 100), 8)
    stage = get_registry().create("verifier", "housing")
    (out,) = stage.verify(Frame(image, "x"), [Candidate.from_circle(151, 99, given, 0.9)])
    assert (out.x, out.y, out.radius) == (151.0, 99.0, given)
    x0, y0, x1, y1 = out.lens_bbox
    assert np.hypot((x0 + x1) / 2 - 150, (y0 + y1) / 2 - 100) <= 0.3 * 8  # grid: s / 2
    assert 6.0 <= (x1 - x0) / 2 <= 10.5 and x1 - x0 == pytest.approx(y1 - y0)
    hx0, hy0, hx1, hy1 = out.housing
    assert hx0 <= x0 and hy0 <= y0 and x1 <= hx1 and y1 <= hy1


def test_records_report_the_housing_as_bbox(tmp_path):
    image = background(200, 300)
    render_head(image, (150, 100), 8)
    path = tmp_path / "head.png"
    cv2.imwrite(str(path), image)
    pipeline = Pipeline(tsrkit.detector("conspicuity"), verifier=tsrkit.verifier("housing"))
    record = pipeline.process(Frame(cv2.imread(str(path)), str(path))).to_record()
    found = [d for d in record["detections"] if d["bbox"] != d["lens_bbox"]]
    assert found, "the housing stage set no housing"
    x0, y0, x1, y1 = found[0]["bbox"]
    assert (x1 - x0) < (y1 - y0)  # a vertical head


def test_scattered_heads_are_deterministic_and_boxed_in_the_frame():
    from tsrkit.synth.heads import scatter_heads

    images = [background(360, 640, seed=1) for _ in range(2)]
    boxes = [scatter_heads(im, np.random.default_rng(9)) for im in images]
    assert boxes[0] == boxes[1] and np.array_equal(images[0], images[1])
    assert len(boxes[0]) == 5
    for x0, y0, x1, y1 in boxes[0]:
        # 3-4 lenses of radius 2-12 px, 2.8 radii per cell, centred in the upper 55 %
        assert 5.6 <= min(x1 - x0, y1 - y0) <= 33.6 + 1e-9
        assert 0 <= (y0 + y1) / 2 <= 360 and 0 <= (x0 + x1) / 2 <= 640


def test_every_fitted_housing_holds_its_lens():
    rng = np.random.default_rng(5)
    gray = cv2.GaussianBlur(rng.integers(0, 256, (240, 320), dtype=np.uint8), (0, 0), 3)
    lenses = [(float(x), float(y), float(r)) for x, y, r in zip(
        rng.uniform(20, 300, 200), rng.uniform(20, 220, 200), rng.uniform(1, 12, 200)
    )]  # fmt: skip
    boxes, _, used = fit_housings(gray, lenses)
    x, y, radii = used.T  # the lens each fit measured and used
    assert np.all(boxes[:, 0] <= x - radii) and np.all(boxes[:, 2] >= x + radii)
    assert np.all(boxes[:, 1] <= y - radii) and np.all(boxes[:, 3] >= y + radii)
    cx, cy, _ = np.array(lenses).T  # and the candidate's own centre
    assert np.all((boxes[:, 0] <= cx) & (cx <= boxes[:, 2]))
    assert np.all((boxes[:, 1] <= cy) & (cy <= boxes[:, 3]))


@pytest.mark.parametrize(
    "frame,lens,box",
    [
        ("im1.jpg", (340.0, 184.0, 1.0), (328.0, 183.0, 358.0, 194.0)),
        ("im11.jpg", (162.0, 238.0, 1.5), (159.0, 235.0, 172.0, 241.0)),
    ],
)
def test_a_distant_lamp_keeps_a_housing_of_its_size(shared_datasets, frame, lens, box):
    # union candidates on distant Japanese heads (800x600): a point (radius 1-1.5 px) on the
    # lamp; the fit once took the ladder's 53-75 px steps for it (a housing 20x too large)
    image = cv2.imread(str(shared_datasets / "iwai_japan_tl" / "images" / frame))
    fitted, _, used = fit_housings(cv2.cvtColor(image, cv2.COLOR_BGR2GRAY), [lens])
    x0, y0, x1, y1 = fitted[0]
    assert used[0, 2] <= 16
    assert max(x1 - x0, y1 - y0) <= 3 * (box[2] - box[0])
