"""Lee's sign classifier: normalised crop -> log-polar image -> PCA -> support vector machine.

The crop of each candidate is intensity-normalised and resampled on a log-polar grid about its
centre (rotation becomes a circular shift along theta), projected on a few principal
components and classified by an SVM whose classes are the sign classes of its training data.
Lee 2017, section 3.4.

Not ``skops.io``: the model stays plain arrays + JSON (``tsrkit.plugin.models``), readable whatever
the
scikit-learn version; the one-vs-one decision is a few lines, tested equal to ``SVC.predict``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import cv2
import numpy as np

from tsrkit.api import (
    Candidate,
    Classifier,
    Detection,
    Detector,
    Frame,
    Model,
    Param,
    Sample,
    TsrkitError,
    hookimpl,
    load_model,
)
from tsrkit_plugins.shared.regions import clip_box

#: Parameters that shape the feature vector; a model records them and they must match.
FEATURE_KEYS = ("transform", "crop_size", "n_rho", "n_theta")


def crop_gray(image: np.ndarray, bbox: Sequence[float], size: int) -> np.ndarray:
    """The box of a BGR image as a ``size x size`` float32 grey crop.

    Raises
    ------
    ValueError
        When the box does not overlap the image.
    """
    xa, ya, xb, yb = clip_box(bbox, image.shape[1], image.shape[0])
    gray = cv2.cvtColor(image[ya:yb, xa:xb], cv2.COLOR_BGR2GRAY)
    return cv2.resize(gray, (size, size), interpolation=cv2.INTER_AREA).astype(np.float32)


def normalise_intensity(gray: np.ndarray) -> np.ndarray:
    """Zero mean, unit standard deviation (3.4: "normalized the intensity"; this reading)."""
    std = gray.std()
    return (gray - gray.mean()) / std if std > 0 else np.zeros_like(gray)


def log_polar(gray: np.ndarray, n_rho: int, n_theta: int) -> np.ndarray:
    """Log-polar resampling about the image centre, shape ``(n_theta, n_rho)`` (3.4).

    Row ``k`` samples the ray at angle ``2 pi k / n_theta`` (clockwise on screen, as y points
    down; Lee counts counter-clockwise, a mirror that changes nothing); columns step along log
    radius out to the inscribed circle. Rotating the image about its centre by
    ``360 / n_theta`` degrees shifts the rows circularly by one.
    """
    h, w = gray.shape
    centre = ((w - 1) / 2, (h - 1) / 2)
    return cv2.warpPolar(
        gray, (n_rho, n_theta), centre, min(w, h) / 2, cv2.INTER_LINEAR | cv2.WARP_POLAR_LOG
    )


def sign_vector(
    image: np.ndarray, bbox: Sequence[float], settings: Mapping[str, Any]
) -> np.ndarray:
    """The feature vector of one box: ``n_rho * n_theta`` log-polar samples, or the raw crop."""
    gray = normalise_intensity(crop_gray(image, bbox, settings["crop_size"]))
    if settings["transform"] == "log-polar":
        gray = log_polar(gray, settings["n_rho"], settings["n_theta"])
    return gray.ravel()


def kernel_matrix(x: np.ndarray, vectors: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
    """The SVM kernel between rows of ``x`` and the support vectors, as scikit-learn's SVC."""
    from sklearn.metrics.pairwise import (
        linear_kernel,
        polynomial_kernel,
        rbf_kernel,
        sigmoid_kernel,
    )

    kind = info["kernel"]
    if kind == "linear":
        return linear_kernel(x, vectors)
    if kind == "rbf":
        return rbf_kernel(x, vectors, gamma=info["gamma"])
    if kind == "poly":
        return polynomial_kernel(
            x, vectors, degree=info["degree"], gamma=info["gamma"], coef0=info["coef0"]
        )
    return sigmoid_kernel(x, vectors, gamma=info["gamma"], coef0=info["coef0"])


def one_vs_one_votes(
    kernel: np.ndarray, dual_coef: np.ndarray, intercept: np.ndarray, n_support: np.ndarray
) -> np.ndarray:
    """Votes per class of libsvm's one-vs-one SVM, shape ``(n_samples, n_classes)``.

    For classes ``i < j`` the decision is ``sum_{s in i} a[j-1, s] K + sum_{s in j} a[i, s] K
    + b_ij``; positive votes for ``i``. ``dual_coef`` and ``intercept`` are scikit-learn's
    public attributes, whose sign is flipped for two classes, hence the flip back here.
    """
    n_classes = len(n_support)
    if n_classes == 2:
        dual_coef, intercept = -dual_coef, -intercept
    starts = np.r_[0, np.cumsum(n_support)]
    votes = np.zeros((kernel.shape[0], n_classes))
    pair = 0
    for i in range(n_classes):
        si = slice(starts[i], starts[i + 1])
        for j in range(i + 1, n_classes):
            sj = slice(starts[j], starts[j + 1])
            decision = (
                kernel[:, si] @ dual_coef[j - 1, si]
                + kernel[:, sj] @ dual_coef[i, sj]
                + intercept[pair]
            )
            votes[:, i] += decision > 0
            votes[:, j] += decision <= 0
            pair += 1
    return votes


class LogPolarSVM(Classifier):
    """Log-polar + PCA + SVM sign classification (Lee 2017, 3.4)."""

    name = "logpolar-svm"
    summary = "Intensity-normalised log-polar crop, PCA, SVM over the model's sign classes"
    section = "Lee 2017, 3.4"
    states = ()
    PARAMS = (
        Param("model", "path", None, help="trained model (tsrkit train logpolar-svm ...)"),
        Param(
            "transform",
            "str",
            "log-polar",
            choices=("log-polar", "none"),
            help="resample the crop log-polar (Lee) or use its pixels (baseline)",
        ),
        Param("crop_size", "int", 64, min=8, max=512, help="crops are resized to this square"),
        Param("n_rho", "int", 32, min=2, max=256, help="log-radius samples", section="3.4"),
        Param("n_theta", "int", 32, min=2, max=256, help="angle samples", section="3.4"),
        Param("n_components", "int", 10, min=1, help="principal components", section="3.4"),
        Param(
            "kernel", "str", "rbf", choices=("linear", "rbf", "poly", "sigmoid"), help="SVM kernel"
        ),
        Param("C", "float", 10.0, min=0.0001, help="SVM regularisation"),
        Param(
            "gamma",
            "float",
            None,
            min=0,
            help="kernel gamma; default 1 / (n_components * variance of the projections)",
        ),
        Param("degree", "int", 3, min=1, max=10, help="poly kernel degree"),
        Param("coef0", "float", 0.0, help="poly / sigmoid kernel constant"),
    )

    def __init__(self, **params):
        super().__init__(**params)
        self._model: Model | None = None

    def _vectors(
        self, pairs: Iterable[tuple[np.ndarray, Sequence[float]]], settings: Mapping[str, Any]
    ) -> np.ndarray:
        rows = [sign_vector(image, bbox, settings) for image, bbox in pairs]
        return np.array(rows, np.float64).reshape(len(rows), -1)

    def fit(self, samples: Iterable[Sample], *, detector: Detector | None = None) -> Model:
        """PCA and SVM on every annotated box; its ``state`` is the class name.

        Raises
        ------
        ValueError
            Fewer than two classes, or fewer boxes than principal components.
        """
        p = self.params
        pairs, labels = [], []
        for sample in samples:
            image = sample.load().image
            for ann in sample.annotations:
                pairs.append((image, ann.bbox))
                labels.append(ann.state)
        classes = sorted(set(labels))
        if len(classes) < 2 or len(labels) < p["n_components"]:
            raise TsrkitError(
                f"logpolar-svm needs two classes and at least n_components="
                f"{p['n_components']} boxes; got {len(classes)} classes, "
                f"{len(labels)} boxes"
            )
        x = self._vectors(pairs, p)
        from sklearn.decomposition import PCA
        from sklearn.svm import SVC

        pca = PCA(n_components=p["n_components"], svd_solver="full").fit(x)
        projected = pca.transform(x)
        gamma = (
            p["gamma"] if p["gamma"] is not None else 1.0 / (projected.shape[1] * projected.var())
        )
        y = np.searchsorted(classes, labels)
        svm = SVC(
            kernel=p["kernel"], C=p["C"], gamma=gamma, degree=p["degree"], coef0=p["coef0"]
        ).fit(projected, y)
        arrays = {
            "pca_mean": pca.mean_,
            "pca_components": pca.components_,
            "explained_variance_ratio": pca.explained_variance_ratio_,
            "support_vectors": svm.support_vectors_,
            "dual_coef": svm.dual_coef_,
            "intercept": svm.intercept_,
            "n_support": svm.n_support_.astype(np.int64),
        }
        info = {
            "classes": classes,
            "kernel": p["kernel"],
            "gamma": float(gamma),
            "degree": p["degree"],
            "coef0": p["coef0"],
            "explained_variance": float(pca.explained_variance_ratio_.sum()),
            **{key: p[key] for key in FEATURE_KEYS},
        }
        return Model(arrays=arrays, info=info)

    def use_model(self, model: Model) -> None:
        """Classify with ``model``; the instance's ``states`` become the model's classes."""
        self._model = model
        self.states = tuple(model.info["classes"])

    def model(self) -> Model:
        """The model in use, loaded from the ``model`` parameter on first use."""
        if self._model is None:
            if self.params["model"] is None:
                raise TsrkitError(
                    "logpolar-svm needs a model: train one with 'tsrkit train "
                    "logpolar-svm --dataset ... --out M' and pass --param model=M"
                )
            self.use_model(load_model(self.params["model"], plugin=self.name))
        assert self._model is not None  # use_model set it
        return self._model

    def project(self, x: np.ndarray) -> np.ndarray:
        """Feature vectors projected on the model's principal components."""
        a = self.model().arrays
        return (x - a["pca_mean"]) @ a["pca_components"].T

    def votes(self, x: np.ndarray) -> np.ndarray:
        """One-vs-one votes per class of feature vectors ``x`` (rows)."""
        model = self.model()
        a = model.arrays
        kernel = kernel_matrix(self.project(x), a["support_vectors"], model.info)
        return one_vs_one_votes(kernel, a["dual_coef"], a["intercept"], a["n_support"])

    def classify(self, frame: Frame, candidates: Sequence[Candidate]) -> list[Detection]:
        if not candidates:
            return []
        model = self.model()
        x = self._vectors(((frame.image, c.bbox) for c in candidates), model.info)
        votes = self.votes(x)
        share = votes / max(len(self.states) - 1, 1)
        return [
            Detection(c, self.states[int(np.argmax(v))], dict(zip(self.states, s.tolist())))
            for c, v, s in zip(candidates, votes, share)
        ]


@hookimpl
def register_classifiers(register):
    register(LogPolarSVM)
