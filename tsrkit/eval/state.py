"""State (colour) evaluation: accuracy, per-class figures, confusion, R-Y errors, discrimination.

Pairs are (ground-truth state, predicted state, the prediction's state scores) of matched
detections. Red/yellow confusions are counted separately as Mascetti et al. 5.1's "R-Y errors";
the discriminative ratio is Zheng 2016, 5.3: ``1 - min confidence / max confidence``.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence

import numpy as np

from tsrkit.eval.matching import centre_hits, greedy_match
from tsrkit.eval.settings import EvalSettings
from tsrkit.plugin import Metric
from tsrkit.records import FrameRecord
from tsrkit.types import STATES, Sample

__all__ = [
    "RATIO_EDGES",
    "StateMetric",
    "discriminative_ratio",
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
        Labels of matched pairs: signal states (:data:`tsrkit.types.STATES`, kept in that
        order) or any other class names, e.g. sign classes (sorted).
    scores : sequence of mappings, optional
        The predictions' ``state_scores`` for the discriminative-ratio figures.
    """
    if len(truth) != len(predicted):
        raise ValueError(f"{len(truth)} true states but {len(predicted)} predictions")
    from sklearn.metrics import confusion_matrix  # on first use: sklearn is slow to import

    labels = label_order(set(truth) | set(predicted))
    matrix = (
        confusion_matrix(truth, predicted, labels=labels)
        if len(truth)
        else np.zeros((len(labels), len(labels)), dtype=int)
    )
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
    """Precision, recall and support of every state that occurs (``sklearn.metrics``).

    Examples
    --------
    >>> per_class(["red", "red", "green"], ["red", "green", "green"], ["red", "green", "off"])
    {'red': {'precision': 1.0, 'recall': 0.5, 'support': 2}, 'green': {'precision': 0.5, \
'recall': 1.0, 'support': 1}}
    """
    if not len(truth):
        return {}
    from sklearn.metrics import precision_recall_fscore_support

    precision, recall, _, support = precision_recall_fscore_support(
        truth, predicted, labels=list(labels), zero_division=np.nan
    )
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


class StateMetric(Metric):
    """``state``: the states of detections matched to ground truth by Zheng's centre rule.

    Each ground-truth box takes at most one detection (best score first) whose centre lies in
    its minimum enclosing circle; the pair's true and predicted states enter the figures.
    """

    name = "state"
    summary = "state accuracy, per-class figures, confusion, R-Y errors, discriminative ratio"
    section = "Mascetti 2016, 5.1; Zheng 2016, 5.3"

    def reset(self, settings: EvalSettings) -> None:
        self.settings = settings
        self.truth: list[str] = []
        self.predicted: list[str] = []
        self.scores: list[Mapping[str, float]] = []

    def update(self, sample: Sample, record: FrameRecord) -> None:
        dets = record.detections
        hits = centre_hits([(d.x, d.y) for d in dets], [a.bbox for a in sample.annotations])
        for i, j in greedy_match([d.score for d in dets], hits.astype(float), 0.5):
            self.truth.append(sample.annotations[j].state)
            self.predicted.append(dets[i].state)
            self.scores.append(dets[i].state_scores)

    def compute(self) -> dict:
        if all(p == "unknown" for p in self.predicted):
            return {
                "state": {
                    **state_metrics([], []),
                    "note": "the method predicts no state (every detection is 'unknown')",
                }
            }
        return {"state": state_metrics(self.truth, self.predicted, self.scores)}
