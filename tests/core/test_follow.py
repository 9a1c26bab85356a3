"""Key frames and following: between key frames the lights of the frame before are found again
by a search around them, a light appearing meanwhile waits for the next key frame, and the whole
frame is searched only on key frames."""

import cv2
import numpy as np
import pytest

import tsrkit
from tsrkit.core.types import Candidate, Frame
from tsrkit.plugin.pipeline import Pipeline
from tsrkit.runner.follow import Follower, region, shifted, windows


class RedDiscs(tsrkit.Detector):
    """Every red blob, at its centroid; remembers the sizes of the images it searched."""

    name = "red-discs"

    def __init__(self, **params):
        super().__init__(**params)
        self.searched = []

    def detect(self, frame):
        self.searched.append(frame.image.shape[:2])
        mask = ((frame.image[..., 2] > 200) & (frame.image[..., 1] < 60)).astype(np.uint8)
        _, _, stats, centres = cv2.connectedComponentsWithStats(mask)
        return [
            Candidate.from_circle(x, y, max(stats[k, 2], stats[k, 3]) / 2, 1.0, "red")
            for k, (x, y) in enumerate(centres)
            if k > 0
        ]


def drive(frames=12):
    """Frames of 120x160 with two red discs moving 2 px right and 1 px down a frame; a third
    appears on frame 5."""
    images = []
    for t in range(frames):
        image = np.zeros((120, 160, 3), np.uint8)
        cv2.circle(image, (30 + 2 * t, 30 + t), 4, (0, 0, 255), -1)
        cv2.circle(image, (100 + 2 * t, 40 + t), 3, (0, 0, 255), -1)
        if t >= 5:
            cv2.circle(image, (60, 90), 4, (0, 0, 255), -1)
        images.append(Frame(image, "drive.mp4", t))
    return images


def centres(result):
    return sorted((round(d.candidate.x), round(d.candidate.y)) for d in result.detections)


def test_lights_are_followed_between_key_frames_and_new_ones_wait_for_the_next():
    detector = RedDiscs()
    follower = Follower(Pipeline(detector), key_every=4)
    followed = [centres(follower.process(f)) for f in drive()]
    every = [centres(Pipeline(RedDiscs()).process(f)) for f in drive()]
    for t, (mine, full) in enumerate(zip(followed, every)):
        if t in (5, 6, 7):  # the third disc appears between key frames 4 and 8
            assert mine == [c for c in full if c != (60, 90)], t
        else:
            assert mine == full, t
    whole = [shape for shape in detector.searched if shape == (120, 160)]
    assert len(whole) == 3 and follower.calls["key"] == 3  # frames 0, 4, 8
    assert follower.calls["followed"] == 9
    assert follower.calls["regions"] == 18  # a window around each disc on each followed frame


def test_another_video_or_a_jump_back_starts_with_a_key_frame():
    detector = RedDiscs()
    follower = Follower(Pipeline(detector), key_every=10)
    images = drive(3)
    follower.process(images[0])
    follower.process(Frame(images[1].image, "other.mp4", 1))
    follower.process(Frame(images[2].image, "other.mp4", 0))
    assert follower.calls["key"] == 3


def test_a_light_leaving_the_frame_is_dropped():
    image = np.zeros((60, 60, 3), np.uint8)
    cv2.circle(image, (55, 30), 3, (0, 0, 255), -1)
    follower = Follower(Pipeline(RedDiscs()), key_every=5)
    assert len(follower.process(Frame(image, "v.mp4", 0)).detections) == 1
    assert follower.process(Frame(np.zeros_like(image), "v.mp4", 1)).detections == ()


def test_a_detection_moves_with_its_crop():
    candidate = Candidate(5.0, 6.0, 2.0, (3.0, 4.0, 7.0, 8.0), 1.0, housing=(2.0, 0.0, 8.0, 14.0))
    moved = shifted(candidate, 10, 20)
    assert (moved.x, moved.y, moved.bbox, moved.housing) == (
        15.0,
        26.0,
        (13.0, 24.0, 17.0, 28.0),
        (12.0, 20.0, 18.0, 34.0),
    )
    assert region(5.0, 5.0, 4.0, 2.0, 30, 20) == (0, 0, 21, 20)


def test_a_follower_refuses_a_tracker_and_bad_settings():
    tracked = Pipeline(RedDiscs(), tracker=tsrkit.tracker("meanshift"))
    with pytest.raises(ValueError, match="replaces the tracker"):
        Follower(tracked)
    with pytest.raises(ValueError, match="key_every >= 1"):
        Follower(Pipeline(RedDiscs()), key_every=0)


def test_overlapping_windows_are_searched_as_one():
    assert windows([(0, 0, 10, 10), (30, 0, 40, 10), (10, 5, 20, 20)]) == [
        (0, 0, 20, 20),
        (30, 0, 40, 10),
    ]
