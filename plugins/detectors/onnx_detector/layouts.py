"""Reading a detection model's outputs: the two layouts, and class-aware NMS.

- ``yolo``: Ultralytics YOLOv8 / YOLO11 exports, one output ``[1, 4 + nc, anchors]`` (or its
  transpose ``[1, anchors, 4 + nc]``): per anchor ``cx, cy, w, h`` in input pixels and ``nc``
  class scores, already through the sigmoid. The plugin keeps each anchor's best class, drops
  those below ``conf`` and suppresses overlaps (:func:`nms`).
- ``boxes``: post-NMS exports (torchvision detection models, RT-DETR style graphs, TensorRT's
  ``num_dets`` / ``det_boxes`` ... plugins): boxes ``[N, 4]`` or ``[1, N, 4]`` as ``x0, y0, x1,
  y1`` in input pixels, scores ``[N]`` and integer labels ``[N]`` (either also with a leading
  1), and optionally a detection count.

Either layout's coordinates may be fractions of the input's size instead of pixels (the
plugin's ``normalized``: Ultralytics' RT-DETR export is the ``yolo`` layout so, ``[1, 300,
4 + nc]``).

Rows with a value that is not finite are dropped by :func:`finite_rows`, which counts them (the
plugin notes the count in the frame's record).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tsrkit.api import ModelError

#: Layout names (``-p layout=...``); ``auto`` chooses from the outputs.
LAYOUTS = ("auto", "yolo", "boxes")

#: Output-name words of the ``boxes`` layout's roles (lower case, matched as substrings).
ROLE_WORDS = {
    "count": ("num_det", "num_box", "count"),
    "boxes": ("box", "bbox"),
    "scores": ("score", "conf", "prob"),
    "labels": ("label", "class", "cls", "categor"),
}


@dataclass(frozen=True)
class OutputInfo:
    """A model output as the session describes it: name, shape (``None`` or a name for a
    dynamic dimension) and element type (``tensor(float)``, ``tensor(int64)``...)."""

    name: str
    shape: tuple[int | str | None, ...]
    type: str

    @property
    def integer(self) -> bool:
        """Whether the output holds integers."""
        return "int" in self.type


@dataclass(frozen=True)
class Decoded:
    """Boxes read from one run of the model, in input pixels.

    ``boxes`` ``(N, 4)`` xyxy float64, ``scores`` ``(N,)`` float64, ``labels`` ``(N,)`` int64;
    ``dropped`` counts the rows left out for values that are not finite.
    """

    boxes: np.ndarray
    scores: np.ndarray
    labels: np.ndarray
    dropped: int = 0


def choose_layout(outputs: Sequence[OutputInfo], layout: str) -> str:
    """The layout to read ``outputs`` by, checked against them: ``yolo`` needs one output of
    rank 3, ``boxes`` two to four outputs that :func:`box_roles` places; ``auto`` is the one
    of the two whose needs the outputs meet.

    Raises
    ------
    ModelError
        When the outputs do not meet the layout's needs (for ``auto``: either's).
    """
    if layout in ("auto", "yolo") and len(outputs) == 1 and len(outputs[0].shape) == 3:
        return "yolo"
    if layout in ("auto", "boxes") and 2 <= len(outputs) <= 4:
        box_roles(outputs)
        return "boxes"
    wanted = {"yolo": "the YOLO layout", "boxes": "the boxes layout"}.get(layout, "any layout")
    raise ModelError(f"cannot read {describe(outputs)} by {wanted}; {LAYOUT_HINT}")


LAYOUT_HINT = (
    "expected one YOLO output [1, 4+classes, anchors] or boxes [N, 4] with scores and labels "
    "(-p layout=yolo|boxes)"
)


def describe(outputs: Sequence[OutputInfo]) -> str:
    """The outputs in a few words, for error messages.

    Examples
    --------
    >>> describe([OutputInfo("out", (1, "n", 4), "tensor(float)")])
    "outputs out[1, 'n', 4]"
    """
    return "outputs " + ", ".join(f"{o.name}{list(o.shape)}" for o in outputs)


def box_roles(outputs: Sequence[OutputInfo]) -> dict[str, int]:
    """Which output is the boxes, the scores, the labels and (optional) the count.

    By name first (:data:`ROLE_WORDS`); the outputs no name places by shape: the one whose
    last dimension is 4 the boxes, an integer output of at most one element per image
    the count (rank <= 2, last dimension 1), another integer output the labels and a float one
    the scores.

    Raises
    ------
    ModelError
        When boxes, scores or labels cannot be told apart.

    Examples
    --------
    >>> outs = [OutputInfo("a", ("n", 4), "tensor(float)"),
    ...         OutputInfo("b", ("n",), "tensor(int64)"), OutputInfo("c", ("n",), "tensor(float)")]
    >>> box_roles(outs)
    {'boxes': 0, 'labels': 1, 'scores': 2}
    """
    roles: dict[str, int] = {}
    left = []
    for i, out in enumerate(outputs):
        name = out.name.lower()
        role = next((r for r, words in ROLE_WORDS.items() if any(w in name for w in words)), None)
        if role is None or role in roles:
            left.append(i)
        else:
            roles[role] = i
    for i in left:
        out = outputs[i]
        if "boxes" not in roles and out.shape and out.shape[-1] == 4:
            role = "boxes"
        elif out.integer and out.shape[-1:] == (1,) and "count" not in roles:
            role = "count"
        else:
            role = "labels" if out.integer else "scores"
        if role in roles:
            raise ModelError(f"cannot tell boxes, scores and labels apart in {describe(outputs)}")
        roles[role] = i
    missing = [r for r in ("boxes", "scores", "labels") if r not in roles]
    if missing:
        raise ModelError(f"no {' or '.join(missing)} among {describe(outputs)}; {LAYOUT_HINT}")
    return dict(sorted(roles.items(), key=lambda item: item[1]))


def finite_rows(boxes: np.ndarray, scores: np.ndarray, labels: np.ndarray) -> Decoded:
    """The rows whose box, score and label are all finite, with the count of the others."""
    keep = np.isfinite(boxes).all(axis=1) & np.isfinite(scores) & np.isfinite(labels)
    return Decoded(
        boxes[keep].astype(np.float64),
        scores[keep].astype(np.float64),
        labels[keep].astype(np.int64),
        int((~keep).sum()),
    )


def decode_yolo(output: np.ndarray, conf: float, classes: int | None) -> Decoded:
    """The anchors of an Ultralytics output whose best class score reaches ``conf``.

    ``classes`` (the number of class names, when known) tells the orientation; without it the
    smaller of the two dimensions is taken for ``4 + nc``, as in every export (84 x 8400),
    unless it is too small to be (at most 4).

    Raises
    ------
    ModelError
        When the output is not ``[1, C, A]`` / ``[1, A, C]``, or its class count is not
        ``classes``.

    Examples
    --------
    >>> out = np.zeros((1, 6, 3), np.float32)  # 2 classes, 3 anchors
    >>> out[0, :, 1] = [50, 40, 10, 20, 0.1, 0.9]  # anchor 1: class 1 at 0.9
    >>> d = decode_yolo(out, 0.25, 2)
    >>> d.boxes.tolist(), d.scores.round(3).tolist(), d.labels.tolist()
    ([[45.0, 30.0, 55.0, 50.0]], [0.9], [1])
    """
    if output.ndim != 3 or output.shape[0] != 1:
        raise ModelError(
            f"YOLO output has shape {list(output.shape)}; expected [1, 4+classes, anchors]"
        )
    rows, cols = output.shape[1:]
    if classes is not None and classes + 4 in (rows, cols) and rows != cols:
        transposed = cols == classes + 4
    elif rows == cols:
        raise ModelError(
            f"YOLO output {list(output.shape)} is square: cannot tell classes from anchors"
        )
    else:  # the smaller dimension, unless it is too small to hold a box and a class
        transposed = cols < rows if min(rows, cols) > 4 else rows <= 4
    table = output[0] if transposed else output[0].T  # (anchors, 4 + nc)
    found = table.shape[1] - 4
    if found < 1:
        raise ModelError(f"YOLO output {list(output.shape)} has no class scores")
    if classes is not None and found != classes:
        raise ModelError(f"the model scores {found} classes but {classes} class names are given")
    labels = np.argmax(table[:, 4:], axis=1)
    scores = table[np.arange(len(table)), 4 + labels]
    keep = ~(scores < conf)  # NaN kept here, dropped (and counted) by finite_rows
    cx, cy, w, h = table[keep, :4].astype(np.float64).T
    boxes = np.stack([cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2], axis=1)
    return finite_rows(boxes, scores[keep], labels[keep])


def decode_boxes(outputs: Sequence[np.ndarray], roles: dict[str, int]) -> Decoded:
    """Boxes, scores and labels of a post-NMS export.

    Raises
    ------
    ModelError
        When the three do not describe the same number of detections.

    Examples
    --------
    >>> d = decode_boxes([np.array([[[0.1, 0.2, 0.3, 0.4]]]), np.array([[0.8]]),
    ...                   np.array([[2]])], {"boxes": 0, "scores": 1, "labels": 2})
    >>> d.boxes.round(3).tolist(), d.scores.round(3).tolist(), d.labels.tolist()
    ([[0.1, 0.2, 0.3, 0.4]], [0.8], [2])
    """
    boxes = np.asarray(outputs[roles["boxes"]])
    if boxes.ndim == 3 and boxes.shape[0] == 1:
        boxes = boxes[0]
    scores = np.asarray(outputs[roles["scores"]]).reshape(-1)
    labels = np.asarray(outputs[roles["labels"]]).reshape(-1)
    if boxes.ndim != 2 or boxes.shape[1] != 4 or not len(boxes) == len(scores) == len(labels):
        raise ModelError(
            f"boxes {list(boxes.shape)}, scores {len(scores)} and labels {len(labels)} do not "
            "match; expected boxes [N, 4] with N scores and N labels"
        )
    if "count" in roles:
        count = int(np.asarray(outputs[roles["count"]]).reshape(-1)[0])
        boxes, scores, labels = boxes[:count], scores[:count], labels[:count]
    return finite_rows(boxes, scores, labels)


def nms(
    boxes: np.ndarray, scores: np.ndarray, labels: np.ndarray, iou: float, limit: int
) -> np.ndarray:
    """Indices of the boxes greedy non-maximum suppression keeps, best first, at most
    ``limit``: a box is dropped when its IoU with a kept box of the same label exceeds ``iou``
    (ties in score: the earlier box first).

    Examples
    --------
    >>> boxes = np.array([[0, 0, 10, 10], [1, 0, 11, 10], [1, 0, 11, 10.0]])
    >>> nms(boxes, np.array([0.9, 0.8, 0.7]), np.array([0, 0, 1]), 0.5, 300).tolist()
    [0, 2]
    """
    order = np.argsort(-scores, kind="stable")
    areas = np.prod(np.clip(boxes[:, 2:] - boxes[:, :2], 0, None), axis=1)
    kept: list[int] = []
    while len(order) and len(kept) < limit:
        best, rest = order[0], order[1:]
        kept.append(int(best))
        low = np.maximum(boxes[best, :2], boxes[rest, :2])
        high = np.minimum(boxes[best, 2:], boxes[rest, 2:])
        inter = np.prod(np.clip(high - low, 0, None), axis=1)
        union = areas[best] + areas[rest] - inter
        overlap = np.divide(inter, union, out=np.zeros_like(inter), where=union > 0)
        order = rest[(overlap <= iou) | (labels[rest] != labels[best])]
    return np.array(kept, np.int64)
