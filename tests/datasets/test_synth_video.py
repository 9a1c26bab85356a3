"""tsrkit datasets synth --video: the frames as a video that the video input reads back."""

from __future__ import annotations

from click.testing import CliRunner

import tsrkit
from tsrkit.cli.main import cli


def test_synth_writes_a_video_of_its_frames(tmp_path):
    video = tmp_path / "drive.mp4"
    args = ["datasets", "synth", "--out", str(tmp_path / "s"), "--frames", "3"]
    result = CliRunner().invoke(
        cli, [*args, "--width", "160", "--height", "96", "--video", str(video)]
    )
    assert result.exit_code == 0, result.output
    frames = list(tsrkit.iter_frames([str(video)]))
    assert len(frames) == 3
    assert frames[0].image.shape == (96, 160, 3)
    assert [f.index for f in frames] == [0, 1, 2]
