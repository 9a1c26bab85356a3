"""Zheng 2016's spatiotemporal framework on video (3.4.4-3.4.5, 5.4): short-range initialisation
(optical flow, colour state machine), long-range tracked recognition, temporal accuracy.

``track_video`` runs it on a video with its GPS log and map (:mod:`tsrkit.geo` finds the
traversals); ``recognise`` on one clip; ``temporal_accuracy`` scores tracks against ground truth.
"""

from tsrkit.spatiotemporal.association import association_score
from tsrkit.spatiotemporal.clip import Clip
from tsrkit.spatiotemporal.flow import project
from tsrkit.spatiotemporal.passes import recognise
from tsrkit.spatiotemporal.points import Point, Track
from tsrkit.spatiotemporal.ranges import frame_traversals, short_range
from tsrkit.spatiotemporal.run import TrackSettings, VideoError, track_video

__all__ = [
    "Clip",
    "Point",
    "Track",
    "TrackSettings",
    "VideoError",
    "association_score",
    "frame_traversals",
    "project",
    "recognise",
    "short_range",
    "track_video",
]
