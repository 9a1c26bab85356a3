"""Temporal agreement on video: a detection is reported only when its light is found on several
consecutive frames.

A lit lens persists from one video frame to the next; a false light from noise, a glint or a
passing reflection often does not. :class:`Agreement` links each frame's detections to those of
the frame before (the nearest one within ``reach`` lens radii of where its last step would carry
it) into chains, and keeps a detection when its chain spans at least ``frames`` frames, counting
the frames after it: a light is reported from its first frame on, never only once it has been
seen long enough. A frame is therefore held until each of its detections is decided (at most
``frames - 1`` frames later). Frames of different sources, or not in increasing order, do not
link. It applies to video frames only: the result of a still image (a source that is not a
video file, :data:`tsrkit.runner.inputs.VIDEO_EXTENSIONS`) has no next frame to agree with and
passes through whole.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from tsrkit.core.types import Detection
from tsrkit.plugin.pipeline import FrameResult
from tsrkit.runner.inputs import VIDEO_EXTENSIONS

__all__ = ["MIN_REACH_PX", "Agreement", "Chain", "Held"]

#: The smallest link distance, pixels.
MIN_REACH_PX = 4.0


@dataclass(eq=False)
class Chain:
    """Detections of one light on consecutive frames: its length so far and last step."""

    length: int = 1
    ended: bool = False
    dx: float = 0.0
    dy: float = 0.0


@dataclass
class Held:
    """A frame waiting for its detections' chains to be decided."""

    result: FrameResult
    chains: list[Chain] = field(default_factory=list)


class Agreement:
    """Keep the detections whose light is found on at least ``frames`` consecutive frames.

    Parameters
    ----------
    frames : int
        The chain length a detection needs; 1 keeps every detection.
    reach : float
        Link distance in lens radii (at least :data:`MIN_REACH_PX`) around where the light's
        last step carries it.
    """

    def __init__(self, frames: int = 2, reach: float = 3.0):
        if frames < 1 or not reach > 0:
            raise ValueError(f"need frames >= 1 and reach > 0; got {frames}, {reach}")
        self.frames = frames
        self.reach = reach
        self._previous: tuple[FrameResult, list[Chain]] | None = None
        self.dropped = 0

    def filter(self, pairs: Iterable[tuple[Any, Any]]) -> Iterator[tuple[Any, Any]]:
        """``(result, extra)`` pairs in order, each :class:`FrameResult` of a video frame with
        only its agreed detections; any other result (a still image's, a skipped input) passes
        through in its place."""
        waiting: deque[tuple[Any, Any]] = deque()
        for result, extra in pairs:
            video = (
                isinstance(result, FrameResult)
                and Path(result.source).suffix.lower() in VIDEO_EXTENSIONS
            )
            waiting.append((self._link(result) if video else result, extra))
            yield from self._ready(waiting, final=False)
        self._end_chains()
        yield from self._ready(waiting, final=True)

    def _link(self, result: FrameResult) -> Held:
        """Chain ``result``'s detections to the previous frame's; chains not continued end."""
        previous = self._previous
        follows = (
            previous is not None
            and previous[0].source == result.source
            and result.index > previous[0].index
        )
        chains: list[Chain] = []
        taken: set[int] = set()
        for detection in result.detections:
            chain = self._continued(detection, previous, taken) if follows else None
            chains.append(chain if chain is not None else Chain())
        if previous is not None:
            for k, chain in enumerate(previous[1]):
                if k not in taken:
                    chain.ended = True
        held = Held(result, chains)
        self._previous = (result, chains)
        return held

    def _continued(
        self,
        detection: Detection,
        previous: tuple[FrameResult, list[Chain]] | None,
        taken: set[int],
    ) -> Chain | None:
        """The previous frame's chain nearest to ``detection`` within reach, continued."""
        assert previous is not None
        c = detection.candidate
        best, best_distance = None, math.inf
        for k, (before, chain) in enumerate(zip(previous[0].detections, previous[1])):
            if k in taken:
                continue
            b = before.candidate
            reach = max(self.reach * max(b.radius, c.radius), MIN_REACH_PX)
            distance = math.hypot(c.x - (b.x + chain.dx), c.y - (b.y + chain.dy))
            if distance <= reach and distance < best_distance:
                best, best_distance = k, distance
        if best is None:
            return None
        taken.add(best)
        chain = previous[1][best]
        b = previous[0].detections[best].candidate
        chain.length += 1
        chain.dx, chain.dy = c.x - b.x, c.y - b.y
        return chain

    def _end_chains(self) -> None:
        if self._previous is not None:
            for chain in self._previous[1]:
                chain.ended = True
            self._previous = None

    def _ready(self, waiting: deque[tuple[Any, Any]], final: bool) -> Iterator[tuple[Any, Any]]:
        """Release the leading pairs whose detections are all decided."""
        while waiting:
            head, extra = waiting[0]
            if isinstance(head, Held):
                decided = all(c.length >= self.frames or c.ended for c in head.chains)
                if not (decided or final):
                    return
                kept = tuple(
                    d
                    for d, c in zip(head.result.detections, head.chains)
                    if c.length >= self.frames
                )
                self.dropped += len(head.result.detections) - len(kept)
                head = replace(head.result, detections=kept)
            waiting.popleft()
            yield head, extra
