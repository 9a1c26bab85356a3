"""The synthetic scene generator: determinism, labels that match the pixels, outputs on disk."""

from __future__ import annotations

import multiprocessing
from collections import Counter
from pathlib import Path

import cv2
import numpy as np
import pytest
from click.testing import CliRunner

from tsrkit.core.errors import TsrkitError
from tsrkit.datasets import scenes as synth
from tsrkit.eval.lighting import mean_v
from tsrkit.plugin.registry import get_registry

#: OpenCV hue ranges (0-179) that vote for each state; cf. Mascetti Table 6 and 4.1.
HUE_RANGES = {"red": ((0, 10), (160, 179)), "yellow": ((11, 34),), "green": ((60, 100),)}


def files_of(folder: Path) -> dict[str, bytes]:
    return {
        p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def generated_files(folder: Path, frames: int, seed: int) -> dict[str, bytes]:
    synth.generate(folder, frames, seed)
    return files_of(folder)


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    """18 frames (6 per lighting) of seed 1, written once for the module."""
    out = tmp_path_factory.mktemp("synth") / "ds"
    return out, synth.generate(out, 18, 1)


def hue_votes(hsv: np.ndarray, x: float, y: float, radius: float) -> Counter:
    """Saturated, bright pixels within 2r of the centre, counted by the state their hue means."""
    h, w = hsv.shape[:2]
    yy, xx = np.mgrid[:h, :w]
    reach = max(2 * radius, 3.0)
    inside = (xx + 0.5 - x) ** 2 + (yy + 0.5 - y) ** 2 <= reach**2
    hue, sat, val = (hsv[..., k][inside].astype(int) for k in range(3))
    colourful = (sat >= 50) & (val >= 90)
    return Counter(
        {
            state: int(sum(((hue >= lo) & (hue <= hi) & colourful).sum() for lo, hi in ranges))
            for state, ranges in HUE_RANGES.items()
        }
    )


def test_same_arguments_give_identical_files_and_other_seeds_differ(tmp_path):
    a = generated_files(tmp_path / "a", 4, 7)
    b = generated_files(tmp_path / "b", 4, 7)
    c = generated_files(tmp_path / "c", 4, 8)
    assert set(a) >= {"annotations.json", "coco.json", "synth.json", "images/000003.jpg"}
    assert a == b
    assert a.keys() == c.keys()
    assert all(a[k] != c[k] for k in a if k.startswith("images/"))
    assert a["annotations.json"] != c["annotations.json"]


def test_every_annotated_lens_is_lit_in_its_colour(generated):
    _, dataset = generated
    checked = night_cores = 0
    for sample in dataset:
        hsv = cv2.cvtColor(cv2.imread(sample.source), cv2.COLOR_BGR2HSV)
        for ann in sample.annotations:
            x, y = ann.center
            votes = hue_votes(hsv, x, y, ann.attributes["radius"])
            assert votes.most_common(1)[0][0] == ann.state, (sample.source, ann, votes)
            assert hsv[int(y), int(x), 2] >= 120, (sample.source, ann)  # the centre is lit
            checked += 1
            if sample.metadata["lighting"] == "night" and ann.attributes["radius"] >= 3:
                # Zheng 4.2: an overexposed, near-white core; the colour is in the halo
                centre = hsv[int(y), int(x)]
                night_cores += centre[2] >= 235 and centre[1] < 150
    assert checked >= 18
    assert night_cores >= 2


def test_lighting_classes_separate_by_mean_brightness(generated):
    _, dataset = generated
    by_light: dict[str, list[float]] = {}
    for sample in dataset:
        by_light.setdefault(sample.metadata["lighting"], []).append(mean_v(sample.load().image))
    assert {k: len(v) for k, v in by_light.items()} == {"day": 6, "dusk": 6, "night": 6}
    assert min(by_light["day"]) > max(by_light["dusk"])
    assert min(by_light["dusk"]) > max(by_light["night"])


def test_boxes_are_lens_boxes_inside_the_image_with_balanced_splits(generated):
    _, dataset = generated
    radii = []
    for sample in dataset:
        for ann in sample.annotations:
            x0, y0, x1, y1 = ann.bbox
            assert 0 <= x0 < x1 <= sample.width and 0 <= y0 < y1 <= sample.height
            r = ann.attributes["radius"]
            assert x1 - x0 == pytest.approx(2 * r, abs=2e-3)
            assert y1 - y0 == pytest.approx(2 * r, abs=2e-3)
            hx0, hy0, hx1, hy1 = ann.attributes["housing"]
            assert hx0 <= x0 and hy0 <= y0 and x1 <= hx1 and y1 <= hy1
            radii.append(r)
    assert min(radii) >= 1.5 and max(radii) <= 9.0
    assert Counter((s.metadata["lighting"], s.split) for s in dataset) == {
        (light, split): 3 for light in synth.LIGHTINGS for split in ("train", "test")
    }


def test_coco_and_normalized_outputs_agree(generated):
    out, dataset = generated
    registry = get_registry()
    normalized = registry.create("format", "normalized").read(out / "annotations.json")
    coco = registry.create("format", "coco").read(out / "coco.json")

    def facts(ds):
        return [
            (
                Path(s.source).resolve(),
                s.split,
                s.metadata["lighting"],
                [
                    (tuple(round(v, 3) for v in a.bbox), a.state, a.attributes["radius"])
                    for a in s.annotations
                ],
            )
            for s in ds
        ]

    assert facts(normalized) == facts(coco) == facts(dataset)
    assert sum(len(s.annotations) for s in coco) == sum(len(s.annotations) for s in dataset)


def test_sample_path_generates_once_and_is_reused(tmp_path, monkeypatch):
    monkeypatch.setenv("TSRKIT_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(synth, "SAMPLE_FRAMES", 3)
    calls = []
    real = synth.generate
    monkeypatch.setattr(synth, "generate", lambda *a, **k: calls.append(a) or real(*a, **k))
    first = synth.sample_path()
    stamp = first.stat().st_mtime_ns
    second = synth.sample_path()
    assert first == second == tmp_path / f"sample-v{synth.GENERATOR_VERSION}" / "annotations.json"
    assert len(calls) == 1 and first.stat().st_mtime_ns == stamp
    assert len(list((first.parent / "images").glob("*.jpg"))) == 3


def _generate_into(out: str) -> None:
    synth.generate(out, 3, 5)


def test_racing_processes_publish_one_complete_folder(tmp_path):
    out = tmp_path / "race"
    with multiprocessing.get_context("fork").Pool(2) as pool:
        pool.map(_generate_into, [str(out)] * 2)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["race"]  # no temp folder left
    assert len(synth.generate(out, 3, 5)) == 3  # same arguments over it: accepted
    assert files_of(out) == generated_files(tmp_path / "again", 3, 5)


def test_existing_folder_with_other_data_needs_overwrite(tmp_path):
    out = tmp_path / "ds"
    synth.generate(out, 2, 0)
    with pytest.raises(TsrkitError, match="overwrite"):
        synth.generate(out, 2, 1)
    dataset = synth.generate(out, 2, 1, overwrite=True)
    assert dataset.samples[0].source == str(out / "images" / "000000.jpg")
    assert synth._read_stamp(out)["seed"] == 1


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"frames": 0}, "frames"),
        ({"lighting": ("noon",)}, "lighting"),
        ({"quality": 0}, "quality"),
        ({"colour": 1}, "unknown synth option"),
    ],
)
def test_bad_arguments_are_rejected(tmp_path, kwargs, message):
    args = {"frames": 2, "seed": 0, **kwargs}
    with pytest.raises(ValueError, match=message):
        synth.generate(tmp_path / "x", **args)
    assert not (tmp_path / "x").exists()


def test_cli_writes_the_dataset_and_reports_mistakes_in_one_line(tmp_path):
    from tsrkit.cli.main import cli

    runner = CliRunner()
    result = runner.invoke(
        cli,
        [
            "datasets",
            "synth",
            "--out",
            str(tmp_path / "s"),
            "--frames",
            "3",
            "--seed",
            "2",
            "--lighting",
            "night",
        ],
    )
    assert result.exit_code == 0, result.output
    assert "wrote 3 frames" in result.output
    dataset = get_registry().create("format", "normalized").read(tmp_path / "s")
    assert {s.metadata["lighting"] for s in dataset} == {"night"}
    bad = runner.invoke(
        cli, ["datasets", "synth", "--out", str(tmp_path / "t"), "--lighting", "noon"]
    )
    assert bad.exit_code == 2 and "lighting" in bad.output and "Traceback" not in bad.output


def test_generate_reports_each_rendered_frame(tmp_path):
    calls = []
    synth.generate(tmp_path / "s", frames=3, seed=2, on_frame=lambda: calls.append(len(calls)))
    assert calls == [0, 1, 2]
