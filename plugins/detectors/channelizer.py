"""``channelizer``: Lee's work-zone channelizer (vertical panel) detector (2017, 3.5) with depth
from the panel's known height (Eq. 3.5).

Below the vanishing point (channelizers stand on the road and are 24 in tall, so they lie under
the horizon of a level camera), two diagonal filters ``g = [[-1, 0], [0, 1]]`` and its horizontal
flip ``g'`` enhance the diagonal stripes; ``I_diag = sqrt(I1^2 + I2^2)`` is thresholded
(Figure 3.5a). A vertical scan line sweeps left to right: columns crossed by several stripe
edges form a candidate's column span (3.5b); a horizontal scan line sweeps it top to bottom for
the rows that hold the pattern, giving the box (3.5c). A box is kept only if orange and white
stripes alternate inside it (the orange check). The panel's height in pixels is then measured to
a fraction of a pixel (its red-channel coverage, row by row: orange and white sheeting are both
bright in red) and ``D = H f_y / h`` gives ``distance_m`` when the focal length is known.
"""

from __future__ import annotations

from dataclasses import replace

import cv2
import numpy as np

from tsrkit.api import (
    PANEL_HEIGHT_M,
    Candidate,
    Detector,
    Frame,
    Param,
    distance_from_height,
    hookimpl,
)

#: Lee's diagonal filter g and its horizontal flip g' (3.5).
DIAG = np.array([[-1.0, 0.0], [0.0, 1.0]], np.float32)
DIAG_FLIPPED = DIAG[:, ::-1].copy()


def diagonal_edges(gray: np.ndarray) -> np.ndarray:
    """``I_diag = sqrt((I * g)^2 + (I * g')^2)`` of a grayscale image, float32 (3.5)."""
    image = gray.astype(np.float32)
    first = cv2.filter2D(image, -1, DIAG, anchor=(0, 0), borderType=cv2.BORDER_REPLICATE)
    second = cv2.filter2D(image, -1, DIAG_FLIPPED, anchor=(0, 0), borderType=cv2.BORDER_REPLICATE)
    return np.sqrt(first * first + second * second)


def runs(flags: np.ndarray, max_gap: int) -> list[tuple[int, int]]:
    """``(start, stop)`` of the runs of True in ``flags``, bridging gaps of up to ``max_gap``."""
    where = np.flatnonzero(flags)
    if len(where) == 0:
        return []
    breaks = np.flatnonzero(np.diff(where) > max_gap + 1)
    starts = np.concatenate([[where[0]], where[breaks + 1]])
    stops = np.concatenate([where[breaks], [where[-1]]]) + 1
    return list(zip(starts.tolist(), stops.tolist()))


def orange_white(patch: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Masks of orange (hue 3-25, S >= 100, V >= 90) and white (S <= 60, V >= 150) pixels."""
    hsv = cv2.cvtColor(patch, cv2.COLOR_BGR2HSV)
    h, s, v = hsv[..., 0], hsv[..., 1], hsv[..., 2]
    return (h >= 3) & (h <= 25) & (s >= 100) & (v >= 90), (s <= 60) & (v >= 150)


def alternations(orange: np.ndarray, white: np.ndarray) -> int:
    """Orange-white changes down the middle columns of a box: the stripe pattern's count."""
    w = orange.shape[1]
    best = 0
    for col in range(w // 3, max(w - w // 3, w // 3 + 1)):
        labels = np.where(orange[:, col], 1, np.where(white[:, col], 2, 0))
        labels = labels[labels > 0]
        best = max(best, int(np.count_nonzero(np.diff(labels))))
    return best


def panel_height(image: np.ndarray, box: tuple[int, int, int, int]) -> float:
    """The panel's height in pixels to a fraction of a pixel. Each column of the box is read in
    the red channel (orange and white sheeting are both bright in red): its coverage of every
    row between the surround's level (rows just above and below the box) and the panel's (the
    median inside) is summed over the box's rows widened by 3 pixels; the median over the
    columns that belong to the panel is the height, so a neighbour caught in the box's edge
    columns does not bias it."""
    x0, y0, x1, y1 = box
    h = image.shape[0]
    top, bottom = max(y0 - 3, 0), min(y1 + 3, h)
    red = image[:, x0:x1, 2].astype(np.float32)
    inside = np.median(red[y0:y1], axis=0)
    outside = np.concatenate([red[max(top - 2, 0) : top + 1], red[bottom - 1 : bottom + 2]])
    surround = np.median(outside, axis=0) if len(outside) else np.zeros(x1 - x0)
    contrast = inside - surround
    panel = contrast >= max(20.0, 0.5 * float(contrast.max()))
    if not panel.any():
        return float(y1 - y0)
    cover = np.clip((red[top:bottom, panel] - surround[panel]) / contrast[panel], 0.0, 1.0)
    return float(np.median(cover.sum(axis=0)))


class Channelizer(Detector):
    """Diagonal edges, vertical then horizontal scan lines, orange check (Lee 2017, 3.5)."""

    name = "channelizer"
    summary = "Work-zone channelizers: diagonal edge filters, scan lines, orange check, depth"
    section = "Lee 2017, 3.5 (Eq. 3.5-3.7)"
    PARAMS = (
        Param("horizon", "float", 0.5, min=0.0, max=1.0, section="3.5",
              help="vanishing point row as a fraction of the height, when the frame's metadata "
              "has no horizon_y; the search looks below it"),
        Param("edge_image", "str", "max", choices=("gray", "max"), section="3.5 (I not given)",
              help="the image I the diagonal filters see: gray, or each BGR channel with the "
              "largest magnitude kept (orange and white differ most in blue)"),
        Param("edge_threshold", "float", 60.0, min=0.0, section="3.5 (value not given; ours)",
              help="I_diag level of a stripe edge"),
        Param("min_column_edges", "int", 3, min=1, help="vertical scan: stripe-edge pixels a "
              "column needs"),
        Param("min_row_edges", "int", 2, min=1,
              help="horizontal scan: stripe-edge pixels a row of the span needs"),
        Param("min_width", "int", 3, min=1, help="narrowest panel, pixels"),
        Param("min_height", "int", 7, min=2, help="shortest panel, pixels"),
        Param("aspect", "floats", (1.3, 4.5), length=2, min=0.1,
              help="height/width range of a panel box (24 x 8-12 in: 2-3)"),
        Param("min_orange", "float", 0.15, min=0.0, max=1.0, section="3.5 orange check",
              help="share of orange pixels a box needs"),
        Param("min_alternations", "int", 2, min=0, help="orange-white changes down the box"),
        Param("panel_height_m", "float", PANEL_HEIGHT_M, min=0.01, section="Eq. 3.5",
              help="real panel height H (24 in)"),
        Param("focal_px", "float", None, min=1.0, section="Eq. 3.5",
              help="focal length f_y in pixels when the frame's metadata has no focal_px; "
              "without either, no distance"),
    )  # fmt: skip

    def detect(self, frame: Frame) -> list[Candidate]:
        image = frame.image
        h = image.shape[0]
        horizon = frame.metadata.get("horizon_y")
        top = int(np.clip(horizon if horizon is not None else self.params["horizon"] * h, 0, h - 2))
        roi = image[top:]
        if self.params["edge_image"] == "gray":
            magnitude = diagonal_edges(cv2.cvtColor(roi, cv2.COLOR_BGR2GRAY))
        else:
            magnitude = np.max([diagonal_edges(roi[..., c]) for c in range(3)], axis=0)
        edges = magnitude >= self.params["edge_threshold"]
        focal = frame.metadata.get("focal_px") or self.params["focal_px"]
        found = []
        for box in self._boxes(edges, (0, 0, edges.shape[1], edges.shape[0]), passes=4):
            x0, y0, x1, y1 = box
            candidate = self._panel(image, (x0, top + y0, x1, top + y1), focal)
            if candidate is not None:
                found.append(candidate)
        return sorted(found, key=lambda c: -c.score)

    def _boxes(self, edges: np.ndarray, box, passes: int):
        """Scan ``box`` of the edge map: the vertical line left to right finds column spans,
        the horizontal line top to bottom the rows of each; a box whose spans no longer split
        is a candidate, else its parts are scanned again (at most ``passes`` times)."""
        x0, y0, x1, y1 = box
        part = edges[y0:y1, x0:x1]
        columns = part.sum(axis=0) >= self.params["min_column_edges"]
        for c0, c1 in runs(columns, max_gap=1):
            if c1 - c0 < self.params["min_width"]:
                continue
            rows = part[:, c0:c1].sum(axis=1) >= self.params["min_row_edges"]
            for r0, r1 in runs(rows, max_gap=2):
                inner = (x0 + c0, y0 + r0, x0 + c1, y0 + r1)
                if inner == box or passes <= 1:
                    yield inner
                else:
                    yield from self._boxes(edges, inner, passes - 1)

    def _panel(self, image: np.ndarray, box, focal) -> Candidate | None:
        x0, y0, x1, y1 = box
        w, h = x1 - x0, y1 - y0
        low, high = self.params["aspect"]
        if h < self.params["min_height"] or not low <= h / max(w, 1) <= high:
            return None
        orange, white = orange_white(image[y0:y1, x0:x1])
        share = float(orange.mean())
        if (
            share < self.params["min_orange"]
            or alternations(orange, white) < self.params["min_alternations"]
        ):
            return None
        height = panel_height(image, box)
        distance = (
            distance_from_height(height, self.params["panel_height_m"], focal) if focal else None
        )
        score = share + float(white.mean())
        candidate = Candidate.from_box((x0, y0, x1, y1), score, state="channelizer")
        return replace(candidate, distance_m=distance)


@hookimpl
def register_detectors(register):
    register(Channelizer)
