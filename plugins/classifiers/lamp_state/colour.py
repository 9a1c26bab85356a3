"""A second opinion for ``lamp-state`` from the lamp's CIELab colour alone.

Beyond the documents. The full model reads the hue histograms of the lens disk and
rim, where the halo of another camera's lamp weighs as much as its core: of VGIS day's 30
ambers 23 have their nearest lamps in CIELab colour (core and rim means) among the other
cameras' ambers, yet the full model, trained on those cameras, reads 14 of them red
(``benchmarks/RESULTS.state.md``, "Is a held-out camera separable by colour"). A model of the
four Lab means alone (:data:`COLOUR`), learned from the same rows, mixed into the full model's
probabilities (:func:`mix`) lets that colour count: leave-one-set-out mean accuracy and red
recall rose on three jitter seeds, the worst set equal or better (``benchmarks/state_loso.py``).
"""

from __future__ import annotations

import numpy as np

from tsrkit_plugins.classifiers.lamp_state.features import N_HUE

#: The feature columns of the lamp's CIELab a / b: of the brightest disk pixels (the core),
#: then of the most chromatic rim pixels.
COLOUR = slice(2 * N_HUE, 2 * N_HUE + 4)
#: The model array holding the colour model (skops bytes, as the full model's).
COLOUR_ARRAY = "colour_estimator_skops"


def colour_columns(features: np.ndarray) -> np.ndarray:
    """The :data:`COLOUR` columns of lamp-state ``features``, contiguous (the colour model's
    input)."""
    return np.ascontiguousarray(features[:, COLOUR])


def mix(full: np.ndarray, colour: np.ndarray, weight: float) -> np.ndarray:
    """``(1 - weight)`` x the full model's probabilities plus ``weight`` x the colour model's
    (the same columns: both learn the same states).

    Examples
    --------
    >>> mix(np.array([[0.9, 0.1]]), np.array([[0.3, 0.7]]), 0.25)
    array([[0.75, 0.25]])
    """
    return (1 - weight) * full + weight * colour
