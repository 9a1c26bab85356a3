"""The learned verifier's trees, evaluated for every candidate of a frame at once.

scikit-learn's ``HistGradientBoostingClassifier.predict_proba`` validates its input and walks
its trees one call per tree (150 calls of per-call overhead for 50 candidates). Here the nodes
of all trees are one set of flat arrays and every (candidate, tree) pair descends together,
one tree level per step, by the rule of scikit-learn's ``_predict_one_from_raw_data``: a value
``<= num_threshold`` goes left, a missing (NaN) value goes where ``missing_go_to_left`` says.
The leaf values are summed tree after tree onto the baseline, in scikit-learn's order, and the
probability is the same ``scipy.special.expit``, so the probabilities equal scikit-learn's to
the bit (``tests/test_verifier_forest.py``). The trees are read from the estimator's
``_predictors`` and ``_baseline_prediction`` (scikit-learn's own arrays; that test would catch
a change of them). A multiclass classifier (one tree per class per iteration, ``lamp-state``'s)
is read too: :meth:`Forest.raw` gives each class's sum, as scikit-learn's ``_raw_predict``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from tsrkit.models import ModelError

if TYPE_CHECKING:  # scikit-learn loads when a model is fitted or read, not on import
    from sklearn.ensemble import HistGradientBoostingClassifier


@dataclass(frozen=True)
class Forest:
    """The trees of a fitted classifier as flat node arrays.

    A node ``i`` is addressed by its slot ``2 i``: ``feature``, ``threshold``, ``nan_left`` and
    ``value`` (a leaf's raw value) hold each node's entry twice, at slots ``2 i`` and
    ``2 i + 1``, and ``children`` holds the slot of node ``i``'s left child at ``2 i`` and of
    its right child at ``2 i + 1`` (a leaf is its own child on both sides), so one step of the
    descent is ``children[slot + goes_right]``. ``roots`` (T,) are the slots of each tree's
    root, deepest tree first, and ``depths`` (T,) those trees' depths (at a step of the
    descent, only the trees still deeper take part); ``order`` (T,) gives the place of each of
    scikit-learn's trees in that list. ``baseline`` (K,) holds each class's starting value
    (K = 1: a binary classifier).
    """

    baseline: np.ndarray
    roots: np.ndarray
    depths: np.ndarray
    order: np.ndarray
    feature: np.ndarray
    threshold: np.ndarray
    nan_left: np.ndarray
    children: np.ndarray
    value: np.ndarray

    @classmethod
    def of(
        cls, estimator: HistGradientBoostingClassifier, where: str, binary: bool = True
    ) -> Forest:
        """The trees of ``estimator`` (read from ``where``); ``binary``: refuse a multiclass one.

        Raises
        ------
        ModelError
            Not one tree per iteration (binary) where ``binary``, or a categorical split.
        """
        trees = [tree for iteration in estimator._predictors for tree in iteration]
        if (binary and estimator.n_trees_per_iteration_ != 1) or any(
            tree.nodes["is_categorical"].any() for tree in trees
        ):
            kind = "the verifier reads binary classifiers" if binary else "reads classifiers"
            raise ModelError(f"model {where}: {kind} without categorical splits only")
        nodes = np.concatenate([tree.nodes for tree in trees])
        sizes = np.array([len(tree.nodes) for tree in trees])
        offset = np.repeat(np.cumsum(sizes) - sizes, sizes)
        leaf = nodes["is_leaf"].astype(bool)
        own = np.arange(len(nodes))
        children = np.column_stack(
            [
                np.where(leaf, own, nodes["left"].astype(np.int64) + offset),
                np.where(leaf, own, nodes["right"].astype(np.int64) + offset),
            ]
        )
        depths = np.array([tree.nodes["depth"].max() for tree in trees])
        deepest = np.argsort(-depths, kind="stable")
        return cls(
            baseline=np.asarray(estimator._baseline_prediction, np.float64).ravel(),
            roots=2 * (np.cumsum(sizes) - sizes)[deepest],
            depths=depths[deepest],
            order=np.argsort(deepest),
            feature=np.repeat(np.where(leaf, 0, nodes["feature_idx"]).astype(np.int64), 2),
            threshold=np.repeat(nodes["num_threshold"].astype(np.float64), 2),
            nan_left=np.repeat(nodes["missing_go_to_left"].astype(bool), 2),
            children=2 * children.ravel(),
            value=np.repeat(nodes["value"].astype(np.float64), 2),
        )

    def probability(self, features: np.ndarray) -> np.ndarray:
        """The probability of the positive class for each row of ``features`` (float64, as
        scikit-learn converts them), of a binary classifier."""
        from scipy.special import expit

        return expit(self.raw(features)[:, 0])

    def raw(self, features: np.ndarray) -> np.ndarray:
        """The (rows, K) raw predictions of ``features``: each class's baseline plus its trees'
        leaf values, summed iteration after iteration as scikit-learn does."""
        x = np.asarray(features, np.float64)
        rows, columns = x.shape
        flat = x.ravel()
        slot = np.repeat(self.roots, rows)  # tree-major: the trees still descending lead
        base = np.tile(np.arange(rows) * columns, len(self.roots))
        missing = bool(np.isnan(flat).any())
        for step in range(int(self.depths[0]) if len(self.depths) else 0):
            active = int(np.count_nonzero(self.depths > step)) * rows
            at = slot[:active]
            value = flat.take(base[:active] + self.feature.take(at))
            if missing:  # NaN: to the side the tree learned
                right = ~(value <= self.threshold.take(at))
                right &= ~(np.isnan(value) & self.nan_left.take(at))
            else:
                right = value > self.threshold.take(at)
            self.children.take(at + right, out=at, mode="clip")  # always in range: unbuffered
        k = len(self.baseline)
        leaves = self.value.take(slot).reshape(len(self.roots), rows)[self.order]
        # one row per iteration, after the baselines: a reduction along the first axis adds the
        # rows one after the other (not pairwise), as scikit-learn adds its trees
        terms = np.concatenate([np.repeat(self.baseline, rows)[None], leaves.reshape(-1, k * rows)])
        return np.add.reduce(terms, axis=0).reshape(k, rows).T
