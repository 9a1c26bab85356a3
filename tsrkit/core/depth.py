"""Distance from a known size (Lee 2017, 3.5, Eq. 3.5-3.7): an object of real height ``H``
metres that spans ``h`` pixels under a focal length of ``f_y`` pixels stands ``D = H f_y / h``
metres from the camera; its lateral and vertical offsets follow from its image position.

Any detector whose target has a standard size can fill a candidate's ``distance_m`` with
:func:`distance_from_height`: Lee's 24-inch channelizer panels, a traffic-light housing (about
1.0-1.1 m for a three-lens 30 cm head) or a lens (20 or 30 cm).
"""

from __future__ import annotations

__all__ = ["PANEL_HEIGHT_M", "distance_from_height", "lateral_offset", "vertical_offset"]

#: Lee's channelizer (vertical panel) height: 24 inches, the US standard (3.5).
PANEL_HEIGHT_M = 24 * 0.0254


def distance_from_height(height_px: float, real_height_m: float, focal_px: float) -> float:
    """Eq. 3.5: ``D = H f_y / h`` in metres.

    Raises
    ------
    ValueError
        When a size or the focal length is not positive.
    """
    if height_px <= 0 or real_height_m <= 0 or focal_px <= 0:
        raise ValueError(
            f"Eq. 3.5 needs positive sizes and focal length; got h={height_px} px, "
            f"H={real_height_m} m, f={focal_px} px"
        )
    return real_height_m * focal_px / height_px


def lateral_offset(u: float, u0: float, depth_m: float, focal_px: float) -> float:
    """Eq. 3.6: ``x = (u - u0) D / f_x`` metres right of the optical axis (the printed
    ``u - u0 D / f_x`` lost its parentheses; the pinhole model needs them)."""
    return (u - u0) * depth_m / focal_px


def vertical_offset(v: float, v0: float, depth_m: float, focal_px: float) -> float:
    """Eq. 3.7: ``y = (v - v0) D / f_y`` metres below the optical axis (parentheses as in
    :func:`lateral_offset`)."""
    return (v - v0) * depth_m / focal_px
