"""Leave-one-camera-out: the recommended preset's candidates, housing and verifier on a camera
it never trained on.

**Folds.** The four detection families (KR, cinTA, DTLD, Japan), each held out whole (every
split: no split of a held-out camera is trained on, so all its frames are test frames), and a
crop fold: real head crops of ``udacity_mit_tl_crops`` test (whole heads) and lit bulbs of
``lisa_vgis_bulb_crops`` (20x20, put into the lit slot of a rendered head) pasted into synthetic
no-light scenes. For a family fold the verifier is trained (``tsrkit.runner.training.train``, the
plugin's own training) on every frame of the three other families; for the crop fold on all
four families with ``--crop-fold`` (default ``crop_frames=0``: no MIT crop pasted, since the
fold tests MIT's camera; VGIS is in no verifier training).

**Pipeline.** The preset's (``--config``, default ``recommended``) detector, housing stage and
verifier parameters; ``-p NAME.KEY=V`` overrides one (``-p verifier.seed=1``, ``-p
union.members=...``). Every candidate of a test frame is scored once (the verifier at threshold
0: its decision score, what ``threshold`` and ``relative`` read, and its reported score, what
AP reads) and dumped (``DIR/dump_FOLD_SET.npz``); every figure is computed from the dumps at
the preset's threshold and relative gate (or ``--threshold`` / ``--relative``).

**Figures per held-out set** (Zheng 5.2.1 centre rule for hits): candidate recall before the
verifier, per set and per light size (r = half the box's shorter side, px); hit-frame
fraction; precision and false lights per frame (exhaustive sets only); recall at IoU 0.5 (the
set's box: lens on KR, housing on the others, the crop on MIT, the bulb on VGIS); AP50 of the
same box (exhaustive sets only); false lights per frame on frames without a light: 30
synthetic no-light 1280x720 scenes, and the held-out set's **empty frames**, its own frames with
every annotated box (grown by a quarter of its long side + 2 px) inpainted
(``cv2.INPAINT_TELEA``): a frame of the held-out camera without a lit light (on the sets that
are not exhaustively labelled, unlabelled lights stay, so those counts are upper bounds).

Candidates are cached on disk (``benchmarks/out/candidate_cache``), named by the detector's name
and its candidates on a few probe frames: a rerun, or a run at another commit whose
detector finds the same candidates, reads them back.

A run into a folder that holds a run of the same settings adds its folds to it (``--only``).

Run:  python benchmarks/camera_loso.py --out benchmarks/out/camera_loso        # ~1 h cold
      python benchmarks/camera_loso.py --tables benchmarks/out/camera_loso [--threshold 0.3]
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import hashlib  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import time  # noqa: E402
from collections.abc import Iterable, Sequence  # noqa: E402
from dataclasses import asdict, dataclass  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402
import yaml  # noqa: E402

import tsrkit  # noqa: E402
from tsrkit import (  # noqa: E402
    Annotation,
    Candidate,
    Detector,
    Sample,
    get_registry,
)
from tsrkit.api import (  # noqa: E402
    centre_hits,
    iou_matrix,
    open_datasets,
    parse_assignments,
    xyxy_to_xywh,
)
from tsrkit.eval.coco import coco_ap, coco_dataset  # noqa: E402
from tsrkit.plugin.presets import resolve_config  # noqa: E402
from tsrkit.runner.training import train  # noqa: E402
from tsrkit.synth.heads import LAMP_COLOURS, render_head  # noqa: E402
from tsrkit_plugins.verifiers.learned import passes  # noqa: E402
from tsrkit_plugins.verifiers.pasting import feathered_alpha, paste, place  # noqa: E402
from tsrkit_plugins.verifiers.unlit import no_light_frames  # noqa: E402

cv2.setNumThreads(1)
#: The plugin tree the run imports.
REPO_PLUGINS = Path(__import__("tsrkit_plugins").__path__[0])


@dataclass(frozen=True)
class Family:
    """A detection family held out whole: registry name, evaluated box, exhaustive labels."""

    key: str
    name: str
    box: str
    exhaustive: bool


FAMILIES = (
    Family("KR", "roboflow_traffic_light_kr", "lens", True),
    Family("cinTA", "roboflow_cinta_v2_id", "housing", True),
    Family("DTLD", "dtld_fridtjofs", "housing", False),
    Family("Japan", "iwai_japan_tl", "housing", False),
)
#: The crop fold's test sets: (key, evaluated box); synthetic scenes, exhaustive by making.
CROP_SETS = (("MIT", "housing"), ("VGIS", "lens"))
#: Synthetic no-light test scenes (seed other than training's).
NO_LIGHT, NO_LIGHT_SEED = 30, 2024
#: Seeds and sizes of the crop fold's scenes.
MIT_SCENES, VGIS_SCENES, CROP_TEST_SEED = 60, 60, 4242
THRESHOLDS = (0.1, 0.2, 0.25, 0.3, 0.35, 0.4, 0.5, 0.6, 0.7)


class CachedDetector(Detector):
    """A detector whose candidates are computed once per frame source, kept in memory and
    appended to a JSON-lines file named by the detector's name and its candidates on
    :data:`PROBES` (so a change of code or parameters that changes no candidate keeps the cache,
    one that changes them starts another)."""

    def __init__(self, inner: Detector, folder: Path):
        super().__init__(**inner.params)
        self.inner = inner
        self.name = inner.name  # type: ignore[misc]
        digest = hashlib.sha256(inner.name.encode())
        for sample in probes():
            for c in inner.detect(sample.load()):
                digest.update(json.dumps(asdict(c)).encode())
        folder.mkdir(parents=True, exist_ok=True)
        self.path = folder / f"{digest.hexdigest()[:16]}.jsonl"
        self._seen: dict[str, list[Candidate]] = {}
        if self.path.exists():
            for line in self.path.read_text().splitlines():
                row = json.loads(line)
                self._seen[row["key"]] = [_candidate(c) for c in row["candidates"]]

    def detect(self, frame):
        key = f"{frame.source}#{frame.index}"
        if key not in self._seen:
            found = self.inner.detect(frame)
            self._seen[key] = found
            with self.path.open("a") as fh:
                fh.write(json.dumps({"key": key, "candidates": [asdict(c) for c in found]}))
                fh.write("\n")
        return self._seen[key]


#: Frames whose candidates name the cache: the first frame of each family.
PROBES = tuple(f.name for f in FAMILIES)


def probes() -> list[Sample]:
    """The cache's probe frames (:data:`PROBES`)."""
    return [open_datasets([name]).samples[0] for name in PROBES]


def _candidate(row: dict) -> Candidate:
    """A cached candidate (tuples back from JSON lists)."""
    boxes = {k: tuple(row[k]) for k in ("bbox", "housing") if row.get(k) is not None}
    return Candidate(**{**row, **boxes})


def inpainted(sample: Sample) -> Sample:
    """``sample``'s frame with every annotated box (grown by a quarter of its long side + 2 px)
    inpainted: a frame of that camera without a lit light."""
    image = sample.load().image
    mask = np.zeros(image.shape[:2], np.uint8)
    for a in sample.annotations:
        x0, y0, x1, y1 = a.bbox
        grow = 0.25 * max(x1 - x0, y1 - y0) + 2
        corners = (
            (int(x0 - grow), int(y0 - grow)),
            (int(np.ceil(x1 + grow)), int(np.ceil(y1 + grow))),
        )
        cv2.rectangle(mask, *corners, 255, -1)
    filled = cv2.inpaint(image, mask, 5, cv2.INPAINT_TELEA)
    height, width = filled.shape[:2]
    return Sample(f"{sample.source}@empty", (), width, height, "test", image=filled)


def no_light_samples() -> list[Sample]:
    """The synthetic no-light test scenes."""
    return [
        Sample(f.source, (), f.width, f.height, "test", image=f.image)
        for f in no_light_frames(NO_LIGHT, seed=NO_LIGHT_SEED)
    ]


def mit_samples() -> list[Sample]:
    """MIT test crops (whole heads) pasted, five a scene, into synthetic daylight no-light
    scenes, each at a housing height log-uniform in 10-110 px (the verifier's pasting:
    :func:`place`, :func:`paste`, written here so that any commit's pasting module serves);
    boxes: the crops."""
    crops = sorted(open_datasets(["udacity_mit_tl_crops:test"]).samples, key=lambda s: s.source)
    images = [c.load().image for c in crops]
    rng = np.random.default_rng(CROP_TEST_SEED)
    out = []
    for frame in no_light_frames(MIT_SCENES, CROP_TEST_SEED, ("day",), "mit-test"):
        image = frame.image.copy()
        boxes: list = []
        for _ in range(5):
            crop = images[int(rng.integers(0, len(images)))]
            height = max(4, int(round(np.exp(rng.uniform(np.log(10), np.log(110))))))
            width = max(2, int(round(height * crop.shape[1] / crop.shape[0])))
            box = place(rng, image.shape[:2], (width, height), boxes)
            if box is not None:
                paste(image, crop, box)
                boxes.append(tuple(float(v) for v in box))
        out.append(_scene(frame.source, image, boxes))
    return out


def vgis_samples() -> list[Sample]:
    """VGIS lit-bulb crops (deduplicated by content) in the lit slot of a rendered head of an
    unlit lens colour, five a scene, in synthetic no-light scenes of the crop's lighting (day
    or night); boxes: the bulbs (lens radius 2-10 px, log-uniform)."""
    crops: dict[str, list[np.ndarray]] = {"day": [], "night": []}
    seen = set()
    for s in sorted(open_datasets(["lisa_vgis_bulb_crops"]).samples, key=lambda s: s.source):
        image = s.load().image
        digest = hashlib.sha256(image.tobytes()).hexdigest()
        if digest not in seen:
            seen.add(digest)
            crops[s.metadata.get("lighting", "day")].append(image)
    rng = np.random.default_rng(CROP_TEST_SEED + 1)
    out = []
    for k in range(VGIS_SCENES):
        lighting = "night" if k % 4 else "day"  # VGIS is 3 / 4 night
        (frame,) = no_light_frames(1, CROP_TEST_SEED + 1 + k, (lighting,), "vgis-test")
        image = frame.image.copy()
        housings: list = []
        bulbs: list = []
        for _ in range(5):
            radius = float(np.exp(rng.uniform(np.log(2), np.log(10))))
            vertical = bool(rng.random() < 0.7)
            lenses = int(rng.integers(3, 5))
            lit = int(rng.integers(0, lenses))
            long = 2.8 * radius * lenses
            size = (int(2.8 * radius), int(long)) if vertical else (int(long), int(2.8 * radius))
            spot = place(rng, image.shape[:2], size, housings)
            if spot is None:
                continue
            x0, y0 = spot[:2]
            step = (lit + 0.5) * 2.8 * radius
            centre = (x0 + 1.4 * radius, y0 + step) if vertical else (x0 + step, y0 + 1.4 * radius)
            head = render_head(image, centre, radius, lenses, lit, vertical, LAMP_COLOURS["red"])
            bulb = crops[lighting][int(rng.integers(0, len(crops[lighting])))]
            housings.append(head.housing)
            bulbs.append(_paste_bulb(image, bulb, centre, radius))
        out.append(_scene(frame.source, image, bulbs))
    return out


def _paste_bulb(image: np.ndarray, bulb: np.ndarray, centre, radius: float):
    """Blend ``bulb`` into the disc of ``radius`` at ``centre`` (feathered); its lens box."""
    cx, cy = centre
    x0, y0 = int(round(cx - radius)), int(round(cy - radius))
    side = max(2, int(round(2 * radius)))
    x1, y1 = min(x0 + side, image.shape[1]), min(y0 + side, image.shape[0])
    x0, y0 = max(x0, 0), max(y0, 0)
    if x1 - x0 < 2 or y1 - y0 < 2:
        return (cx - radius, cy - radius, cx + radius, cy + radius)
    resized = cv2.resize(bulb, (x1 - x0, y1 - y0), interpolation=cv2.INTER_AREA).astype(float)
    yy, xx = np.mgrid[y0:y1, x0:x1] + 0.5
    disc = np.clip(radius + 0.5 - np.hypot(xx - cx, yy - cy), 0, 1)
    alpha = (disc * feathered_alpha(y1 - y0, x1 - x0, 1))[:, :, None]
    under = image[y0:y1, x0:x1].astype(float)
    image[y0:y1, x0:x1] = np.clip(np.round(alpha * resized + (1 - alpha) * under), 0, 255)
    return (float(x0), float(y0), float(x1), float(y1))


def _scene(source: str, image: np.ndarray, boxes: Sequence) -> Sample:
    annotations = tuple(Annotation(tuple(float(v) for v in b), "unknown") for b in boxes)
    height, width = image.shape[:2]
    return Sample(source, annotations, width, height, "test", image=image)


def dump(samples: Iterable[Sample], detector: Detector, verifier, box: str) -> dict:
    """Every candidate of ``samples`` after the verifier's stage at threshold 0, flat arrays:
    ``frame``, ``decision`` and ``score`` (the verifier's), ``agreement`` (the detector's own
    score), ``light`` (index of the frame's light its centre hits, -1), ``fit`` (index of a
    light its ``box`` meets at IoU >= 0.5, -1), the reported ``boxes``; and per frame the
    number of lights, the truth boxes (for AP) and per light its lens radius (:func:`lens_radius`)
    and whether a raw candidate's centre lies in its circle (candidate recall)."""
    rows: dict[str, list] = {k: [] for k in ("frame", "decision", "score", "agreement")}
    rows |= {"light": [], "fit": [], "boxes": []}
    lights, truth, radius, found_by = [], [], [], []
    samples = list(samples)
    for index, sample in enumerate(samples):
        frame = sample.load()
        boxes = [a.bbox for a in sample.annotations]
        lights.append(len(boxes))
        truth += [(index, *b) for b in boxes]
        found = detector.detect(frame)
        radius += [lens_radius(b, box) for b in boxes]
        if boxes:
            points = [(c.x, c.y) for c in found]
            hit = centre_hits(points, boxes).any(axis=0) if points else np.zeros(len(boxes), bool)
            found_by += hit.tolist()
        staged, decision, score = verifier.scores(frame, found) if found else ([], [], [])
        if not len(staged):
            continue
        reported = [c.bbox if box == "lens" else c.object_bbox for c in staged]
        light = np.full(len(staged), -1)
        fit = np.full(len(staged), -1)
        if boxes:
            hits = centre_hits([(c.x, c.y) for c in staged], boxes)
            light = np.where(hits.any(axis=1), hits.argmax(axis=1), -1)
            good = iou_matrix(reported, boxes) >= 0.5
            fit = np.where(good.any(axis=1), good.argmax(axis=1), -1)
        rows["frame"].append(np.full(len(staged), index))
        rows["decision"].append(np.asarray(decision, float))
        rows["score"].append(np.asarray(score, float))
        rows["agreement"].append(np.clip([c.score for c in staged], 0, 1))
        rows["light"].append(light)
        rows["fit"].append(fit)
        rows["boxes"].append(np.asarray(reported, float).reshape(-1, 4))
    out = {
        k: np.concatenate(v) if v else np.zeros((0, 4) if k == "boxes" else 0)
        for k, v in rows.items()
    }
    out["lights"] = np.asarray(lights)
    out["truth"] = np.asarray(truth, float).reshape(-1, 5)
    out["light_radius"] = np.asarray(radius, float)
    out["light_found"] = np.asarray(found_by, bool)
    out["shapes"] = np.array([(s.width or 0, s.height or 0) for s in samples])
    return out


#: Lens radius bins (px) of the candidate recall table; the issue's tiny lights are r <= 3.
LENS_BINS = ((0, 2), (2, 3), (3, 4), (4, 6), (6, 12), (12, np.inf))


def lens_radius(box: Sequence[float], kind: str) -> float:
    """The lens radius of an annotated light: half a lens box's shorter side; half a housing
    box's shorter side / 1.3 (as ``candidate_recall.py`` bins them)."""
    short = min(box[2] - box[0], box[3] - box[1])
    return short / 2 if kind == "lens" else short / 2 / 1.3


def recall_by_lens(d: dict) -> list[tuple[float | None, int]]:
    """Candidate recall and light count, over all lights then per :data:`LENS_BINS`."""
    r, found = d["light_radius"], d["light_found"]
    cells = [(found.mean() if len(r) else None, len(r))]
    for low, high in LENS_BINS:
        inside = (r >= low) & (r < high)
        cells.append((found[inside].mean() if inside.any() else None, int(inside.sum())))
    return cells


def figures(d: dict, threshold: float, relative: float, exhaustive: bool) -> dict:
    """Zheng hit / recall / precision / false lights per frame, recall at IoU 0.5 and AP50
    of one dump at ``threshold`` and ``relative`` (on the decision scores)."""
    hit, recall, precision, fps, fitted = [], [], [], [], 0
    for index, n in enumerate(d["lights"]):
        rows = np.flatnonzero(d["frame"] == index)
        keep = rows[passes(d["decision"][rows], threshold, relative)] if len(rows) else rows
        light, fit = d["light"][keep], d["fit"][keep]
        tp = int(np.count_nonzero(light >= 0))
        fps.append(len(keep) - tp)
        if n:
            found = len(np.unique(light[light >= 0]))
            hit.append(found > 0)
            recall.append(found / n)
            fitted += len(np.unique(fit[fit >= 0]))
            if len(keep):
                precision.append(tp / len(keep))
    total = int(np.sum(d["lights"]))
    return {
        "hit": float(np.mean(hit)) if hit else None,
        "recall": float(np.mean(recall)) if recall else None,
        "precision": float(np.mean(precision)) if precision and exhaustive else None,
        "fp_per_frame": float(np.mean(fps)) if fps else None,
        "iou50_recall": fitted / total if total else None,
    }


def ap50(d: dict, name: str) -> float | None:
    """AP at IoU 0.5 (pycocotools) of every candidate ranked by its reported score."""
    images = [
        {"id": i + 1, "width": int(w), "height": int(h)} for i, (w, h) in enumerate(d["shapes"])
    ]
    truth = [
        {"id": k + 1, "image_id": int(f) + 1, "category_id": 1, "iscrowd": 0,
         "bbox": xyxy_to_xywh(b), "area": float((b[2] - b[0]) * (b[3] - b[1]))}
        for k, (f, *b) in enumerate(d["truth"].tolist())
    ]  # fmt: skip
    results = [
        {"image_id": int(f) + 1, "category_id": 1, "score": float(s), "bbox": xyxy_to_xywh(b)}
        for f, s, b in zip(d["frame"], d["score"], d["boxes"].tolist())
    ]
    return coco_ap(coco_dataset(images, truth, name), results)["ap50"]


def load_preset(name: str, overrides: Sequence[str]) -> tuple[str, dict, dict]:
    """The preset's detector name, detector parameters and verifier parameters, with the
    ``NAME.KEY=V`` overrides."""
    config = yaml.safe_load(resolve_config(name).read_text())
    detector = config["detector"]["name"]
    det_params = dict(config["detector"].get("params") or {})
    ver_params = dict(config.get("verifier", {}).get("params") or {})
    for key, value in parse_assignments(list(overrides)).items():
        owner, _, field = key.partition(".")
        if owner == detector:
            det_params[field] = value
        elif owner == "verifier":
            ver_params[field] = value
        else:
            raise SystemExit(f"-p {key}: neither {detector}.KEY nor verifier.KEY")
    return detector, det_params, ver_params


def run(args) -> None:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    reg = get_registry()
    name, det_params, ver_params = load_preset(args.config, args.param)
    detector = CachedDetector(reg.create("detector", name, det_params), Path(args.cache))
    threshold = float(ver_params.pop("threshold", 0.5))
    relative = float(ver_params.pop("relative", 0.0))
    commit = subprocess.run(
        ["git", "-C", str(REPO_PLUGINS.parent), "rev-parse", "--short", "HEAD"],
        capture_output=True, text=True,
    ).stdout.strip()  # fmt: skip
    results: dict = {
        "config": args.config, "detector": name, "detector_params": det_params,
        "verifier_params": ver_params, "threshold": threshold, "relative": relative,
        "crop_fold": args.crop_fold, "code": {"commit": commit, "tsrkit": tsrkit.__file__},
        "folds": {},
    }  # fmt: skip
    earlier = out / "results.json"
    if earlier.exists():  # a run of other folds (--only) into the same folder: keep its folds
        before = json.loads(earlier.read_text())
        same = ("config", "detector_params", "verifier_params", "threshold", "relative")
        if any(before[k] != results[k] for k in same):
            raise SystemExit(f"{earlier}: a run of other settings; choose another --out")
        results["folds"] = before["folds"]
        results["code"] = before["code"] | {"later": results["code"]}
    started = time.perf_counter()
    folds = [(f.key, [o for o in FAMILIES if o.key != f.key], {}) for f in FAMILIES]
    folds.append(("crops", list(FAMILIES), parse_assignments(args.crop_fold)))
    for key, trained_on, extra in folds:
        if args.only and key not in args.only:
            continue
        model = out / f"verifier_{key}"
        refs = [f.name for f in trained_on]
        params = {**ver_params, **extra}
        t0 = time.perf_counter()
        if not model.with_suffix(".npz").exists():
            train("verifier", open_datasets(refs), model, params, detector)
        fit_s = time.perf_counter() - t0
        verifier = reg.create(
            "verifier", "verifier", {**params, "model": str(model), "threshold": 0.0}
        )
        if key == "crops":
            tests = {"MIT": (mit_samples(), "housing"), "VGIS": (vgis_samples(), "lens")}
        else:
            family = next(f for f in FAMILIES if f.key == key)
            samples = list(open_datasets([family.name]).samples)
            tests = {
                key: (samples, family.box),
                f"{key}-empty": ([inpainted(s) for s in samples], "housing"),
            }
        tests["no-light"] = (no_light_samples(), "housing")
        fold = {"train": refs, "params": params, "fit_seconds": round(fit_s, 1), "sets": {}}
        for part, (samples, box) in tests.items():
            d = dump(samples, detector, verifier, box)
            np.savez_compressed(out / f"dump_{key}_{part}.npz", **d)
            fold["sets"][part] = {"box": box, "frames": len(samples)}
            print(
                key,
                part,
                len(d["frame"]),
                "candidates",
                round(time.perf_counter() - started),
                "s",
                flush=True,
            )
        results["folds"][key] = fold
        (out / "results.json").write_text(json.dumps(results, indent=1))
    results["seconds"] = round(time.perf_counter() - started, 1)
    (out / "results.json").write_text(json.dumps(results, indent=1))
    print(tables(out, threshold, relative))


def _f(value, spec=".2f") -> str:
    return (
        "n/a"
        if value is None or (isinstance(value, float) and np.isnan(value))
        else format(value, spec)
    )


def tables(out: Path, threshold: float | None = None, relative: float | None = None) -> str:
    """The Markdown tables of a finished run in ``out``."""
    results = json.loads((out / "results.json").read_text())
    t = results["threshold"] if threshold is None else threshold
    rel = results["relative"] if relative is None else relative
    exhaustive = {f.key: f.exhaustive for f in FAMILIES} | {"MIT": True, "VGIS": True}
    lines = [
        f"Run: {results['config']} at {results['code']['commit']}; {results['detector']} "
        f"{json.dumps(results['detector_params'])}; verifier "
        f"{json.dumps(results['verifier_params'])}; threshold {t}, relative {rel}; crop fold "
        f"trained with {results['crop_fold']}.",
        "",
        "| held out | frames | cand. recall | hit | precision | recall IoU.5 | AP50 (box) "
        "| FP/frame | empty-frame FP/frame | no-light FP/frame |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    size_rows = []
    for key, fold in results["folds"].items():
        nolight = dict(np.load(out / f"dump_{key}_no-light.npz"))
        nl = figures(nolight, t, rel, True)["fp_per_frame"]
        for part, info in fold["sets"].items():
            if part in ("no-light",) or part.endswith("-empty"):
                continue
            d = dict(np.load(out / f"dump_{key}_{part}.npz"))
            f = figures(d, t, rel, exhaustive[part])
            empty = out / f"dump_{key}_{part}-empty.npz"
            e = (
                figures(dict(np.load(empty)), t, rel, True)["fp_per_frame"]
                if empty.exists()
                else None
            )
            ap = ap50(d, part) if exhaustive[part] else None
            cells = recall_by_lens(d)
            lines.append(
                f"| {part} | {info['frames']} | {_f(cells[0][0])} | {_f(f['hit'])} | "
                f"{_f(f['precision'])} | {_f(f['iou50_recall'])} | {_f(ap)} ({info['box']}) | "
                f"{_f(f['fp_per_frame'] if exhaustive[part] else None)} | "
                f"{_f(e)}{'' if exhaustive[part] or e is None else ' (upper bound)'} | {_f(nl)} |"
            )
            size_rows.append(f"| {part} | " + " | ".join(f"{_f(v)} ({n})" for v, n in cells) + " |")
    bins = ["all"] + [f"{lo:g}-{hi:g}" if hi < np.inf else f">={lo:g}" for lo, hi in LENS_BINS]
    lines += [
        "",
        "Candidate recall (a raw candidate's centre in the light's circle) by lens radius r, px "
        "(lens box: half its shorter side; housing box: half its shorter side / 1.3); lights in "
        "brackets:",
        "",
        "| held out | " + " | ".join(bins) + " |",
        "|---|" + "---:|" * len(bins),
        *size_rows,
    ]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", default="recommended", help="preset or run configuration")
    parser.add_argument("-p", "--param", action="append", default=[], help="NAME.KEY=V override")
    parser.add_argument(
        "--crop-fold",
        nargs="*",
        default=["crop_frames=0"],
        metavar="KEY=V",
        help="verifier parameters of the crop fold's training (no MIT crop)",
    )
    parser.add_argument("--out", default="benchmarks/out/camera_loso")
    parser.add_argument("--cache", default="benchmarks/out/candidate_cache")
    parser.add_argument("--only", nargs="*", help="only these folds (KR cinTA DTLD Japan crops)")
    parser.add_argument("--tables", metavar="DIR", help="only print the tables of a finished run")
    parser.add_argument("--threshold", type=float, help="tables: verifier threshold")
    parser.add_argument("--relative", type=float, help="tables: relative gate")
    args = parser.parse_args()
    if args.tables:
        if not (Path(args.tables) / "results.json").is_file():
            parser.error(f"--tables {args.tables}: no results.json there")
        print(tables(Path(args.tables), args.threshold, args.relative))
        return
    run(args)


if __name__ == "__main__":
    main()
