"""State (colour) evaluation: accuracy, per-class figures, confusion, R-Y errors, discriminative ratio.

Pairs are (ground-truth state, predicted state, the prediction's state scores) of matched
detections. Red/yellow confusions are counted separately as Mascetti et al. 5.1's "R-Y errors";
the discriminative ratio is Zheng 2016, 5.3: ``1 - min confidence / max confidence``.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from sklearn.metrics import confusion_matrix

from tsrkit.types import STATES

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


def state_metrics(truth: Sequence[str], predicted: Sequence[str],
                  scores: Sequence[Mapping[str, float]] | None = None) -> dict:
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
    labels = label_order(set(truth) | set(predicted))
    matrix = (confusion_matrix(truth, predicted, labels=labels) if len(truth)
              else np.zeros((len(labels), len(labels)), dtype=int))
    return {
        "pairs": len(truth),
        "accuracy": float(np.trace(matrix) / matrix.sum()) if matrix.sum() else None,
        "per_class": per_class(matrix, labels),
        "confusion": {"labels": labels, "matrix": matrix.tolist()},
        "red_yellow_errors": red_yellow_errors(matrix, labels),
        "discriminative_ratio": ratio_figures(truth, predicted, scores or []),
    }


def label_order(seen: set[str]) -> list[str]:
    """The confusion-matrix labels: all signal states when only those occur, else sorted.

    Examples
    --------
    >>> label_order({"green", "red"})
    ['red', 'yellow', 'green', 'off', 'unknown']
    >>> label_order({"stop", "yield", "unknown"})
    ['stop', 'unknown', 'yield']
    """
    return list(STATES) if seen <= set(STATES) else sorted(seen)


def per_class(matrix: np.ndarray, labels: Sequence[str]) -> dict[str, dict]:
    """Precision, recall and support of every state that occurs (rows truth, columns predicted)."""
    out = {}
    for k, label in enumerate(labels):
        support, predicted = int(matrix[k].sum()), int(matrix[:, k].sum())
        if support or predicted:
            hits = float(matrix[k, k])
            out[label] = {"precision": hits / predicted if predicted else None,
                          "recall": hits / support if support else None,
                          "support": support}
    return out


def red_yellow_errors(matrix: np.ndarray, labels: Sequence[str]) -> dict[str, int]:
    """Mascetti 5.1's R-Y errors: red predicted as yellow, yellow as red, and their sum.

    Empty for label sets without both red and yellow (sign classes).
    """
    if "red" not in labels or "yellow" not in labels:
        return {}
    r, y = labels.index("red"), labels.index("yellow")
    red_as_yellow, yellow_as_red = int(matrix[r, y]), int(matrix[y, r])
    return {"red_as_yellow": red_as_yellow, "yellow_as_red": yellow_as_red,
            "total": red_as_yellow + yellow_as_red}


def ratio_figures(truth: Sequence[str], predicted: Sequence[str],
                  scores: Sequence[Mapping[str, float]]) -> dict:
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
    bins = [{"from": RATIO_EDGES[k], "to": RATIO_EDGES[k + 1], "pairs": int((index == k).sum()),
             "misclassification_rate": float(wrong_a[index == k].mean())}
            for k in range(len(RATIO_EDGES) - 1) if (index == k).any()]
    return {"mean": float(ratios_a.mean()), "bins": bins}
