"""The ``onnx-detector`` plugin: a user's ONNX detection model as a tsrkit detector."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from tsrkit.api import Candidate, Detector, Frame, ModelError, Param, ParamError, hookimpl
from tsrkit_plugins.detectors.onnx_detector.layouts import (
    LAYOUTS,
    Decoded,
    box_roles,
    choose_layout,
    decode_boxes,
    decode_yolo,
    nms,
)
from tsrkit_plugins.detectors.onnx_detector.letterbox import letterbox, tiles
from tsrkit_plugins.detectors.onnx_detector.names import class_names, state_of
from tsrkit_plugins.detectors.onnx_detector.session import Session, open_session


class OnnxDetector(Detector):
    """A user's ONNX detection model through ONNX Runtime, its boxes as candidates.

    Each box becomes a :class:`~tsrkit.api.Candidate` centred in the box, with the box as
    ``bbox`` (the housing for a model trained on housing boxes), the lens radius estimated as
    half the box's shorter side (the lens of a vertical or horizontal head spans its width or
    height), the class score as ``score`` and the state its class name says
    (:func:`~tsrkit_plugins.detectors.onnx_detector.names.state_of`), else none.
    """

    name = "onnx-detector"
    summary = (
        "your own ONNX detection model (Ultralytics YOLO or post-NMS boxes) through ONNX "
        "Runtime: letterbox, NMS, optional tiles; state from the class names"
    )
    section = "beyond the documents: a learned detector beside the paper methods"
    PARAMS = (
        Param("model", "path", None, help="the .onnx detection model (required)"),
        Param(
            "layout",
            "str",
            "auto",
            choices=LAYOUTS,
            help="outputs: yolo [1, 4+classes, anchors]; boxes (boxes, scores, labels after "
            "NMS); auto: told from the outputs",
        ),
        Param("conf", "float", 0.25, min=0, max=1, help="keep boxes scoring at least this"),
        Param(
            "iou",
            "float",
            0.7,
            min=0,
            max=1,
            help="NMS drops a box overlapping a better one of its class by more (yolo layout, "
            "and between tiles); Ultralytics' predict default",
        ),
        Param(
            "names",
            "str",
            None,
            help="class names, comma-separated, in id order (unset: MODEL.yaml/.json beside "
            "the model, else the model's Ultralytics metadata)",
        ),
        Param("classes", "ints", None, min=0, help="keep only these class ids (COCO: 9)"),
        Param(
            "size",
            "ints",
            None,
            min=1,
            help="input HEIGHT,WIDTH (or one side) for a model whose input size is dynamic",
        ),
        Param(
            "normalized",
            "bool",
            False,
            help="box coordinates are fractions of the input's width and height (e.g. "
            "Ultralytics RT-DETR exports)",
        ),
        Param(
            "tile",
            "int",
            0,
            min=0,
            help="also run on square tiles of this many frame pixels (0: whole frame only)",
        ),
        Param("tile_overlap", "float", 0.2, min=0, max=0.9, help="share of a tile overlapped"),
        Param("max_det", "int", 300, min=1, help="keep at most this many boxes per frame"),
    )

    def __init__(self, **params: Any) -> None:
        super().__init__(**params)
        if self.params["model"] is None:
            raise ParamError(f"{self.name}: parameter 'model' is required (an .onnx file)")
        size = self.params["size"]
        if size is not None and len(size) not in (1, 2):
            raise ParamError(f"{self.name}: parameter 'size' is HEIGHT,WIDTH or one side")
        self._session: Session | None = None
        self._layout = ""
        self._roles: dict[str, int] = {}
        self._size = (0, 0)
        self._names: list[str] | None = None
        self._states: list[str | None] = []

    def __getstate__(self) -> dict[str, Any]:
        """The plugin without its session (ONNX Runtime sessions do not pickle); a worker
        opens its own on first use."""
        return {**self.__dict__, "_session": None}

    def session(self) -> Session:
        """The open model, opened and checked on first use.

        Raises
        ------
        ModelError
            For a missing or unreadable model, inputs or outputs the plugin cannot read, an
            unknown input size, or class names that do not fit.
        """
        if self._session is None:
            path = Path(self.params["model"])
            session = open_session(path)
            self._layout = choose_layout(session.outputs, self.params["layout"])
            self._roles = box_roles(session.outputs) if self._layout == "boxes" else {}
            self._size = self.input_size(session, path)
            self._names = class_names(self.params["names"], path, session.metadata)
            self._states = [state_of(n) for n in self._names or ()]
            self._session = session
        return self._session

    def input_size(self, session: Session, path: Path) -> tuple[int, int]:
        """``(H, W)``: the model's, else the ``size`` parameter, else Ultralytics' ``imgsz``
        metadata."""
        given = self.params["size"]
        wanted = None if given is None else (given[0], given[-1])
        if session.size is not None:
            if wanted is not None and wanted != session.size:
                raise ModelError(f"{path}: the model's input is {session.size}, not size={given}")
            return session.size
        if wanted is not None:
            return wanted
        imgsz = session.metadata.get("imgsz", "").strip("[]() ").split(",")
        if len(imgsz) == 2 and all(v.strip().isdigit() for v in imgsz):
            return int(imgsz[0]), int(imgsz[1])
        raise ModelError(f"{path}: the input size is dynamic; give it with -p size=HEIGHT,WIDTH")

    def run(self, image: np.ndarray, origin: tuple[int, int]) -> Decoded:
        """The boxes the model finds in ``image`` (a frame or a tile at ``origin``), in frame
        pixels."""
        session = self.session()
        tensor, placed = letterbox(image, self._size)
        outputs = session.run(tensor)
        if self._layout == "yolo":
            count = None if self._names is None else len(self._names)
            found = decode_yolo(outputs[0], self.params["conf"], count)
        else:
            found = decode_boxes(outputs, self._roles)
        if self.params["normalized"]:
            height, width = self._size
            found = replace(found, boxes=found.boxes * [width, height, width, height])
        boxes = placed.to_image(found.boxes) + np.tile(origin, 2)
        return Decoded(boxes, found.scores, found.labels, found.dropped)

    def regions(self, width: int, height: int) -> list[tuple[int, int, int, int]]:
        """The whole frame, then the tiles when ``tile`` is set and the frame exceeds it."""
        whole = (0, 0, width, height)
        side = self.params["tile"]
        if not side or (width <= side and height <= side):
            return [whole]
        return [whole, *tiles(width, height, side, self.params["tile_overlap"])]

    def detect(self, frame: Frame) -> list[Candidate]:
        """The model's boxes in ``frame``, best first (see the class docstring)."""
        p = self.params
        image = frame.image
        if image.ndim == 2:
            image = cv2.cvtColor(image, cv2.COLOR_GRAY2BGR)
        regions = self.regions(frame.width, frame.height)
        parts = [self.run(image[y0:y1, x0:x1], (x0, y0)) for x0, y0, x1, y1 in regions]
        boxes = np.concatenate([d.boxes for d in parts]).reshape(-1, 4)
        scores = np.concatenate([d.scores for d in parts])
        labels = np.concatenate([d.labels for d in parts])
        boxes = np.clip(boxes, 0, [frame.width, frame.height, frame.width, frame.height])
        keep = (scores >= p["conf"]) & (boxes[:, 2] > boxes[:, 0]) & (boxes[:, 3] > boxes[:, 1])
        if p["classes"] is not None:
            keep &= np.isin(labels, p["classes"])
        boxes, scores, labels = boxes[keep], scores[keep], labels[keep]
        if self._layout == "yolo" or len(parts) > 1:
            order = nms(boxes, scores, labels, p["iou"], p["max_det"])
        else:
            order = np.argsort(-scores, kind="stable")[: p["max_det"]]
        dropped = sum(d.dropped for d in parts)
        note = f"{self.name}: {dropped} boxes with values that are not finite left out"
        self.notes = (note,) if dropped else ()
        return [Candidate.from_box(boxes[i], scores[i], self.state(int(labels[i]))) for i in order]

    def state(self, label: int) -> str | None:
        """The state class ``label``'s name says, None without one."""
        return self._states[label] if 0 <= label < len(self._states) else None


@hookimpl
def register_detectors(register):
    """Register the ONNX detector."""
    register(OnnxDetector)
