"""The association score of two candidates under the signal colour state machine (Zheng 2016,
3.4.4, Eq. 3.35-3.38).

The first candidate holds the earlier state, the second the later one. ``pc`` is the distance
between their centres over the smaller radius; ``pc_x``, ``pc_y`` its signed components from the
first to the second (image axes: x right, y down). Reading of Eq. 3.37 (the printed cases): the
same colour scores ``1 - pc``; green -> yellow and yellow -> red, where the lit lens moves up
or left in a head (red on top or left), score ``1 - pc/3`` when ``pc_x <= slack`` and
``pc_y <= slack``; red -> green, moving down or right, scores ``1 - pc/6`` when ``pc_x >= -slack``
and ``pc_y >= -slack``; every other change (and ``unknown``) scores 0. ``slack`` is 0 in the
paper; a positive value tolerates flow jitter across the head's axis.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from tsrkit.spatiotemporal.points import COLOURS, Point

__all__ = [
    "FORWARD",
    "association_score",
    "colour_change_score",
    "pair_score",
    "position_change_score",
]

#: Colour changes of the state machine that move the lit lens up / left (Eq. 3.37).
FORWARD = {("green", "yellow"), ("yellow", "red")}


def position_change_score(
    c0: str, c1: str, pc: float, pc_x: float, pc_y: float, slack: float = 0.0
) -> float:
    """``pcs_{c0,c1}`` of Eq. 3.37 (0 for changes the state machine does not allow).

    >>> position_change_score("red", "red", 0.5, 0.3, 0.4)
    0.5
    >>> position_change_score("green", "yellow", 3.0, 0.0, -3.0)
    0.0
    >>> position_change_score("red", "green", 3.0, 0.0, 3.0)
    0.5
    >>> position_change_score("green", "red", 0.1, 0.0, 0.0)
    0.0
    """
    if c0 == c1 and c0 in COLOURS:
        return 1.0 - pc
    if (c0, c1) in FORWARD and pc_x <= slack and pc_y <= slack:
        return 1.0 - pc / 3.0
    if (c0, c1) == ("red", "green") and pc_x >= -slack and pc_y >= -slack:
        return 1.0 - pc / 6.0
    return 0.0


def colour_change_score(cs0: float, cs1: float) -> float:
    """``ccs_{c0,c1}`` of Eq. 3.38: the geometric mean of the two classification scores.

    >>> colour_change_score(0.25, 1.0)
    0.5
    """
    return math.sqrt(max(cs0, 0.0) * max(cs1, 0.0))


def pair_score(pcs: float, ccs: float) -> float:
    """``as_{c0,c1}`` of Eq. 3.36: ``max(pcs, 0) * exp(ccs)``.

    >>> round(pair_score(0.5, 1.0), 4)
    1.3591
    >>> pair_score(-0.2, 1.0)
    0.0
    """
    return max(pcs, 0.0) * math.exp(ccs)


def association_score(first: Point, second: Point, slack: float = 0.0) -> float:
    """``as`` of Eq. 3.35: the best ``as_{c0,c1}`` over every pair of colours, each weighted by
    the candidates' classification scores. As printed, ``exp(ccs)`` lies in ``[1, e]``: the
    position term dominates, and an allowed change without colour evidence still counts.

    >>> a = Point(10.0, 10.0, 2.0, "red", {"red": 1.0})
    >>> b = Point(10.0, 11.0, 2.0, "red", {"red": 0.25, "green": 0.0})
    >>> round(association_score(a, b), 4)  # red -> green, lens 0.5 radii down: 1 - 0.5/6
    0.9167
    >>> c = Point(11.0, 9.8, 2.0, "red", {"red": 0.25})  # right and up: only red -> red
    >>> round(association_score(a, c), 4)  # (1 - hypot(0.5, 0.1)) * exp(sqrt(0.25))
    0.808
    """
    scale = min(first.radius, second.radius)
    if scale <= 0:
        return 0.0
    dx, dy = (second.x - first.x) / scale, (second.y - first.y) / scale
    pc = math.hypot(dx, dy)
    return max(
        (
            pair_score(
                position_change_score(c0, c1, pc, dx, dy, slack),
                colour_change_score(_score(first.scores, c0), _score(second.scores, c1)),
            )
            for c0 in COLOURS
            for c1 in COLOURS
        ),
        default=0.0,
    )


def _score(scores: Mapping[str, float], colour: str) -> float:
    return float(scores.get(colour, 0.0))
