"""``cnn-verifier``: confirm, box and read every candidate with a small convolutional network.

Beyond the three documents. Each candidate's window (:mod:`.windows`: twelve lens radii wide,
so the whole housing is in view, vertical or horizontal) is cut to 32x32; all of a frame's
crops go through the ONNX model in one batch (ONNX Runtime, one thread). The network gives the
probability that the candidate is a lit traffic light (Zheng 2016, 5.2.1's centre rule is
what it was taught), the housing box in the window, and the state. A candidate is kept when its
probability reaches ``threshold`` (and ``relative`` x its frame's best); of kept candidates
whose housing boxes overlap by more than ``overlap`` (IoU), only the most probable stays (one
head found by several detectors, or on several lamps, is one light). A kept candidate reports
the probability as its score, the network's housing box and, with ``states`` on, the state.

Trained by ``tsrkit train cnn-verifier --detector D --dataset ...`` (the ``train`` extra:
PyTorch; :mod:`.training`), on the detector's candidates on the datasets' frames, synthetic
no-light scenes, rendered lit heads and real head crops pasted into the frames
(:mod:`tsrkit_plugins.verifiers.mining`, :mod:`tsrkit_plugins.verifiers.pasting`).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from dataclasses import replace
from itertools import chain
from pathlib import Path
from typing import Any

import numpy as np

from tsrkit.api import (
    Candidate,
    Detector,
    Frame,
    Model,
    ModelError,
    Param,
    Sample,
    TsrkitError,
    Verifier,
    hookimpl,
    iou_matrix,
    load_model,
)
from tsrkit_plugins.verifiers.cnn.data import STATE_NAMES, CropSet, Scene, collect
from tsrkit_plugins.verifiers.cnn.runtime import session
from tsrkit_plugins.verifiers.cnn.windows import CONTEXT, INPUT, crops, to_input
from tsrkit_plugins.verifiers.learned import passes
from tsrkit_plugins.verifiers.mining import HEADS_SEED, Heads, head_frames
from tsrkit_plugins.verifiers.pasting import crop_frames
from tsrkit_plugins.verifiers.unlit import no_light_frames

DEFAULT_MODEL = Path(__file__).parent.parent / "models" / "cnn_verifier_default"
#: What a model's card must say of its input for this plugin to read it.
LAYOUT = {
    "version": 1,
    "input": [3, INPUT, INPUT],
    "channels": "BGR",
    "normalisation": "(v / 255 - 0.5) / 0.25",
    "window_radii": CONTEXT,
    "states": list(STATE_NAMES),
}


def suppress(boxes: np.ndarray, scores: np.ndarray, overlap: float) -> np.ndarray:
    """Indices kept by greedy non-maximum suppression: best score first, dropping every box
    whose IoU with a kept one exceeds ``overlap`` (ties: earlier first).

    Examples
    --------
    >>> boxes = np.array([[0, 0, 10, 10], [1, 0, 11, 10], [20, 0, 30, 10]], float)
    >>> suppress(boxes, np.array([0.5, 0.9, 0.7]), 0.5).tolist()
    [1, 2]
    """
    order = np.argsort(-scores, kind="stable")
    iou = iou_matrix(boxes, boxes)
    kept: list[int] = []
    for i in order:
        if all(iou[i, j] <= overlap for j in kept):
            kept.append(int(i))
    return np.array(kept, int)


def housings(boxes: np.ndarray, lenses: Sequence[Sequence[float]], frame: Frame) -> np.ndarray:
    """The network's housing boxes made sound: corners in order, grown to hold the candidate's
    lens box (a housing holds its lit lens), clipped to the frame; a non-finite one is the lens.

    Examples
    --------
    >>> frame = Frame(np.zeros((50, 100, 3), np.uint8), "f")
    >>> housings(np.array([[30.0, 40, 10, -5]]), [(12, 8, 16, 12)], frame).tolist()
    [[10.0, 0.0, 30.0, 40.0]]
    """
    lens = np.asarray(lenses, float).reshape(-1, 4)
    b = np.where(np.isfinite(boxes).all(axis=1, keepdims=True), boxes, lens)
    x0 = np.minimum(np.minimum(b[:, 0], b[:, 2]), lens[:, 0])
    y0 = np.minimum(np.minimum(b[:, 1], b[:, 3]), lens[:, 1])
    x1 = np.maximum(np.maximum(b[:, 0], b[:, 2]), lens[:, 2])
    y1 = np.maximum(np.maximum(b[:, 1], b[:, 3]), lens[:, 3])
    height, width = frame.image.shape[:2]
    return np.stack(
        [
            np.clip(x0, 0, width),
            np.clip(y0, 0, height),
            np.clip(x1, 0, width),
            np.clip(y1, 0, height),
        ],
        axis=1,
    )


class CnnVerifier(Verifier):
    """Confirm, box and read candidates with a small CNN run through ONNX Runtime."""

    name = "cnn-verifier"
    summary = "small CNN over each candidate's window: lit-light probability, housing box, state"
    section = "beyond the documents; labels by Zheng 5.2.1"
    PARAMS = (
        Param(
            "model",
            "path",
            None,
            help="trained model (.onnx with its .json card; tsrkit train cnn-verifier); "
            "default: the shipped model, trained on openly licensed data only",
        ),
        Param(
            "threshold",
            "float",
            0.5,
            min=0.0,
            max=1.0,
            help="candidates whose probability is below this are rejected",
        ),
        Param(
            "relative",
            "float",
            0.0,
            min=0.0,
            max=1.0,
            help="candidates below this fraction of their frame's best probability are "
            "rejected too; 0: off",
        ),
        Param(
            "prior",
            "float",
            0.0,
            min=0.0,
            max=1.0,
            help="weight of the detector's own score (clipped to [0, 1], e.g. the union's "
            "agreement) in the candidate's score: (1 - prior) x probability + prior x score; "
            "0: the network's probability alone",
        ),
        Param(
            "overlap",
            "float",
            0.3,
            min=0.0,
            max=1.0,
            help="of kept candidates whose housing boxes overlap by more than this IoU, "
            "only the most probable stays (1: keep all)",
        ),
        Param(
            "after",
            "verifier",
            "",
            help="a verifier run on the candidates first (e.g. 'verifier': the forest "
            "verifier with its housing stage), whose kept candidates the network then confirms "
            "(their score is what prior blends in); '' for none",
        ),
        Param(
            "housing",
            "str",
            "network",
            choices=("network", "stage"),
            help="the housing box a kept candidate reports: the network's, or the one the "
            "'after' stage fitted where it fitted one (the network's elsewhere)",
        ),
        Param(
            "states",
            "bool",
            True,
            help="report the network's state on each kept candidate (a classifier after "
            "it replaces it)",
        ),
        Param(
            "width",
            "int",
            8,
            min=4,
            max=64,
            help="training: channels of the first convolution block (then x2, x4, x4)",
        ),
        Param("epochs", "int", 14, min=1, max=200, help="training: passes over the positives"),
        Param(
            "patience",
            "int",
            4,
            min=1,
            max=200,
            help="training: epochs without a better held-out average precision before "
            "stopping (with holdout)",
        ),
        Param("learning_rate", "float", 3e-3, min=1e-5, max=1.0, help="training: peak rate"),
        Param(
            "negative_ratio",
            "float",
            3.0,
            min=0.5,
            max=100.0,
            help="training: negatives drawn per positive, every epoch anew",
        ),
        Param(
            "per_camera",
            "int",
            1000,
            min=10,
            max=10**7,
            help="training: positives drawn per camera and epoch at most (a set with many "
            "lights, as cinTA's near heads, does not outweigh the others)",
        ),
        Param(
            "hard",
            "float",
            0.5,
            min=0.0,
            max=1.0,
            help="training: share of each epoch's negatives that are the hardest of a random "
            "pool (scored by the network so far); 0: all drawn at random",
        ),
        Param(
            "turn",
            "float",
            0.2,
            min=0.0,
            max=1.0,
            help="training: share of crops turned a quarter turn (vertical heads seen "
            "horizontal and the reverse)",
        ),
        Param(
            "holdout",
            "str",
            "",
            help="training: frames whose source contains this text validate (early "
            "stopping; a camera the rest does not show), '' for none",
        ),
        Param(
            "synthetic_frames",
            "int",
            120,
            min=0,
            max=10000,
            help="training: synthetic 1280x720 scenes without a lit light (negatives)",
        ),
        Param(
            "head_frames",
            "int",
            40,
            min=0,
            max=10000,
            help="training: synthetic scenes with 5 rendered lit heads each (half horizontal)",
        ),
        Param(
            "crop_frames",
            "int",
            80,
            min=0,
            max=10000,
            help="training: training frames with 5 real head crops pasted in "
            "(udacity_mit_tl_crops train, the sets' own housings, some turned); 0: off",
        ),
        Param("seed", "int", 0, min=0, help="training: seed of the draws and the weights"),
        Param("threads", "int", 1, min=1, max=64, help="training: PyTorch threads"),
    )

    def __init__(self, **params: Any):
        super().__init__(**params)
        self._runtime: Any = None

    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        state["_runtime"] = None  # a session is not sent to worker processes: each opens its own
        return state

    def _where(self) -> str:
        return str(self.params["model"] or DEFAULT_MODEL)

    @property
    def runtime(self) -> Any:
        """The ONNX Runtime session of the model, opened on first use.

        Raises
        ------
        ModelError
            A missing, corrupt or foreign model, or one whose card names another input.
        """
        if self._runtime is None:
            where = self._where()
            model = load_model(where, plugin=self.name)
            if "onnx" not in model.files:
                raise ModelError(f"model {where}: holds no ONNX network")
            if model.info.get("layout") != LAYOUT:
                raise ModelError(
                    f"model {where}: its card describes another input "
                    f"({model.info.get('layout')!r}); retrain it (tsrkit train cnn-verifier)"
                )
            self._runtime = session(model.files["onnx"], where)
        return self._runtime

    def outputs(self, frame: Frame, candidates: Sequence[Candidate]) -> dict[str, np.ndarray]:
        """The network's outputs for every candidate: ``light`` (N), ``box`` (N, 4, frame
        pixels) and ``state`` (N, 5) probabilities."""
        batch, windows = crops(frame.image, candidates)
        light, box, state = self.runtime.run(None, {"crops": to_input(batch)})
        frame_boxes = np.array([w.to_frame(b) for w, b in zip(windows, box)], float)
        frame_boxes = frame_boxes.reshape(-1, 4)
        return {"light": np.asarray(light, float), "box": frame_boxes, "state": np.asarray(state)}

    def verify(self, frame: Frame, candidates: Sequence[Candidate]) -> list[Candidate]:
        part = self.params["after"]
        if part is not None and candidates:
            candidates = part.plugin.verify(frame, candidates)
        if not candidates:
            return []
        return self.decide(frame, candidates, self.outputs(frame, candidates))

    def decide(
        self, frame: Frame, candidates: Sequence[Candidate], out: dict[str, np.ndarray]
    ) -> list[Candidate]:
        """The candidates kept given the network's ``out`` (:meth:`outputs`) on them: scored
        (the probability blended with the detector's score by ``prior``), gated by
        ``threshold`` and ``relative``, boxed (:func:`housings`) and suppressed by ``overlap``,
        best first."""
        prior = self.params["prior"]
        own = np.clip([c.score for c in candidates], 0.0, 1.0)
        score = (1.0 - prior) * np.nan_to_num(out["light"], nan=0.0) + prior * own
        keep = np.flatnonzero(passes(score, self.params["threshold"], self.params["relative"]))
        boxes = housings(out["box"][keep], [candidates[int(i)].bbox for i in keep], frame)
        if self.params["housing"] == "stage":
            for row, i in enumerate(keep):
                fitted = candidates[int(i)].housing
                if fitted is not None:
                    boxes[row] = fitted
        chosen = suppress(boxes, score[keep], self.params["overlap"])
        kept = []
        for k in chosen:
            i = keep[k]
            c = candidates[i]
            state = (
                STATE_NAMES[int(np.argmax(out["state"][i]))] if self.params["states"] else c.state
            )
            kept.append(
                replace(
                    c,
                    score=float(score[i]),
                    housing=tuple(float(v) for v in boxes[k]),
                    housing_score=float(out["light"][i]),
                    state=state,
                )
            )
        return kept

    def scenes(self, samples: Sequence[Sample], exhaustive: bool = True) -> Iterator[Scene]:
        """The training scenes: every sample's frame (camera ``holdout`` when its source
        contains the ``holdout`` text, else ``train``; ``exhaustive``: every lit light is
        boxed), then the synthetic no-light scenes, the rendered-head scenes and the
        pasted-crop scenes of the parameters."""
        held = self.params["holdout"]
        real = (
            Scene(
                s.load(),
                [a.bbox for a in s.annotations],
                [a.state for a in s.annotations],
                exhaustive,
                "holdout" if held and held in s.source else "train",
            )
            for s in samples
        )
        unlit = (
            Scene(f, [], [], True, "synthetic")
            for f in no_light_frames(self.params["synthetic_frames"])
        )
        heads = (
            Scene(f, boxes, [None] * len(boxes), True, "rendered")
            for f, boxes in head_frames(Heads(self.params["head_frames"], 0.5, 0.3), HEADS_SEED)
        )
        pasted = (
            Scene(f, boxes, [None] * len(boxes), exhaustive, "pasted")
            for f, boxes in crop_frames(
                self.params["crop_frames"], samples, training=samples, rotate=0.3
            )
        )
        return chain(real, unlit, heads, pasted)

    def fit(self, samples: Iterable[Sample], *, detector: Detector | None = None) -> Model:
        """Learn to confirm, box and read ``detector``'s candidates on ``samples``. Unboxed
        candidates are negatives where the dataset is exhaustively labelled (its ``exhaustive``
        fact; a concatenation of sets that disagree is not), else only low in the frame
        (:mod:`.data`).

        Raises
        ------
        TsrkitError
            No detector; no positive or no negative crop; PyTorch missing.
        """
        if detector is None:
            raise TsrkitError("cnn-verifier: fit needs the detector whose candidates it verifies")
        exhaustive = bool(getattr(samples, "info", {}).get("exhaustive", True))
        return self.fit_crops(collect(self.scenes(list(samples), exhaustive), detector))

    def fit_crops(self, data: CropSet, validation: CropSet | None = None) -> Model:
        """Train on labelled crops (``validation``: crops of the ``holdout`` frames unless
        given) and return the model: the ONNX network and its card."""
        from tsrkit_plugins.verifiers.cnn.training import Settings, train

        p = self.params
        if validation is None and p["holdout"]:
            held = data.camera == "holdout"
            data, validation = data.take(np.flatnonzero(~held)), data.take(np.flatnonzero(held))
        settings = Settings(
            width=p["width"],
            epochs=p["epochs"],
            patience=p["patience"],
            learning_rate=p["learning_rate"],
            negative_ratio=p["negative_ratio"],
            per_camera=p["per_camera"],
            hard=p["hard"],
            turn=p["turn"],
            seed=p["seed"],
            threads=p["threads"],
        )
        trained = train(data, settings, validation)
        counts = {
            "positives": int((data.light == 1).sum()),
            "negatives": int((data.light == 0).sum()),
            "with_box": int(np.isfinite(data.box).all(axis=1).sum()),
            "with_state": {s: int((data.state == i).sum()) for i, s in enumerate(STATE_NAMES)},
        }
        info = {
            "layout": LAYOUT,
            "crops": counts,
            "epoch_kept": trained.epoch,
            "history": trained.history,
            "onnx_vs_torch_max_difference": trained.difference,
        }
        info["width"] = p["width"]
        return Model(arrays=trained.weights, info=info, files={"onnx": trained.onnx})


@hookimpl
def register_verifiers(register):
    register(CnnVerifier)
