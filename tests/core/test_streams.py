"""Pipelines over images and videos in worker processes: the serial records, in input order."""

import json

import cv2
import numpy as np
import pytest
from benchmark_fakes import FrameCrasher, UntrainedDetector, make

import tsrkit
from tsrkit.core.errors import TsrkitError
from tsrkit.core.types import Skipped
from tsrkit.plugin.pipeline import Pipeline
from tsrkit.runner.follow import Follower
from tsrkit.runner.inputs import Work, iter_video, plan_work
from tsrkit.runner.streams import CHUNK_FRAMES, run_pipeline
from tsrkit.synth import sample_path


@pytest.fixture(scope="module")
def video(tmp_path_factory):
    """An MPEG-4 clip (key frames every 12 frames) of the sample's frames, 150 frames long."""
    images = sorted((sample_path().parent / "images").glob("*.jpg"))
    path = tmp_path_factory.mktemp("video") / "drive.mp4"
    first = cv2.imread(str(images[0]))
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"mp4v"), 25.0, first.shape[1::-1])
    assert writer.isOpened()
    for i in range(150):
        writer.write(cv2.imread(str(images[i % len(images)])))
    writer.release()
    return path


def records(stream):
    out = []
    for result, _ in stream:
        if isinstance(result, Skipped):
            out.append(("skipped", result.source, result.reason))
        else:
            record = result.to_record()
            record.pop("ms")
            out.append(json.dumps(record, sort_keys=True))
    return out


def pipeline():
    return Pipeline(tsrkit.detector("gray-tophat"))


def test_seeking_decodes_the_same_pixels_as_reading_from_the_start(video):
    serial = {f.index: f.image for f in iter_video(video)}
    for start in (1, 13, 64, 100):
        for frame in iter_video(video, 1, start, start + 3):
            assert np.array_equal(frame.image, serial[frame.index]), (start, frame.index)


def test_video_chunks_cover_the_kept_frames_once(video):
    units = list(plan_work([video], every=3, start=5, end=140, chunk=10))
    assert all(isinstance(u, Work) and u.video for u in units)
    assert [(u.start, u.end) for u in units] == [(5, 35), (35, 65), (65, 95), (95, 125), (125, 140)]


def test_workers_give_the_serial_records_in_order(video, tmp_path):
    bad = tmp_path / "broken.jpg"
    bad.write_bytes(b"not a jpeg")
    good = sorted((sample_path().parent / "images").glob("*.jpg"))[:3]
    inputs = [str(good[0]), str(video), str(bad), *map(str, good[1:])]
    serial = records(run_pipeline(pipeline(), inputs))
    parallel = records(run_pipeline(pipeline(), inputs, workers=2))
    assert len(serial) == 1 + 150 + 1 + 2 > CHUNK_FRAMES * 2
    assert parallel == serial
    assert serial[151][0] == "skipped"
    stepped = dict(every=3, start=5, end=140)
    assert records(run_pipeline(pipeline(), [video], workers=2, **stepped)) == records(
        run_pipeline(pipeline(), [video], **stepped)
    )


def test_a_follower_gives_the_same_records_whatever_the_workers(video):
    """Chunks of 60 frames (a multiple of 5) start on key frames: each run of frames after a
    key frame is processed the same way in one process or in two."""
    follower = Follower(Pipeline(tsrkit.detector("conspicuity")), key_every=5)
    serial = records(run_pipeline(follower, [video]))
    assert records(run_pipeline(follower, [video], workers=2)) == serial
    assert len(serial) == 150


def test_in_a_worker_a_crashing_plugin_costs_its_frame_and_a_setup_error_ends_the_run(video):
    """Frame 70 lies in the second chunk, processed by a worker: it is skipped in place, as
    when run here; a setup problem raised in a worker (no model) reaches the caller."""
    crashing = Pipeline(make(FrameCrasher, crash_at=70))
    serial = records(run_pipeline(crashing, [video]))
    assert records(run_pipeline(crashing, [video], workers=2)) == serial
    assert [i for i, r in enumerate(serial) if r[0] == "skipped"] == [70]
    assert serial[70][1].endswith("drive.mp4#70")
    assert "plugin error: RuntimeError: deliberate crash" in serial[70][2]
    with pytest.raises(TsrkitError, match="needs a model"):
        list(run_pipeline(Pipeline(make(UntrainedDetector)), [video], workers=2))


def test_a_tracker_needs_one_worker(video):
    tracked = Pipeline(tsrkit.detector("gray-tophat"), tracker=tsrkit.tracker("meanshift"))
    with pytest.raises(TsrkitError, match="one worker"):
        next(run_pipeline(tracked, [video], workers=2))
