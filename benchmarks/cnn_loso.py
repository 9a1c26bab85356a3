"""Leave-one-camera-out of the CNN verifier (``cnn-verifier``), and the shipped model.

**Folds.** The five detection families (KR, cinTA, DTLD, Japan, Traffic-pi), each held out
whole: its fold's network is trained on every frame of the four others (an unboxed candidate
is a negative only on the exhaustively labelled KR and cinTA, or low in the frame on the others:
``tsrkit_plugins.verifiers.cnn.data``), plus 120 synthetic no-light scenes, 40 scenes of
rendered lit heads and 80 synthetic scenes with MIT train crops pasted in (the same for every
fold). No fold ever trains on ``taiwan_dashcam_video``: its annotated keyframes are real road
scenes of five more dash-cams that every fold model, and the shipped one, has never seen.

**Pipeline.** The preset's detector (``--config``, default ``recommended``) gives the candidates
(cached in ``OUT/candidates``); each fold's model then runs through the plugin's own ``verify``
with the preset's verifier parameters, so the figures are those of the preset as it ships with
the fold's network.

**Figures per held-out set** (Zheng 5.2.1 centre rule): candidate recall before the verifier;
hit-frame fraction; mean per-frame precision and recall (exhaustive sets only for precision);
recall at IoU 0.5 of the set's box (the lens box on KR, the network's housing box elsewhere);
state accuracy, red and amber recall of the lights found (the network's state head, and
``lamp-state`` on the same detections); false lights per frame on frames without a lit light:
the held-out set's frames without a box (exhaustive sets), the Taiwanese keyframes (a detection
whose centre lies in no box grown by half its size, the dataset README's rule; on all 55
keyframes and on the 31 holding no box), and 30 synthetic no-light scenes.

**Shipped model** (``--ship``): trained on openly licensed data only (KR and cinTA, every split,
CC BY 4.0; MIT crops, CC BY-SA 4.0; tsrkit's synthetic scenes), written to
``plugins/verifiers/models/cnn_verifier_default.{onnx,json}`` with the fold figures on its card.

Run:  python benchmarks/cnn_loso.py --out benchmarks/out/cnn_loso          # ~40 min cold
      python benchmarks/cnn_loso.py --out benchmarks/out/cnn_loso --only KR --epochs 2 --quick
      python benchmarks/cnn_loso.py --out benchmarks/out/cnn_loso --ship
"""

from __future__ import annotations

import harness

harness.single_thread()

import argparse  # noqa: E402
import json  # noqa: E402
import shlex  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from dataclasses import asdict, dataclass, replace  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

import tsrkit  # noqa: E402
from tsrkit.api import (  # noqa: E402
    Candidate,
    Frame,
    Sample,
    atomic_open,
    centre_hits,
    greedy_match,
    iou_matrix,
    load_model,
    open_datasets,
    save_model,
)
from tsrkit_plugins.verifiers.cnn.data import STATE_NAMES, CropSet, Scene, scene_crops  # noqa: E402
from tsrkit_plugins.verifiers.cnn.plugin import DEFAULT_MODEL  # noqa: E402
from tsrkit_plugins.verifiers.mining import HEADS_SEED, Heads, head_frames  # noqa: E402
from tsrkit_plugins.verifiers.pasting import crop_frames  # noqa: E402
from tsrkit_plugins.verifiers.unlit import no_light_frames  # noqa: E402


@dataclass(frozen=True)
class Family:
    """A detection family: key, registry name, evaluated box, exhaustive labels, open licence."""

    key: str
    name: str
    box: str
    exhaustive: bool
    open: bool


FAMILIES = (
    Family("KR", "roboflow_traffic_light_kr", "lens", True, True),
    Family("cinTA", "roboflow_cinta_v2_id", "housing", True, True),
    Family("DTLD", "dtld_fridtjofs", "housing", False, False),
    Family("Japan", "iwai_japan_tl", "housing", False, False),
    Family("pi", "traffic_pi_us", "housing", False, False),
)
TAIWAN = "taiwan_dashcam_video"
NO_LIGHT_TEST, NO_LIGHT_TEST_SEED = 30, 2024


def scene_of(sample: Sample, exhaustive: bool, camera: str) -> Scene:
    return Scene(
        sample.load(),
        [a.bbox for a in sample.annotations],
        [a.state for a in sample.annotations],
        exhaustive,
        camera,
    )


def taiwan_scenes() -> list[tuple[Scene, list[tuple[float, ...]]]]:
    """The Taiwanese keyframes (frame N of the JSON is frame N - 1 of the clip) with their
    boxes, and the boxes grown by half their size (the false-light rule)."""
    import cv2

    root = harness.data_dir() / TAIWAN
    marks = json.loads((root / "lights_keyframes.json").read_text())
    out = []
    for clip, entry in sorted(marks.items()):
        video = cv2.VideoCapture(str(root / f"{clip}.mp4"))
        frames = []
        while True:
            ok, image = video.read()
            if not ok:
                break
            frames.append(image)
        for number, lights in sorted(entry["frames"].items(), key=lambda kv: int(kv[0])):
            image = frames[int(number) - 1]
            boxes = [tuple(float(v) for v in light["box"]) for light in lights]
            grown = []
            for x0, y0, x1, y1 in boxes:
                gx, gy = (x1 - x0) / 2.0, (y1 - y0) / 2.0
                grown.append((x0 - gx, y0 - gy, x1 + gx, y1 + gy))
            frame = Frame(image, f"{TAIWAN}/{clip}.mp4#{int(number) - 1}")
            out.append((Scene(frame, boxes, [None] * len(boxes), True, "taiwan"), grown))
    return out


class Candidates:
    """The preset detector's candidates per frame source, cached as JSON lines."""

    def __init__(self, detector, path: Path):
        self.detector, self.path = detector, path
        self.seen: dict[str, list[Candidate]] = {}
        if path.exists():
            for line in path.read_text().splitlines():
                row = json.loads(line)
                self.seen[row["source"]] = [_candidate(c) for c in row["candidates"]]

    def __call__(self, frame: Frame) -> list[Candidate]:
        if frame.source not in self.seen:
            found = self.detector.detect(frame)
            self.seen[frame.source] = found
            with self.path.open("a") as fh:
                row = {"source": frame.source, "candidates": [asdict(c) for c in found]}
                fh.write(json.dumps(row) + "\n")
        return self.seen[frame.source]


def _candidate(row: dict) -> Candidate:
    boxes = {k: tuple(row[k]) for k in ("bbox", "housing") if row.get(k) is not None}
    return Candidate(**{**row, **boxes})


def training_crops(scenes, candidates: Candidates, start: int = 0) -> CropSet:
    parts = []
    for index, scene in enumerate(scenes, start):
        found = candidates(scene.frame)
        if found:
            parts.append(scene_crops(scene, found, index))
    return CropSet.concat(parts)


def synthetic_scenes() -> list[Scene]:
    """The synthetic training scenes every fold shares (the plugin's defaults)."""
    unlit = [Scene(f, [], [], True, "synthetic") for f in no_light_frames(120)]
    heads = [
        Scene(f, b, [None] * len(b), True, "rendered")
        for f, b in head_frames(Heads(40, 0.5, 0.3), HEADS_SEED)
    ]
    pasted = [Scene(f, b, [None] * len(b), True, "pasted") for f, b in crop_frames(80, rotate=0.3)]
    return unlit + heads + pasted


def family_samples(family: Family) -> list[Sample]:
    return list(open_datasets([family.name]).samples)


@dataclass
class Seen:
    """A test frame as the figures need it: its candidates and the network's outputs on them,
    its truth (boxes, states; for the Taiwanese keyframes the boxes grown by half), its size."""

    source: str
    shape: tuple[int, int]
    found: list
    boxes: list
    states: list
    grown: list | None = None
    load: object = None
    out: dict | None = None
    kept: list | None = None

    def frame(self) -> Frame:
        """A frame of this size without pixels (what ``decide`` reads)."""
        return Frame(np.broadcast_to(np.zeros(1, np.uint8), (*self.shape, 3)), self.source)


def seen_samples(samples, candidates: Candidates) -> list[Seen]:
    out = []
    for s in samples:
        frame = s.load()
        out.append(
            Seen(
                frame.source,
                frame.image.shape[:2],
                candidates(frame),
                [a.bbox for a in s.annotations],
                [a.state for a in s.annotations],
                load=s.load,
            )
        )
    return out


def seen_scenes(scenes, candidates: Candidates) -> list[Seen]:
    """Seen frames of (scene, grown boxes) pairs (Taiwan) or plain frames (synthetic)."""
    out = []
    for item in scenes:
        scene, grown = item if isinstance(item, tuple) else (Scene(item, [], []), [])
        frame = scene.frame
        out.append(
            Seen(
                frame.source,
                frame.image.shape[:2],
                candidates(frame),
                list(scene.boxes),
                [],
                grown,
                load=lambda f=frame: f,
            )
        )
    return out


def run_network(verifier, seen: list[Seen]) -> None:
    """The network's outputs on every seen frame's candidates (kept on the frame)."""
    for s in seen:
        s.out = verifier.outputs(s.load(), s.found) if s.found else None


def kept_of(rule, s: Seen) -> list:
    """What ``rule`` keeps of the frame's candidates (from the stored outputs, or from the
    pixels for a rule that reads them)."""
    if getattr(rule, "reads_pixels", False):
        return rule.decide(s.load(), s.found, None) if s.found else []
    return rule.decide(s.frame(), s.found, s.out) if s.found and s.out is not None else []


def evaluate(rule, seen: list[Seen], family: Family, lamp=None) -> dict:
    """Figures of ``rule`` (a verifier deciding on the stored outputs) on a held-out family
    (see the module docstring); state figures when ``lamp`` is given."""
    frames_gt = hits_frames = 0
    recall_sum = precision_sum = 0.0
    precision_frames = cand_hit = n_gt = iou_hit = 0
    empty_frames = empty_false = 0
    state_rows: list[tuple[str, str, str | None]] = []
    for s in seen:
        kept = kept_of(rule, s)
        if not s.boxes:
            empty_frames += 1
            empty_false += len(kept)
            continue
        n_gt += len(s.boxes)
        frames_gt += 1
        if s.found:
            hits = np.asarray(centre_hits([(c.x, c.y) for c in s.found], s.boxes))
            cand_hit += int(hits.any(0).sum())
        recall = 0.0
        if kept:
            hits = np.asarray(centre_hits([(c.x, c.y) for c in kept], s.boxes))
            matched = greedy_match([c.score for c in kept], hits.astype(float), 0.5)
            recall = len(matched) / len(s.boxes)
            precision_sum += len(matched) / len(kept)
            precision_frames += 1
            mine = [c.lens_bbox if family.box == "lens" else c.object_bbox for c in kept]
            iou_hit += len(greedy_match([c.score for c in kept], iou_matrix(mine, s.boxes), 0.5))
            if lamp is not None:
                found = [kept[i] for i, _ in matched]
                others = [d.state for d in lamp.classify(s.load(), found)] if found else []
                for (i, j), other in zip(matched, others):
                    if s.states[j] in STATE_NAMES:
                        state_rows.append((s.states[j], kept[i].state or "unknown", other))
        recall_sum += recall
        hits_frames += recall > 0
    out = {
        "frames": len(seen),
        "lights": n_gt,
        "candidate_recall": cand_hit / n_gt if n_gt else None,
        "hit": hits_frames / frames_gt if frames_gt else None,
        "recall": recall_sum / frames_gt if frames_gt else None,
        "precision": precision_sum / precision_frames if precision_frames else None,
        "recall_iou50": iou_hit / n_gt if n_gt else None,
        "empty_frames": empty_frames,
        "false_per_empty_frame": empty_false / empty_frames if empty_frames else None,
    }
    if lamp is not None:
        out.update(state_figures(state_rows))
    return out


def state_figures(rows) -> dict:
    out: dict = {"state_n": len(rows)}
    for k, name in ((1, "cnn"), (2, "lamp")):
        got = [r for r in rows if r[k] is not None]
        if not got:
            continue
        out[f"state_{name}"] = float(np.mean([r[0] == r[k] for r in got]))
        for colour in ("red", "yellow"):
            of = [r for r in got if r[0] == colour]
            out[f"{colour}_recall_{name}"] = (
                float(np.mean([r[k] == colour for r in of])) if of else None
            )
    return out


def false_lights(rule, taiwan: list[Seen], synthetic: list[Seen]) -> dict:
    """False lights per frame on the Taiwanese keyframes (a centre in no grown box) and the
    synthetic no-light scenes."""
    all_false = empty_false = empty_frames = 0
    for s in taiwan:
        kept = kept_of(rule, s)
        inside = np.array(
            [any(g[0] <= c.x <= g[2] and g[1] <= c.y <= g[3] for g in s.grown) for c in kept],
            bool,
        )
        false = int((~inside).sum()) if kept else 0
        all_false += false
        if not s.boxes:
            empty_false += false
            empty_frames += 1
    synth_false = sum(len(kept_of(rule, s)) for s in synthetic)
    return {
        "taiwan_false_per_keyframe": all_false / len(taiwan),
        "taiwan_false_per_empty_keyframe": empty_false / max(empty_frames, 1),
        "taiwan_empty_keyframes": empty_frames,
        "synthetic_false_per_frame": synth_false / len(synthetic),
    }


class Forest:
    """The forest preset's verifier as a rule (it reads the frame's pixels, not outputs)."""

    reads_pixels = True

    def __init__(self, verifier):
        self.verifier = verifier

    def decide(self, frame, found, out):
        return self.verifier.verify(frame, found)


#: Keep rules swept on every fold (threshold, relative, prior).
RULES = tuple(
    (t, r, p)
    for t in (0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95)
    for r in (0.0, 0.8)
    for p in (0.0, 0.3, 0.5, 0.7)
)


def fold_figures(model_path, params, family, seen, taiwan, synthetic, lamp) -> dict:
    """The fold's figures at the preset's rule (with states) and at every rule of
    :data:`RULES` (without)."""
    network = tsrkit.verifier("cnn-verifier", model=str(model_path))
    for group in (seen, taiwan, synthetic):
        run_network(network, group)
    main = tsrkit.verifier("cnn-verifier", model=str(model_path), **params)
    figures = evaluate(main, seen, family, lamp)
    figures.update(false_lights(main, taiwan, synthetic))
    sweep = {}
    for t, r, p in RULES:
        rule = tsrkit.verifier(
            "cnn-verifier",
            model=str(model_path),
            threshold=t,
            relative=r,
            prior=p,
            overlap=params.get("overlap", 0.3),
        )
        row = evaluate(rule, seen, family)
        row.update(false_lights(rule, taiwan, synthetic))
        sweep[f"t{t:g}_r{r:g}_p{p:g}"] = row
    figures["rules"] = sweep
    return figures


#: Cascade rules swept (threshold, prior) after the forest preset's verifier.
CASCADE = tuple((t, p) for t in (0.1, 0.2, 0.3, 0.4, 0.5, 0.6) for p in (0.0, 0.3, 0.5))


def forest_kept(forest, groups) -> None:
    """What the forest preset's verifier keeps of every seen frame's candidates (on the
    frame), stored as the frame's candidates of a cascade."""
    for group in groups:
        for s in group:
            s.kept = forest.verify(s.load(), s.found) if s.found else []


def cascade_figures(model_path, family, seen, taiwan, synthetic, lamp) -> dict:
    """The fold's network confirming what the forest preset kept: figures at every rule of
    :data:`CASCADE` (the housing the forest's stage fitted is kept)."""
    network = tsrkit.verifier("cnn-verifier", model=str(model_path))
    views = {}
    for name, group in (("seen", seen), ("taiwan", taiwan), ("synthetic", synthetic)):
        views[name] = [replace(s, found=s.kept, out=None) for s in group]
        for v in views[name]:
            v.out = network.outputs(v.load(), v.found) if v.found else None
    sweep = {}
    for t, p in CASCADE:
        rule = tsrkit.verifier(
            "cnn-verifier", model=str(model_path), threshold=t, prior=p, housing="stage"
        )
        row = evaluate(rule, views["seen"], family, lamp if (t, p) == (0.3, 0.0) else None)
        row.update(false_lights(rule, views["taiwan"], views["synthetic"]))
        sweep[f"t{t:g}_p{p:g}"] = row
    return sweep


def adapted_figures(
    model, crops: CropSet, path: Path, params, family, seen, taiwan, synthetic, lamp
) -> dict:
    """The fold's figures after its network's batch-norm statistics were re-estimated on the
    held-out camera's candidate crops (no labels used: every candidate of its frames)."""
    from tsrkit_plugins.verifiers.cnn.augment import centre
    from tsrkit_plugins.verifiers.cnn.training import adapt

    inputs = np.stack([centre(c, 32) for c in crops.crops])
    onnx, arrays = adapt(dict(model.arrays), model.info["width"], inputs)
    where = path.with_name(path.name + "_adapted")
    save_model(
        where,
        replace(model, arrays=arrays, files={"onnx": onnx}),
        plugin="cnn-verifier",
        plugin_version="0.1.0",
        params={},
        training={"fold": family.key, "adapted": True},
    )
    return fold_figures(where, params, family, seen, taiwan, synthetic, lamp)


def tables(folder: Path, rule: str) -> str:
    """Markdown: each fold's figures at ``rule`` (``tT_rR_pP``), and the forest preset's on the
    same candidates (``baseline.json``) beside them."""
    folds = json.loads((folder / "folds.json").read_text())
    baseline_path = folder / "baseline.json"
    forest = json.loads(baseline_path.read_text()) if baseline_path.exists() else {}

    def f(v):
        return "-" if v is None else f"{v:.2f}"

    head = (
        "| fold | verifier | hit | precision | recall | recall IoU 0.5 | Taiwan false / keyframe "
        "(no-light keyframes) | synthetic false / frame | state acc / red / amber |"
    )
    lines = [head, "|" + "---|" * 9]
    for key, figures in folds.items():
        row = figures["rules"][rule]
        state = f"{f(figures.get('state_cnn'))} / {f(figures.get('red_recall_cnn'))} / " + f(
            figures.get("yellow_recall_cnn")
        )
        lines.append(
            f"| {key} | cnn {rule} | {f(row['hit'])} | {f(row['precision'])} | "
            f"{f(row['recall'])} | {f(row['recall_iou50'])} | "
            f"{f(row['taiwan_false_per_keyframe'])} ({f(row['taiwan_false_per_empty_keyframe'])})"
            f" | {f(row['synthetic_false_per_frame'])} | {state} |"
        )
        if key in forest:
            b = forest[key]
            lamp = f"{f(b.get('state_lamp'))} / {f(b.get('red_recall_lamp'))} / " + f(
                b.get("yellow_recall_lamp")
            )
            lines.append(
                f"| {key} | forest preset | {f(b['hit'])} | {f(b['precision'])} | "
                f"{f(b['recall'])} | {f(b['recall_iou50'])} | "
                f"{f(b['taiwan_false_per_keyframe'])} ({f(b['taiwan_false_per_empty_keyframe'])})"
                f" | {f(b['synthetic_false_per_frame'])} | {lamp} |"
            )
    return "\n".join(lines)


def card(folder: Path, rule: str) -> None:
    """The shipped model's card: its leave-one-camera-out figures become the cascade's at
    ``rule`` (each fold's network after the forest verifier; ``cascade.json``) and the shipped
    network's on the same folds (``cascade_shipped.json``; it saw KR and cinTA)."""
    path = DEFAULT_MODEL.with_suffix(".json")
    meta = json.loads(path.read_text())
    keep = (
        "hit",
        "precision",
        "recall",
        "recall_iou50",
        "taiwan_false_per_keyframe",
        "taiwan_false_per_empty_keyframe",
        "synthetic_false_per_frame",
    )
    figures = {}
    for name in ("cascade", "cascade_shipped"):
        rows = json.loads((folder / f"{name}.json").read_text())
        figures[name] = {k: {f: r[rule][f] for f in keep} for k, r in rows.items()}
    meta["info"]["leave_one_camera_out"] = {
        "rule": rule,
        "pipeline": "union -> forest verifier (recommended-forest) -> cnn-verifier",
        "fold_networks": figures["cascade"],
        "shipped_network": figures["cascade_shipped"],
        "command": "python benchmarks/cnn_loso.py --cascade [--model SHIPPED]",
    }
    with atomic_open(path, "w") as fh:
        fh.write(json.dumps(meta, indent=1) + "\n")


def commit() -> str:
    try:
        return subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            check=True,
            cwd=harness.REPO,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("benchmarks/out/cnn_loso"))
    parser.add_argument("--config", default="recommended")
    parser.add_argument("--only", action="append", help="fold keys (repeatable)")
    parser.add_argument("--epochs", type=int, default=14)
    parser.add_argument("--width", type=int, default=16)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--threshold", type=float, default=None, help="verifier threshold")
    parser.add_argument("--quick", action="store_true", help="10 frames a set (a smoke run)")
    parser.add_argument("--ship", action="store_true", help="train and write the shipped model")
    parser.add_argument(
        "--adapt", action="store_true", help="also measure batch-norm adaptation per fold"
    )
    parser.add_argument(
        "--evaluate", action="store_true", help="evaluate the folds' saved models (no training)"
    )
    parser.add_argument(
        "--cascade", action="store_true", help="the folds' networks after the forest verifier"
    )
    parser.add_argument(
        "--model", type=Path, help="with --cascade: this network for every fold (the shipped)"
    )
    parser.add_argument(
        "--card",
        metavar="RULE",
        help="write OUT's cascade figures at RULE (tT_pP) into the shipped model's card",
    )
    parser.add_argument("--tables", metavar="RULE", help="print OUT's tables at RULE (tT_rR_pP)")
    parser.add_argument(
        "--baseline",
        action="store_true",
        help="also evaluate the forest verifier preset (shipped model)",
    )
    args = parser.parse_args()
    if args.tables:
        print(tables(args.out, args.tables))
        return
    if args.card:
        card(args.out, args.card)
        return
    harness.announce()
    args.out.mkdir(parents=True, exist_ok=True)
    chosen = tsrkit.select(config=args.config)
    candidates = Candidates(chosen.detector, args.out / "candidates.jsonl")
    limit = 10 if args.quick else None
    families = {f.key: family_samples(f)[:limit] for f in FAMILIES}
    t0 = time.time()
    synthetic = synthetic_scenes()[: limit and 3 * limit]
    synth_crops = training_crops(synthetic, candidates, 100000)
    family_crops = {
        f.key: training_crops(
            [scene_of(s, f.exhaustive, f.key) for s in families[f.key]], candidates, 10000 * i
        )
        for i, f in enumerate(FAMILIES)
    }
    taiwan = seen_scenes(taiwan_scenes()[:limit], candidates)
    test_unlit = seen_scenes(
        list(no_light_frames(NO_LIGHT_TEST, NO_LIGHT_TEST_SEED))[:limit], candidates
    )
    seen = {f.key: seen_samples(families[f.key], candidates) for f in FAMILIES}
    print(f"candidates and crops: {time.time() - t0:.0f} s", file=sys.stderr)
    for key, crops in family_crops.items():
        print(
            f"  {key}: {len(crops)} crops, {int((crops.light == 1).sum())} positive",
            file=sys.stderr,
        )
    verifier_params = {}
    if chosen.verifier is not None and chosen.verifier.name == "cnn-verifier":
        verifier_params = {
            k: chosen.verifier.params[k] for k in ("threshold", "relative", "overlap", "prior")
        }
    if args.threshold is not None:
        verifier_params["threshold"] = args.threshold
    lamp = tsrkit.classifier("lamp-state")
    results: dict = {}
    folds = [f for f in FAMILIES if not args.only or f.key in args.only]
    if args.ship or args.baseline or args.cascade:
        folds = []
    for family in folds:
        train = CropSet.concat(
            [synth_crops] + [c for k, c in family_crops.items() if k != family.key]
        )
        path = args.out / f"model_{family.key}"
        t0 = time.time()
        if args.evaluate:
            model = load_model(path, "cnn-verifier")
        else:
            trainer = tsrkit.verifier(
                "cnn-verifier",
                epochs=args.epochs,
                width=args.width,
                seed=args.seed,
                threads=args.threads,
            )
            model = trainer.fit_crops(train)
            save_model(
                path,
                model,
                plugin="cnn-verifier",
                plugin_version="0.1.0",
                params=trainer.params,
                training={"fold": family.key},
            )
        seconds = time.time() - t0
        figures = fold_figures(
            path, verifier_params, family, seen[family.key], taiwan, test_unlit, lamp
        )
        figures["train_seconds"] = seconds
        figures["epochs"] = model.info["epoch_kept"]
        if args.adapt:
            figures["adapted"] = adapted_figures(
                model,
                family_crops[family.key],
                path,
                verifier_params,
                family,
                seen[family.key],
                taiwan,
                test_unlit,
                lamp,
            )
        results[family.key] = figures
        print(family.key, json.dumps(figures), file=sys.stderr)
        name = "folds_evaluated.json" if args.evaluate else "folds.json"
        (args.out / name).write_text(json.dumps(results, indent=1))
    if args.cascade:
        forest = tsrkit.select(config="recommended-forest").verifier
        forest_kept(forest, [*seen.values(), taiwan, test_unlit])
        cascades = {}
        for family in FAMILIES:
            if args.only and family.key not in args.only:
                continue
            cascades[family.key] = cascade_figures(
                args.model or args.out / f"model_{family.key}",
                family,
                seen[family.key],
                taiwan,
                test_unlit,
                lamp,
            )
            print("cascade", family.key, json.dumps(cascades[family.key]), file=sys.stderr)
            name = "cascade_shipped.json" if args.model else "cascade.json"
            (args.out / name).write_text(json.dumps(cascades, indent=1))
    if args.baseline:
        baseline = tsrkit.select(config="recommended-forest").verifier
        rows = {}
        for family in FAMILIES:
            figures = evaluate(Forest(baseline), seen[family.key], family, lamp)
            figures.update(false_lights(Forest(baseline), taiwan, test_unlit))
            rows[family.key] = figures
            print("forest", family.key, json.dumps(figures), file=sys.stderr)
        (args.out / "baseline.json").write_text(json.dumps(rows, indent=1))
    if args.ship:
        ship(args, synth_crops, family_crops, results)


def ship(args, synth_crops: CropSet, family_crops, results) -> None:
    """Train the shipped model on the open families and synthetic scenes; write it with its
    card (the fold figures of ``OUT/folds.json`` when there)."""
    folds = args.out / "folds.json"
    figures = json.loads(folds.read_text()) if folds.exists() else results
    open_keys = [f.key for f in FAMILIES if f.open]
    train = CropSet.concat([synth_crops] + [family_crops[k] for k in open_keys])
    trainer = tsrkit.verifier(
        "cnn-verifier", epochs=args.epochs, width=args.width, seed=args.seed, threads=args.threads
    )
    model = trainer.fit_crops(train)
    info = dict(model.info)
    info["leave_one_camera_out"] = figures
    info["preset"] = args.config
    info["trained_by"] = {
        "command": "python " + " ".join(shlex.quote(a) for a in sys.argv),
        "commit": commit(),
    }
    licences = {
        "roboflow_traffic_light_kr": "CC BY 4.0",
        "roboflow_cinta_v2_id": "CC BY 4.0",
        "udacity_mit_tl_crops:train (pasted into synthetic scenes)": "CC BY-SA 4.0",
        "tsrkit synthetic scenes": "MIT (tsrkit)",
    }
    save_model(
        DEFAULT_MODEL,
        replace(model, info=info),
        plugin="cnn-verifier",
        plugin_version="0.1.0",
        params=trainer.params,
        training={
            "dataset": "roboflow_traffic_light_kr + roboflow_cinta_v2_id (every split)",
            "licences": licences,
            "shared_under": "CC BY-SA 4.0 (it learned from MIT's CC BY-SA 4.0 crops)",
            "detector": args.config + " preset's detector",
        },
    )
    print(f"wrote {DEFAULT_MODEL}.onnx and .json", file=sys.stderr)


if __name__ == "__main__":
    main()
