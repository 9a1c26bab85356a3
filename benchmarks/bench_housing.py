"""The housing stage: speed at 50 candidates on a 1280x720 frame (one thread), fit quality on
the real housing boxes given their lit lens, and housing AP50 / recall after the paper detectors.

    python benchmarks/bench_housing.py
    python benchmarks/bench_housing.py --stages    # only: where the fit is lost, stage by stage
    python benchmarks/bench_housing.py --fit       # only: speed and fit quality
    python benchmarks/bench_housing.py --select roboflow_cinta_v2_id:valid dtld_fridtjofs:train
    python benchmarks/bench_housing.py --pads 0 0.5 1 1.5 2 3   # only: fits after a pixel pad
    python benchmarks/bench_housing.py --rendered  # only: fits on rendered heads of every layout

``--stages`` fits each test housing from four starts and gives the share at IoU >= 0.5: the
true lit lens (centre and radius from the box, :func:`find_lens`), the ``union`` detector's
best-scored candidate whose centre lies in the box's circle (Zheng's rule), and the two mixed
(true centre with the candidate's radius, the candidate's centre with the true radius).

``--pads P...`` gives the share of housings fitted at IoU >= 0.5 from their lit lens after the
fit is widened by P pixels on every side (the stage's ``pad``), on each housing set's training
and test split (the Japanese set whole: its split lets near-duplicate frames cross), with the
median slack per side between the fit and the annotated box, and the share whose fit lies the
way the box does (horizontal or vertical).

``--rendered`` fits rendered heads of every layout (vertical and horizontal, 3 and 4 lenses,
each lamp lit, lens radius 4, 6 and 9 px) from their lit lens on a sky-to-road background and on
a dark one (a hillside), plain and with a light rim around the dark face (as Japan's heads), and
gives the shares at IoU >= 0.5 and >= 0.8 (the fit itself, without the stage's pad).

``--select SET:SPLIT...`` asks which of the ``union`` candidates on one light gives its box: the
share of annotated boxes (housings; lenses on lens-boxed sets) met at IoU >= 0.5 by the
best-scored candidate whose centre hits the light (Zheng's rule), by the housing stage's
first-ranked hitting candidate (after its duplicate suppression), by any hitting candidate, and
by any candidate the stage keeps; with the AP50 (pycocotools) of all the stage's candidates
ranked by the detector's scores (on a set that is not exhaustively labelled it counts
unlabelled lights as false).

Datasets draw their boxes with different margins around the head (DTLD's carry several pixels
of background), so each share is also given margin-free (:func:`margin_free_iou`): a fit that
only misses the annotation's margin counts, a wrong housing does not.
"""

from __future__ import annotations

import harness

harness.single_thread()

import argparse  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from tsrkit import (  # noqa: E402
    Candidate,
    Frame,
    get_registry,
)
from tsrkit.api import (  # noqa: E402
    centre_hits,
    iou_matrix,
    open_dataset,
    xyxy_to_xywh,
)
from tsrkit.eval.coco import coco_ap, coco_dataset  # noqa: E402
from tsrkit.synth.heads import LAMP_COLOURS, background, render_head  # noqa: E402
from tsrkit_plugins.shared.regions import find_lens  # noqa: E402
from tsrkit_plugins.verifiers.housing.fit import fit_housings  # noqa: E402
from tsrkit_plugins.verifiers.housing.margin import learn_margin, margin_free_iou, widen  # noqa: E402


def speed() -> tuple[float, float]:
    """Median wall-clock and CPU ms of the housing stage on a 1280x720 frame with 50
    candidates (the CPU time is the one to read on a shared machine)."""
    image = background(720, 1280)
    rng = np.random.default_rng(0)
    candidates = []
    for k in range(50):
        x, y = 60 + 23 * k, 100 + 10 * (k % 40)
        render_head(image, (x, y), 4 + k % 6, 3, k % 3)
        candidates.append(Candidate.from_circle(x, y, 4 + k % 6, float(rng.random())))
    stage = get_registry().create("verifier", "housing")
    frame = Frame(image, "bench")
    wall, cpu = [], []
    for _ in range(30):
        start, start_cpu = time.perf_counter(), time.process_time()
        stage.verify(frame, candidates)
        wall.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
    return 1000 * float(np.median(wall)), 1000 * float(np.median(cpu))


#: The training split of each housing set (as in ``verifier_loso.py``): its margin is learned
#: there, never on the test split.
TRAIN_SPLIT = {"roboflow_cinta_v2_id": "valid", "dtld_fridtjofs": "train"}
#: Splits the ``--pads`` and ``--stages`` tables read per housing set (None: the whole set).
PAD_SPLITS = {
    "roboflow_cinta_v2_id": ("valid", "test"),
    "dtld_fridtjofs": ("train", "test"),
    "iwai_japan_tl": (None,),
}
STAGE_SPLITS = {"roboflow_cinta_v2_id": "test", "dtld_fridtjofs": "test", "iwai_japan_tl": None}


def split_samples(name: str, split: str | None):
    """The samples of ``name``'s ``split`` (None: all of them)."""
    dataset = open_dataset(name)
    return dataset.samples if split is None else dataset.split(split)


def fit_quality(name: str) -> str:
    """IoU of the fit with each test housing box, its lit lens found inside the box; also
    margin-free, and with the margin learned on the set's training split."""
    margin = learn_margin(open_dataset(name).split(TRAIN_SPLIT[name]))
    ious, free, widened = [], [], []
    for sample in open_dataset(name).split("test"):
        frame = sample.load()
        gray = cv2.cvtColor(frame.image, cv2.COLOR_BGR2GRAY)
        boxes = [a.bbox for a in sample.annotations]
        lenses = [find_lens(frame.image, b) for b in boxes]
        fitted, _, _ = fit_housings(gray, [(c.x, c.y, c.radius) for c in lenses])
        ious += [iou_matrix([b], [f])[0, 0] for b, f in zip(boxes, fitted)]
        free += [margin_free_iou(b, f) for b, f in zip(boxes, fitted)]
        widened += [iou_matrix([b], [f])[0, 0] for b, f in zip(boxes, widen(fitted, margin))]
    iou = np.array(ious)
    return (
        f"{name} test: {len(iou)} housings, mean IoU {iou.mean():.2f}, "
        f"IoU >= 0.5: {(iou >= 0.5).mean():.2f}, >= 0.7: {(iou >= 0.7).mean():.2f}; "
        f"margin-free IoU >= 0.5: {(np.array(free) >= 0.5).mean():.2f}; margin learned on "
        f"{TRAIN_SPLIT[name]} {margin:.2f}, then IoU >= 0.5: "
        f"{(np.array(widened) >= 0.5).mean():.2f}"
    )


def lens_fits(name: str, split: str | None) -> tuple[np.ndarray, np.ndarray]:
    """The annotated housings of a split and the fits from their lit lens (unwidened)."""
    truth, fits = [], []
    for sample in split_samples(name, split):
        boxes = [a.bbox for a in sample.annotations]
        if not boxes:
            continue
        image = sample.load().image
        lenses = [find_lens(image, b) for b in boxes]
        fitted, _, _ = fit_housings(
            cv2.cvtColor(image, cv2.COLOR_BGR2GRAY), [(c.x, c.y, c.radius) for c in lenses]
        )
        truth += boxes
        fits += list(fitted)
    return np.asarray(truth, float), np.asarray(fits, float)


def wide(boxes: np.ndarray) -> np.ndarray:
    """Whether each box (N, 4) is wider than tall."""
    return boxes[:, 2] - boxes[:, 0] > boxes[:, 3] - boxes[:, 1]


def pad_row(name: str, split: str | None, pads: list[float]) -> str:
    """One row of the ``--pads`` table."""
    truth, fits = lens_fits(name, split)
    shares = []
    for pad in pads:
        grown = widen(fits, 0.0, pad)
        iou = np.array([iou_matrix([t], [g])[0, 0] for t, g in zip(truth, grown)])
        shares.append(f"{np.mean(iou >= 0.5):.3f}")
    slack = np.median((fits - truth) * [1, 1, -1, -1], axis=0)
    sides = " / ".join(f"{v:.1f}" for v in slack)
    lying = np.mean(wide(fits) == wide(truth))
    return (
        f"| {name} | {split or 'all'} | {len(truth)} | {' | '.join(shares)} | {sides} "
        f"| {lying:.3f} |"
    )


def dark_background(height: int, width: int, seed: int) -> np.ndarray:
    """A dark, slightly brown, noisy background (a hillside behind the heads)."""
    rng = np.random.default_rng(seed)
    image = np.full((height, width, 3), (45.0, 50.0, 60.0)) + rng.normal(0, 5, (height, width, 3))
    return np.clip(image, 0, 255).astype(np.uint8)


def rendered_row(backdrop: str, rim: bool) -> str:
    """One row of the ``--rendered`` table (module docstring)."""
    ious = []
    for vertical in (True, False):
        for lenses in (3, 4):
            for lit in range(lenses):
                for radius in (4, 6, 9):
                    seed = lenses * 10 + lit
                    image = (
                        background(300, 420, seed)
                        if backdrop == "sky"
                        else dark_background(300, 420, seed)
                    )
                    colour = list(LAMP_COLOURS.values())[lit % 3]
                    head = render_head(
                        image, (210.3, 150.6), radius, lenses, lit, vertical, colour, False,
                        (200, 200, 200) if rim else None,
                    )  # fmt: skip
                    gray = cv2.cvtColor(cv2.GaussianBlur(image, (0, 0), 0.7), cv2.COLOR_BGR2GRAY)
                    fitted, _, _ = fit_housings(gray, [head.lens])
                    ious.append(iou_matrix([head.housing], fitted)[0, 0])
    iou = np.array(ious)
    return (
        f"| {backdrop} | {'light rim' if rim else 'plain'} | {len(iou)} | "
        f"{np.mean(iou >= 0.5):.3f} | {np.mean(iou >= 0.8):.3f} |"
    )


def stage_starts(name: str, split: str | None = "test") -> str:
    """Share of ``name``'s housings (of ``split``; None: all) fitted at IoU >= 0.5 from each
    start (module docstring)."""
    union = get_registry().create("detector", "union")
    starts = ("true lens", "true centre, cand. radius", "cand. centre, true radius", "candidate")
    fitted: dict[str, list[float]] = {k: [] for k in starts}
    free: dict[str, list[float]] = {k: [] for k in starts}
    offsets, total = [], 0
    for sample in split_samples(name, split):
        boxes = [a.bbox for a in sample.annotations]
        if not boxes:
            continue
        total += len(boxes)
        frame = sample.load()
        gray = cv2.cvtColor(frame.image, cv2.COLOR_BGR2GRAY)
        found = union.detect(frame)
        hits = centre_hits([(c.x, c.y) for c in found], boxes) if found else None
        for j, box in enumerate(boxes):
            lens = find_lens(frame.image, box)
            idx = np.flatnonzero(hits[:, j]) if hits is not None else []
            lenses = {"true lens": (lens.x, lens.y, lens.radius)}
            if len(idx):
                c = max((found[i] for i in idx), key=lambda c: c.score)
                lenses["true centre, cand. radius"] = (lens.x, lens.y, c.radius)
                lenses["cand. centre, true radius"] = (c.x, c.y, lens.radius)
                lenses["candidate"] = (c.x, c.y, c.radius)
                offsets.append(np.hypot(c.x - lens.x, c.y - lens.y) / lens.radius)
            for key, start in lenses.items():
                fit, _, _ = fit_housings(gray, [start])
                fitted[key].append(iou_matrix([box], fit)[0, 0])
                free[key].append(margin_free_iou(box, fit[0]))
    cells = " | ".join(
        f"{np.sum(np.array(fitted[k]) >= 0.5) / total:.2f} "
        f"({np.sum(np.array(free[k]) >= 0.5) / total:.2f})"
        for k in starts
    )
    return (
        f"| {name} ({split or 'all'}) | {total} | {len(offsets) / total:.2f} | {cells} "
        f"| {np.median(offsets):.2f} |"
    )


def matches(out: list[Candidate], boxes: list, lens_boxed: bool) -> tuple[np.ndarray, np.ndarray]:
    """(candidates, boxes) matrices: IoU >= 0.5 of the evaluated box, and centre hits."""
    fitted = [c.bbox if lens_boxed else c.housing for c in out]
    return iou_matrix(fitted, boxes) >= 0.5, centre_hits([(c.x, c.y) for c in out], boxes)


def first_met(good: np.ndarray, hits: np.ndarray) -> int:
    """Boxes met by the first (best-ranked) candidate that hits them."""
    first = np.argmax(hits, axis=0)  # the first hitting row of each box's column
    return int((good[first, np.arange(hits.shape[1])] & hits.any(axis=0)).sum())


def selection(spec: str) -> str:
    """One ``--select`` row (module docstring) for ``spec`` = ``SET:SPLIT``."""
    name, split = spec.split(":")
    lens_boxed = open_dataset(name).info.get("box") == "lens"
    union = get_registry().create("detector", "union")
    create = get_registry().create
    every, stage = create("verifier", "housing", {"nms_iou": 1.0}), create("verifier", "housing")
    counts = dict.fromkeys(("best", "first", "any", "kept"), 0)
    images: list[dict] = []
    truth: list[dict] = []
    results: list[dict] = []
    total = 0
    for index, sample in enumerate(open_dataset(name).split(split), 1):
        boxes = [a.bbox for a in sample.annotations]
        total += len(boxes)
        frame = sample.load()
        images.append({"id": index, "width": sample.width, "height": sample.height})
        truth += [
            {"id": len(truth) + k, "image_id": index, "category_id": 1, "iscrowd": 0,
             "bbox": xyxy_to_xywh(b), "area": (b[2] - b[0]) * (b[3] - b[1])}
            for k, b in enumerate(boxes, 1)
        ]  # fmt: skip
        found = union.detect(frame)
        if not found:
            continue
        if boxes:
            good, hits = matches(every.verify(frame, found), boxes, lens_boxed)  # by score
            counts["best"] += first_met(good, hits)
            counts["any"] += int((good & hits).any(axis=0).sum())
        out = stage.verify(frame, found)
        results += [
            {"image_id": index, "category_id": 1, "score": c.score,
             "bbox": xyxy_to_xywh(c.bbox if lens_boxed else c.housing)}
            for c in out
        ]  # fmt: skip
        if not boxes:
            continue
        good, hits = matches(out, boxes, lens_boxed)
        counts["first"] += first_met(good, hits)
        counts["kept"] += int(good.any(axis=0).sum())
    cells = " | ".join(f"{v / total:.3f}" for v in counts.values())
    ap50 = coco_ap(coco_dataset(images, truth, name), results)["ap50"]
    return f"| {name} {split} | {total} | {cells} | {ap50:.3f} |"


def detector_runs(name: str, detector: str, stage: list[str]) -> str:
    """Housing AP50 and recall at IoU 0.5 of ``detector`` with ``stage`` on ``name`` test."""
    with tempfile.TemporaryDirectory() as out:
        tsrkit = Path(sys.executable).parent / "tsrkit"
        cmd = [str(tsrkit), "benchmark", "--dataset", name, "--split", "test", "-d", detector]
        cmd += [*stage, "--eval-box", "housing", "-o", out, "-q", "--writer", "json"]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        report = json.loads((Path(out) / "report.json").read_text())
    iou = report["iou50"]
    ap = "n/a" if iou.get("ap") is None else f"{iou['ap']:.3f}"
    return (
        f"| {name} | {detector} | {' '.join(stage) or '-'} | {ap} | {iou['recall']:.3f} | "
        f"{report['per_frame']['hit_frame_fraction']:.3f} |"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stages", action="store_true", help="only the stage-by-stage table")
    parser.add_argument("--fit", action="store_true", help="only the speed and fit quality")
    parser.add_argument("--select", nargs="+", metavar="SET:SPLIT", help="only: which candidate")
    parser.add_argument("--pads", nargs="+", type=float, metavar="P", help="only: fits + P px")
    parser.add_argument("--rendered", action="store_true", help="only: rendered heads")
    args = parser.parse_args()
    harness.announce()
    if args.pads:
        print(
            "| set | split | housings | "
            + " | ".join(f"pad {p:g} px" for p in args.pads)
            + " | median slack l / t / r / b (px) | lies as the box |"
        )
        print("|---|---|---:|" + "---:|" * len(args.pads) + "---|---:|")
        for name, splits in PAD_SPLITS.items():
            for split in splits:
                print(pad_row(name, split, args.pads), flush=True)
        return
    if args.rendered:
        print("| background | head | heads | IoU >= 0.5 | IoU >= 0.8 |\n|---|---|---:|---:|---:|")
        for backdrop in ("sky", "dark"):
            for rim in (False, True):
                print(rendered_row(backdrop, rim), flush=True)
        return
    if args.select:
        print(
            "| set | boxes | best-scored hitting | stage's first hitting | any hitting | any kept "
            "| AP50 |\n|---|---:|---:|---:|---:|---:|---:|"
        )
        for spec in args.select:
            print(selection(spec), flush=True)
        return
    if args.stages:
        print("shares at IoU >= 0.5, margin-free in brackets\n")
        print(
            "| set (split) | housings | union hit | true lens | true centre, cand. radius "
            "| cand. centre, true radius | candidate | cand. offset (true radii, median) |"
        )
        print("|---|---:|---:|---:|---:|---:|---:|---:|")
        for name, split in STAGE_SPLITS.items():
            print(stage_starts(name, split), flush=True)
        return
    wall, cpu = speed()
    print(
        f"housing stage, 1280x720, 50 candidates, one thread: {wall:.2f} ms wall, "
        f"{cpu:.2f} ms CPU (medians of 30)"
    )
    for name in ("roboflow_cinta_v2_id", "dtld_fridtjofs"):
        print(fit_quality(name))
    if args.fit:
        return
    print("\n| set (test) | detector | stage | housing AP50 | recall at IoU 0.5 | hit |")
    print("|---|---|---|---:|---:|---:|")
    for name in ("roboflow_cinta_v2_id", "dtld_fridtjofs"):
        for detector in ("lab-frst", "conspicuity"):
            for stage in ([], ["-V", "housing"]):
                print(detector_runs(name, detector, stage), flush=True)


if __name__ == "__main__":
    main()
