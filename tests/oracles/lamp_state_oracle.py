"""lamp-state as the plugin computed it before it was batched (one ``clip_box`` per crop, every
housing resampled upright and again transposed when wide, a colour conversion over a tall
stack, ``np.digitize`` hue bins, scikit-learn's ``predict_proba``): the oracle the faster
classifier must match exactly. The feature functions the speed-up left alone are imported.

Housings are resampled as lamp-state defines it since long housings are halved (outputs
changed by design): a side at least ``HALVE_FROM`` times its output length is first halved
(:func:`halved`: an odd last pixel dropped, pairs averaged), then the whole crop resampled by
OpenCV's area rule. Since layout 4 every housing is read, a horizontal one turned end over end
where its bottom end is redder, and the red+amber reading looks for two lamps in the profile
(:func:`_two_lit`, one profile and one pair of lamps at a time)."""

from __future__ import annotations

import cv2
import numpy as np

from tsrkit.core.geometry import clip_box
from tsrkit_plugins.classifiers.lamp_state import STATES, blend, prefer_red, red_yellow
from tsrkit_plugins.classifiers.lamp_state.colour import COLOUR, mix
from tsrkit_plugins.classifiers.lamp_state.features import (
    DISK,
    HALVE_FROM,
    HOUSING_SIZE,
    HUE_EDGES,
    LENS_PATCH,
    N_FEATURES,
    N_HUE,
    N_LENS,
    RIM,
    band,
    housing_of,
    lit_lenses,
    quantiles,
    red_amber_rows,
    scaled,
)


def _patches(image, boxes, size):
    out = np.zeros((len(boxes), size[1], size[0], 3), np.uint8)
    for i, box in enumerate(boxes):
        x0, y0, x1, y1 = clip_box(box, image.shape[1], image.shape[0])
        if x1 > x0 and y1 > y0:
            out[i] = cv2.resize(image[y0:y1, x0:x1], size, interpolation=cv2.INTER_AREA)
    return out


def halved(crop, size, halve_from):
    """``crop`` with each side at least ``halve_from`` times its ``size`` (width, height)
    length halved: its last pixel dropped there when the length is odd, then each 2 x 2 (or
    2 x 1) block's mean by OpenCV's integer-scale area resampling (the mean rounded to the
    nearest integer, exact ties either way: ``tests/classifiers/test_lamp_state.py`` checks it
    against numpy's block sums); ``crop`` itself when no side is that long or one enlarges."""
    height, width = crop.shape[:2]
    if width < size[0] or height < size[1]:
        return crop
    kx = 2 if width >= halve_from * size[0] else 1
    ky = 2 if height >= halve_from * size[1] else 1
    if kx == ky == 1:
        return crop
    w, h = width // kx, height // ky
    return cv2.resize(crop[: ky * h, : kx * w], (w, h), interpolation=cv2.INTER_AREA)


def _housing_patches(image, boxes, size):
    out = np.zeros((len(boxes), size[1], size[0], 3), np.uint8)
    for i, box in enumerate(boxes):
        x0, y0, x1, y1 = clip_box(box, image.shape[1], image.shape[0])
        if x1 > x0 and y1 > y0:
            crop = halved(image[y0:y1, x0:x1], size, HALVE_FROM)
            out[i] = cv2.resize(crop, size, interpolation=cv2.INTER_AREA)
    return out


def _convert(stack, code):
    n, h, w, _ = stack.shape
    return cv2.cvtColor(stack.reshape(n * h, w, 3), code).reshape(n, h, w, 3)


def _hue_histograms(hsv, mask):
    n = hsv.shape[0]
    mask = np.broadcast_to(mask, hsv.shape[:3])
    bins = np.digitize(hsv[..., 0], HUE_EDGES) - 1 + N_HUE * np.arange(n)[:, None, None]
    weight = hsv[..., 1].astype(np.float32) * hsv[..., 2] / 65025.0
    hist = np.bincount(bins[mask], weights=weight[mask], minlength=n * N_HUE)
    hist = hist[: n * N_HUE].reshape(n, N_HUE)
    return hist / np.maximum(hist.sum(axis=1, keepdims=True), 1e-6)


def _lens_features(image, lenses):
    r = np.array([max(c.radius, 0.5) * 1.3 for c in lenses])
    x, y = np.array([c.x for c in lenses]), np.array([c.y for c in lenses])
    stack = _patches(image, np.stack([x - r, y - r, x + r, y + r], axis=1), (LENS_PATCH,) * 2)
    n = len(lenses)
    hsv = _convert(stack, cv2.COLOR_BGR2HSV)
    lab = _convert(stack, cv2.COLOR_BGR2LAB).astype(np.float32) - (0, 128, 128)
    value = hsv[..., 2][:, DISK].astype(np.float32)
    bright = value >= quantiles(value, 0.7)[:, None]
    chroma = np.hypot(lab[..., 1], lab[..., 2])[:, RIM]
    vivid = chroma >= quantiles(chroma, 0.7)[:, None]

    def masked_mean(values, mask):
        return (values * mask[..., None]).sum(axis=1) / np.maximum(mask.sum(axis=1), 1)[:, None]

    over = (value > 230) & (hsv[..., 1][:, DISK] < 80)
    return np.concatenate(
        [
            _hue_histograms(hsv, DISK),
            _hue_histograms(hsv, RIM),
            masked_mean(lab[:, DISK, 1:], bright) / 128,
            masked_mean(lab[:, RIM, 1:], vivid) / 128,
            over.mean(axis=1, keepdims=True),
        ],
        axis=1,
    ).reshape(n, -1)


def _slots(profile):
    along = profile.shape[1]
    half = max(1, along // 18)
    centres = (2 * np.arange(3) + 1) * along // 6
    return np.stack([profile[:, c - half : c + half + 1].mean(axis=1) for c in centres], axis=1)


def _lamp_peaks(p, prominence=0.15):
    """The lamps of one profile, one by one: interior local maxima standing out by
    ``prominence`` of the range within a sixth of the length on both sides, the first of any
    within two bins."""
    along = len(p)
    reach = along // 6
    span = max(p.max() - p.min(), 1e-3)
    peaks, seen = [], []
    for i in range(1, along - 1):
        if p[i] < p[max(0, i - 2) : i + 3].max():
            continue
        before, after = p[max(0, i - reach) : i], p[i + 1 : i + 1 + reach]
        if before.min() > p[i] - prominence * span or after.min() > p[i] - prominence * span:
            continue
        if not (seen and i - seen[-1] <= 2):
            peaks.append(i)
        seen.append(i)
    return peaks


def _two_lit(profile, redness, dip=0.7):
    n, along = profile.shape
    half = along // 12
    out = np.zeros(n)
    for k in range(n):
        p, r = profile[k], redness[k]
        edged = np.pad(p, 1, mode="edge")
        peaks = _lamp_peaks(p)
        for x, a in enumerate(peaks):
            for b in peaks[x + 1 :]:
                d = b - a
                if not (along // 6 <= d <= along // 2) or b + d > along + 1:
                    continue
                third = min(b + d, along - 1)
                dark = edged[third : third + 3].mean()
                lower, higher = min(p[a], p[b]), max(p[a], p[b])
                red_a = r[max(0, a - half) : a + half + 1].max()
                red_b = r[max(0, b - half) : b + half + 1].max()
                if (
                    lower > dark
                    and p[a : b + 1].min() < dark + dip * (lower - dark)
                    and red_a > 0
                    and red_a >= red_b
                ):
                    out[k] = max(out[k], (lower - dark) / max(higher - dark, 1e-3))
    return out


def _housing_features(upright, hsv, vertical):
    n = hsv.shape[0]
    value = band(hsv[..., 2].astype(np.float32) / 255)
    colourful = band(hsv[..., 1].astype(np.float32) / 255) * value
    thirds = np.array_split(np.arange(value.shape[1]), 3)
    profile = value.mean(axis=2)
    bgr = band(upright.astype(np.float32) / 255)
    redness = (bgr[..., 2] - bgr[..., 1]).mean(axis=2)
    weight = profile**4
    position = weight @ np.linspace(0, 1, weight.shape[1]) / np.maximum(weight.sum(axis=1), 1e-6)
    return np.concatenate(
        [
            np.stack([quantiles(value[:, rows].reshape(n, -1), 0.9) for rows in thirds], 1),
            np.stack([quantiles(colourful[:, rows].reshape(n, -1), 0.9) for rows in thirds], 1),
            position[:, None],
            vertical[:, None].astype(np.float32),
            np.ones((n, 1), np.float32),
            scaled(_slots(profile)),
            scaled(_slots(colourful.mean(axis=2))),
            _two_lit(profile, redness)[:, None],
        ],
        axis=1,
    )


def _upright_housings(image, boxes):
    vertical = (boxes[:, 3] - boxes[:, 1]) >= (boxes[:, 2] - boxes[:, 0])
    out = _housing_patches(image, boxes, HOUSING_SIZE)
    wide = np.flatnonzero(~vertical)
    if len(wide):
        turned = _housing_patches(image, boxes[wide], HOUSING_SIZE[::-1])
        out[wide] = turned.transpose(0, 2, 1, 3)
    return out, vertical


def _turned_by_colour(upright, vertical):
    """Each horizontal patch end over end when its bottom end slot is redder than its top."""
    out = upright.copy()
    bgr = band(upright.astype(np.float32) / 255)
    redness = (bgr[..., 2] - bgr[..., 1]).mean(axis=2)
    ends = _slots(redness)
    for i in range(len(upright)):
        if not vertical[i] and ends[i, 2] > ends[i, 0]:
            out[i] = upright[i, ::-1]
    return out


def lamp_features(image, candidates):
    """The (N, N_FEATURES) features of ``candidates``, computed the old way."""
    rows = np.zeros((len(candidates), N_FEATURES), np.float32)
    housings = [housing_of(c) for c in candidates]
    boxed = [i for i, h in enumerate(housings) if h is not None]
    lenses = list(candidates)
    if boxed:
        boxes = np.array([housings[i] for i in boxed], np.float64)
        upright, vertical = _upright_housings(image, boxes)
        found = lit_lenses(boxes, vertical, _convert(upright, cv2.COLOR_BGR2HSV))
        for k, i in enumerate(boxed):
            if candidates[i].housing in (None, candidates[i].bbox):
                lenses[i] = found[k]
        upright = _turned_by_colour(upright, vertical)
        hsv = _convert(upright, cv2.COLOR_BGR2HSV)
        rows[boxed, N_LENS:] = _housing_features(upright, hsv, vertical)
    if lenses:
        rows[:, :N_LENS] = _lens_features(image, lenses)
    return np.nan_to_num(rows)


def classify(classifier, frame, candidates):
    """``(state, state_scores)`` of each candidate as ``classifier`` (a lamp-state) read them
    before: the old features, scikit-learn's ``predict_proba`` (of the colour model too, mixed
    in by ``colour_weight``), then the same fusion."""
    estimator = classifier.estimator
    features = lamp_features(frame.image, candidates)
    states = classifier._states
    probability = estimator.predict_proba(features)
    if classifier._colour is not None:  # the colour model's share, by scikit-learn as well
        colour = classifier._colour[0].predict_proba(features[:, COLOUR])
        probability = mix(probability, colour, classifier.params["colour_weight"])
    probability = prefer_red(probability, states, classifier.params["red_prior"])
    weight = classifier.params["ab_hist_weight"]
    known = set(states)
    other = np.zeros((len(candidates), len(STATES)))
    if weight > 0:
        found = classifier.params["fused"].plugin.classify(frame, candidates)
        known |= {s for d in found for s in d.state_scores}
        other = np.array([[d.state_scores.get(s, 0.0) for s in STATES] for d in found])
    ratio = classifier.params["red_yellow_ratio"]
    rule = red_amber_rows(frame.image, candidates, features)  # the rule's reading, shared
    table = red_yellow(blend(probability, states, other, weight), rule, ratio)
    if ratio < 1:
        known.add("red_yellow")
    out = []
    for row in table:
        scores = {s: float(v) for s, v in zip(STATES, row) if s in known}
        out.append((STATES[int(np.argmax(row))], scores))
    return out
