"""Zheng's extended k-d tree (3.4.2) against the basic k-d tree query: the same nearest
intersection on a long synthetic drive and on the real Seattle drive at video frame times, with
far fewer searches; and the one case Condition 3-1 does not cover."""

import numpy as np
from conftest import shared_datasets_dir
from scipy.spatial import cKDTree

from tsrkit.geo import Track, read_signals, read_track, traversals
from tsrkit.geo.nearest import TAU_MIN, nearest_extended, nearest_kdtree
from tsrkit.geo.simulate import grid_city, grid_drive
from tsrkit.geo.vicinity import vicinity_profile

SET = shared_datasets_dir() / "nk_seattle_gps_bellevue_osm"


class CountingTree(cKDTree):
    searched = 0

    def query(self, x, *args, **kwargs):
        self.searched += len(x)
        return super().query(x, *args, **kwargs)


def test_a_long_synthetic_drive_gets_the_basic_answer_from_a_tenth_of_the_searches():
    city = grid_city(30, seed=3)
    times, points = grid_drive(30, 200_000, fps=14.0, seed=4)  # 4 h of video frames
    tree = CountingTree(city)
    index, distance = nearest_extended(tree, points, times, TAU_MIN)
    basic, basic_distance = nearest_kdtree(cKDTree(city), points)
    np.testing.assert_array_equal(index, basic)
    np.testing.assert_allclose(distance, basic_distance, atol=1e-9)
    assert len(np.unique(basic)) > 100  # the drive crossed many regions
    assert tree.searched < len(points) / 10


def test_the_seattle_drive_at_14_fps_gets_the_same_vicinity_and_traversals():
    fixes = read_track(SET / "gps_data.txt")
    signals = read_signals(SET / "map-issue147.osm.gz")
    frame_times = np.arange(fixes.time[0], fixes.time[-1], 1 / 14)
    lat, lon = fixes.at(frame_times)  # Eq. 4.2; gaps are NaN and left out
    keep = np.isfinite(lat)
    frames = Track("frames", frame_times[keep], lat[keep], lon[keep])
    assert len(frames) > 100_000
    basic, basic_distance, _ = vicinity_profile(frames, signals)
    extended, distance, _ = vicinity_profile(frames, signals, tau_min=TAU_MIN)
    np.testing.assert_array_equal(extended, basic)
    np.testing.assert_allclose(distance, basic_distance, atol=1e-6)
    assert len(set(basic[basic_distance < 30])) >= 10
    assert traversals(frames, signals, 30.0)  # the frames pass signals


def test_condition_3_1_is_an_assumption_a_corner_clip_within_tau_breaks():
    tree = cKDTree([[0.0, 0.0], [100.0, 0.0]])
    points = np.array([[0.0, 1.0], [60.0, 1.0], [0.0, 1.0]])  # out of region 0 and back
    times = np.array([0.0, 1.0, 2.0])
    assert list(nearest_kdtree(tree, points)[0]) == [0, 1, 0]
    assert list(nearest_extended(tree, points, times, tau_min=1.5)[0]) == [0, 1, 0]
    assert list(nearest_extended(tree, points, times, tau_min=10.0)[0]) == [0, 0, 0]


def test_empty_and_single_positions():
    tree = cKDTree([[0.0, 0.0], [10.0, 0.0]])
    index, distance = nearest_extended(tree, np.zeros((0, 2)), np.zeros(0))
    assert index.shape == distance.shape == (0,)
    index, distance = nearest_extended(tree, np.array([[9.0, 0.0]]), np.zeros(1))
    assert list(index) == [1] and distance[0] == 1.0
