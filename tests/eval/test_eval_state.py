"""State metrics: confusion, per-class figures, Mascetti's R-Y errors, Zheng's discrimination."""

import numpy as np
import pytest

from tsrkit.eval.state import confusion, discriminative_ratio, label_order, per_class, state_metrics


def test_confusion_accuracy_and_red_yellow_errors():
    truth = ["red", "red", "red", "yellow", "green", "green"]
    pred = ["red", "yellow", "red", "red", "green", "red"]
    m = state_metrics(truth, pred)
    assert m["accuracy"] == pytest.approx(3 / 6)
    labels = m["confusion"]["labels"]
    matrix = m["confusion"]["matrix"]
    assert matrix[labels.index("red")][labels.index("yellow")] == 1
    assert matrix[labels.index("green")][labels.index("red")] == 1
    assert m["red_yellow_errors"] == {"red_as_yellow": 1, "yellow_as_red": 1, "total": 2}
    # red: predicted 4 times, right twice; 3 true reds, 2 found.
    assert m["per_class"]["red"] == {"precision": 0.5, "recall": pytest.approx(2 / 3), "support": 3}
    assert m["per_class"]["yellow"] == {"precision": 0.0, "recall": 0.0, "support": 1}
    assert "off" not in m["per_class"]


def test_sign_classes_get_their_own_labels_and_no_red_yellow_figure():
    m = state_metrics(["stop", "yield", "stop"], ["stop", "stop", "unknown"])
    assert m["confusion"]["labels"] == ["stop", "unknown", "yield"]
    assert m["confusion"]["matrix"] == [[1, 1, 0], [0, 0, 0], [1, 0, 0]]
    assert m["accuracy"] == pytest.approx(1 / 3)
    assert m["red_yellow_errors"] == {}


def test_length_mismatch_is_rejected():
    with pytest.raises(ValueError, match="2 true states but 1"):
        state_metrics(["red", "red"], ["red"])


def test_no_pairs_gives_no_accuracy():
    assert state_metrics([], [])["accuracy"] is None


def test_discriminative_ratio_zheng_5_3():
    assert discriminative_ratio({"red": 0.8, "yellow": 0.2, "green": 0.4}) == pytest.approx(0.75)
    assert discriminative_ratio({"red": 0.5, "yellow": 0.5, "green": 0.5}) == 0.0
    assert discriminative_ratio({}) is None
    assert discriminative_ratio({"red": 0.0, "green": 0.0}) is None


def test_misclassification_rate_per_ratio_bin():
    scores = [{"red": 1.0, "green": 0.05}, {"red": 1.0, "green": 0.9}, {"red": 1.0, "green": 0.95}]
    m = state_metrics(["red", "green", "red"], ["red", "red", "red"], scores)
    bins = {
        b["from"]: (b["pairs"], b["misclassification_rate"])
        for b in m["discriminative_ratio"]["bins"]
    }
    # Ratios 0.95, 0.1 and 0.05 (floating point puts 1 - 0.9 just under 0.1).
    assert bins[0.9] == (1, 0.0)
    assert sum(p for p, _ in bins.values()) == 3
    assert m["discriminative_ratio"]["mean"] == pytest.approx((0.95 + 0.1 + 0.05) / 3)


def test_confusion_and_per_class_agree_with_sklearn():
    from sklearn.metrics import confusion_matrix, precision_recall_fscore_support

    rng = np.random.default_rng(5)
    states = ["red", "yellow", "green", "off"]
    truth = list(rng.choice(states, 300, p=[0.5, 0.1, 0.4, 0.0]))
    predicted = list(rng.choice(states, 300))
    labels = label_order(set(truth) | set(predicted))
    assert confusion(truth, predicted, labels).tolist() == (
        confusion_matrix(truth, predicted, labels=labels).tolist()
    )
    precision, recall, _, support = precision_recall_fscore_support(
        truth, predicted, labels=labels, zero_division=np.nan
    )
    ours = per_class(truth, predicted, labels)
    for label, p, r, n in zip(labels, precision, recall, support):
        if label in ours:
            assert ours[label]["support"] == n
            assert ours[label]["precision"] == pytest.approx(p)
            assert ours[label]["recall"] == (None if np.isnan(r) else pytest.approx(r))
    assert ours["off"]["recall"] is None  # predicted, never true
