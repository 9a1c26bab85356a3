"""Whether the camera moves, from the video: the image change of the road just ahead between
consecutive frames, and the moments a stop begins and ends, dated by it more finely than by
1 Hz GPS fixes (:mod:`tsrkit.spatiotemporal.kinematics` finds the stop; this dates its ends).

The measure of a frame is the mean absolute grey-level difference to the previous frame over
the lower :data:`ROAD_SHARE` of the image (the road a few metres ahead, where a moving car's
image moves fastest), minimised over small vertical shifts (:data:`SHIFT_PX`) so that the
camera's vibration (a car at rest with its engine on) is not taken for motion. At rest it is
the sensor noise; moving, it grows with the speed.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import cv2
import numpy as np

from tsrkit.spatiotemporal.events import STOP_SPEED, Motion

__all__ = ["ROAD_SHARE", "SHIFT_PX", "dated_rest", "image_motion", "rest_edges"]

#: Share of the image's height, from the bottom, that the measure looks at.
ROAD_SHARE = 0.3
#: Vertical shifts (pixels, either way) tried between two frames.
SHIFT_PX = 2
#: A frame moves when its measure exceeds the rest level by this factor.
REST_FACTOR = 1.6


def image_motion(images: Mapping[int, np.ndarray]) -> dict[int, float]:
    """The measure (module notes) of every frame of ``images`` whose predecessor is there."""
    road = {}
    for index, image in images.items():
        grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY).astype(np.float32)
        road[index] = grey[int(grey.shape[0] * (1 - ROAD_SHARE)) :]
    motion = {}
    for index, now in road.items():
        before = road.get(index - 1)
        if before is None:
            continue
        inner = now[SHIFT_PX:-SHIFT_PX]
        motion[index] = min(
            float(np.abs(inner - before[SHIFT_PX + s : len(before) - SHIFT_PX + s]).mean())
            for s in range(-SHIFT_PX, SHIFT_PX + 1)
        )
    return motion


def rest_edges(
    frames: Sequence[int], values: Sequence[float], arrive: int, leave: int, search: int
) -> tuple[int, int]:
    """The first and last frames at rest of a stop that the GPS places at ``arrive..leave``:
    the rest level is the median measure inside it, a frame moves when its measure and its
    neighbour's (the one further from the stop) both exceed :data:`REST_FACTOR` times that level
    (a lone spike is a compression artefact), and each end moves, within ``search`` frames, to
    the frame next to the nearest moving one. Ends that the measures cannot date stay as
    given."""
    measure = dict(zip(frames, values))
    inside = [measure[f] for f in range(arrive, leave + 1) if f in measure]
    if len(inside) < 3:
        return arrive, leave
    level = REST_FACTOR * float(np.median(inside))

    def moving(f: int, g: int) -> bool:
        return measure.get(f, 0.0) > level and measure.get(g, 0.0) > level

    first = arrive
    for f in range(min(arrive + search, leave - 1), arrive - search - 1, -1):
        if moving(f, f - 1):  # the last moving frame before the rest
            first = f + 1
            break
    last = leave
    for f in range(max(leave - search, first + 1), leave + search + 1):
        if moving(f, f + 1):  # the first moving frame after it
            last = f - 1
            break
    return first, last


def dated_rest(
    motion: Motion, frames: Sequence[int], measure: Mapping[int, float], fps: float
) -> Motion:
    """``motion`` (sampled at ``frames``) with each stop's ends moved to where the video dates
    them (:func:`rest_edges`, searching two seconds either way): at rest in between, and at
    least :data:`~tsrkit.spatiotemporal.events.STOP_SPEED` where the video shows motion."""
    speed = motion.speed.copy()
    rest = speed < STOP_SPEED
    frames = list(frames)
    values = [measure.get(f, np.nan) for f in frames]
    k = 0
    while k < len(rest):
        if not rest[k]:
            k += 1
            continue
        end = k
        while end + 1 < len(rest) and rest[end + 1]:
            end += 1
        first, last = rest_edges(frames, values, frames[k], frames[end], int(round(2 * fps)))
        lo, hi = (
            frames.index(first) if first in frames else k,
            frames.index(last) if last in frames else end,
        )
        speed[min(k, lo) : max(end, hi) + 1] = np.maximum(
            speed[min(k, lo) : max(end, hi) + 1], STOP_SPEED
        )
        speed[lo : hi + 1] = 0.0
        k = max(end, hi) + 1
    return Motion(motion.time, motion.distance, speed)
