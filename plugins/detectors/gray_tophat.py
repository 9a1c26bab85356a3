"""GRAY-TOPHAT baseline (de Charette & Nashashibi, as Zheng 2016 5.2.2 implemented it).

The white top-hat (image minus its morphological opening) of the grayscale frame highlights
small bright spots; Zheng's localization (3.2.2, ``localization.py``) then extracts candidates
from it exactly as from a conspicuity map. The top-hat has no radius map, so each component's
DRMShift window keeps the radius of the disk with the component's area.

Structuring element. Zheng (5.2.2) gives no size; de Charette & Nashashibi, whom he follows,
used 11x11. The opening removes bright spots narrower than the element, so the top-hat keeps
only lenses up to about ``se_size`` across: 11 px loses Zheng's largest lenses (radius 9, 19 px
across), 21 px keeps them. Measured (``tsrkit benchmark -d gray-tophat -p se_size=N``, per-frame
recall / precision / hit, Zheng 5.2.1): bundled sample (lens radius 1.5-9) 0.220 / 0.103 / 0.417
at 11 against 0.405 / 0.224 / 0.604 at 21; ``roboflow_cinta_v2_id`` 0.366 / 0.239 / 0.393 against
0.396 / 0.278 / 0.423; ``roboflow_traffic_light_kr`` 0 at both. So the default is 21 px
(``benchmarks/PAPERS.md``).
"""

from __future__ import annotations

import cv2
import numpy as np

from tsrkit.api import Candidate, Detector, Frame, Param, hookimpl
from tsrkit_plugins.detectors.localization import (
    LOCALIZATION_PARAMS,
    ROI_PARAM,
    localize,
    region_of_interest,
)


def white_tophat(image: np.ndarray, se_size: int) -> np.ndarray:
    """White top-hat of the grayscale of a BGR uint8 image with an elliptic (disk) structuring
    element ``se_size`` pixels across, as float32 (5.2.2)."""
    if se_size < 1:
        raise ValueError(f"se_size must be >= 1; got {se_size}")
    gray = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    element = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (se_size, se_size))
    return cv2.morphologyEx(gray, cv2.MORPH_TOPHAT, element).astype(np.float32)


class GrayTophat(Detector):
    """White top-hat on grayscale, then Zheng's localization (5.2.2)."""

    name = "gray-tophat"
    summary = "White top-hat on grayscale + Zheng's localization (GRAY-TOPHAT baseline)"
    section = "Zheng 2016, 5.2.2 (de Charette & Nashashibi) with 3.2.2"
    PARAMS = (
        Param(
            "se_size",
            "int",
            21,
            min=3,
            max=201,
            section="5.2.2 (size not given; de Charette's 11 measured worse: module docstring)",
            help="structuring-element diameter in pixels; wider than the largest lens",
        ),
        ROI_PARAM,
    ) + LOCALIZATION_PARAMS

    def detect(self, frame: Frame) -> list[Candidate]:
        """Candidates, best first, scored by the top-hat value (0..255) at their centre."""
        roi = region_of_interest(frame.image, self.params["roi_top"])
        return localize(white_tophat(roi, self.params["se_size"]), self.params)


@hookimpl
def register_detectors(register):
    register(GrayTophat)
