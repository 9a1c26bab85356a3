"""Zheng 2016's five light conditions (Figure 4-2) on hand-made frames, and ``--lighting``."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from benchmark_fakes import OracleDetector, hand_dataset, make
from click.testing import CliRunner

from tsrkit.cli.main import cli
from tsrkit.core.errors import TsrkitError
from tsrkit.core.types import Dataset
from tsrkit.eval.lighting import ZHENG_CONDITIONS, ZHENG_RULE, frame_condition, zheng_condition
from tsrkit.reporting.benchmarking import benchmark, with_sun_elevation


def frame(sky_bgr, ground_bgr, height=30, width=20):
    """A frame whose top third is ``sky_bgr`` and the rest ``ground_bgr``."""
    image = np.empty((height, width, 3), np.uint8)
    image[: height // 3] = sky_bgr
    image[height // 3 :] = ground_bgr
    return image


def dark_with_lamps(share):
    """A night frame (V 10) with ``share`` of its pixels lit at V 220."""
    image = np.full((20, 20, 3), 10, np.uint8)
    image.reshape(-1, 3)[: int(share * 400)] = 220
    return image


@pytest.mark.parametrize(
    "image, expected",
    [
        (frame((230, 160, 90), (120, 120, 120)), "sunny"),  # blue sky
        (frame((235, 235, 235), (120, 120, 120)), "cloudy"),  # white, saturated-bright sky
        (frame((255, 255, 255), (255, 255, 255)), "cloudy"),  # blown out, no colour
        (frame((70, 70, 80), (50, 50, 55)), "dawn_dusk"),  # dim and grey
        (dark_with_lamps(0.06), "dark_lit"),
        (dark_with_lamps(0.0), "dark_unlit"),
        (np.zeros((8, 8, 3), np.uint8), "dark_unlit"),
    ],
)
def test_image_statistics_name_each_condition(image, expected):
    assert zheng_condition(image) == expected


def test_solar_elevation_decides_day_twilight_and_night():
    grey_day = frame((235, 235, 235), (120, 120, 120))
    assert zheng_condition(grey_day, sun_elevation=30.0) == "cloudy"
    assert zheng_condition(grey_day, sun_elevation=0.0) == "dawn_dusk"
    assert zheng_condition(grey_day, sun_elevation=-12.0) == "dark_lit"
    assert zheng_condition(dark_with_lamps(0.0), sun_elevation=-12.0) == "dark_unlit"
    lamps = dark_with_lamps(0.06)
    assert [zheng_condition(lamps, e) for e in (40, 0, -40)] == ["cloudy", "dawn_dusk", "dark_lit"]


def test_bad_input_is_one_clear_error():
    with pytest.raises(ValueError, match="sun elevation must be a finite"):
        zheng_condition(np.zeros((4, 4, 3), np.uint8), sun_elevation=float("nan"))
    with pytest.raises(ValueError, match="lighting must be one of mascetti, zheng"):
        frame_condition(np.zeros((4, 4, 3), np.uint8), "lux")
    with pytest.raises(ValueError, match="expected a BGR image"):
        zheng_condition(np.zeros((4, 4), np.uint8))


def test_benchmark_lighting_zheng_names_zheng_conditions_and_states_the_rule():
    data = hand_dataset(4)
    default = benchmark(data, make(OracleDetector), cache=False)
    zheng = benchmark(data, make(OracleDetector), cache=False, lighting="zheng")
    names = {row["lighting"] for row in zheng["categories"]}
    assert names and names <= set(ZHENG_CONDITIONS)
    assert "lighting categories: " + ZHENG_RULE in zheng.get("notes", [])
    assert not any("lighting categories" in n for n in default.get("notes", []))
    with pytest.raises(TsrkitError, match="lighting must be one of"):
        benchmark(data, make(OracleDetector), cache=False, lighting="lux")


def test_cli_refuses_an_unknown_lighting_scheme_in_one_line():
    for verb in ("benchmark", "compare"):
        result = CliRunner().invoke(cli, [verb, "--lighting", "lux"])
        assert result.exit_code == 2
        assert "'lux' is not one of 'mascetti', 'zheng'" in result.output


def test_time_and_position_decide_the_period_in_a_benchmark():
    data = hand_dataset(2)
    noon, night = "2024-06-21T12:00:00Z", "2024-06-21T00:00:00Z"
    samples = tuple(
        dataclasses.replace(s, metadata={**s.metadata, "utc": utc, "lat": 0.0, "lon": 0.0})
        for s, utc in zip(data.samples, (noon, night), strict=True)
    )
    report = benchmark(
        Dataset("timed", samples), make(OracleDetector), cache=False, lighting="zheng"
    )
    # frame 0 is black (mean V 0), frame 1 a flat grey: the Sun, not the pixels, says day
    assert {row["lighting"] for row in report["categories"]} == {"cloudy", "dark_unlit"}
    assert with_sun_elevation(samples)[0].metadata["sun_elevation"] > 60
