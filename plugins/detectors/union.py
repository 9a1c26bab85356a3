"""``union``: the candidates of several detectors, merged, for recall.

Beyond the documents: the learned verifier can only keep what some detector proposed, and each
paper detector misses lights the others find (lab-frst the small ones, conspicuity the
over-exposed ones, ...). ``union`` runs several registered detectors, each with its own
parameters, and merges their candidates:

1. **Comparable scores.** Each detector's scores are on its own scale (saliency, symmetry,
   boosting votes), so each member's candidates are rank-normalised: the member's k-th best of
   n scores ``1 - k / n`` (its best 1, the rest evenly below).
2. **Duplicate suppression.** Candidates are taken best-first; one whose centre lies within
   ``merge`` x the larger of the two lens radii (``reach_by``; at least ``min_distance`` px) of
   a kept candidate is the same light. With ``reach_by=smaller`` a large blob no longer
   swallows the lamps near it: leave-one-dataset-out it raised AP50 (KR 0.33 -> 0.38, cinTA
   0.34 -> 0.36) but cost held-out cinTA hit 0.67 -> 0.54, so ``larger`` stays the default
   (``benchmarks/RESULTS.verifier.md``). The kept candidate keeps its own centre, takes the
   largest lens radius of its duplicates (a detector without a radius estimate, such as
   lab-frst, gives a far too small one: on the KR test lenses this raises the share of lens
   boxes at IoU >= 0.5 from 0.09 to 0.39) and gains the duplicate's rank score (once per
   member). Its score is the mean over all members of these rank scores (0 for a member that
   did not find it): a light several detectors agree on ranks above one found by a single
   detector, and scores lie in
   [0, 1] (the ``verifier``'s ``prior`` can blend them with its probability).

Members are written ``NAME [KEY=VALUE ...]; NAME ...``, e.g.
``lab-frst top=15; conspicuity n_top=15``; values are checked by each member's own schema.

**Default members** (:data:`DEFAULT_MEMBERS`, the recommended preset's), **in the band above
the horizon.** A member with ``scale_top=0.6`` searches the upper 60 % of the rows only: a
traffic light stands above the camera, so from a dash-cam it is seen above the horizon, near the
middle row. Members at one band and scale run on one frame made for them, and every member
reads the colour conversions of the one frame (:attr:`Frame.views`). The defaults are lab-blob
for lenses of radius 1-4 px at full resolution in the band, lab-frst (``fraction=0.1``: the
symmetry map binarised at a tenth of its maximum, not Zheng 5.2.2's half, so that green lamps
stay when a blue sign or sky is the frame's strongest spot) for radii 2-12 px on the half-size
band, and adaboost-hsv for large lamps anywhere at half size. Against the earlier members
(lab-frst ``top=15 fraction=0.1``, conspicuity ``n_top=15``, adaboost-hsv ``max_boxes=10``,
tl-recognizer on the whole frame) they find more lights on every set and size (candidate recall
DTLD 0.92 -> 0.96, iwai_japan_tl 0.85 -> 0.88, lenses of radius <= 3 px DTLD 0.76 -> 0.84) at
about 75 instead of 35 candidates per frame and an eighth of the time; the band costs 2 of 658
iwai_japan_tl lights and 2 of 131 cinTA test lights against the whole frame
(``benchmarks/RESULTS.verifier.md``, ``benchmarks/RESULTS.detector_speed.md``). A camera that
looks up at lights (not from a car) should set ``scale_top=1`` or other members.

**Upscaled members** (multi-resolution, after Mascetti et al. 2016, 4.2, who run extraction
and pruning on a resized frame; here the frame is enlarged so that 2-3 px lenses reach the
sizes a member was built for). Two keys belong to the union, not to the member:
``scale=S`` runs the member on the frame resized by ``S`` (``cv2.INTER_LINEAR``) and
``scale_top=T`` first keeps only the upper ``T`` share of its rows (where the lights are),
e.g. ``lab-frst top=15 scale=2 scale_top=0.6``. Centres map back with the pixel-centre
convention ``x = (x' + 0.5) / s - 0.5`` (``s`` the exact per-axis factor), radii as
``r' / s``. The same detector may then appear twice, at two scales. Frame metadata passes
unchanged (a member reading ``focal_px`` would see the unscaled focal length). On a window of a
larger frame (``metadata[WINDOW]``, what :class:`tsrkit.runner.follow.Follower` searches between
key frames) the band is the larger frame's.
"""

from __future__ import annotations

from dataclasses import replace

import cv2
import numpy as np

from tsrkit.api import (
    WINDOW,
    Box,
    Candidate,
    Detector,
    Frame,
    Param,
    ParamError,
    circle_box,
    hookimpl,
)

DEFAULT_MEMBERS = (
    "lab-blob top=30 levels=2 scale_top=0.6; "
    "lab-frst top=15 fraction=0.1 radii=1,2,3,4,5,6 scale=0.5 scale_top=0.6; "
    "adaboost-hsv max_boxes=10 scale=0.5"
)

#: The union's own keys in a member's assignments (not passed to the member).
SCALE_PARAMS = (
    Param("scale", "float", 1.0, min=0.25, max=4.0, help="resize factor of the member's frame"),
    Param("scale_top", "float", 1.0, min=0.01, max=1.0, help="upper share of rows it searches"),
)


def map_back(c: Candidate, sx: float, sy: float) -> Candidate:
    """A candidate found on a frame resized by ``(sx, sy)``, in the original frame's pixels:
    ``x = (x' + 0.5) / sx - 0.5`` (pixel centres stay centres), radius ``r' / sx``."""

    return replace(
        c,
        x=(c.x + 0.5) / sx - 0.5,
        y=(c.y + 0.5) / sy - 0.5,
        radius=c.radius / sx,
        bbox=_map_box(c.bbox, sx, sy),
        housing=None if c.housing is None else _map_box(c.housing, sx, sy),
    )


def _map_box(b: Box, sx: float, sy: float) -> Box:
    """:func:`map_back`'s convention applied to each edge of the box ``b``."""
    return (
        (b[0] + 0.5) / sx - 0.5,
        (b[1] + 0.5) / sy - 0.5,
        (b[2] + 0.5) / sx - 0.5,
        (b[3] + 0.5) / sy - 0.5,
    )


class ScaledMember:
    """A member detector run on the upper ``top`` share of the frame, resized by ``scale``
    (Mascetti et al. 2016, 4.2's multi-resolution, here to enlarge small lenses)."""

    def __init__(self, detector: Detector, scale: float, top: float):
        self.detector, self.scale, self.top = detector, scale, top

    def rows(self, frame: Frame) -> int:
        """How many of ``frame``'s upper rows are in the band: its upper ``top`` share, or for
        a window of a larger frame (``frame.metadata[WINDOW]``) those in the larger frame's
        upper ``top`` share (0 for a window below it)."""
        window = frame.metadata.get(WINDOW)
        if window is None:
            return max(1, int(round(frame.height * self.top)))
        return min(frame.height, int(round(window[3] * self.top)) - window[1])

    def view(self, frame: Frame, shared: dict) -> Frame:
        """The frame the member runs on: ``frame``'s upper ``top`` share of rows
        (:meth:`Frame.band`, sharing ``frame``'s colour views), resized by ``scale``. Made once
        per band and size for all the members that ask with the same ``shared`` dict."""
        rows = self.rows(frame)
        size = (max(1, int(round(frame.width * self.scale))), max(1, int(round(rows * self.scale))))
        if ("band", rows) not in shared:
            shared["band", rows] = frame if rows == frame.height else frame.band(rows)
        band = shared["band", rows]
        if size == (band.width, band.height):
            return band
        if (rows, size) not in shared:
            resized = cv2.resize(band.image, size, interpolation=cv2.INTER_LINEAR)
            shared[rows, size] = replace(band, image=resized)
        return shared[rows, size]

    def detect(self, frame: Frame, shared: dict | None = None) -> list[Candidate]:
        """The member's candidates on its :meth:`view` of ``frame``, in ``frame``'s pixels."""
        rows = self.rows(frame)
        if rows < 1:  # a window below the band
            return []
        view = self.view(frame, {} if shared is None else shared)
        found = self.detector.detect(view)
        if (view.width, view.height) == (frame.width, rows):
            return found
        return [map_back(c, view.width / frame.width, view.height / rows) for c in found]


def rank_scores(count: int) -> np.ndarray:
    """Rank-normalised scores of ``count`` best-first candidates: ``1 - k / count``."""
    return 1.0 - np.arange(count) / max(count, 1)


def merge(
    lists: list[list[Candidate]], factor: float, min_distance: float, reach_by: str = "larger"
) -> list[Candidate]:
    """Merge best-first candidate lists (one per member) by the module's rules, best first;
    ``reach_by`` names which of two radii sets the merging distance (``larger`` or
    ``smaller``)."""
    pick_radius = np.maximum if reach_by == "larger" else np.minimum
    pool = []  # (rank score, member, candidate)
    for member, candidates in enumerate(lists):
        ordered = sorted(candidates, key=lambda c: -c.score)
        pool += [(s, member, c) for s, c in zip(rank_scores(len(ordered)), ordered)]
    pool.sort(key=lambda item: (-item[0], item[1]))
    kept: list[tuple[Candidate, dict[int, float], list[float]]] = []
    at = np.empty((len(pool), 3))  # kept candidates' x, y and own radius, in kept order
    for score, member, c in pool:
        n = len(kept)
        reach = np.maximum(factor * pick_radius(c.radius, at[:n, 2]), min_distance)
        near = np.flatnonzero(np.hypot(c.x - at[:n, 0], c.y - at[:n, 1]) <= reach)
        if len(near):  # the first kept candidate within reach, as a loop over them finds it
            _, votes, radii = kept[near[0]]
            votes.setdefault(member, score)
            radii.append(c.radius)
        else:
            at[n] = c.x, c.y, c.radius
            kept.append((c, {member: score}, [c.radius]))
    share = 1.0 / max(len(lists), 1)
    merged = [
        replace(
            c,
            radius=max(radii),
            bbox=circle_box(c.x, c.y, max(radii)),
            score=float(sum(votes.values())) * share,
        )
        for c, votes, radii in kept
    ]
    return sorted(merged, key=lambda c: -c.score)


class Union(Detector):
    """Several detectors' candidates, rank-normalised and merged with duplicate suppression."""

    name = "union"
    summary = "union of several detectors' candidates: rank-normalised scores, duplicates merged"
    section = "beyond the documents"
    PARAMS = (
        Param(
            "members",
            "detectors",
            DEFAULT_MEMBERS,
            help="member detectors with their parameters: 'NAME KEY=VALUE ...; NAME ...'; "
            "scale=S (and scale_top=T) runs a member on the frame's top T upscaled by S",
            options=SCALE_PARAMS,
        ),
        Param(
            "merge",
            "float",
            1.0,
            min=0.0,
            max=10.0,
            help="two candidates whose centres are within this many lens radii (the larger "
            "radius) are the same light",
        ),
        Param(
            "min_distance",
            "float",
            3.0,
            min=0.0,
            max=100.0,
            help="... or within this many pixels, whatever their radii",
        ),
        Param(
            "reach_by",
            "str",
            "larger",
            choices=("larger", "smaller"),
            help="which of the two lens radii sets the merging distance",
        ),
    )

    def __init__(self, **params):
        super().__init__(**params)
        self.members = [
            ScaledMember(part.plugin, part.options["scale"], part.options["scale_top"])
            for part in self.params["members"]
        ]
        runs = [(m.detector.name, m.scale, m.top) for m in self.members]
        twice = sorted({run[0] for run in runs if runs.count(run) > 1})
        if twice:
            raise ParamError(f"union: member {twice[0]!r} given twice at the same scale")

    def detect(self, frame: Frame) -> list[Candidate]:
        """Every member's candidates, merged; scores in [0, 1]. Members at one band and
        scale run on one frame made for them, and all share ``frame``'s colour views."""
        shared: dict = {}
        lists = [member.detect(frame, shared) for member in self.members]
        p = self.params
        return merge(lists, p["merge"], p["min_distance"], p["reach_by"])


@hookimpl
def register_detectors(register):
    register(Union)
