"""Can pruning make the conspicuity detector 3x faster than commit d213fc8 and keep its output?
(the study behind "Exact pruning" in RESULTS.detector_speed.md).

The idea: compute the exact map (Zheng 2016, Eq. 3.1-3.12) only where a cheap per-pixel upper
bound U says it could reach the lowest threshold the localization (3.2.2, Figure 3-10) will
use, plus the windows DRMShift reads around the peaks; leave the rest 0. This script measures,
on real frames, the three quantities that decide whether that can pay:

1. What an exact pruning must compute at the very least: the localization's thresholds per
   iteration (``h_peak`` times the product of the maxima it normalised by, recorded by wrapping
   ``localization.normalise``), the share of pixels whose map reaches the lowest one, and that
   set widened by the largest DRMShift window (square of half-side ``max(radii)``).
2. How many pixels two upper bounds let through at that lowest threshold (known in advance here,
   which a real detector does not know, so this is the best case):
   ``maxmin``: per radius, disk mean <= max L over the (2r+1) box, quadrant contrast <= max L -
   min L over it, saturation feature <= max S over the (4r+1) box (OpenCV dilate/erode).
   ``means``: per radius, disk mean <= min(max L, box sum / disk size); quadrant contrast
   (Eq. 3.5-3.8, ``Q/nq - (B - Q)/nbd`` with B the quadrant-box sum) <= ``min((nb Lmax - B)/nbd,
   (B - nb Lmin)/nq)``, which is tight on flat boxes; disk saturation mean <= box sum / disk size,
   annulus mean <= (sum of the (4r+1) box - sum of the square inscribed in the disk) / annulus
   size. Box sums come from the detector's own integral tables (a compiled kernel, 28 reads per
   pixel and radius). Both bounds are checked to lie above the exact map on every pixel.
3. What it would cost: the detector's fixed parts (colour conversions + tables, localization),
   the ``means`` bound, and the exact kernel on only the pixels that bound lets through plus the
   DRMShift windows (``products_on_runs``), against the full detector and against d213fc8's
   detector, interleaved in one run (CPU medians per frame).

Usage: python benchmarks/conspicuity_pruning.py [--frames 4] [--reps 3]
"""

import harness

harness.single_thread()

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402
from numba import njit  # noqa: E402

import tsrkit  # noqa: E402
from tsrkit import Frame  # noqa: E402
from tsrkit_plugins.detectors import localization  # noqa: E402
from tsrkit_plugins.detectors.conspicuity import conspicuity as cs  # noqa: E402
from tsrkit_plugins.detectors.conspicuity.conspicuity_kernel import (  # noqa: E402
    INTEGRAL,
    prefix_tables,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_conspicuity import baseline_detector, baseline_module  # noqa: E402

REPO = harness.REPO
DATA = harness.data_dir()
SETS = ("roboflow_traffic_light_kr", "dtld_fridtjofs", "roboflow_cinta_v2_id")
RADII = tuple(range(1, 11))


def frames(name, count, size):
    """The first ``count`` frames of a dataset, resized to ``size`` (native when None)."""
    root = DATA / name
    entries = json.loads((root / "annotations.json").read_text())[:count]
    images = [cv2.imread(str(root / e["file"])) for e in entries]
    if size is None:
        return images
    return [cv2.resize(im, size, interpolation=cv2.INTER_AREA) for im in images]


def thresholds(cmap, params):
    """The localization's threshold of every iteration, in map units (see module notes)."""
    peaks = []
    plain = localization.normalise

    def recording(wcm, peak=None, copy=False):
        peaks.append(float(wcm.max()) if peak is None else peak)
        return plain(wcm, peak, copy)

    localization.normalise = recording
    try:
        localization.localize(cmap.values, params, cmap.radius)
    finally:
        localization.normalise = plain
    return params["h_peak"] * np.cumprod(peaks)


def reach_of(needed, reach):
    """``needed`` widened by a square of half-side ``reach`` (the DRMShift windows)."""
    side = 2 * reach + 1
    return cv2.dilate(needed.astype(np.uint8), np.ones((side, side), np.uint8)) > 0


def maxmin_bound(image):
    """The ``maxmin`` upper bound of the product under the root of Eq. 3.1 (unit weights)."""
    light = cs.lightness(image).astype(np.float32) / 255
    sat = cs.saturation(image).astype(np.float32) / 255
    best = np.zeros(light.shape, np.float32)
    for r in RADII:
        box, wide = np.ones((2 * r + 1,) * 2, np.uint8), np.ones((4 * r + 1,) * 2, np.uint8)
        lmax = cv2.dilate(light, box, borderType=cv2.BORDER_REFLECT_101)
        lmin = cv2.erode(light, box, borderType=cv2.BORDER_REFLECT_101)
        smax = cv2.dilate(sat, wide, borderType=cv2.BORDER_REFLECT_101)
        np.maximum(best, lmax * (lmax - lmin) * smax, out=best)
    return best


def extremes(channel):
    """Per radius, the max and min of a uint8 channel over the (2r+1) box (mirrored borders),
    by repeated 3x3 dilation and erosion into preallocated planes."""
    kernel = np.ones((3, 3), np.uint8)
    highs = np.empty((len(RADII), *channel.shape), np.uint8)
    lows = np.empty_like(highs)
    high, low = channel, channel
    for k in range(len(RADII)):
        high = cv2.dilate(high, kernel, dst=highs[k], borderType=cv2.BORDER_REFLECT_101)
        low = cv2.erode(low, kernel, dst=lows[k], borderType=cv2.BORDER_REFLECT_101)
    return highs, lows


@njit(cache=True, fastmath=True, error_model="numpy")
def means_bound(light, sat, pad, lmax, lmin, sizes, out):
    """The ``means`` upper bound (module notes) of the product under the root of Eq. 3.1 with
    unit weights and margin 0, maximised over the radii 1..R, in float32; ``sizes[k]`` holds
    radius ``k + 1``'s quarter, box, disk and annulus pixel counts and inscribed half-side.

    Box sums are four reads of a 2-D int32 integral table of the mirrored lightness ``light``
    or saturation ``sat`` (``table[y, c]`` sums the padded rows ``< y`` and columns ``< c``);
    each image row is one vectorisable pass per radius."""
    height, width = out.shape
    for i in range(height):
        y = pad + i
        for k in range(sizes.shape[0]):
            r = k + 1
            nq, nb, nd, na, s = sizes[k, 0], sizes[k, 1], sizes[k, 2], sizes[k, 3], sizes[k, 4]
            over_nbd, over_nq = np.float32(1 / (nb - nq)), np.float32(1 / nq)
            over_nd, over_na = np.float32(1 / nd), np.float32(1 / na)
            scale, fnb = np.float32(1 / 255.0**3), np.float32(nb)
            a, b, c, d = pad - r, pad, pad + 1, pad + r + 1
            e, f, g, h = pad - 2 * r, pad + 2 * r + 1, pad - s, pad + s + 1
            up, mid, mid1, down = light[y - r], light[y], light[y + 1], light[y + r + 1]
            up_a, up_b, up_c, up_d = _cols(up, a, b, c, d, width)
            mid_a, mid_b, mid_c, mid_d = _cols(mid, a, b, c, d, width)
            mid1_a, mid1_b, mid1_c, mid1_d = _cols(mid1, a, b, c, d, width)
            down_a, down_b, down_c, down_d = _cols(down, a, b, c, d, width)
            disk_lo, disk_hi = sat[y - r], sat[y + r + 1]
            ring_lo, ring_hi = sat[y - 2 * r], sat[y + 2 * r + 1]
            in_lo, in_hi = sat[y - s], sat[y + s + 1]
            sd_hi_d, sd_lo_d = disk_hi[d : d + width], disk_lo[d : d + width]
            sd_hi_a, sd_lo_a = disk_hi[a : a + width], disk_lo[a : a + width]
            sr_hi_f, sr_lo_f = ring_hi[f : f + width], ring_lo[f : f + width]
            sr_hi_e, sr_lo_e = ring_hi[e : e + width], ring_lo[e : e + width]
            si_hi_h, si_lo_h = in_hi[h : h + width], in_lo[h : h + width]
            si_hi_g, si_lo_g = in_hi[g : g + width], in_lo[g : g + width]
            hi_row, lo_row, best = lmax[k, i], lmin[k, i], out[i]
            for j in range(width):
                hi, lo = np.float32(hi_row[j]), np.float32(lo_row[j])
                ul = np.float32(mid1_c[j] - up_c[j] - mid1_a[j] + up_a[j])
                ur = np.float32(mid1_d[j] - up_d[j] - mid1_b[j] + up_b[j])
                dl = np.float32(down_c[j] - mid_c[j] - down_a[j] + mid_a[j])
                dr = np.float32(down_d[j] - mid_d[j] - down_b[j] + mid_b[j])
                low, high = fnb * lo, fnb * hi
                contrast = max(
                    max(
                        min((high - ul) * over_nbd, (ul - low) * over_nq),
                        min((high - ur) * over_nbd, (ur - low) * over_nq),
                    ),
                    max(
                        min((high - dl) * over_nbd, (dl - low) * over_nq),
                        min((high - dr) * over_nbd, (dr - low) * over_nq),
                    ),
                )
                contrast = max(np.float32(0), contrast)
                disk = min(hi, np.float32(down_d[j] - up_d[j] - down_a[j] + up_a[j]) * over_nd)
                inner = np.float32(sd_hi_d[j] - sd_lo_d[j] - sd_hi_a[j] + sd_lo_a[j])
                ring = np.float32(sr_hi_f[j] - sr_lo_f[j] - sr_hi_e[j] + sr_lo_e[j]) - np.float32(
                    si_hi_h[j] - si_lo_h[j] - si_hi_g[j] + si_lo_g[j]
                )
                value = disk * contrast * max(inner * over_nd, ring * over_na) * scale
                best[j] = max(best[j], value)


@njit(cache=True, inline="always")
def _cols(row, a, b, c, d, width):
    """Four ``width``-long views of a table row from columns ``a``, ``b``, ``c``, ``d``."""
    return row[a : a + width], row[b : b + width], row[c : c + width], row[d : d + width]


def bound_sizes():
    """Per radius: quarter, box, disk, annulus sizes and the inscribed square's half-side."""
    return np.array(
        [
            (
                cs.quarter_disk_size(r),
                (r + 1) ** 2,
                cs.disk_size(r),
                cs.disk_size(2 * r) - cs.disk_size(r),
                math.isqrt(r * r // 2),
            )
            for r in RADII
        ],
        np.int64,
    )


def integrals(image):
    """int32 integral tables of the mirrored lightness and saturation, and their padding."""
    pad = 2 * max(RADII)
    light, sat = (
        prefix_tables(cs.mirror(channel, pad))[INTEGRAL]
        for channel in (cs.lightness(image), cs.saturation(image))
    )
    return light, sat, pad


def means_of(image):
    """The ``means`` bound of a BGR frame."""
    bound = np.zeros(image.shape[:2], np.float32)
    means_bound(*integrals(image), *extremes(cs.lightness(image)), bound_sizes(), bound)
    return bound


def mask_runs(mask):
    """Row runs ``(row, first column, end column)`` of the set pixels of a boolean mask."""
    edges = np.diff(np.pad(mask.astype(np.int8), ((0, 0), (1, 1))), axis=1)
    rows, starts = np.nonzero(edges == 1)
    _, ends = np.nonzero(edges == -1)
    return np.stack([rows, starts, ends], axis=1).astype(np.int64)


def study(images, params):
    """Per frame: iterations, lowest threshold / max, and the shares of pixels (see notes)."""
    rows = []
    for image in images:
        cmap = cs.conspicuity_map(image)
        levels = thresholds(cmap, params)
        lowest = float(levels.min())
        needed = cmap.values >= lowest
        product = cmap.values.astype(np.float64) ** 3
        level = lowest**3 * (1 - 1e-6)
        means = means_of(image)
        maxmin = maxmin_bound(image)
        assert np.all(means >= product * (1 - 1e-5) - 1e-9), "means bound below the map"
        assert np.all(maxmin >= product * (1 - 1e-5) - 1e-9), "maxmin bound below the map"
        rows.append(
            (
                len(levels),
                lowest / float(cmap.values.max()),
                needed.mean(),
                reach_of(needed, max(RADII)).mean(),
                (maxmin >= level).mean(),
                (means >= level).mean(),
                ((means >= level) | reach_of(needed, max(RADII))).mean(),
            )
        )
    return np.array(rows)


def cpu_medians(calls, reps):
    """Median CPU milliseconds per item of each ``name: (call, items)``, interleaved."""
    times = {name: [] for name in calls}
    for _ in range(reps):
        for name, (call, items) in calls.items():
            for item in items:
                start = time.process_time()
                call(item)
                times[name].append(time.process_time() - start)
    return {name: 1e3 * float(np.median(t)) for name, t in times.items()}


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    harness.add_frames(parser, 4)
    harness.add_repeats(parser, 3, flag="--reps")
    parser.add_argument("--baseline", default="d213fc8")
    args = parser.parse_args()
    harness.announce()
    detector = tsrkit.detector("conspicuity")
    params = detector.params
    print(
        "set, size: iterations | lowest threshold / max | share of pixels: map >= lowest, "
        "+ DRMShift reach | maxmin >= lowest | means >= lowest | means + reach (min-max over "
        "frames)"
    )
    for name in SETS:
        for size in ((1280, 720), None):
            table = study(frames(name, args.frames, size), params)
            cells = [f"{lo:.3g}-{hi:.3g}" for lo, hi in zip(table.min(0), table.max(0))]
            print(f"{name} {size or 'native'}: " + " | ".join(cells))

    images = frames(SETS[0], args.frames * 2, (1280, 720))
    old = baseline_detector(baseline_module(args.baseline))
    prepared = []
    for image in images:
        cmap = cs.conspicuity_map(image)
        bound = means_of(image)
        lowest = float(thresholds(cmap, params).min())
        reach = reach_of(cmap.values >= lowest, max(RADII))
        bounded = mask_runs((bound >= lowest**3 * (1 - 1e-6)) | reach)
        parts = (
            cs.channel_tables(image, RADII, 0),
            integrals(image),
            extremes(cs.lightness(image)),
        )
        prepared.append((image, cmap, parts, bounded, mask_runs(reach)))

    def exact_on(runs):
        return lambda item: cs.products_on_runs(
            *item[2][0], item[runs], RADII, (1.0, 1.0, 1.0), 0, "max"
        )

    def bound_only(item):
        out = np.zeros(item[0].shape[:2], np.float32)
        means_bound(*item[2][1], *item[2][2], bound_sizes(), out)

    calls = {
        f"{args.baseline} detector": (lambda im: old.detect(Frame(im, "b")), images),
        "detector now": (lambda im: detector.detect(Frame(im, "b")), images),
        "conversions + tables": (lambda im: cs.channel_tables(im, RADII, 0), images),
        "lightness max/min (20 morph. ops)": (lambda im: extremes(cs.lightness(im)), images),
        "means bound kernel": (bound_only, prepared),
        "exact on means-kept pixels": (exact_on(3), prepared),
        "exact on needed pixels only": (exact_on(4), prepared),
        "localization": (
            lambda item: localization.localize(item[1].values, params, item[1].radius),
            prepared,
        ),
    }
    times = cpu_medians(calls, args.reps)
    print(f"\nCPU ms per 1280x720 frame, median ({len(images)} {SETS[0]} frames):")
    for name, value in times.items():
        print(f"  {name:36s} {value:8.2f}")

    def share(runs):
        return np.mean([np.sum(p[runs][:, 2] - p[runs][:, 1]) / p[1].values.size for p in prepared])

    fixed = times["conversions + tables"] + times["localization"]
    baseline = times[f"{args.baseline} detector"]
    pruned = (
        fixed
        + times["lightness max/min (20 morph. ops)"]
        + times["means bound kernel"]
        + times["exact on means-kept pixels"]
    )
    perfect = fixed + times["exact on needed pixels only"]
    print(
        f"  {args.baseline} / detector now: {baseline / times['detector now']:.2f}x\n"
        f"  pruned with the means bound (exact on {share(3):.1%} of pixels, lowest threshold "
        f"known): {pruned:.1f} ms, {baseline / pruned:.2f}x\n"
        f"  pruned with a perfect free bound (exact on {share(4):.1%}): {perfect:.1f} ms, "
        f"{baseline / perfect:.2f}x\n"
        f"  runs per frame, means-kept / needed: "
        f"{np.mean([len(p[3]) for p in prepared]):.0f} / "
        f"{np.mean([len(p[4]) for p in prepared]):.0f}"
    )


if __name__ == "__main__":
    main()
