"""Mascetti et al. 2016's TL-recognizer: HSV range filters, contour pruning, NCC templates.

``tl_recognizer.py`` is the detector plugin, ``tl_geometry.py`` the contour and housing
geometry, ``tl_templates.py`` the NCC template validation and ``tl_tuning.py`` the fitting of
the colour ranges and threshold (``tsrkit train tl-recognizer``).
"""

from tsrkit_plugins.detectors.tl_recognizer.tl_recognizer import (
    TlRecognizer,
    enclosed_cores,
    red_or_yellow,
    register_detectors,
)

__all__ = ["TlRecognizer", "enclosed_cores", "red_or_yellow", "register_detectors"]
