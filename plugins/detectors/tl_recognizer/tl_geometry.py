"""Camera geometry of TL-recognizer (Mascetti et al. 2016, 3.1 Property 1, 3.4 Properties 2-3).

The horizon line from pitch and roll, the rotation that makes it horizontal, and the pruning of
contours whose size is not that of a lens at a plausible distance. Angles are in radians here;
image coordinates are pixels, x right, y down, relative to the image centre where stated.

Sign conventions (the reading chosen where the extracted equations disagree): pitch rho > 0 tilts
the camera up, so the horizon lies ``f tan(rho)`` *below* the centre (Eq. 1 with theta = 0);
roll theta > 0 turns the horizon counter-clockwise as seen in the image, i.e. its direction is
``(cos theta, -sin theta)`` in y-down pixels. Eq. 1 as printed (and A.1/A.2) place the point P at
``C + f tan(rho) (sin theta, cos theta)``, the foot of the perpendicular from C (the proof's
"distance between C and P is f tan(rho)") only for this direction; the x terms of Eq. 1 carry the
opposite sign, which we read as a garbled sign.
"""

from __future__ import annotations

import numpy as np


def horizon_line(
    pitch: float, roll: float, centre: tuple[float, float], focal_px: float
) -> tuple[float, float, float]:
    """Coefficients ``(a, b, c)`` of the horizon ``a x + b y + c = 0`` (Property 1, Eq. 1).

    ``a = sin(theta)``, ``b = cos(theta)``, ``c = -sin(theta) C_x - cos(theta) C_y - f tan(rho)``:
    the line through ``P = C + f tan(rho) (sin theta, cos theta)`` with inclination theta (see the
    module docstring for the sign reading).

    Examples
    --------
    >>> a, b, c = horizon_line(0.0, 0.0, (100.0, 50.0), 200.0)
    >>> float(-c / b)   # level camera: the horizon is the centre row
    50.0
    """
    cx, cy = centre
    a, b = np.sin(roll), np.cos(roll)
    return float(a), float(b), float(-a * cx - b * cy - focal_px * np.tan(pitch))


def level_coordinates(points: np.ndarray, roll: float, centre: tuple[float, float]) -> np.ndarray:
    """Rotate pixel ``points`` (N, 2) by the inverse horizon inclination (Algorithm 1, line 8).

    Returns ``(u, v)`` relative to the image centre in a frame where the horizon is horizontal:
    ``u = cos(theta) dx - sin(theta) dy``, ``v = sin(theta) dx + cos(theta) dy``; ``v`` grows
    downwards and the horizon is the line ``v = f tan(rho)``.
    """
    d = np.asarray(points, dtype=np.float64) - np.asarray(centre, dtype=np.float64)
    c, s = np.cos(roll), np.sin(roll)
    return np.stack([c * d[:, 0] - s * d[:, 1], s * d[:, 0] + c * d[:, 1]], axis=1)


def image_coordinates(uv: np.ndarray, roll: float, centre: tuple[float, float]) -> np.ndarray:
    """Inverse of :func:`level_coordinates`: levelled ``(u, v)`` back to image pixels."""
    uv = np.asarray(uv, dtype=np.float64)
    c, s = np.cos(roll), np.sin(roll)
    x = c * uv[:, 0] + s * uv[:, 1]
    y = -s * uv[:, 0] + c * uv[:, 1]
    return np.stack([x, y], axis=1) + np.asarray(centre, dtype=np.float64)


def horizontal_distance(
    d1: float, d2: float, focal_px: float, pitch: float, lens_height: float
) -> float:
    """Horizontal distance d_h from the camera to the lens (Property 2, Eq. 2).

    ``d1`` and ``d2`` are the directed (positive upwards) distances in pixels from the image
    centre to the bottom and the top of the levelled contour; ``lens_height`` is l_h in metres.
    """
    a1, a2 = np.arctan(d1 / focal_px), np.arctan(d2 / focal_px)
    return float(lens_height * np.cos(a2 + pitch) * np.cos(a1 + pitch) / np.sin(a2 - a1))


def vertical_distance(d_h: float, d1: float, focal_px: float, pitch: float) -> float:
    """Height d_v of the lens bottom above the camera (Property 2, Eq. 3)."""
    return float(d_h * np.tan(np.arctan(d1 / focal_px) + pitch))


def object_width(distance: float, contour_width: float, focal_px: float, alpha: float) -> float:
    """Width w of the object a contour of ``contour_width`` pixels shows (Property 3, Eq. 4)."""
    return float(distance * contour_width / (focal_px * np.cos(alpha)))


def passes_distance_and_width(
    top: float,
    bottom: float,
    width_px: float,
    *,
    focal_px: float,
    pitch: float,
    lens_m: float,
    horizontal_m: tuple[float, float],
    vertical_m: tuple[float, float],
    max_rotation: float,
    width_slack: float,
) -> bool:
    """The "distance" and "width" properties of 3.4 for one levelled contour.

    ``top`` and ``bottom`` are levelled ``v`` extents (pixels, y down, relative to the centre) and
    ``width_px`` the levelled width. The width test accepts the contour when the lens width
    ``lens_m`` lies in ``[w(alpha=0), w(alpha=max_rotation)]`` widened by ``width_slack`` (a
    relative tolerance for pixel quantisation, not in the paper).
    """
    d1, d2 = -bottom, -top
    if d2 <= d1:
        return False
    d_h = horizontal_distance(d1, d2, focal_px, pitch, lens_m)
    d_v = vertical_distance(d_h, d1, focal_px, pitch)
    if not (horizontal_m[0] <= d_h <= horizontal_m[1] and vertical_m[0] <= d_v <= vertical_m[1]):
        return False
    distance = float(np.hypot(d_h, d_v))
    w_min = object_width(distance, width_px, focal_px, 0.0)
    w_max = object_width(distance, width_px, focal_px, max_rotation)
    return w_min * (1 - width_slack) <= lens_m <= w_max * (1 + width_slack)
