"""Zheng's conspicuity map (3.2.1): fast maps against the direct-correlation oracle, and
hand-computed micro images."""

import json
from itertools import pairwise

import cv2
import numpy as np
import pytest
from oracles.conspicuity_oracle import conspicuity_reference

import tsrkit
from tsrkit.core.types import Frame
from tsrkit_plugins.detectors.conspicuity import conspicuity as cs, conspicuity_kernel as ck
from tsrkit_plugins.detectors.conspicuity.colour import lightness_and_saturation


def random_image(seed, shape=(44, 57)):
    rng = np.random.default_rng(seed)
    return rng.integers(0, 256, (*shape, 3), dtype=np.uint8)


def lit_disk(radius, shape=(60, 64), centre=(31, 29), colour=(40, 200, 60)):
    image = np.full((*shape, 3), 30, np.uint8)
    cv2.circle(image, (centre[1], centre[0]), radius, colour, -1)
    return image


def assert_matches_oracle(image, **settings):
    fast = cs.conspicuity_map(image, **settings)
    values, radius, stack = conspicuity_reference(image, **settings)
    assert np.abs(fast.values - values).max() <= 1e-4
    # The arg-max radius must agree wherever the oracle's best radius is not a near tie.
    radii = sorted(set(settings.get("radii", range(1, 11))))
    at_fast = np.take_along_axis(stack, np.searchsorted(radii, fast.radius)[None], 0)[0]
    assert np.all((fast.radius == radius) | (np.abs(at_fast - values) <= 1e-4))


@pytest.mark.parametrize(
    "seed, settings",
    [
        (0, {}),
        (1, {"quadrant_rule": "min"}),
        (2, {"margin": 2, "weights": (1.0, 2.0, 0.5)}),
        (3, {"radii": (2, 3, 5), "weights": (2.0, 1.0, 4.0)}),
        (4, {"radii": (3, 12), "margin": 6}),
    ],
)
def test_fast_map_matches_oracle_on_random_images(seed, settings):
    assert_matches_oracle(random_image(seed), **settings)


def test_fast_map_matches_oracle_on_a_real_frame(shared_datasets):
    root = shared_datasets / "roboflow_traffic_light_kr"
    entry = next(e for e in json.loads((root / "annotations.json").read_text()) if e["boxes"])
    box = entry["boxes"][0]
    image = cv2.imread(str(root / entry["file"]))
    cx, cy = int((box["x_min"] + box["x_max"]) / 2), int((box["y_min"] + box["y_max"]) / 2)
    y0, x0 = max(0, cy - 30), max(0, cx - 35)
    assert_matches_oracle(np.ascontiguousarray(image[y0 : y0 + 60, x0 : x0 + 70]))


def kernel_window(tables, terms, row, col, count, out):
    """The kernel's sum of one window's terms at table row ``row``, columns ``col ..``."""
    mid = ck.positive_ends(terms, np.array([0, len(terms)]))[0]
    offsets = ck.flat_offsets(terms, tables.shape)
    base = row * tables.shape[2] + col
    ck.window_sum(tables.reshape(-1), offsets, 0, mid, len(terms), base, count, out)


def window_sums(channel, pad, windows, row, dtype=np.int32):
    """Kernel sums of several planned windows on one row of a channel mirrored by ``pad``, with
    tables and sums in ``dtype``."""
    tables = ck.prefix_tables(cs.mirror(channel, pad), dtype)
    out = np.zeros((len(windows), channel.shape[1]), dtype)
    for window, plan in zip(out, windows):
        terms = np.array(cs.kernel_terms(plan), np.int32)
        kernel_window(tables, terms, pad + 1 + row, pad, channel.shape[1], window)
    return out


def test_prefix_tables_are_row_prefixes_and_their_column_integrals():
    # Heights 44 (rows four at a time), 7 and 3 (with a tail of single rows).
    channels = [f(random_image(7)) for f in (cs.lightness, cs.saturation)]
    channels += [cs.saturation(random_image(7, (h, 9))) for h in (7, 3)]
    for channel in channels:
        tables = ck.prefix_tables(channel)
        prefix, integral = tables[ck.PREFIX], tables[ck.INTEGRAL]
        rows = np.cumsum(channel, axis=1, dtype=np.int64)
        assert not prefix[0].any() and not prefix[:, 0].any()
        assert np.array_equal(prefix[1:, 1:], rows)
        assert np.array_equal(integral[1:, 1:], np.cumsum(rows, axis=0))
        assert not integral[0].any() and not integral[:, 0].any()
        # int16 tables hold the same entries modulo 2**16 (they pass 32767 here).
        narrow = ck.prefix_tables(channel, np.int16)
        assert narrow.dtype == np.int16 and (tables.max() > 32767 or channel.shape[0] < 44)
        assert np.array_equal(narrow, tables.astype(np.int16))


def radius_inputs(tables, pad, radius, margin, row):
    """What the kernel combines for one radius on one image row: the four quarter staircases
    summed into buffers, the flat tables and the flat starts of the shared, corner and margin
    entries (None with margin 0)."""
    plan = cs.kernel_plan((radius,), margin)
    count = tables.shape[2] - 1 - 2 * pad
    base = (pad + 1 + row) * tables.shape[2] + pad
    flat = tables.reshape(-1)
    stairs = np.zeros((ck.LIGHT_WINDOWS, count), tables.dtype)
    offsets = ck.flat_offsets(plan.light_terms, tables.shape)
    for w, (a, b) in enumerate(pairwise(plan.light_starts)):
        ck.window_sum(flat, offsets, a, plan.light_mids[w], b, base, count, stairs[w])
    shared, corners = (
        tuple(int(base + o) for o in ck.flat_offsets(np.asarray(terms), tables.shape))
        for terms in (cs.SHARED_TERMS, plan.corners[0])
    )
    margins = None
    if plan.margins is not None:
        margins = tuple(int(base + o) for o in ck.flat_offsets(plan.margins[0], tables.shape))
    return stairs, flat, shared, corners, margins


def row_features(channel, radius, margin, row, use_min=False, dtype=np.int32):
    """The kernel's A1 sums and integer contrasts (Eq. 3.5-3.8) of one radius on one row."""
    pad = 2 * radius + margin
    tables = ck.prefix_tables(cs.mirror(channel, pad), dtype)
    count = channel.shape[1]
    disk, contrast = np.zeros(count, np.int64), np.zeros(count, np.int64)
    nq, nb = cs.quarter_disk_size(radius), (radius + margin + 1) ** 2
    inputs = radius_inputs(tables, pad, radius, margin, row)
    ck.light_features(*inputs, nq, nb, use_min, count, disk, contrast, dtype)
    return disk, contrast


def direct_features(channel, radius, margin, row, x):
    """The A1 sum and the integer contrast at one pixel, summed directly over masks."""
    pad = 2 * radius + margin
    r, s = radius, radius + margin
    padded = cs.mirror(channel, pad).astype(np.int64)
    cy, cx = pad + row, pad + x
    dy, dx = np.mgrid[-s : s + 1, -s : s + 1]
    window = padded[cy - s : cy + s + 1, cx - s : cx + s + 1]
    disk = np.hypot(dy, dx) <= r
    parts = []
    for v, h in cs.QUADRANTS:
        side = (v * dy >= 0) & (h * dx >= 0)
        quarter, box = int(window[disk & side].sum()), int(window[side].sum())
        parts.append((r + margin + 1) ** 2 * quarter - cs.quarter_disk_size(r) * box)
    return int(window[disk].sum()), parts


def test_lightness_windows_are_exact_integer_sums():
    light = cs.lightness(random_image(4))
    for radius, margin in ((1, 0), (4, 0), (10, 0), (3, 2)):
        disk, contrast = row_features(light, radius, margin, 7)
        low, _ = row_features(light, radius, margin, 7, use_min=True)
        for x in (0, 9, 30, 56):
            total, parts = direct_features(light, radius, margin, 7, x)
            assert disk[x] == total and low[x] == total
            assert contrast[x] == max(0, max(parts))
        _, strict = row_features(light, radius, margin, 7, use_min=True)
        assert all(
            strict[x] == max(0, min(direct_features(light, radius, margin, 7, x)[1]))
            for x in (0, 9, 30, 56)
        )


def test_window_sums_survive_wrapping_integrals():
    # Column integrals of a bright 3000 x 3000 frame pass 2**31; the window sums stay exact.
    bright = np.full((3000, 3000), 255, np.uint8)
    tables = ck.prefix_tables(bright)
    assert tables[ck.INTEGRAL].min() < 0
    terms = np.array(cs.kernel_terms(cs.disk_plan(3)), np.int32)
    out = np.zeros(4, np.int32)
    kernel_window(tables, terms, 2990, 2990, 4, out)
    assert np.all(out == 255 * cs.disk_size(3))


@pytest.mark.parametrize("radius", [2, 4, 7])
def test_single_lit_disk_peaks_at_its_centre_with_its_radius(radius):
    cmap = cs.conspicuity_map(lit_disk(radius))
    assert cmap.values[31, 29] == pytest.approx(cmap.values.max(), abs=1e-6)
    assert cmap.radius[31, 29] == radius
    # The printed Eq. 3.5 (max) makes a plateau over the lens; the prose's min a single peak.
    strict = cs.conspicuity_map(lit_disk(radius), quadrant_rule="min")
    assert np.unravel_index(np.argmax(strict.values), strict.values.shape) == (31, 29)
    assert strict.radius[31, 29] == radius
    assert np.sum(strict.values >= strict.values.max() - 1e-6) == 1


def test_quadrant_contrast_is_zero_on_a_flat_image():
    flat = np.full((30, 40, 3), (20, 120, 200), np.uint8)
    light = cs.lightness(flat)
    for r in (1, 3, 6):
        for use_min in (False, True):
            disk, contrast = row_features(light, r, 0, 5, use_min)
            assert not contrast.any() and np.all(disk == int(light[0, 0]) * cs.disk_size(r))
    assert cs.conspicuity_map(flat, radii=(1, 3, 6)).values.max() < 1e-2


def test_geometric_mean_ratio_is_invariant_to_feature_scales():
    rng = np.random.default_rng(5)
    features = [rng.uniform(0.05, 1.0, 50).astype(np.float32) for _ in range(3)]
    weights = np.array((1.0, 2.0, 0.5), np.float32)

    def geometric_mean(scales):
        product = np.zeros(50, np.float32)
        ck.weighted_product(
            *(f * np.float32(s) for f, s in zip(features, scales)), weights, 50, product
        )
        return cs.weighted_root(product, weights)

    base, scaled = geometric_mean((1, 1, 1)), geometric_mean((0.3, 7.0, 0.01))
    np.testing.assert_allclose(scaled / scaled[0], base / base[0], rtol=1e-5)
    assert not np.allclose(scaled, base)


def test_disk_and_annulus_sizes():
    assert [cs.disk_size(r) for r in (1, 2, 3)] == [5, 13, 29]
    assert cs.quarter_disk_size(1) == 3
    sat = np.zeros((20, 20), np.uint8)
    sat[10, 10] = 255
    sums = window_sums(sat, 8, [cs.disk_plan(2), cs.disk_plan(4)], 10)
    feature = np.zeros(20, np.float32)
    ck.saturation_feature(sums[0], sums[1], cs.mean_scale(13), cs.mean_scale(49 - 13), 20, feature)
    # At the lit pixel the disk mean wins (1/13); three columns away only the annulus sees it.
    assert feature[10] == pytest.approx(1 / 13) and feature[13] == pytest.approx(1 / 36)


@pytest.mark.parametrize(
    "kwargs", [{"weights": (0, 0, 0)}, {"weights": (1, 1)}, {"radii": (0, 2)}, {"margin": -1}]
)
def test_bad_settings_raise_value_error(kwargs):
    with pytest.raises(ValueError):
        cs.conspicuity_map(lit_disk(3), **kwargs)


def test_non_bgr_input_raises_value_error():
    with pytest.raises(ValueError, match="BGR uint8"):
        cs.conspicuity_map(np.zeros((10, 10), np.uint8))


def test_detector_finds_the_lit_disk_with_score_and_radius():
    detector = tsrkit.detector("conspicuity")
    candidates = detector.detect(Frame(lit_disk(4), "disk.png"))
    best = candidates[0]
    assert abs(best.x - 29.5) <= 0.5 and abs(best.y - 31.5) <= 0.5
    assert best.radius == 4
    assert best.score == pytest.approx(float(cs.conspicuity_map(lit_disk(4)).values.max()))
    assert [c.score for c in candidates] == sorted((c.score for c in candidates), reverse=True)


def test_region_of_interest_hides_the_lower_frame():
    image = lit_disk(4, shape=(80, 64), centre=(60, 29))
    assert not tsrkit.detector("conspicuity", roi_top=0.5).detect(Frame(image, "x"))
    assert tsrkit.detector("conspicuity").detect(Frame(image, "x"))


#: Candidates of the round-1 NumPy implementation (commit e57479b) on 480x356 resizes of
#: roboflow_traffic_light_kr frames: (x, y, radius, score). The compiled kernel must keep them.
ROUND_ONE_CANDIDATES = {
    0: [(228.531, 164.473, 2, 0.656477)],
    5: [
        (303.466, 98.541, 2, 0.558103),
        (309.465, 77.661, 7, 0.531864),
        (373.47, 9.464, 6, 0.523986),
        (302.432, 88.479, 3, 0.520394),
        (363.456, 18.528, 6, 0.512656),
        (384.419, 3.8, 5, 0.507688),
        (209.58, 58.611, 7, 0.488395),
        (224.146, 73.623, 9, 0.480928),
        (371.499, 41.511, 4, 0.475431),
        (326.35, 98.294, 9, 0.472935),
    ],
    11: [
        (227.406, 294.412, 5, 0.498181),
        (123.45, 298.521, 6, 0.488416),
        (293.029, 136.568, 7, 0.480127),
        (211.576, 295.528, 4, 0.47258),
        (456.198, 26.839, 8, 0.46342),
        (107.498, 298.416, 6, 0.463031),
        (431.853, 44.701, 8, 0.461131),
        (95.437, 298.548, 5, 0.438441),
        (208.432, 182.492, 6, 0.431261),
        (292.383, 113.416, 7, 0.430705),
    ],
}


def test_candidates_on_real_frames_match_the_round_one_implementation(shared_datasets):
    root = shared_datasets / "roboflow_traffic_light_kr"
    entries = json.loads((root / "annotations.json").read_text())
    detector = tsrkit.detector("conspicuity")
    for index, expected in ROUND_ONE_CANDIDATES.items():
        image = cv2.resize(
            cv2.imread(str(root / entries[index]["file"])), (480, 356), interpolation=cv2.INTER_AREA
        )
        found = detector.detect(Frame(image, entries[index]["file"]))
        assert [c.radius for c in found] == [e[2] for e in expected]
        for candidate, (x, y, _, score) in zip(found, expected):
            assert (candidate.x, candidate.y) == (
                pytest.approx(x, abs=2e-3),
                pytest.approx(y, abs=2e-3),
            )
            assert candidate.score == pytest.approx(score, abs=2e-6)


def test_map_does_not_depend_on_how_the_rows_are_split_into_runs():
    image = random_image(6, (30, 41))
    tables = cs.channel_tables(image, list(range(1, 11)), 0)
    whole = cs.products_on_runs(
        *tables, cs.full_runs(30, 41), list(range(1, 11)), (1.0, 1.0, 1.0), 0, "max"
    )
    pieces = np.array([(i, a, b) for i in range(30) for a, b in ((0, 7), (7, 8), (8, 41))])
    split = cs.products_on_runs(*tables, pieces, list(range(1, 11)), (1.0, 1.0, 1.0), 0, "max")
    assert np.array_equal(whole[0], split[0]) and np.array_equal(whole[1], split[1])
    assert whole[0].max() > 0
    partial = cs.products_on_runs(
        *tables, pieces[pieces[:, 1] == 7], list(range(1, 11)), (1.0, 1.0, 1.0), 0, "max"
    )
    assert np.array_equal(partial[0][:, 7], whole[0][:, 7]) and not partial[0][:, 8:].any()
    # Output arrays holding anything: every pixel of the runs is written.
    garbage = (np.full((30, 41), np.nan, np.float32), np.full((30, 41), 99, np.int32))
    cs.products_on_runs(
        *tables, cs.full_runs(30, 41), list(range(1, 11)), (1.0, 2.0, 1.0), 0, "max", garbage
    )
    expected = cs.products_on_runs(
        *tables, cs.full_runs(30, 41), list(range(1, 11)), (1.0, 2.0, 1.0), 0, "max"
    )
    assert np.array_equal(garbage[0], expected[0]) and np.array_equal(garbage[1], expected[1])


def test_lightness_windows_are_exact_in_int16_at_their_largest():
    # All-white lightness: every radius-10 window at its largest magnitude (the quadrant box
    # 121 * 255 = 30855, the axes term -43 * 255), summed over tables that wrap many times; a
    # white half-plane gives the largest contrasts.
    white = np.full((50, 3000), 255, np.uint8)
    disk, contrast = row_features(white, 10, 0, 20, dtype=np.int16)
    assert np.all(disk == 255 * cs.disk_size(10)) and not contrast.any()
    half = white.copy()
    half[:, 1500:] = 0
    for use_min in (False, True):
        narrow = row_features(half, 10, 0, 20, use_min, np.int16)
        wide = row_features(half, 10, 0, 20, use_min, np.int32)
        assert np.array_equal(narrow[0], wide[0]) and np.array_equal(narrow[1], wide[1])
        assert narrow[1][1499] == max(
            0, (min if use_min else max)(direct_features(half, 10, 0, 20, 1499)[1])
        )
    assert narrow[0][1499] == direct_features(half, 10, 0, 20, 1499)[0]


def column_disk_rows(channel, radii, row, dtype=np.uint16):
    """The kernel's disks of radii ``radii`` (the saturation plan of ``kernel_plan``: 1..10
    and their doubles) on one row of a channel, from its column sums (``fill_columns``,
    ``column_disks``), with tables and band sums in ``dtype``."""
    plan = cs.kernel_plan(tuple(radii), 0)
    pad = 2 * max(radii)
    tables = ck.prefix_tables(cs.mirror(channel, pad), dtype)
    count = channel.shape[1]
    columns = np.full((pad + 2, tables.shape[2]), 7, dtype)
    columns[-1] = 0
    flat = tables.reshape(-1)
    ck.fill_columns(flat, tables[0].size, tables.shape[2], pad, row, 0, count, columns)
    offsets = plan.sat_terms[:, 0] * tables.shape[2] + plan.sat_terms[:, 1]
    sat = np.full((len(plan.sat_bands) - 1, count), -1, np.int32)
    band = np.zeros(count, dtype)
    ck.column_disks(
        columns.reshape(-1), offsets, plan.sat_starts, plan.sat_bands, pad, count, band, sat
    )
    return sat


def test_saturation_disks_from_column_sums_are_exact_in_uint16_bands():
    radii = list(range(1, 11))
    sat_radii = sorted(set(radii) | {2 * r for r in radii})
    # All white: every band at its largest sum (up to 257 * 255 = 65535), tables wrapping.
    white = np.full((60, 3000), 255, np.uint8)
    disks = column_disk_rows(white, radii, 30)
    assert np.all(disks == 255 * np.array([cs.disk_size(r) for r in sat_radii])[:, None])
    # Black-and-white pattern and a real frame's saturation: equal to direct sums.
    pattern = np.where(random_image(9, (50, 300)) > 127, 255, 0).astype(np.uint8)[:, :, 0]
    for channel in (pattern, cs.saturation(random_image(10, (45, 77)))):
        for row in (0, 21, channel.shape[0] - 1):
            disks = column_disk_rows(channel, radii, row)
            for d, radius in enumerate(sat_radii):
                assert np.array_equal(disks[d], disk_row(channel, radius, row))
    for radius in (9, 10, 14, 20):
        bands = cs.disk_bands(radius, ck.BAND_PIXELS)
        assert bands[0][0] == -radius and bands[-1][1] == radius
        assert all(a[1] + 1 == b[0] for a, b in pairwise(bands))
        sizes = [
            sum(2 * cs.half_widths(radius)[abs(d)] + 1 for d in range(a, b + 1)) for a, b in bands
        ]
        assert max(sizes) <= ck.BAND_PIXELS and sum(sizes) == cs.disk_size(radius)
        plans = [cs.column_plan(radius, *band, 99) for band in bands]
        assert all(len(plan) % 4 == 0 for plan in plans)
        assert [t for plan in plans for t in plan if t[0] != 99] == [
            (cs.half_widths(radius)[abs(dx)], dx) for dx in range(-radius, radius + 1)
        ]
    assert len(cs.disk_bands(20, ck.BAND_PIXELS)) == 6


@pytest.mark.parametrize(
    "radii, margin, narrow",
    [((1, 2, 10), 0, True), ((3,), 7, True), ((11,), 0, False), ((4,), 8, False)],
)
def test_sums_are_16_bit_only_while_every_lightness_window_fits(radii, margin, narrow):
    assert cs.narrow_sums(radii, margin) is narrow
    light, sat, _ = cs.channel_tables(random_image(1), radii, margin)
    assert (light.dtype, sat.dtype) == ((np.int16, np.uint16) if narrow else (np.int32, np.int32))


def test_16_bit_tables_give_the_32_bit_map_bit_for_bit(shared_datasets):
    root = shared_datasets / "dtld_fridtjofs"
    entry = json.loads((root / "annotations.json").read_text())[0]
    image = cv2.imread(str(root / entry["file"]))[:200, :360]
    radii = list(range(1, 11))
    light, sat, pad = cs.channel_tables(image, radii, 0)
    assert (light.dtype, sat.dtype) == (np.int16, np.uint16)
    wide = [ck.prefix_tables(cs.mirror(f(image), pad)) for f in (cs.lightness, cs.saturation)]
    runs = cs.full_runs(*image.shape[:2])
    for rule, weights in (("max", (1.0, 1.0, 1.0)), ("min", (1.0, 2.0, 0.5))):
        narrow = cs.products_on_runs(light, sat, pad, runs, radii, weights, 0, rule)
        expected = cs.products_on_runs(*wide, pad, runs, radii, weights, 0, rule)
        assert np.array_equal(narrow[0], expected[0]) and np.array_equal(narrow[1], expected[1])
        assert narrow[0].max() > 0


def disk_row(channel, radius, row):
    """Direct int32 disk sums of radius ``radius`` along one row of a mirrored channel."""
    padded = cs.mirror(channel, radius).astype(np.int64)[row : row + 2 * radius + 1]
    windows = np.lib.stride_tricks.sliding_window_view(padded, (2 * radius + 1,) * 2)[0]
    disk = np.hypot(*np.mgrid[-radius : radius + 1, -radius : radius + 1]) <= radius
    return (windows * disk).sum(axis=(1, 2)).astype(np.int32)


def test_fused_combination_equals_the_integer_steps_bit_for_bit(shared_datasets):
    # The fused pass (in float32 and in int64) against the separate int64 steps, for every
    # radius of the paper's plan, on rows of a real frame and of a black-and-white pattern
    # (window sums at their 16-bit extremes).
    root = shared_datasets / "dtld_fridtjofs"
    entry = json.loads((root / "annotations.json").read_text())[0]
    real = cv2.imread(str(root / entry["file"]))[:60, :400]
    pattern = np.where(random_image(8, (60, 400)) > 127, 255, 0).astype(np.uint8)
    plan = cs.kernel_plan(tuple(range(1, 11)), 0)
    rng = np.random.default_rng(8)
    for image in (real, pattern):
        light, _, pad = cs.channel_tables(image, list(range(1, 11)), 0)
        count = image.shape[1]
        for k, radius in enumerate(plan.radii):
            nq, nb = int(plan.n_quarter[k]), int(plan.n_box[k])
            inputs = radius_inputs(light, pad, int(radius), 0, 30)
            inner, outer = (disk_row(cs.saturation(image), r, 30) for r in (radius, 2 * radius))
            start = rng.uniform(0, 1e-5, count).astype(np.float32)
            results = []
            for exact in (np.float32, np.int64):
                best = (start.copy(), np.zeros(count, np.int32))
                ck.unit_max_product(
                    *inputs,
                    inner,
                    outer,
                    nq,
                    nb,
                    plan.scales[k],
                    radius,
                    count,
                    *best,
                    False,
                    np.int16,
                    exact,
                )
                results.append(best)
            disk, contrast = np.zeros(count, np.int64), np.zeros(count, np.int64)
            ck.light_features(*inputs, nq, nb, False, count, disk, contrast, np.int16)
            features, product = np.zeros((3, count), np.float32), np.zeros(count, np.float32)
            features[0] = disk.astype(np.float32) * plan.scales[k, 0]
            features[1] = contrast.astype(np.float32) * plan.scales[k, 1]
            ck.saturation_feature(
                inner, outer, plan.scales[k, 2], plan.scales[k, 3], count, features[2]
            )
            ck.weighted_product(*features, np.ones(3, np.float32), count, product)
            steps = (start.copy(), np.zeros(count, np.int32))
            ck.keep_best(product, radius, count, *steps, False)
            for fused in results:
                assert np.array_equal(fused[0], steps[0]) and np.array_equal(fused[1], steps[1])
            assert np.count_nonzero(steps[1]) > count // 10


def test_unusable_settings_fail_at_construction_as_a_parameter_error():
    import tsrkit
    from tsrkit.plugin.params import ParamError

    with pytest.raises(ParamError, match="detector 'conspicuity': weights must be"):
        tsrkit.detector("conspicuity", weights=(0, 0, 0))


def test_one_pass_conversion_equals_opencv_lightness_and_saturation(shared_datasets):
    # All 2**24 colours agreed in a scratch run (benchmarks/RESULTS.detector_speed.md); here a
    # random sample of 2**20 colours, the grey ramp, the pure hues, and a real frame (as a view).
    rng = np.random.default_rng(9)
    sample = rng.integers(0, 256, (1024, 1024, 3), dtype=np.uint8)
    ramps = np.zeros((4, 256, 3), np.uint8)
    ramps[0] = np.arange(256)[:, None]
    for channel in range(3):
        ramps[channel + 1, :, channel] = np.arange(256)
    root = shared_datasets / "roboflow_traffic_light_kr"
    entry = json.loads((root / "annotations.json").read_text())[0]
    frame = cv2.imread(str(root / entry["file"]))[10:200:2, 5:300]
    for image in (sample, ramps, frame):
        light, sat = lightness_and_saturation(image)
        assert np.array_equal(light, cs.lightness(image))
        assert np.array_equal(sat, cs.saturation(image))


def test_workspace_reuses_buffers_but_returned_maps_are_fresh():
    first, second = random_image(10), lit_disk(4)
    kept = cs.conspicuity_map(first)
    expected = kept.values.copy()
    cs.conspicuity_map(second)
    assert np.array_equal(kept.values, expected)
    space = cs.Workspace()
    a = space.array("x", (4, 5), np.int16)
    assert space.array("x", (2, 3), np.uint8).ctypes.data == a.ctypes.data
    tables = cs.channel_tables(first, list(range(1, 11)), 0, space)
    assert np.array_equal(tables[0], cs.channel_tables(first, list(range(1, 11)), 0)[0])


def test_threads_get_their_own_workspace():
    from concurrent.futures import ThreadPoolExecutor

    images = [random_image(seed, (90, 120)) for seed in range(6)]
    serial = [cs.conspicuity_map(image) for image in images]
    detector = tsrkit.detector("conspicuity")
    expected = [detector.detect(Frame(image, "x")) for image in images]
    with ThreadPoolExecutor(3) as pool:
        maps = list(pool.map(cs.conspicuity_map, images * 3))
        found = list(pool.map(lambda image: detector.detect(Frame(image, "x")), images * 3))
    for k, cmap in enumerate(maps):
        assert np.array_equal(cmap.values, serial[k % 6].values)
        assert np.array_equal(cmap.radius, serial[k % 6].radius)
    assert found == expected * 3
