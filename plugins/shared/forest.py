"""The learned verifier's trees, evaluated for every candidate of a frame at once.

scikit-learn's ``HistGradientBoostingClassifier.predict_proba`` validates its input and walks
its trees one call per tree (150 calls of per-call overhead for 50 candidates). Here the nodes
of all trees are one set of flat arrays, and one compiled pass (:func:`descend`) walks every
(candidate, tree) pair by the rule of scikit-learn's ``_predict_one_from_raw_data``: a value
``<= num_threshold`` goes left, a missing (NaN) value goes where ``missing_go_to_left`` says.
The leaf values are added tree after tree onto the baseline, in scikit-learn's order, and the
probability is the same ``scipy.special.expit``, so the probabilities equal scikit-learn's to
the bit (``tests/verifiers/test_verifier_forest.py``), also for a single row (the NumPy form before
this one summed a lone row's leaves pairwise, off scikit-learn's sum in the last bits). The trees
are read from the estimator's ``_predictors`` and ``_baseline_prediction`` (scikit-learn's own
arrays; that test would catch a change of them). A multiclass classifier (one tree per class
per iteration, ``lamp-state``'s) is read too: :meth:`Forest.raw` gives each class's sum, as
scikit-learn's ``_raw_predict``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from tsrkit.api import ModelError

if TYPE_CHECKING:  # scikit-learn loads when a model is fitted or read, not on import
    from sklearn.ensemble import HistGradientBoostingClassifier


@njit(cache=True, nogil=True)
def descend(
    x: np.ndarray,
    roots: np.ndarray,
    depths: np.ndarray,
    feature: np.ndarray,
    threshold: np.ndarray,
    nan_right: np.ndarray | None,
    children: np.ndarray,
    value: np.ndarray,
    out: np.ndarray,
) -> None:
    """Add to ``out`` (rows, K), holding each class's baseline, the leaf value each row of
    ``x`` reaches in each tree of ``roots`` (scikit-learn's order: tree ``t`` is class
    ``t % K``'s), tree after tree (see :class:`Forest` for the node arrays).

    All rows descend a tree together, one level per step (``depths`` levels: a leaf is its own
    child), without a branch on the data: the rows' steps are independent, where a descent row
    by row waits on each node and mispredicts half of its turns (1.3-1.6x as long on the shipped
    models). ``nan_right`` None: ``x`` holds no missing value (compiled without the test)."""
    k = out.shape[1]
    node = np.empty(x.shape[0], np.int64)
    for t in range(roots.shape[0]):
        node[:] = roots[t]
        for _ in range(depths[t]):
            for row in range(x.shape[0]):
                at = node[row]
                v = x[row, feature[at]]
                right = v > threshold[at]
                if nan_right is not None:
                    right |= np.isnan(v) & nan_right[at]
                node[row] = children[at, np.int64(right)]
        for row in range(x.shape[0]):
            out[row, t % k] += value[node[row]]


@dataclass(frozen=True)
class Forest:
    """The trees of a fitted classifier as flat node arrays.

    ``feature``, ``threshold``, ``nan_right`` (a missing value goes right) and ``value`` (a
    leaf's raw value) hold each node's entry, ``children`` (nodes, 2) the index of its left and
    right child (a leaf is its own child on both sides), ``roots`` (T,) the index of each
    tree's root, in scikit-learn's order (iteration after iteration, one tree per class in
    each), ``depths`` (T,) their depths, and ``baseline`` (K,) each class's starting value
    (K = 1: a binary classifier).
    """

    baseline: np.ndarray
    roots: np.ndarray
    depths: np.ndarray
    feature: np.ndarray
    threshold: np.ndarray
    nan_right: np.ndarray
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
        return cls(
            baseline=np.asarray(estimator._baseline_prediction, np.float64).ravel(),
            roots=np.cumsum(sizes) - sizes,
            depths=np.array([tree.nodes["depth"].max() for tree in trees], np.int64),
            feature=np.where(leaf, 0, nodes["feature_idx"]).astype(np.int64),
            threshold=nodes["num_threshold"].astype(np.float64),
            nan_right=~nodes["missing_go_to_left"].astype(bool),
            children=np.column_stack(
                [
                    np.where(leaf, own, nodes["left"].astype(np.int64) + offset),
                    np.where(leaf, own, nodes["right"].astype(np.int64) + offset),
                ]
            ),
            value=nodes["value"].astype(np.float64),
        )

    def probability(self, features: np.ndarray) -> np.ndarray:
        """The probability of the positive class for each row of ``features`` (float64, as
        scikit-learn converts them), of a binary classifier."""
        from scipy.special import expit

        return expit(self.raw(features)[:, 0])

    def raw(self, features: np.ndarray) -> np.ndarray:
        """The (rows, K) raw predictions of ``features``: each class's baseline plus its trees'
        leaf values, added iteration after iteration as scikit-learn does."""
        x = np.ascontiguousarray(features, np.float64)
        out = np.repeat(self.baseline[None], len(x), axis=0)
        descend(
            x,
            self.roots,
            self.depths,
            self.feature,
            self.threshold,
            self.nan_right if np.isnan(x).any() else None,
            self.children,
            self.value,
            out,
        )
        return out
