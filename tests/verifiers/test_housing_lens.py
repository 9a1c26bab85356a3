"""The lit-lens measurement before the housing fit: rendered heads of known lens, no lens."""

import cv2
import numpy as np
import pytest

from tsrkit.synth.heads import LAMP_COLOURS, background, render_head
from tsrkit_plugins.verifiers.housing.boxes import box_sums, integral
from tsrkit_plugins.verifiers.housing.lens import measure_lenses


def test_box_sums_are_clipped_pixel_sums():
    gray = np.arange(12, dtype=np.uint8).reshape(3, 4)
    boxes = np.array([[0, 0, 4, 3], [1, 1, 3, 2], [-5, -5, 1.4, 1.6], [3, 2, 2, 1]], float)
    total, count = box_sums(integral(gray), boxes)
    # all; row 1, columns 1-2 (5 + 6); the clipped top-left pixel (0, rounded to 1 x 2: 0 + 4);
    # a box whose ends cross is empty
    assert total.tolist() == [66, 11, 4, 0] and count.tolist() == [12, 2, 2, 0]


def numpy_box_sums(table, boxes):
    """The NumPy definition the compiled pass replaced: round half to even, clip, gather."""
    height, width = table.shape[0] - 1, table.shape[1] - 1
    corners = np.clip(np.rint(boxes), 0.0, [width, height, width, height]).astype(np.intp)
    x0, y0, x1, y1 = (corners[..., k] for k in range(4))
    x1, y1 = np.maximum(x1, x0), np.maximum(y1, y0)
    total = table[y1, x1] - table[y0, x1] - table[y1, x0] + table[y0, x0]
    return total, ((x1 - x0) * (y1 - y0)).astype(np.float64)


def test_box_sums_equal_the_numpy_definition_at_ties_edges_and_any_shape():
    rng = np.random.default_rng(3)
    table = integral(rng.integers(0, 256, (37, 53), dtype=np.uint8))
    # corners on half-pixels (ties round to even), far outside the frame, crossing
    boxes = rng.integers(-40, 120, (6, 5, 7, 4)) / 2.0
    boxes[0, 0, 0] = (0.5, 1.5, 2.5, 36.5)
    total, count = box_sums(table, boxes)
    want_total, want_count = numpy_box_sums(table, boxes)
    assert total.dtype == np.int32 and count.dtype == np.float64 and total.shape == (6, 5, 7)
    assert np.array_equal(total, want_total) and np.array_equal(count, want_count)
    assert count[0, 0, 0] == (2 - 0) * (36 - 2)  # rint: 0.5 -> 0, 1.5 -> 2, 2.5 -> 2, 36.5 -> 36
    # NaN and infinite corners stay inside the table: NaN and -inf at 0, +inf at the far edge
    odd = box_sums(table, np.array([[np.nan, 0, 4, 4], [-np.inf, 0, np.inf, 2], [3, 3, np.nan, 9]]))
    assert odd[0].tolist() == [table[4, 4], table[2, 53], 0] and odd[1].tolist() == [16, 106, 0]
    empty_total, empty_count = box_sums(table, np.zeros((0, 4)))
    assert empty_total.shape == empty_count.shape == (0,)


@pytest.mark.parametrize("radius", [3, 5, 8, 13])
@pytest.mark.parametrize("colour", ["red", "yellow", "green"])
def test_the_lit_lens_is_found_from_a_wrong_radius_and_an_off_centre_start(radius, colour):
    image = background(300, 420, seed=radius)
    render_head(image, (210.3, 150.6), radius, 3, 1, True, LAMP_COLOURS[colour])
    table = integral(cv2.cvtColor(image, cv2.COLOR_BGR2GRAY))
    for start in (0.5, 3.0 * radius):  # a centre-only detector, a large merged blob
        x, y, r, found = measure_lenses(
            table, np.array([210.3 + 0.4 * radius]), np.array([150.6]), np.array([start])
        )
        assert found[0]
        assert np.hypot(x[0] - 210.3, y[0] - 150.6) <= 0.5 * radius
        assert 0.6 * radius <= r[0] <= 1.4 * radius


def test_no_lit_lens_keeps_the_candidates_own():
    table = integral(np.full((100, 100), 120, np.uint8))
    x, y, r, found = measure_lenses(table, np.array([50.0]), np.array([40.0]), np.array([7.0]))
    assert not found[0] and (x[0], y[0], r[0]) == (50.0, 40.0, 7.0)
