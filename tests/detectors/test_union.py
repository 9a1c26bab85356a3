"""The ``union`` detector: members built by the core, rank-normalised scores, duplicate
suppression."""

import cv2
import numpy as np
import pytest

from tsrkit.core.types import WINDOW, Candidate, Frame
from tsrkit.plugin.params import ParamError
from tsrkit.plugin.registry import get_registry
from tsrkit.synth.heads import background, render_head
from tsrkit_plugins.detectors.union import (
    ScaledMember,
    map_back,
    merge,
    rank_scores,
)


def union(members: str):
    return get_registry().create("detector", "union", {"members": members})


def test_members_are_built_with_their_own_parameters():
    built = union("lab-frst top=15; conspicuity n_top=15 ;tl-recognizer")
    assert [(m.detector.name, m.scale, m.top) for m in built.members] == [
        ("lab-frst", 1.0, 1.0),
        ("conspicuity", 1.0, 1.0),
        ("tl-recognizer", 1.0, 1.0),
    ]
    assert built.members[0].detector.params["top"] == 15
    assert built.members[1].detector.params["n_top"] == 15
    assert [str(p) for p in built.params["members"]] == [
        "lab-frst top=15",
        "conspicuity n_top=15",
        "tl-recognizer",
    ]


@pytest.mark.parametrize("text", ["", " ; ", "union", "lab-frst; lab-frst top=3", "lab-frst top"])
def test_bad_members_are_one_clear_error(text):
    with pytest.raises(ParamError):
        union(text)


def test_a_member_parameter_outside_its_schema_is_refused():
    with pytest.raises(ParamError, match="top"):
        get_registry().create("detector", "union", {"members": "lab-frst top=-4"})


def test_rank_scores_put_each_members_best_at_one():
    assert rank_scores(4).tolist() == [1.0, 0.75, 0.5, 0.25]


def test_merge_suppresses_duplicates_and_sums_the_agreeing_members_rank_scores():
    # member A: raw scores in the thousands; member B: in [0, 1]; ranks make them comparable
    a = [Candidate.from_circle(100, 100, 4, 5000.0), Candidate.from_circle(300, 50, 4, 10.0)]
    b = [Candidate.from_circle(102, 101, 5, 0.2), Candidate.from_circle(200, 200, 3, 0.9)]
    merged = merge([a, b], factor=1.0, min_distance=3.0)
    # (100, 100): A's best (1.0) + B's second (0.5), B's duplicate at 2.2 px < 5 px dropped;
    # scores are the mean over the two members
    assert [(c.x, c.y, c.score) for c in merged] == [
        (100, 100, 0.75),
        (200, 200, 0.5),
        (300, 50, 0.25),
    ]
    # the kept candidate keeps its centre and takes the duplicates' largest lens radius
    assert merged[0].radius == 5 and merged[0].bbox == (95.0, 95.0, 105.0, 105.0)


def test_min_distance_merges_radius_less_centres():
    a = [Candidate.from_circle(10, 10, 0.5, 1.0)]
    b = [Candidate.from_circle(12, 12, 0.5, 1.0)]
    assert len(merge([a, b], factor=1.0, min_distance=3.0)) == 1
    assert len(merge([a, b], factor=1.0, min_distance=2.0)) == 2


def test_a_large_blob_swallows_a_nearby_lens_only_when_the_larger_radius_sets_the_reach():
    blob = [Candidate.from_circle(100, 100, 40, 1.0)]  # a bright region, 40 px "radius"
    lens = [Candidate.from_circle(125, 100, 3, 1.0)]  # a lamp 25 px from its centre
    assert len(merge([blob, lens], factor=1.0, min_distance=3.0)) == 1
    assert len(merge([blob, lens], factor=1.0, min_distance=3.0, reach_by="smaller")) == 2


def test_union_finds_what_each_member_finds_on_a_rendered_head():
    image = background(240, 320, seed=3)
    head = render_head(image, (160.0, 120.0), 6, 3, 0)
    frame = Frame(image, "head")
    registry = get_registry()
    union = registry.create(
        "detector", "union", {"members": "lab-frst top=15; conspicuity n_top=15"}
    )
    found = union.detect(frame)
    members = [d.detect(frame) for d in union.members]
    assert len(found) <= sum(len(m) for m in members)
    assert max(c.score for c in found) <= 1.0
    x, y = head.lens[:2]
    for member in members:  # what a member finds near the lit lens, the union finds too
        if any(np.hypot(c.x - x, c.y - y) < 6 for c in member):
            assert any(np.hypot(c.x - x, c.y - y) < 12 for c in found)


def test_a_member_may_come_twice_at_two_scales_but_not_twice_at_one():
    built = union("lab-frst; lab-frst scale=2")
    assert [(m.detector.name, m.scale) for m in built.members] == [
        ("lab-frst", 1.0),
        ("lab-frst", 2.0),
    ]
    with pytest.raises(ParamError, match="same scale"):
        union("lab-frst scale=2; lab-frst top=3 scale=2")


@pytest.mark.parametrize("value", ["scale=0", "scale=9", "scale=two", "scale_top=0"])
def test_a_bad_scale_is_one_clear_error(value):
    with pytest.raises(ParamError, match="scale"):
        union(f"lab-frst {value}")


def test_map_back_uses_the_pixel_centre_convention():
    # at scale 2 the original pixel 0 covers resized pixels 0 and 1: its centre is 0.5 there
    c = map_back(Candidate.from_circle(0.5, 20.5, 3.0, 1.0), 2.0, 2.0)
    assert (c.x, c.y, c.radius) == (0.0, 10.0, 1.5)
    assert c.bbox == (-1.5, 8.5, 1.5, 11.5)  # (b + 0.5) / 2 - 0.5 per edge of (-2.5, 17.5, ...)


class Centroid:
    """A stand-in member: one candidate at the brightness-weighted centroid of the frame."""

    def detect(self, frame):
        weight = frame.image.astype(float).sum(axis=2)
        rows, cols = np.indices(weight.shape)
        x, y = (cols * weight).sum() / weight.sum(), (rows * weight).sum() / weight.sum()
        return [Candidate.from_circle(x, y, 1.0, 1.0)]


@pytest.mark.parametrize("scale, tol", [(2.0, 1e-6), (3.0, 1e-6), (1.5, 2e-3)])
def test_an_upscaled_members_centres_map_back_exactly(scale, tol):
    # a 2 px lamp drawn with sub-pixel precision on black: bilinear resizing by a whole factor
    # keeps its brightness-weighted centroid, so the mapped-back centre equals the original
    # one (a fractional factor's interpolation weights move it by about 1e-3 px)
    image = np.zeros((60, 80, 3), np.uint8)
    render_head(image, (40.3, 20.6), 2, 3, 0)
    frame = Frame(image.astype(np.float32), "lamp")  # float: no rounding after resizing
    (expected,) = Centroid().detect(frame)
    (found,) = ScaledMember(Centroid(), scale, 1.0).detect(frame)
    assert found.x == pytest.approx(expected.x, abs=tol)
    assert found.y == pytest.approx(expected.y, abs=tol)
    assert found.radius == pytest.approx(1.0 / scale)


def test_scale_top_searches_only_the_upper_rows():
    image = np.zeros((100, 80, 3), np.uint8)
    image[70:74, 30:34] = 255  # a lamp at rows 70-73, below the upper 60 rows
    image[10:14, 50:54] = 255  # and one at rows 10-13
    (found,) = ScaledMember(Centroid(), 2.0, 0.6).detect(Frame(image, "two lamps"))
    assert (found.x, found.y) == pytest.approx((51.5, 11.5))


def test_a_window_of_a_frame_keeps_the_frames_band():
    """On a window (what key-frame following searches) the band is the whole frame's rows,
    not the window's: a window holding the band's last rows searches them, one below finds
    nothing."""
    image = np.zeros((100, 80, 3), np.uint8)
    image[54:58, 30:34] = 255  # a lamp at rows 54-57, inside the frame's upper 60 rows
    member = ScaledMember(Centroid(), 1.0, 0.6)
    window = Frame(image[40:80], "w", metadata={WINDOW: (0, 40, 80, 100)})
    (found,) = member.detect(window)  # rows 54-57 are in the window's lower half
    assert (found.x, found.y) == pytest.approx((31.5, 15.5))
    below = Frame(image[60:100], "w", metadata={WINDOW: (0, 60, 80, 100)})
    assert member.detect(below) == []


def test_an_upscaled_member_finds_a_small_lamp_its_full_scale_twin_misses():
    image = background(240, 320, seed=3)
    head = render_head(image, (160.3, 80.6), 2, 3, 0)  # lens radius 2 px
    frame = Frame(image, "small head")
    x, y = head.lens[:2]

    def nearest(members):
        found = get_registry().create("detector", "union", {"members": members}).detect(frame)
        return min(np.hypot(c.x - x, c.y - y) for c in found)

    assert nearest("conspicuity n_top=15") > 5
    assert nearest("conspicuity n_top=15 scale=2") < 1


def test_members_at_one_band_and_scale_share_one_frame_and_its_colour_views():
    """The union makes each band and size once: members there get the same frame object, and
    a band reads the whole frame's colour views; each member's candidates are those it finds
    on its own."""
    members = (
        "lab-frst top=15; lab-blob scale_top=0.6; tl-recognizer scale_top=0.6; "
        "lab-blob scale=0.5; lab-frst top=15 scale=0.5"
    )
    union = get_registry().create("detector", "union", {"members": members})
    image = background(240, 320, seed=2)
    render_head(image, (160.0, 90.0), 6, 3, 0)
    frame = Frame(image, "head")
    shared: dict = {}
    views = [m.view(frame, shared) for m in union.members]
    assert views[0] is frame and views[1] is views[2] and views[3] is views[4]
    assert views[1].height == 144 and views[3].width == 160
    assert views[1].views._parent is frame.views and views[3].views is not frame.views
    alone = [m.detect(frame) for m in union.members]
    assert alone == [m.detect(frame, shared) for m in union.members]
    assert union.detect(frame) == merge(alone, 1.0, 3.0)


def merged_by_loop(lists, factor, min_distance, reach_by):
    """The merging rule candidate by candidate against each kept one, in Python floats."""
    pick = max if reach_by == "larger" else min
    pool = []
    for member, candidates in enumerate(lists):
        ordered = sorted(candidates, key=lambda c: -c.score)
        pool += [(1.0 - k / len(ordered), member, c) for k, c in enumerate(ordered)]
    pool.sort(key=lambda item: (-item[0], item[1]))
    kept = []
    for score, member, c in pool:
        for other, votes, radii in kept:
            if np.hypot(c.x - other.x, c.y - other.y) <= max(
                factor * pick(c.radius, other.radius), min_distance
            ):
                votes.setdefault(member, score)
                radii.append(c.radius)
                break
        else:
            kept.append((c, {member: score}, [c.radius]))
    return [(c.x, c.y, max(r), sum(v.values()) / len(lists)) for c, v, r in kept]


@pytest.mark.parametrize("reach_by", ["larger", "smaller"])
def test_merge_keeps_what_the_candidate_by_candidate_rule_keeps(reach_by):
    rng = np.random.default_rng(len(reach_by))
    for _ in range(100):
        lists = [
            [
                Candidate.from_circle(
                    *rng.uniform(0, 150, 2), rng.choice([0.5, 2, 6]), rng.random()
                )
                for _ in range(rng.integers(0, 25))
            ]
            for _ in range(4)
        ]
        found = [(c.x, c.y, c.radius, c.score) for c in merge(lists, 1.0, 3.0, reach_by)]
        expected = merged_by_loop(lists, 1.0, 3.0, reach_by)
        assert sorted(found, key=lambda t: (-t[3], t[0], t[1])) == sorted(
            expected, key=lambda t: (-t[3], t[0], t[1])
        )


def test_members_on_one_frame_and_its_band_convert_it_to_lab_once(monkeypatch):
    """lab-frst and lab-blob on the whole frame and lab-blob on its upper band: one CIELab
    conversion and one L*(a+b) map for the three (the band slices the frame's); a member at
    another size converts its own frame once."""
    conversions = []
    convert = cv2.cvtColor

    def counted(image, code, *args):
        conversions.append((code, image.shape[:2]))
        return convert(image, code, *args)

    monkeypatch.setattr(cv2, "cvtColor", counted)
    image = background(240, 320, seed=5)
    render_head(image, (100.0, 60.0), 3, 3, 0)
    members = "lab-frst top=15; lab-blob; lab-blob levels=3 scale_top=0.6; lab-frst scale=0.5"
    union(members).detect(Frame(image, "head"))
    assert conversions == [(cv2.COLOR_BGR2Lab, (240, 320)), (cv2.COLOR_BGR2Lab, (120, 160))]
