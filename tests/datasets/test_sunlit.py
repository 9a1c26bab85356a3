"""The Sun-lit scene renderer: Planck's law (Lee 2017, Eq. 4.7), consistent metadata, and the
physics the Sun-compensated model depends on."""

from __future__ import annotations

import numpy as np
import pytest

from tsrkit.sun.radiance import blackbody_bgr, planck
from tsrkit.sun.relative import sun_view
from tsrkit.synth.sunlit import illumination, render_frame, sweep


def test_planck_peaks_where_wien_says_and_daylight_is_white_balanced():
    wavelengths = np.linspace(300e-9, 1200e-9, 9001)
    for temperature in (3000.0, 5800.0):
        peak = wavelengths[np.argmax(planck(wavelengths, temperature))]
        assert peak == pytest.approx(2.897771955e-3 / temperature, rel=1e-3)
    assert blackbody_bgr(5500.0) == pytest.approx([1.0, 1.0, 1.0])
    warm, cold = blackbody_bgr(3000.0), blackbody_bgr(12000.0)
    assert warm[2] > 1.0 > warm[0] and cold[0] > 1.0 > cold[2]  # red-ish, blue-ish


def test_metadata_gives_back_the_rendered_relative_azimuth():
    data = sweep([0.0, 45.0, 170.0], frames_each=2, seed=3)
    for sample in data:
        view = sun_view(sample.metadata)
        assert view.relative_azimuth == pytest.approx(
            sample.metadata["relative_azimuth_deg_true"], abs=0.01
        )
        assert view.sun_elevation == pytest.approx(sample.metadata["sun_elevation_deg"], abs=1e-6)
        assert view.sun_elevation >= 5.0


def test_rendering_is_deterministic():
    a = sweep([30.0], frames_each=2, seed=5)
    b = sweep([30.0], frames_each=2, seed=5)
    assert all(np.array_equal(x.image, y.image) for x, y in zip(a, b))
    assert [x.annotations for x in a] == [y.annotations for y in b]


def sign_colour(light, seed: int) -> np.ndarray:
    """Median BGR of the orange faces of one rendered frame."""
    image, annotations = render_frame(np.random.default_rng(seed), light)
    found = []
    for a in annotations:
        if a.state == "orange":
            x0, y0, x1, y1 = (int(v) for v in a.bbox)
            cx, cy, r = (x0 + x1) // 2, (y0 + y1) // 2, max((x1 - x0) // 6, 1)
            found.append(image[cy - r : cy + r, cx + r : cx + 2 * r].reshape(-1, 3))
    return np.median(np.concatenate(found), axis=0) if found else None


def test_direct_sun_saturates_red_and_shade_is_dark_and_blue():
    lit = next(c for s in range(20) if (c := sign_colour(illumination(20.0, 0.0), s)) is not None)
    shade = next(
        c for s in range(20) if (c := sign_colour(illumination(20.0, 150.0), s)) is not None
    )
    assert lit[2] >= 250  # Lee's Figure 4.7: the red channel saturates under the Sun
    assert shade[2] < 200 and shade[2] < lit[2] - 60
    assert shade[0] / shade[2] > lit[0] / lit[2]  # sky light is bluer


def lenses_of(annotation) -> list[tuple[float, float, float]]:
    """Centres and radius of the three lenses of a rendered head (top to bottom)."""
    x0, y0, x1, y1 = annotation.attributes["housing"]
    pitch = (y1 - y0) / 3
    return [((x0 + x1) / 2, y0 + (k + 0.5) * pitch, pitch / 2.8) for k in range(3)]


def disc_mean(image: np.ndarray, x: float, y: float, r: float) -> np.ndarray:
    yy, xx = np.mgrid[: image.shape[0], : image.shape[1]]
    return image[(xx + 0.5 - x) ** 2 + (yy + 0.5 - y) ** 2 <= (0.7 * r) ** 2].mean(axis=0)


def test_lit_lamp_clips_at_its_core_and_unlit_lenses_glow_only_with_the_sun_behind():
    states = ["light_red", "light_yellow", "light_green"]
    behind, _ = render_frame(np.random.default_rng(8), illumination(30.0, 0.0), lights=3)
    ahead, annotations = render_frame(np.random.default_rng(8), illumination(30.0, 170.0), lights=3)
    heads = [a for a in annotations if a.state in states]
    assert len(heads) == 3
    glow = []
    for head in heads:
        lit = states.index(head.state)
        (lx, ly, lr) = lenses_of(head)[lit]
        box = head.bbox
        assert box == pytest.approx((lx - lr, ly - lr, lx + lr, ly + lr), abs=1e-6)
        core = ahead[int(ly), int(lx)]
        assert core.max() == 255  # the emitting lamp clips, Sun or not
        for k, (x, y, r) in enumerate(lenses_of(head)):
            if k != lit:
                glow.append(disc_mean(behind, x, y, r).sum() - disc_mean(ahead, x, y, r).sum())
    assert min(glow) > 30  # retro-reflected sunlight: the phantom lamps of Lee 4.1.2


def test_channelizers_are_striped_orange_and_white_panels_of_the_standard_shape():
    image, annotations = render_frame(
        np.random.default_rng(2), illumination(40.0, 30.0), channelizers=3
    )
    panels = [a for a in annotations if a.state == "channelizer"]
    assert len(panels) == 3
    for panel in panels:
        x0, y0, x1, y1 = panel.bbox
        assert (y1 - y0) / (x1 - x0) == pytest.approx(2.4)
    big = max(panels, key=lambda a: a.bbox[3] - a.bbox[1])
    x0, y0, x1, y1 = (int(round(v)) for v in big.bbox)
    patch = image[y0 + 1 : y1 - 1, x0 + 1 : x1 - 1].reshape(-1, 3).astype(int)
    orange = (patch[:, 2] - patch[:, 0]) > 80
    white = np.abs(patch[:, 2] - patch[:, 0]) < 40
    assert 0.25 < orange.mean() < 0.75 and white.mean() > 0.2


def test_scene_objects_are_drawn_after_the_signs():
    plain = render_frame(np.random.default_rng(4), illumination(40.0, 30.0))[1]
    more = render_frame(
        np.random.default_rng(4), illumination(40.0, 30.0), lights=2, channelizers=2
    )[1]
    assert more[: len(plain)] == plain and len(more) == len(plain) + 4
