"""A dataset's box margin: the margin-free IoU, learning a margin from training boxes, the
stage's ``margin``."""

import numpy as np
import pytest

from tsrkit.core.types import Annotation, Candidate, Frame, Sample
from tsrkit.plugin.registry import get_registry
from tsrkit.synth.heads import LAMP_COLOURS, background, render_head
from tsrkit_plugins.verifiers.housing.margin import learn_margin, margin_free_iou, widen


def test_widen_grows_every_side_by_a_share_of_the_short_side():
    assert widen(np.array([[0.0, 0.0, 10.0, 20.0]]), 0.1).tolist() == [[-1, -1, 11, 21]]


def test_a_fit_missing_only_the_margin_is_margin_free():
    truth, fit = (0, 0, 10, 20), (2, 2, 8, 18)  # 2 px = 0.2 of the short side on every side
    # plain IoU: 6 x 16 / (10 x 20) = 0.48; shrinking the truth by 0.2 x 10 px matches exactly
    assert margin_free_iou(truth, fit) == pytest.approx(1.0)
    # another housing stays wrong: a box beside the truth
    assert margin_free_iou(truth, (10, 0, 20, 20)) < 0.2


def rendered_set(margin: float) -> list[Sample]:
    """Rendered heads annotated with boxes ``margin`` x their width larger on every side."""
    samples = []
    for k, (lenses, lit) in enumerate([(3, 0), (3, 2), (4, 1), (3, 1)]):
        image = background(240, 320, seed=k)
        head = render_head(image, (160.4, 120.7), 6 + k, lenses, lit, True, LAMP_COLOURS["red"])
        box = widen(np.array([head.housing]), margin)[0]
        samples.append(Sample(f"head{k}", (Annotation(tuple(box), "red"),), image=image))
    return samples


@pytest.mark.parametrize("margin", [0.0, 0.25])
def test_the_margin_of_a_set_is_learned_from_its_boxes(margin):
    assert learn_margin(rendered_set(margin)) == pytest.approx(margin, abs=0.06)


@pytest.mark.parametrize(("margin", "pad"), [(0.25, 0.0), (0.0, 1.0), (0.25, 1.5)])
def test_the_stage_widens_its_housings_by_its_margin_and_pad(margin, pad):
    image = background(200, 300)
    render_head(image, (150, 100), 8)
    lens = [Candidate.from_circle(150, 100, 8, 0.9)]
    stage = get_registry().create
    plain, wide = (
        stage("verifier", "housing", params).verify(Frame(image, "x"), lens)
        for params in ({"margin": 0.0, "pad": 0.0}, {"margin": margin, "pad": pad})
    )
    assert np.allclose(wide[0].housing, widen(np.array([plain[0].housing]), margin, pad)[0])
    assert wide[0].bbox == plain[0].bbox  # the margin widens the housing, not the lens


def test_the_default_pad_is_one_pixel_per_side():
    image = background(200, 300)
    render_head(image, (150, 100), 8)
    lens = [Candidate.from_circle(150, 100, 8, 0.9)]
    stage = get_registry().create
    plain = stage("verifier", "housing", {"pad": 0.0}).verify(Frame(image, "x"), lens)
    default = stage("verifier", "housing").verify(Frame(image, "x"), lens)
    assert np.allclose(np.subtract(default[0].housing, plain[0].housing), [-1, -1, 1, 1])
