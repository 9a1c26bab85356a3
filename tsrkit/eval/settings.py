"""What an evaluation needs to know besides the frames: threshold, evaluated box, exhaustiveness.

``resolve_box`` turns the ``box`` option (``auto | housing | lens``) into the box the metrics
read from each record; ``auto`` follows the dataset's registry ``box`` convention.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from tsrkit.core.errors import TsrkitError
from tsrkit.eval.lighting import LIGHTING_SCHEMES, ZHENG_RULE

if TYPE_CHECKING:
    from tsrkit.core.types import Dataset

__all__ = [
    "BOX_OPTIONS",
    "NOT_DETECTION",
    "EvalSettings",
    "eval_settings",
    "lighting_note",
    "not_exhaustive_note",
    "resolve_box",
]

#: Values of the ``box`` option (``--eval-box``).
BOX_OPTIONS = ("auto", "housing", "lens")


@dataclass(frozen=True)
class EvalSettings:
    """The settings every metric is reset with.

    Parameters
    ----------
    dataset : str
        Dataset name (the COCO ground truth's description).
    iou_threshold : float
        Lee 3.6.2's ``tau`` of the ``iou`` section (``iou50`` always uses 0.5).
    box : {"lens", "housing"}
        Which record box is evaluated: ``lens_bbox``, or ``bbox`` (housing when fitted).
    exhaustive : bool
        False when the dataset does not box every light: false positives are not meaningful.
    detection : bool
        False for a classifier alone on the ground-truth boxes (detection metrics do not apply).
    lighting : {"mascetti", "zheng"}
        The lighting categories' scheme (:func:`tsrkit.eval.lighting.frame_condition`).
    """

    dataset: str = ""
    iou_threshold: float = 0.5
    box: str = "lens"
    exhaustive: bool = True
    detection: bool = True
    lighting: str = "mascetti"

    def false_positive_figure(self, value: float | None) -> float | None:
        """``value`` on an exhaustively labelled dataset, else None (not meaningful)."""
        return value if self.exhaustive else None


def resolve_box(option: str, info: Mapping[str, Any]) -> str:
    """The evaluated box: ``lens`` or ``housing`` (``auto``: lens when the dataset's convention is
    lens, else housing).

    Examples
    --------
    >>> resolve_box("auto", {"box": "lens"}), resolve_box("auto", {"box": "housing"})
    ('lens', 'housing')
    """
    if option not in BOX_OPTIONS:
        raise TsrkitError(f"evaluation box must be one of {', '.join(BOX_OPTIONS)}; got '{option}'")
    if option != "auto":
        return option
    convention = info.get("box") or info.get("box_convention")
    return "lens" if convention == "lens" else "housing"


def not_exhaustive_note(dataset: str) -> str:
    """The report's note for a dataset whose registry entry says ``exhaustive: false``."""
    return (
        f"dataset '{dataset}' is not exhaustively labelled (registry: exhaustive: false): "
        "false-positive-based figures (precision, AP) are not meaningful and are left out "
        "(null)"
    )


def lighting_note(settings: EvalSettings) -> list[str]:
    """The report's note stating the lighting rule: none for the default (Mascetti's Table 4,
    so reference reports stay as they were), the rule for Zheng's conditions."""
    return ["lighting categories: " + ZHENG_RULE] if settings.lighting == "zheng" else []


#: What replaces a detection section in a classifier-only (crop) report.
NOT_DETECTION = {
    "note": "classifier alone on the ground-truth boxes: detection metrics do not apply"
}


def eval_settings(
    dataset: Dataset,
    detection: bool = True,
    iou_threshold: float = 0.5,
    box: str = "auto",
    lighting: str = "mascetti",
) -> EvalSettings:
    """The evaluation settings of ``dataset``: the box (``auto`` follows its registry ``box``
    convention), whether it is exhaustively labelled (registry ``exhaustive``) and the
    lighting scheme."""
    if lighting not in LIGHTING_SCHEMES:
        raise TsrkitError(
            f"lighting must be one of {', '.join(LIGHTING_SCHEMES)}; got '{lighting}'"
        )
    return EvalSettings(
        dataset.name,
        iou_threshold,
        resolve_box(box, dataset.info),
        dataset.info.get("exhaustive", True) is not False,
        detection,
        lighting,
    )
