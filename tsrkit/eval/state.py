"""State (colour) evaluation: accuracy, per-class figures, confusion, R-Y errors, discrimination.

Pairs are (ground-truth state, predicted state, the prediction's state scores) of matched
detections. Red/yellow confusions are counted separately as Mascetti et al. 5.1's "R-Y errors";
the discriminative ratio is Zheng 2016, 5.3: ``1 - min confidence / max confidence``.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from tsrkit.core.results import Figure, MetricResult, Plot, Table, fmt
from tsrkit.core.types import STATES

if TYPE_CHECKING:
    from matplotlib.figure import Figure as MplFigure

__all__ = [
    "RATIO_EDGES",
    "StateResult",
    "confusion",
    "discriminative_ratio",
    "draw_confusion",
    "label_order",
    "per_class",
    "ratio_figures",
    "red_yellow_errors",
    "state_metrics",
]

#: Discriminative-ratio bin edges for the misclassification-rate curve (Zheng Figure 5-15).
RATIO_EDGES = (0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0)


def discriminative_ratio(scores: Mapping[str, float]) -> float | None:
    """``1 - min / max`` of the colour confidences (Zheng 5.3); None without positive scores.

    Examples
    --------
    >>> discriminative_ratio({"red": 0.8, "yellow": 0.2, "green": 0.4})
    0.75
    """
    values = [float(v) for v in scores.values()]
    if len(values) < 2 or max(values) <= 0:
        return None
    return 1.0 - min(values) / max(values)


def state_metrics(
    truth: Sequence[str],
    predicted: Sequence[str],
    scores: Sequence[Mapping[str, float]] | None = None,
) -> dict:
    """Accuracy, per-class precision/recall, confusion matrix, R-Y errors and ratio figures.

    Parameters
    ----------
    truth, predicted : sequences of str
        Labels of matched pairs: signal states (:data:`tsrkit.core.types.STATES`, kept in that
        order) or any other class names, e.g. sign classes (sorted).
    scores : sequence of mappings, optional
        The predictions' ``state_scores`` for the discriminative-ratio figures.
    """
    if len(truth) != len(predicted):
        raise ValueError(f"{len(truth)} true states but {len(predicted)} predictions")
    labels = label_order(set(truth) | set(predicted))
    matrix = confusion(truth, predicted, labels)
    return {
        "pairs": len(truth),
        "accuracy": float(np.trace(matrix) / matrix.sum()) if matrix.sum() else None,
        "per_class": per_class(truth, predicted, labels),
        "confusion": {"labels": labels, "matrix": matrix.tolist()},
        "red_yellow_errors": red_yellow_errors(matrix, labels),
        "discriminative_ratio": ratio_figures(truth, predicted, scores or []),
    }


def label_order(seen: set[str]) -> list[str]:
    """The confusion-matrix labels: all signal states when only those occur, else sorted.

    Examples
    --------
    >>> label_order({"green", "red"})
    ['red', 'yellow', 'green', 'red_yellow', 'off', 'unknown']
    >>> label_order({"stop", "yield", "unknown"})
    ['stop', 'unknown', 'yield']
    """
    return list(STATES) if seen <= set(STATES) else sorted(seen)


def per_class(
    truth: Sequence[str], predicted: Sequence[str], labels: Sequence[str]
) -> dict[str, dict]:
    """Precision, recall and support of every state that occurs (None where undefined).

    Examples
    --------
    >>> per_class(["red", "red", "green"], ["red", "green", "green"], ["red", "green", "off"])
    {'red': {'precision': 1.0, 'recall': 0.5, 'support': 2}, 'green': {'precision': 0.5, \
'recall': 1.0, 'support': 1}}
    """
    if not len(truth):
        return {}
    matrix = confusion(truth, predicted, labels)
    support = matrix.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        precision = np.diag(matrix) / matrix.sum(axis=0)
        recall = np.diag(matrix) / support
    predicted_counts = Counter(predicted)
    return {
        label: {
            "precision": None if np.isnan(p) else float(p),
            "recall": None if np.isnan(r) else float(r),
            "support": int(n),
        }
        for label, p, r, n in zip(labels, precision, recall, support)
        if n or predicted_counts[label]
    }


def confusion(truth: Sequence[str], predicted: Sequence[str], labels: Sequence[str]) -> np.ndarray:
    """The confusion matrix: row = true label, column = predicted, in ``labels``' order (pairs
    with a label outside ``labels`` are not counted), as ``sklearn.metrics.confusion_matrix``
    without its import time.

    Examples
    --------
    >>> confusion(["red", "red", "green"], ["red", "green", "green"], ["red", "green"]).tolist()
    [[1, 1], [0, 1]]
    """
    index = {label: i for i, label in enumerate(labels)}
    matrix = np.zeros((len(labels), len(labels)), dtype=int)
    for true, guess in zip(truth, predicted):
        if true in index and guess in index:
            matrix[index[true], index[guess]] += 1
    return matrix


def red_yellow_errors(matrix: np.ndarray, labels: Sequence[str]) -> dict[str, int]:
    """Mascetti 5.1's R-Y errors: red predicted as yellow, yellow as red, and their sum.

    Empty for label sets without both red and yellow (sign classes).
    """
    if "red" not in labels or "yellow" not in labels:
        return {}
    r, y = labels.index("red"), labels.index("yellow")
    red_as_yellow, yellow_as_red = int(matrix[r, y]), int(matrix[y, r])
    return {
        "red_as_yellow": red_as_yellow,
        "yellow_as_red": yellow_as_red,
        "total": red_as_yellow + yellow_as_red,
    }


def ratio_figures(
    truth: Sequence[str], predicted: Sequence[str], scores: Sequence[Mapping[str, float]]
) -> dict:
    """Mean discriminative ratio and the misclassification rate per ratio bin (Zheng 5.3)."""
    ratios, wrong = [], []
    for t, p, s in zip(truth, predicted, scores):
        ratio = discriminative_ratio(s)
        if ratio is not None:
            ratios.append(ratio)
            wrong.append(t != p)
    if not ratios:
        return {"mean": None, "bins": []}
    ratios_a, wrong_a = np.asarray(ratios), np.asarray(wrong)
    index = np.clip(np.digitize(ratios_a, RATIO_EDGES[1:-1]), 0, len(RATIO_EDGES) - 2)
    bins = [
        {
            "from": RATIO_EDGES[k],
            "to": RATIO_EDGES[k + 1],
            "pairs": int((index == k).sum()),
            "misclassification_rate": float(wrong_a[index == k].mean()),
        }
        for k in range(len(RATIO_EDGES) - 1)
        if (index == k).any()
    ]
    return {"mean": float(ratios_a.mean()), "bins": bins}


def draw_confusion(
    figure: MplFigure, labels: Sequence[str], matrix: Sequence[Sequence[int]]
) -> None:
    """A confusion matrix (rows: ground truth, columns: predicted), counts annotated."""
    ax = figure.subplots()
    image = ax.imshow(matrix, cmap="Blues")
    for i, row in enumerate(matrix):
        for j, count in enumerate(row):
            ax.text(j, i, str(count), ha="center", va="center", fontsize=8)
    ax.set_xticks(range(len(labels)), labels, rotation=45, ha="right")
    ax.set_yticks(range(len(labels)), labels)
    ax.set_xlabel("predicted")
    ax.set_ylabel("ground truth")
    figure.colorbar(image, ax=ax, label="matched detections", shrink=0.8)


@dataclass(frozen=True)
class StateResult(MetricResult):
    """``state``: the accuracy as a headline figure, the confusion and per-class tables, the R-Y
    errors and discriminative ratio as a remark, and the confusion plot."""

    order: ClassVar[int] = 40

    @property
    def state(self) -> Mapping[str, Any]:
        return self.sections.get("state") or {}

    def _shown(self) -> bool:
        return bool(self.state.get("pairs")) and "note" not in self.state

    def headline(self) -> list[Figure]:
        return [
            Figure(
                "state.accuracy",
                "state",
                self.state.get("accuracy"),
                about="state accuracy of the matched detections",
            )
        ]

    def remarks(self) -> list[str]:
        if "note" in self.state:
            return [self.state["note"]]
        if not self._shown():
            return []
        ry = self.state["red_yellow_errors"]
        ratio = (
            "mean discriminative ratio (Zheng 5.3): "
            f"{fmt(self.state['discriminative_ratio']['mean'])}."
        )
        if not ry:  # sign classes: no red/yellow pair
            return [ratio[0].upper() + ratio[1:]]
        return [
            f"R-Y errors (Mascetti 5.1): {ry['total']} ({ry['red_as_yellow']} red as yellow, "
            f"{ry['yellow_as_red']} yellow as red); {ratio}"
        ]

    def tables(self) -> list[Table]:
        if not self._shown():
            return []
        labels, matrix = self.state["confusion"]["labels"], self.state["confusion"]["matrix"]
        per_class = self.state["per_class"]
        return [
            Table(
                "confusion",
                "States of matched detections: confusion",
                ("truth \\ predicted", *labels),
                tuple((label, *map(str, row)) for label, row in zip(labels, matrix)),
                "Rows: the ground-truth state; columns: the predicted state; each matched "
                "detection (centre in a box's enclosing circle, one per box) counts once.",
            ),
            Table(
                "per-class",
                "States of matched detections: per class",
                ("state", "precision", "recall", "support"),
                tuple(
                    (name, fmt(c["precision"]), fmt(c["recall"]), str(c["support"]))
                    for name, c in per_class.items()
                ),
            ),
        ]

    def plots(self) -> list[Plot]:
        if not self._shown():
            return []
        labels, matrix = self.state["confusion"]["labels"], self.state["confusion"]["matrix"]
        return [
            Plot(
                "confusion.png",
                "State confusion of the matched detections: ground truth down, prediction "
                "across; the diagonal is right.",
                lambda figure: draw_confusion(figure, labels, matrix),
                (5.0, 4.0),
            )
        ]
