"""Zheng 5.2.1 per-frame recall/precision and the Table 5-2 breakdown on hand-built frames."""

import pytest

from tsrkit.eval.categories import category_table, precision_bound, radius_label, recall_label
from tsrkit.eval.perframe import FrameScore, max_target_radius, score_frame, summarise

BOXES = [(0, 0, 10, 10), (20, 0, 30, 10), (40, 0, 50, 10), (60, 0, 70, 10)]


def test_four_signals_two_found_three_candidates():
    # Candidates: two inside box 0's circle, one inside box 2's, one nowhere.
    score = score_frame([(5, 5), (6, 4), (45, 5), (100, 100)], BOXES)
    # Recall: boxes 0 and 2 hit of 4 -> 2/4. Precision: 3 of 4 candidates inside a circle.
    assert (score.gt_hit, score.n_gt, score.det_tp, score.n_det) == (2, 4, 3, 4)
    assert score.recall == 0.5 and score.precision == 0.75
    assert recall_label(score) == "2/4"
    assert precision_bound(score) == 75


def test_labels_zero_full_and_empty():
    assert recall_label(score_frame([], BOXES[:3])) == "0"
    assert recall_label(score_frame([(5, 5), (25, 5), (45, 5)], BOXES[:3])) == "1"
    missed = score_frame([], BOXES[:1])
    assert missed.precision is None and precision_bound(missed) == 0


def test_precision_lower_bound_of_one_third_is_30_percent():
    assert precision_bound(FrameScore(3, 3, 1, 1)) == 30
    assert precision_bound(FrameScore(1, 1, 1, 1)) == 100


def test_max_target_radius_uses_half_the_shorter_side_rounded():
    assert max_target_radius([(0, 0, 5, 9), (0, 0, 3, 3)]) == 3  # 2.5 rounds half up
    assert max_target_radius([]) == 0


def test_summary_follows_design_definitions():
    frames = [
        score_frame([(5, 5)], BOXES[:2]),  # recall 1/2, precision 1
        score_frame([(5, 5), (200, 200)], BOXES[:1]),  # recall 1, precision 1/2
        score_frame([], BOXES[:1]),  # recall 0, no candidates
        score_frame([(1, 1), (2, 2)], []),  # no ground truth: 2 false positives
        score_frame([], []),  # empty frame
    ]
    summary = summarise(frames)
    assert summary["recall_mean"] == pytest.approx((0.5 + 1 + 0) / 3)
    assert summary["precision_mean"] == pytest.approx((1 + 0.5) / 2)
    assert summary["hit_frame_fraction"] == pytest.approx(2 / 3)
    assert summary["frames_without_gt"] == 2
    assert summary["false_positives_without_gt"] == 2
    assert summary["frames_without_gt_with_detections"] == 1


def test_category_table_groups_by_lighting_then_radius():
    frames = [
        score_frame([(5, 5)], [(0, 0, 10, 10)], "low"),  # radius 5, recall 1
        score_frame([], [(0, 0, 4, 4)], "low"),  # radius 2, recall 0
        score_frame([(5, 5), (90, 90)], [(0, 0, 10, 10)], "high"),  # radius 5, prec 1/2
        score_frame([(1, 1)], [], "high"),
    ]  # no GT: not a row
    rows = category_table(frames)
    keys = [(r["lighting"], r["max_radius"], r["frames"]) for r in rows]
    assert keys == [
        ("high", None, 1),
        ("high", 5, 1),
        ("low", None, 2),
        ("low", 2, 1),
        ("low", 5, 1),
    ]
    low = rows[2]
    assert low["recall_counts"] == {"0": 1, "1": 1}
    assert low["precision_counts"] == {"0%": 1, "100%": 1}
    assert low["bubbles"] == [
        {"recall": 0.0, "fpr": 1.0, "frames": 1},
        {"recall": 1.0, "fpr": 0.0, "frames": 1},
    ]
    assert rows[1]["bubbles"] == [{"recall": 1.0, "fpr": 0.5, "frames": 1}]


def test_large_radii_share_bins_so_full_resolution_sets_give_a_handful_of_rows():
    # boxes of side 2r: radii 3, 9 keep their own rows (Table 5-2), 10-13 share one, 80 is >= 70
    frames = [score_frame([], [(0, 0, 2 * r, 2 * r)], "day") for r in (3, 9, 10, 12, 13, 80)]
    rows = category_table(frames)
    assert [(r["max_radius"], r["frames"]) for r in rows] == [
        (None, 6),
        (3, 1),
        (9, 1),
        (10, 3),
        (70, 1),
    ]
    assert [radius_label(r["max_radius"]) for r in rows[1:]] == ["3", "9", "10-13", ">=70"]


def test_bubble_figure_stays_compact_whatever_the_radii(tmp_path):
    from PIL import Image

    from tsrkit.eval.categories import CategoriesResult

    frames = [
        score_frame([(r, r)], [(0, 0, 2 * r, 2 * r)], light)
        for r in range(2, 120)
        for light in ("day", "dusk", "night")
    ]
    plots = CategoriesResult({"categories": category_table(frames)}).plots()
    (bubbles,) = [p for p in plots if p.name == "recall_fpr_bubbles.png"]
    (tmp_path / "b.png").write_bytes(bubbles.png())
    width, height = Image.open(tmp_path / "b.png").size
    # 15 radius bins x 3 lightings: one axes, not 354 panels (the old layout: 1320 x 29000 px)
    assert width <= 1800 and height <= 500
