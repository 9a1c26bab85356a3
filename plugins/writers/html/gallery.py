"""The worst frames of a run, drawn so that the lights can be seen: each frame small with every
box, and beside it an enlarged crop around each light that went wrong (a missed light, a false
positive, a wrong state), with the boxes redrawn at the crop's scale."""

from __future__ import annotations

import base64
import html
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np

from tsrkit.api import RunResult

#: Frames shown.
FRAMES = 8
#: Width (px) of a whole-frame thumbnail.
THUMB_WIDTH = 480
#: Side (px) of a crop as shown.
CROP_SIDE = 160
#: A crop spans this many times the light's box, and at least :data:`MIN_WINDOW` pixels.
CONTEXT = 4.0
MIN_WINDOW = 40
#: Crops shown per frame.
CROPS = 6
#: Colours (BGR): ground truth, detection in a box, false positive, missed-light marker.
GREEN, BLUE, RED, ORANGE = (0, 200, 0), (255, 120, 0), (0, 0, 255), (0, 200, 255)


@dataclass
class FrameErrors:
    """One frame's detections against its ground truth (a detection is in a box when its centre
    is): detections in a box, false positives, missed boxes with their states, and detections
    in a box whose known state differs from the box's."""

    hits: list = field(default_factory=list)
    false: list = field(default_factory=list)
    missed: list = field(default_factory=list)
    wrong: list = field(default_factory=list)

    @property
    def count(self) -> int:
        return len(self.missed) + len(self.false) + len(self.wrong)


def frame_errors(sample, record) -> FrameErrors:
    """The :class:`FrameErrors` of one evaluated frame."""
    errors, covered = FrameErrors(), set()
    for d in record.detections:
        inside = [
            k
            for k, a in enumerate(sample.annotations)
            if a.bbox[0] <= d.x <= a.bbox[2] and a.bbox[1] <= d.y <= a.bbox[3]
        ]
        (errors.hits if inside else errors.false).append(d)
        covered.update(inside)
        truth = [
            sample.annotations[k]
            for k in inside
            if sample.annotations[k].state not in ("unknown", None)
        ]
        if truth and d.state != "unknown" and d.state not in {a.state for a in truth}:
            errors.wrong.append((d, truth[0]))
    errors.missed = [a for k, a in enumerate(sample.annotations) if k not in covered]
    return errors


def data_uri(encoded: bytes, kind: str = "png") -> str:
    return f"data:image/{kind};base64,{base64.b64encode(encoded).decode('ascii')}"


def _jpeg(image: np.ndarray) -> bytes | None:
    ok, encoded = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, 88])
    return encoded.tobytes() if ok else None


def _rect(image, box, colour, scale=1.0, origin=(0.0, 0.0), pad=0) -> None:
    """``box`` (image coordinates) drawn 2 px wide at ``scale`` from ``origin``, ``pad`` pixels
    outside it so that a small light inside stays visible."""
    x0, y0, x1, y1 = ((v - origin[k % 2]) * scale for k, v in enumerate(box))
    top_left = (int(round(x0)) - pad, int(round(y0)) - pad)
    cv2.rectangle(image, top_left, (int(round(x1)) + pad, int(round(y1)) + pad), colour, 2)


def overview(image: np.ndarray, sample, errors: FrameErrors, box: str) -> bytes | None:
    """The whole frame at most :data:`THUMB_WIDTH` wide, every box drawn."""
    scale = min(1.0, THUMB_WIDTH / image.shape[1])
    out = cv2.resize(image, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
    for a in sample.annotations:
        _rect(out, a.bbox, GREEN, scale)
    for colour, dets in ((BLUE, errors.hits), (RED, errors.false)):
        for d in dets:
            _rect(out, d.box(box), colour, scale)
    for a in errors.missed:
        x = int((a.bbox[0] + a.bbox[2]) / 2 * scale)
        y = int(a.bbox[3] * scale) + 8
        cv2.drawMarker(out, (x, y), ORANGE, cv2.MARKER_TRIANGLE_UP, 12, 2)
    return _jpeg(out)


def crop(image: np.ndarray, centre_box, boxes) -> bytes | None:
    """A square window around ``centre_box`` (:data:`CONTEXT` times its size), scaled to
    :data:`CROP_SIDE` pixels (nearest neighbour when enlarged, so that small lights stay
    sharp), with ``boxes`` (``(box, colour)``) drawn at that scale."""
    x0, y0, x1, y1 = centre_box
    side = max(MIN_WINDOW, CONTEXT * max(x1 - x0, y1 - y0))
    height, width = image.shape[:2]
    side = min(side, width, height)
    left = min(max((x0 + x1) / 2 - side / 2, 0), width - side)
    top = min(max((y0 + y1) / 2 - side / 2, 0), height - side)
    window = image[int(top) : int(top + side), int(left) : int(left + side)]
    if not window.size:
        return None
    scale = CROP_SIDE / window.shape[1]
    method = cv2.INTER_NEAREST if scale >= 2 else cv2.INTER_AREA
    out = cv2.resize(window, (CROP_SIDE, int(round(window.shape[0] * scale))), interpolation=method)
    for box, colour in boxes:
        _rect(out, box, colour, scale, (int(left), int(top)), pad=3)
    return _jpeg(out)


def crops(image: np.ndarray, sample, errors: FrameErrors, box: str) -> list[tuple[bytes, str]]:
    """The crops of a frame's errors, with their labels (at most :data:`CROPS`)."""
    truth = [(a.bbox, GREEN) for a in sample.annotations]
    wanted = [
        *((a.bbox, f"missed {a.state}", []) for a in errors.missed),
        *((d.box(box), _false_label(d.state), [(d.box(box), RED)]) for d in errors.false),
        *((a.bbox, f"{a.state} read as {d.state}", [(d.box(box), BLUE)]) for d, a in errors.wrong),
    ]
    shown = []
    for centre, label, own in wanted[:CROPS]:
        encoded = crop(image, centre, truth + own)
        if encoded is not None:
            shown.append((encoded, label))
    return shown


def _false_label(state: str) -> str:
    return "false positive" if state == "unknown" else f"false positive ({state})"


def gallery(run: RunResult) -> str:
    """The :data:`FRAMES` frames with the most errors, each with its crops; stable order (equal
    errors keep dataset order)."""
    box = run.report.get("evaluated_box") or "lens"
    scored = [(frame_errors(s, r), s) for s, r in run.pairs()]
    scored = sorted((e for e in scored if e[0].count), key=lambda e: -e[0].count)
    figures = []
    for errors, sample in scored[:FRAMES]:
        try:
            image = sample.load().image
        except Exception:  # an image that is gone or unreadable is not shown
            continue
        whole = overview(image, sample, errors, box)
        if whole is None:
            continue
        caption = (
            f"{Path(sample.source).name}: {len(errors.missed)} missed, {len(errors.false)} "
            f"false positives, {len(errors.hits)} found, {len(errors.wrong)} wrong states"
        )
        shown = "".join(
            f'<figure class="crop"><img alt="{html.escape(label)}" src="{data_uri(png, "jpeg")}">'
            f"<figcaption>{html.escape(label)}</figcaption></figure>"
            for png, label in crops(image, sample, errors, box)
        )
        figures.append(
            f'<div class="frame"><p>{html.escape(caption)}</p>'
            f'<img class="gallery" alt="{html.escape(caption)}" src="{data_uri(whole, "jpeg")}">'
            f'<div class="crops">{shown}</div></div>'
        )
    if not figures:
        return "<p>No frame with a miss or a false positive.</p>"
    return (
        "<p>Each frame whole, then enlarged around each light that went wrong. Green: ground "
        "truth; blue: a detection in a box; red: a false positive; orange triangle (whole "
        "frame): a missed light.</p>" + "".join(figures)
    )
