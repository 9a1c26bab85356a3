"""``tsrkit track VIDEO``: the traversals of a drive found from its GPS log and map, and per
traversal the tracks of Zheng 2016's short-range initialisation and long-range tracked
recognition (3.4.2-3.4.5), computed on the clip's frames only.

Each traversal's record is cached under ``cache_dir`` keyed by the clip's decoded pixels, the
plugins' identities and the settings, so an interrupted run resumes at the first traversal it had
not finished.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from tsrkit.core.atomic import write_json
from tsrkit.core.errors import TsrkitError
from tsrkit.core.files import InputFileError, read_json
from tsrkit.core.types import Skipped
from tsrkit.geo import Signals, Track
from tsrkit.plugin.pipeline import Pipeline
from tsrkit.plugin.selection import Selection
from tsrkit.runner.engine import MAX_CACHE_ENTRY, plugin_identity
from tsrkit.runner.inputs import iter_video
from tsrkit.spatiotemporal.clip import Clip
from tsrkit.spatiotemporal.egomotion import image_motion
from tsrkit.spatiotemporal.headpass import follow_head
from tsrkit.spatiotemporal.passes import TOP_N, recognise
from tsrkit.spatiotemporal.ranges import DOWNSTREAM_M, UPSTREAM_M, FrameTraversal, frame_traversals
from tsrkit.spatiotemporal.timeline import controlling_tracks

__all__ = [
    "RECORD_VERSION",
    "TrackSettings",
    "VideoError",
    "decode_clip",
    "identity",
    "track_video",
    "traversal_record",
    "video_facts",
]

#: Bumped when a traversal's record changes meaning; part of the cache key.
RECORD_VERSION = 3


class VideoError(TsrkitError):
    """A video that cannot be opened or declares no frame rate or frame count."""


@dataclass(frozen=True)
class TrackSettings:
    """The framework's settings: vicinity threshold (m), short range (trajectory m upstream
    and downstream of the anchor), tracks kept, the state-machine slack of Eq. 3.37, the
    flow window margin (pixels, 0 for whole frames) and the share of the frame's height
    searched by whole-frame detection (Zheng 5.4: the upper 60 %)."""

    vicinity: float = 30.0
    upstream: float = UPSTREAM_M
    downstream: float = DOWNSTREAM_M
    top: int = TOP_N
    slack: float = 0.0
    margin: int = 0
    roi_top: float = 0.6


def video_facts(path: str | os.PathLike) -> tuple[float, int]:
    """Frame rate and frame count the container declares.

    Raises
    ------
    VideoError
    """
    capture = cv2.VideoCapture(str(path), cv2.CAP_FFMPEG)
    try:
        if not capture.isOpened():
            raise VideoError(f"{path}: cannot open as a video")
        fps = float(capture.get(cv2.CAP_PROP_FPS) or 0.0)
        frames = int(capture.get(cv2.CAP_PROP_FRAME_COUNT) or 0)
    finally:
        capture.release()
    if fps <= 0 or frames <= 0:
        raise VideoError(f"{path}: the video declares no frame rate or frame count")
    return fps, frames


def decode_clip(video: str, first: int, last: int) -> tuple[dict[int, np.ndarray], str]:
    """Frames ``first..last`` of ``video`` (streamed: seek, then decode only these) and the
    SHA-256 of their pixels."""
    digest = hashlib.sha256()
    images = {}
    for frame in iter_video(Path(video), 1, first, last + 1):
        if isinstance(frame, Skipped):
            raise VideoError(f"{frame.source}: {frame.reason}")
        images[frame.index] = frame.image
        digest.update(frame.image.tobytes())
    if not images:
        raise VideoError(f"{video}: frames {first}-{last} could not be decoded")
    return images, digest.hexdigest()


def identity(selection: Selection, settings: TrackSettings) -> str:
    """The plugins' names, versions and parameters and the settings, as one cache-key string."""
    plugins = {
        kind: plugin_identity(getattr(selection, kind))
        for kind in ("detector", "verifier", "classifier", "tracker")
    }
    return json.dumps(
        {"plugins": plugins, "settings": asdict(settings), "version": RECORD_VERSION},
        sort_keys=True,
        default=str,
    )


def traversal_record(
    number: int, found: FrameTraversal, signals: Signals, clip: Clip, settings: TrackSettings
) -> dict[str, Any]:
    """Run the passes on the clip and describe the traversal, its tracks and, as ``heads``,
    the tracks of the heads controlling the approach followed over the whole clip
    (:func:`~tsrkit.spatiotemporal.timeline.controlling_tracks` until the anchor frame, then
    :mod:`tsrkit.spatiotemporal.headpass`), and per frame the camera's image motion
    (:func:`~tsrkit.spatiotemporal.egomotion.image_motion`, which dates stops)."""
    start = time.perf_counter()
    tracks, made = recognise(clip, found.upstream, found.downstream, settings.top, settings.slack)
    height, width = clip.images[clip.first].shape[:2]
    described = [t.to_json() for t in tracks]
    chosen = {t["id"] for t in controlling_tracks(described, (width, height), found.anchor)}
    heads = [follow_head(clip, t) for t in tracks if t.id in chosen]
    return {
        "traversal": number,
        **found.traversal.to_json(signals),
        "first_frame": found.first,
        "last_frame": found.last,
        "anchor_frame": found.anchor,
        "short_range": [found.upstream, found.downstream],
        "tracks_first_pass": made,
        "tracks": described,
        "heads": [t.to_json() for t in heads],
        "image_motion": {str(k): round(v, 3) for k, v in image_motion(clip.images).items()},
        "calls": dict(clip.calls),
        "seconds": round(time.perf_counter() - start, 3),
    }


#: The fields a cached traversal record must hold to be used.
CACHED_FIELDS = (
    "intersection",
    "movement",
    "first_frame",
    "last_frame",
    "anchor_frame",
    "short_range",
    "tracks",
)


def read_cached(path: Path) -> dict[str, Any] | None:
    """The traversal record cached at ``path``, or None when there is none or it cannot be
    used (not a regular file, too large, cut short, edited by hand): the traversal is then
    computed again and the entry rewritten."""
    if not path.is_file():
        return None
    try:
        record = read_json(path, MAX_CACHE_ENTRY)
    except (InputFileError, OSError):
        return None
    if not isinstance(record, dict) or not all(k in record for k in CACHED_FIELDS):
        return None
    tracks, short = record["tracks"], record["short_range"]
    if not isinstance(tracks, list) or not all(isinstance(t, dict) for t in tracks):
        return None
    return record if isinstance(short, list) and len(short) == 2 else None


def track_video(
    video: str,
    track: Track,
    signals: Signals,
    selection: Selection,
    settings: TrackSettings,
    start_utc: float | None = None,
    cache_dir: str | os.PathLike | None = None,
    on_frames: Callable[[int], None] | None = None,
) -> Iterator[dict[str, Any]]:
    """One record per traversal of ``video`` (frame 0 at ``start_utc``, default the first GPS
    fix), in time order; ``on_frames(n)`` is told each clip's frame count when it is done."""
    fps, count = video_facts(video)
    start = float(track.time[0]) if start_utc is None else float(start_utc)
    found = frame_traversals(
        track, signals, start, fps, count, settings.vicinity, settings.upstream, settings.downstream
    )
    pipeline = selection.pipeline()
    regional = Pipeline(pipeline.detector, pipeline.classifier, None, pipeline.verifier)
    key_base = identity(selection, settings)
    for number, item in enumerate(found):
        images, digest = decode_clip(video, item.first, item.last)
        key = hashlib.sha256((digest + key_base).encode()).hexdigest()
        cached = Path(cache_dir, key[:2], f"{key}.json") if cache_dir else None
        record = read_cached(cached) if cached is not None else None
        if record is not None:
            record = {**record, "traversal": number, "cached": True}
        else:
            clip = Clip(video, images, pipeline, regional, settings.margin, settings.roi_top)
            record = traversal_record(number, item, signals, clip, settings)
            if cached is not None:
                write_json(cached, record, indent=None)
        if on_frames is not None:
            on_frames(len(images))
        yield {**record, "fps": fps, "start_utc": start}
