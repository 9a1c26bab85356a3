"""Training on data that cannot train a model is one line and exit status 2, never a traceback."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest
from click.testing import CliRunner

from tsrkit.cli.main import cli


@pytest.fixture
def yellow_only(tmp_path):
    """A one-frame dataset whose only light is yellow: no red, no green, one class."""
    image = np.full((120, 160, 3), 60, np.uint8)
    cv2.circle(image, (80, 60), 6, (20, 180, 250), -1)
    cv2.imwrite(str(tmp_path / "a.png"), image)
    box = {"label": "yellow", "x_min": 74, "y_min": 54, "x_max": 86, "y_max": 66}
    entry = {"file": "a.png", "split": "train", "width": 160, "height": 120, "boxes": [box]}
    (tmp_path / "annotations.json").write_text(json.dumps([entry]))
    return tmp_path


@pytest.mark.parametrize(
    ("plugin", "message"),
    [
        ("ab-hist", "ab-hist: no training samples for red, green"),
        ("hsi-backprojection", "hsi-backprojection: no training samples for red, green"),
        ("sun-pca", "sun-pca: target 'orange'"),
        ("logpolar-svm", "logpolar-svm needs two classes"),
    ],
)
def test_training_without_the_classes_a_model_needs_is_one_line(yellow_only, plugin, message):
    result = CliRunner().invoke(
        cli, ["train", plugin, "--dataset", str(yellow_only), "--out", str(yellow_only / "m")]
    )
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert "Traceback" not in result.output and not isinstance(result.exception, ValueError)
