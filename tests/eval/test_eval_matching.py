"""Zheng's centre-in-enclosing-circle rule and IoU matching on hand-worked boxes."""

import numpy as np
import pytest

from tsrkit.core.geometry import enclosing_circles, iou_matrix
from tsrkit.eval.matching import centre_hits, greedy_match
from tsrkit.eval.overlap import score_overlap, summarise_overlap


def test_enclosing_circle_of_a_3_4_5_box():
    centres, radii = enclosing_circles([(0, 0, 6, 8), (10, 10, 12, 12)])
    assert centres.tolist() == [[3, 4], [11, 11]]
    assert radii.tolist() == pytest.approx([5.0, np.sqrt(2)])


def test_centre_hits_circle_not_box():
    # A 10x10 box at the origin has circle radius 7.07 around (5, 5): the corner-adjacent
    # point (10.5, 5) lies outside the box but inside the circle; (5, 12.2) lies outside both.
    hits = centre_hits([(10.5, 5), (5, 12.2), (5, 5)], [(0, 0, 10, 10)])
    assert hits[:, 0].tolist() == [True, False, True]


def test_centre_hits_empty_inputs_have_right_shape():
    assert centre_hits([], [(0, 0, 1, 1)]).shape == (0, 1)
    assert centre_hits([(1, 1)], []).shape == (1, 0)


def test_iou_worked_example():
    # Overlap 1x2 = 2, union 4 + 4 - 2 = 6.
    assert iou_matrix([(0, 0, 2, 2)], [(1, 0, 3, 2)])[0, 0] == pytest.approx(1 / 3)


def test_inverted_box_is_rejected():
    with pytest.raises(ValueError, match="x_min <= x_max"):
        iou_matrix([(2, 0, 0, 2)], [(0, 0, 1, 1)])


def test_greedy_match_takes_best_score_first_and_each_box_once():
    iou = np.array([[0.6, 0.0], [0.9, 0.55]])
    # Detection 1 (score 0.9) claims box 0; detection 0 then has nothing left above 0.5.
    assert greedy_match([0.1, 0.9], iou, 0.5) == [(1, 0)]
    assert greedy_match([0.9, 0.1], iou, 0.5) == [(0, 0), (1, 1)]


def test_lee_threshold_is_strict():
    assert greedy_match([1.0], np.array([[0.5]]), 0.5) == []
    assert greedy_match([1.0], np.array([[0.5]]), 0.5, strict=False) == [(0, 0)]


def test_overlap_precision_recall_and_area_ratios():
    # Detection (0,0,4,2) on ground truth (0,0,2,2): IoU 0.5 fails at 0.5, passes at 0.4;
    # then area precision = 4/8 and area recall = 4/4.
    frame = score_overlap([(0, 0, 4, 2), (50, 50, 52, 52)], [0.9, 0.8], [(0, 0, 2, 2)], 0.4)
    summary = summarise_overlap([frame], 0.4)
    assert summary["precision"] == 0.5 and summary["recall"] == 1.0
    assert summary["area_precision"] == pytest.approx(0.5)
    assert summary["area_recall"] == pytest.approx(1.0)
    assert (
        summarise_overlap([score_overlap([(0, 0, 4, 2)], [1], [(0, 0, 2, 2)], 0.5)], 0.5)["recall"]
        == 0.0
    )
