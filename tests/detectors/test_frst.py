"""The fast radial symmetry transform against its loop oracle and on discs of known radius."""

from __future__ import annotations

import numpy as np
import pytest
from oracles.frst_arrays import frst_arrays
from oracles.frst_oracle import frst_oracle

from tsrkit_plugins.detectors.frst.frst import (
    cast_votes,
    frst,
    kappa,
    radial_strength,
    select_voters,
    sobel_gradient,
)


def disc(radius: float, size: int = 41, bright: bool = True) -> np.ndarray:
    """An anti-aliased disc of ``radius`` centred in a ``size`` x ``size`` image."""
    yy, xx = np.mgrid[:size, :size]
    centre = size // 2
    image = np.clip(radius + 0.5 - np.hypot(yy - centre, xx - centre), 0, 1)
    return (image if bright else 1 - image).astype(np.float32)


@pytest.mark.parametrize("mode", ["both", "bright", "dark"])
@pytest.mark.parametrize("orientation_only", [False, True])
@pytest.mark.parametrize("beta", [0.0, 0.25])
def test_fast_matches_oracle_on_random_images(mode, orientation_only, beta):
    rng = np.random.default_rng([len(mode), int(orientation_only), int(beta * 100)])
    image = rng.random((29, 37)).astype(np.float32)
    args = dict(
        radii=range(1, 11), alpha=3.0, beta=beta, mode=mode, orientation_only=orientation_only
    )
    fast = frst(image, **args)
    slow = frst_oracle(image, **args)
    assert np.abs(slow).max() > 0.05
    assert np.abs(fast - slow).max() <= 1e-4


def test_fast_matches_oracle_on_a_blocky_uint8_image():
    rng = np.random.default_rng(7)
    image = np.kron(rng.integers(0, 256, (6, 8)), np.ones((5, 5))).astype(np.uint8)
    fast = frst(image, radii=(1, 2, 4, 6), alpha=2.0)
    slow = frst_oracle(image, radii=(1, 2, 4, 6), alpha=2.0)
    assert np.abs(fast - slow).max() <= 1e-4 * max(1.0, np.abs(slow).max())


@pytest.mark.parametrize("radius", [2, 3, 5, 7])
def test_bright_disc_peaks_at_its_centre_for_its_radius(radius):
    image = disc(radius)
    own = frst(image, radii=[radius], alpha=3.0)
    assert np.unravel_index(np.argmax(own), own.shape) == (20, 20)
    at_centre = [frst(image, radii=[n], alpha=3.0)[20, 20] for n in range(1, 11)]
    assert int(np.argmax(at_centre)) + 1 == radius


def test_bright_disc_gives_a_positive_peak_and_dark_disc_a_negative_one():
    bright = frst(disc(4), alpha=3.0)
    dark = frst(disc(4, bright=False), alpha=3.0)
    assert np.unravel_index(np.argmax(bright), bright.shape) == (20, 20)
    assert bright.max() > 10 * abs(bright.min())
    assert np.unravel_index(np.argmin(dark), dark.shape) == (20, 20)
    assert -dark.min() > 10 * dark.max()


def test_bright_and_dark_modes_keep_one_polarity():
    image = disc(4, bright=False)
    assert frst(image, mode="bright", alpha=3.0).min() >= 0
    dark = frst(image, mode="dark", alpha=3.0)
    assert dark.max() <= 0
    assert np.unravel_index(np.argmin(dark), dark.shape) == (20, 20)


@pytest.mark.parametrize("mode", ["both", "bright", "dark"])
@pytest.mark.parametrize("orientation_only", [False, True])
@pytest.mark.parametrize("beta", [0.0, 0.3])
def test_transform_is_bit_identical_to_the_array_version(mode, orientation_only, beta):
    rng = np.random.default_rng([len(mode), int(orientation_only), int(beta * 10)])
    image = (rng.random((47, 61)) * (rng.random((47, 61)) < 0.6)).astype(np.float32)
    args = dict(radii=(1, 2, 3, 5, 8, 13), alpha=3.0, beta=beta, mode=mode)
    fast = frst(image, orientation_only=orientation_only, **args)
    assert np.abs(fast).max() > 0
    assert np.array_equal(fast, frst_arrays(image, orientation_only=orientation_only, **args))


@pytest.mark.parametrize("shape", [(1, 1), (1, 9), (9, 1), (3, 40), (25, 4)])
def test_images_smaller_than_the_radii_match_the_array_version(shape):
    image = np.random.default_rng(shape).random(shape).astype(np.float32)
    for mode in ("both", "bright", "dark"):
        fast = frst(image, radii=(1, 4, 10), alpha=2.0, mode=mode)
        assert np.array_equal(fast, frst_arrays(image, radii=(1, 4, 10), alpha=2.0, mode=mode))


@pytest.mark.parametrize("sign", [1, -1])
def test_votes_of_voters_hitting_one_pixel_all_count(sign):
    image = disc(5)
    voters = select_voters(*sobel_gradient(image), beta=0.0)
    n, width = 5, image.shape[1]
    span = width + 2 * n
    counts, sums = np.zeros(41 * span, np.int64), np.zeros(41 * span)
    slot_of = np.arange(-n, n + 1) % 41
    centre_row = voters.starts[20], voters.starts[21]
    index = np.empty(width, np.intp)
    args = (voters.row, voters.col, voters.ux, voters.uy, voters.magnitude, *centre_row, n, sign)
    cast_votes(*args, slot_of + 20, span, counts, sums, index)
    # The voters of the centre row sit on the disc's left and right edges, 5 px from the centre,
    # with gradients pointing inwards (bright disc) or outwards: only p+ve lands on the centre.
    centre = 20 * span + 20 + n
    assert counts[centre] == (2 if sign > 0 else 0)
    assert counts.sum() == centre_row[1] - centre_row[0]
    assert sums.sum() == pytest.approx(voters.magnitude[slice(*centre_row)].sum())


def test_orientation_is_clipped_at_kappa():
    magnitude = np.array([2.0, 2.0, 2.0])
    orientation = np.array([9, 10, 40])
    strength = radial_strength(magnitude, orientation, kappa(5), alpha=2.0)
    assert strength[0] == pytest.approx(2.0 / 9.9 * (9 / 9.9) ** 2)
    assert strength[1] == strength[2] == pytest.approx(2.0 / 9.9)
    assert (kappa(1), kappa(2), kappa(10)) == (8.0, 9.9, 9.9)


def test_flat_image_has_no_symmetry():
    assert not frst(np.full((20, 20), 0.3, np.float32)).any()


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(image=np.zeros((5, 5, 3))), "2-D"),
        (dict(radii=[0, 1]), "radii"),
        (dict(alpha=0), "alpha"),
        (dict(beta=1.0), "beta"),
        (dict(mode="grey"), "mode"),
    ],
)
def test_bad_arguments_name_the_problem(kwargs, match):
    args = dict(image=np.zeros((9, 9), np.float32)) | kwargs
    with pytest.raises(ValueError, match=match):
        frst(**args)
