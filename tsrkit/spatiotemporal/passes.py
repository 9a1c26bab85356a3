"""Short-range initialisation and long-range tracked recognition of one traversal (Zheng 2016,
3.4.4-3.4.5): the backward first pass (Algorithm 3-2), the top-N stability selection, the
forward second pass with restricted-region detection, and the long-range passes in both
directions (Algorithm 3-4).

Frames are indices of a :class:`~tsrkit.spatiotemporal.clip.Clip`; ``i_u < i_d`` are the
upstream and downstream ends of the short range.
"""

from __future__ import annotations

import numpy as np

from tsrkit.spatiotemporal.association import association_score
from tsrkit.spatiotemporal.clip import Clip
from tsrkit.spatiotemporal.points import Point, Track

__all__ = [
    "TOP_N",
    "associate",
    "best_match",
    "first_pass",
    "long_range",
    "recognise",
    "second_pass",
    "select",
]

#: Tracks kept after the first pass (Zheng 5.4: "up to five tracks").
TOP_N = 5


def associate(scores: np.ndarray) -> list[tuple[int, int]]:
    """Lines 17-27 of Algorithm 3-2: keep each track's (column's) best score, then give a
    detection (row) to the track where its kept score is the row's maximum and non-zero.

    >>> associate(np.array([[0.9, 0.0], [0.5, 0.7]]))
    [(0, 0), (1, 1)]
    >>> associate(np.array([[0.9, 0.8], [0.1, 0.2]]))  # detection 1 is no track's best
    [(0, 0)]
    """
    if scores.size == 0:
        return []
    kept = np.where(scores >= scores.max(axis=0, keepdims=True), scores, 0.0)
    pairs, taken = [], set()
    for d in range(kept.shape[0]):
        t = int(np.argmax(kept[d]))
        if kept[d, t] > 0 and t not in taken:
            pairs.append((d, t))
            taken.add(t)
    return pairs


def first_pass(clip: Clip, i_u: int, i_d: int, slack: float = 0.0) -> list[Track]:
    """Algorithm 3-2: from ``i_d`` back to ``i_u``, detect every frame, project each track's
    candidate from the later frame by DOF, associate (the detection is the first, earlier
    candidate of Eq. 3.35), fill unmatched tracks with their DOF candidate and start a track
    per unmatched detection."""
    tracks: list[Track] = []
    for i in range(i_d, i_u - 1, -1):
        detected = clip.detect(i)
        projected = clip.project_all([t.points[i + 1] for t in tracks], i + 1, i)
        scores = np.array(
            [[association_score(d, p, slack) for p in projected] for d in detected]
        ).reshape(len(detected), len(projected))
        used = set()
        for d, t in associate(scores):
            tracks[t].points[i] = detected[d]
            used.add(d)
        for track, candidate in zip(tracks, projected):
            track.points.setdefault(i, candidate)
        for d, point in enumerate(detected):
            if d not in used:
                tracks.append(Track(len(tracks), {i: point}))
    return tracks


def select(tracks: list[Track], top: int = TOP_N) -> list[Track]:
    """The ``top`` tracks by stability score (3.4.4), most stable first."""
    return sorted(tracks, key=lambda t: (-t.stability, t.id))[:top]


def best_match(
    candidates: list[Point], reference: Point, later: bool, slack: float
) -> Point | None:
    """The candidate of highest positive association score with ``reference``; ``later`` says
    the candidates hold the later state (the reference came from an upstream frame)."""
    best, best_score = None, 0.0
    for candidate in candidates:
        first, second = (reference, candidate) if later else (candidate, reference)
        score = association_score(first, second, slack)
        if score > best_score:
            best, best_score = candidate, score
    return best


def second_pass(clip: Clip, tracks: list[Track], i_u: int, i_d: int, slack: float = 0.0) -> None:
    """The pruning pass of 3.4.4: from ``i_u`` forward to ``i_d``, replace each DOF candidate
    by the best detection in its restricted region, and extend a track's head by forward DOF
    while detections follow (in place)."""
    for i in range(i_u, i_d + 1):
        for track in tracks:
            if i in track.points:
                candidate = track.points[i]
            elif i - 1 in track.points and i - 1 >= i_u:
                candidate = clip.project(track.points[i - 1], i - 1, i)
            else:
                continue
            if candidate.origin != "dof":
                continue
            match = best_match(clip.detect_near(i, candidate), candidate, True, slack)
            if match is not None:
                track.points[i] = match


def long_range(clip: Clip, tracks: list[Track], i_u: int, i_d: int, slack: float = 0.0) -> None:
    """Algorithm 3-4: beyond the short range, upstream to the clip's first frame and
    downstream to its last, project each track's candidate to the next frame and keep the best
    detection in the restricted region; a direction halts when no track found one (in place)."""
    for start, step, stop in ((i_u, -1, clip.first), (i_d, 1, clip.last)):
        previous = start
        while previous != stop:
            current = previous + step
            found = False
            for track in tracks:
                if previous not in track.points:
                    continue
                candidate = clip.project(track.points[previous], previous, current)
                match = best_match(clip.detect_near(current, candidate), candidate, step > 0, slack)
                if match is not None:
                    track.points[current] = match
                    found = True
            if not found:
                break
            previous = current


def recognise(
    clip: Clip, i_u: int, i_d: int, top: int = TOP_N, slack: float = 0.0
) -> tuple[list[Track], int]:
    """The tracks of one traversal: first pass, top-``top`` selection, second pass, long
    range (3.4.4-3.4.5). Returns the selected tracks and how many the first pass made."""
    tracks = first_pass(clip, i_u, i_d, slack)
    chosen = select(tracks, top)
    second_pass(clip, chosen, i_u, i_d, slack)
    long_range(clip, chosen, i_u, i_d, slack)
    return chosen, len(tracks)
