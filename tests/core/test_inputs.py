"""Input decoding: every image format to BGR uint8, bad files skipped with a reason, videos."""

import cv2
import numpy as np
import pytest

from tsrkit.core.types import Frame, Skipped
from tsrkit.runner.inputs import ImageReadError, iter_frames, read_image, to_bgr8


def scene(h=24, w=32):
    rng = np.random.default_rng(0)
    image = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
    image[4:10, 5:12] = (0, 0, 255)
    return image


@pytest.mark.parametrize("ext", [".png", ".ppm", ".bmp", ".tiff", ".webp"])
def test_lossless_formats_round_trip(tmp_path, ext):
    image = scene()
    path = tmp_path / f"a{ext}"
    params = [cv2.IMWRITE_WEBP_QUALITY, 101] if ext == ".webp" else []
    assert cv2.imwrite(str(path), image, params)
    out = read_image(path)
    assert out.dtype == np.uint8 and out.shape == image.shape
    np.testing.assert_array_equal(out, image)


def test_jpeg_is_decoded(tmp_path):
    ramp = np.linspace(0, 255, 32, dtype=np.uint8)
    image = np.dstack([np.tile(ramp, (24, 1))] * 3)
    cv2.imwrite(str(tmp_path / "a.jpg"), image, [cv2.IMWRITE_JPEG_QUALITY, 100])
    out = read_image(tmp_path / "a.jpg")
    assert out.shape == image.shape and np.abs(out.astype(int) - image).max() <= 3


def test_sixteen_bit_png_is_scaled_to_eight_bits(tmp_path):
    deep = np.zeros((4, 4, 3), np.uint16)
    deep[0, 0] = (65535, 32768, 257)
    cv2.imwrite(str(tmp_path / "deep.png"), deep)
    out = read_image(tmp_path / "deep.png")
    assert out.dtype == np.uint8
    assert out[0, 0].tolist() == [255, 128, 1]
    assert out[1, 1].tolist() == [0, 0, 0]


def test_rgba_drops_alpha_and_gray_is_promoted(tmp_path):
    rgba = np.zeros((4, 5, 4), np.uint8)
    rgba[..., :3] = (10, 20, 30)
    rgba[..., 3] = 0
    cv2.imwrite(str(tmp_path / "rgba.png"), rgba)
    assert read_image(tmp_path / "rgba.png")[0, 0].tolist() == [10, 20, 30]
    gray = np.full((4, 5), 77, np.uint8)
    cv2.imwrite(str(tmp_path / "gray.png"), gray)
    out = read_image(tmp_path / "gray.png")
    assert out.shape == (4, 5, 3) and out[2, 2].tolist() == [77, 77, 77]
    assert to_bgr8(np.full((1, 1), 1.0, np.float32)).tolist() == [[[255, 255, 255]]]


def test_bad_files_raise_with_the_reason(tmp_path):
    (tmp_path / "empty.png").write_bytes(b"")
    good = cv2.imencode(".jpg", scene(64, 64))[1].tobytes()
    (tmp_path / "cut.jpg").write_bytes(good[: len(good) // 2])
    png = cv2.imencode(".png", scene(64, 64))[1].tobytes()
    (tmp_path / "cut.png").write_bytes(png[: len(png) // 2])
    (tmp_path / "fake.png").write_text("not an image at all")
    cases = {
        "empty.png": "empty file",
        "cut.jpg": "truncated JPEG",
        "cut.png": "truncated PNG",
        "fake.png": "not a decodable image",
        "missing.png": "no such file",
    }
    for name, reason in cases.items():
        with pytest.raises(ImageReadError, match=reason):
            read_image(tmp_path / name)


def test_folder_is_recursive_sorted_and_reports_skips(tmp_path):
    cv2.imwrite(str(tmp_path / "b.png"), scene())
    (tmp_path / "sub").mkdir()
    cv2.imwrite(str(tmp_path / "sub" / "a.png"), scene())
    (tmp_path / "notes.txt").write_text("hello")
    (tmp_path / ".hidden.png").write_bytes(b"")
    (tmp_path / "zero.jpg").write_bytes(b"")
    items = list(iter_frames([tmp_path, tmp_path / "nope.png"]))
    frames = [i.source for i in items if isinstance(i, Frame)]
    skipped = {i.source.rsplit("/", 1)[-1]: i.reason for i in items if isinstance(i, Skipped)}
    assert [f.rsplit("/", 2)[-2:] for f in frames] == [[tmp_path.name, "b.png"], ["sub", "a.png"]]
    assert set(skipped) == {"notes.txt", "zero.jpg", "nope.png"}
    assert "unsupported type '.txt'" in skipped["notes.txt"]
    assert skipped["zero.jpg"] == "empty file"


@pytest.fixture(scope="module")
def video(tmp_path_factory):
    """A 10-frame MJPG video whose frame i is uniformly grey at level 20 * i."""
    path = tmp_path_factory.mktemp("video") / "clip.avi"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 10.0, (32, 24))
    assert writer.isOpened()
    for i in range(10):
        writer.write(np.full((24, 32, 3), 20 * i, np.uint8))
    writer.release()
    return path


def test_video_frames_are_stepped(video):
    frames = list(iter_frames([video], every=2, start=1, end=8))
    assert [f.index for f in frames] == [1, 3, 5, 7]
    assert [round(float(f.image.mean()) / 20) for f in frames] == [1, 3, 5, 7]
    assert frames[1].timestamp == pytest.approx(0.3)
    assert len(list(iter_frames([video]))) == 10


def test_unreadable_video_is_skipped(tmp_path):
    (tmp_path / "bad.mp4").write_bytes(b"\x00" * 100)
    items = list(iter_frames([tmp_path / "bad.mp4"]))
    assert len(items) == 1 and isinstance(items[0], Skipped)


def test_invalid_stepping_is_refused(video):
    with pytest.raises(ValueError):
        list(iter_frames([video], every=0))
