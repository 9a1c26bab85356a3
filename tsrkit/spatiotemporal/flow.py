"""Projection of a candidate from frame j to frame i by Farneback dense optical flow (Zheng
2016, 3.4.4, Eq. 3.30-3.34).

The flow is computed with OpenCV's ``calcOpticalFlowFarneback`` on grayscale frames, either over
the whole frame or over a window around the candidate (``margin`` pixels beyond its box: the
same dense flow, computed only where it is read). The candidate's points are read as its circle
(its extreme points lie on it); each moves by the flow at its position (Eq. 3.33-3.34) and the
projected candidate is the centre and half extent of the moved points (Eq. 3.30-3.32).
"""

from __future__ import annotations

import math
from dataclasses import replace

import cv2
import numpy as np

from tsrkit.spatiotemporal.points import Point, frame_status

__all__ = [
    "CIRCLE_POINTS",
    "FARNEBACK",
    "circle_points",
    "displace",
    "enclosing_extent",
    "farneback",
    "project",
    "project_with",
    "window",
]

#: Farneback settings: pyramid scale, levels, window, iterations, poly_n, poly_sigma.
FARNEBACK = (0.5, 3, 15, 3, 5, 1.2)
#: Points sampled on a candidate's circle.
CIRCLE_POINTS = 16


def farneback(gray_j: np.ndarray, gray_i: np.ndarray) -> np.ndarray:
    """Dense flow from ``gray_j`` to ``gray_i`` (H x W x 2: x and y displacement), Farneback's
    polynomial-expansion method (Zheng's reference 64) with :data:`FARNEBACK` settings."""
    return cv2.calcOpticalFlowFarneback(gray_j, gray_i, None, *FARNEBACK, 0)


def displace(xs: np.ndarray, ys: np.ndarray, flow: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eq. 3.33-3.34: ``x_i = x_j + flow_x``, ``y_i = y_j + flow_y`` with the flow read
    bilinearly at each point (pixel centres at ``k + 0.5``; clamped to the border).

    >>> flow = np.zeros((4, 4, 2), np.float32); flow[..., 0] = 2.0; flow[..., 1] = -1.0
    >>> displace(np.array([1.0]), np.array([1.0]), flow)
    (array([3.]), array([0.]))
    """
    mx = (np.asarray(xs, np.float32) - 0.5).reshape(1, -1)
    my = (np.asarray(ys, np.float32) - 0.5).reshape(1, -1)
    moved = cv2.remap(flow, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)[0]
    return xs + moved[:, 0].astype(np.float64), ys + moved[:, 1].astype(np.float64)


def enclosing_extent(xs: np.ndarray, ys: np.ndarray) -> tuple[float, float, float]:
    """Eq. 3.30-3.32: centre ``((min + max) / 2)`` per axis and radius ``max(x extent,
    y extent) / 2`` of a projected candidate's points.

    >>> enclosing_extent(np.array([0.0, 4.0, 2.0]), np.array([1.0, 1.0, 2.0]))
    (2.0, 1.5, 2.0)
    """
    x0, x1, y0, y1 = float(xs.min()), float(xs.max()), float(ys.min()), float(ys.max())
    return (x0 + x1) / 2, (y0 + y1) / 2, max(x1 - x0, y1 - y0) / 2


def circle_points(x: float, y: float, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """:data:`CIRCLE_POINTS` points on the candidate's circle."""
    angles = np.linspace(0, 2 * math.pi, CIRCLE_POINTS, endpoint=False)
    return x + radius * np.cos(angles), y + radius * np.sin(angles)


def window(point: Point, shape: tuple[int, ...], margin: int) -> tuple[int, int, int, int]:
    """The flow window ``(x0, y0, x1, y1)`` around a candidate, inside the image (0: all)."""
    h, w = shape[:2]
    if margin <= 0:
        return 0, 0, w, h
    reach = point.radius + margin
    cx = min(max(point.x, 0.0), float(w))
    cy = min(max(point.y, 0.0), float(h))
    x0, x1 = max(int(cx - reach), 0), min(int(math.ceil(cx + reach)), w)
    y0, y1 = max(int(cy - reach), 0), min(int(math.ceil(cy + reach)), h)
    return x0, y0, max(x1, x0 + 1), max(y1, y0 + 1)


def project(point: Point, gray_j: np.ndarray, gray_i: np.ndarray, margin: int = 0) -> Point:
    """The candidate ``point`` of frame j projected onto frame i (Eq. 3.30-3.34), flagged
    ``dof`` with its in-frame status; it keeps its state and scores (the state of the frame
    it came from, 3.4.4)."""
    x0, y0, x1, y1 = window(point, gray_j.shape, margin)
    flow = farneback(gray_j[y0:y1, x0:x1], gray_i[y0:y1, x0:x1])
    return project_with(point, flow, gray_i.shape, (x0, y0))


def project_with(
    point: Point, flow: np.ndarray, shape: tuple[int, ...], origin: tuple[int, int] = (0, 0)
) -> Point:
    """Eq. 3.30-3.34 with a computed ``flow`` whose pixel (0, 0) is image pixel ``origin``.

    >>> flow = np.zeros((20, 20, 2), np.float32); flow[..., 0] = 3.0
    >>> p = project_with(Point(5.0, 5.0, 2.0, "red", {}), flow, (20, 20))
    >>> (round(p.x, 3), round(p.y, 3), round(p.radius, 3), p.origin, p.status)
    (8.0, 5.0, 2.0, 'dof', 'in')
    """
    x0, y0 = origin
    xs, ys = circle_points(point.x - x0, point.y - y0, max(point.radius, 0.5))
    cx, cy, radius = enclosing_extent(*displace(xs, ys, flow))
    h, w = shape[:2]
    return replace(
        point,
        x=cx + x0,
        y=cy + y0,
        radius=radius,
        origin="dof",
        status=frame_status(cx + x0, cy + y0, radius, w, h),
    )
