"""lamp-state across cameras: leave one camera out, per held-out set accuracy, red recall and
amber recall (and red+amber recall where labelled).

Each fold holds out one camera family and trains ``lamp-state`` (its own ``fit``: its default
parameters, colour-jittered copies and whatever else its training does) on the training parts
of all the others; the held-out lights are read by its own ``classify`` on their annotated
boxes. A fold never trains on the camera it tests. Where a set boxes housings (cinTA, DTLD,
Japan), ``--boxes housing`` (the default) gives each box as a candidate whose housing is its
own box, as the pipeline gives a fitted housing: the ground-truth housing is read as a housing
whatever its shape (DTLD's boxes around a backplate are often too square to be taken for one
by shape alone), its lit lens found in it. ``--boxes plain`` gives the bare boxes, read as
housings only when elongated: how lamp-state before layout 4 was measured (its reading of a
candidate with a housing takes the candidate for the lens, so it needs bare boxes).

Families and their parts (training part; held-out sets):

* ``mit``: MIT crops, train; MIT test.
* ``vgis``: VGIS bulb crops, day and night, deduplicated by sha256 (first occurrence kept, as
  the datasets README asks); VGIS day, VGIS night (20x20 bulbs: no housing, no position).
* ``kr``: KR, test + valid (lens boxes); the same.
* ``cinta``: cinTA, test + valid (housing boxes); the same.
* ``dtld``: DTLD, all splits (housing boxes); all of it, and its test split (the figure of
  earlier runs).
* ``japan``: ``iwai_japan_tl``, all splits (horizontal housings, red on the right, blue-green
  greens); all of it (its file-level split lets scenes cross splits, so it is one fold).

Everything goes through the classifier's public ``fit`` and ``classify``, so the same command
measures any commit's lamp-state: put that commit's ``tsrkit`` and ``plugins`` (as
``tsrkit_plugins``) first on ``PYTHONPATH`` (``benchmarks/RESULTS.state.md`` gives the
commands).

    python benchmarks/state_loso.py [--seed N] [--boxes housing|plain] [-p NAME=VALUE ...]
        [--shipped]

``--seed`` seeds lamp-state's training (jitter and boosting): a change is judged against the
spread of several seeds, as one light moves a small set's figures. ``-p`` sets lamp-state
parameters. ``--shipped`` adds the shipped model read on every set (in-domain for the sets it
was trained on, held out for DTLD and Japan).
"""

from __future__ import annotations

import harness

harness.single_thread(opencv=False)

import argparse  # noqa: E402
import hashlib  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from collections import Counter  # noqa: E402
from dataclasses import replace  # noqa: E402
from pathlib import Path  # noqa: E402

from tsrkit import (  # noqa: E402
    Candidate,
    Dataset,
    Sample,
    TsrkitError,
    get_registry,
    save_model,
)
from tsrkit.api import open_dataset  # noqa: E402

#: The states read and scored (others, such as off, arrows and unknown, are passed over).
STATES = ("red", "yellow", "green", "red_yellow")
#: The housing-boxed and crop sets the targets are read on, in table order.
TABLE = (
    "mit test",
    "vgis day",
    "vgis night",
    "kr",
    "cinta",
    "dtld",
    "dtld test",
    "japan",
)


def deduplicated(dataset: Dataset, lighting: str) -> Dataset:
    """VGIS crops of one lighting, each distinct file once (first occurrence)."""
    seen, kept = set(), []
    for sample in dataset:
        with open(sample.source, "rb") as fh:
            digest = hashlib.sha256(fh.read()).hexdigest()
        if sample.metadata.get("lighting") == lighting and digest not in seen:
            kept.append(sample)
        seen.add(digest)
    return Dataset(f"vgis {lighting}", tuple(kept), dataset.format, dataset.root, dataset.info)


def families() -> dict[str, dict[str, Dataset]]:
    """Per camera family: its ``train`` part (used when another family is held out) and its
    held-out sets (see the module notes)."""
    mit = open_dataset("udacity_mit_tl_crops")
    vgis = open_dataset("lisa_vgis_bulb_crops")
    kr = open_dataset("roboflow_traffic_light_kr")
    cinta = open_dataset("roboflow_cinta_v2_id")
    dtld = open_dataset("dtld_fridtjofs")
    japan = open_dataset(str(harness.data_dir() / "iwai_japan_tl" / "annotations.json"))
    japan = Dataset(japan.name, japan.samples, japan.format, japan.root, {"box": "housing"})
    day, night = deduplicated(vgis, "day"), deduplicated(vgis, "night")
    both = Dataset("vgis", day.samples + night.samples, vgis.format, vgis.root, vgis.info)
    return {
        "mit": {"train": mit.split("train"), "mit test": mit.split("test")},
        "vgis": {"train": both, "vgis day": day, "vgis night": night},
        "kr": {"train": kr, "kr": kr},
        "cinta": {"train": cinta, "cinta": cinta},
        "dtld": {"train": dtld, "dtld": dtld, "dtld test": dtld.split("test")},
        "japan": {"train": japan, "japan": japan},
    }


def wanted_boxes(sample: Sample, housed: bool) -> tuple[list[Candidate], list[str]]:
    """The annotated lights of ``sample`` whose state is in :data:`STATES`, as candidates (each
    its own housing when ``housed``), and their states."""
    wanted = [a for a in sample.annotations if a.state in STATES]
    boxes = [Candidate.from_box(a.bbox, 1.0) for a in wanted]
    if housed:
        boxes = [replace(box, housing=box.bbox) for box in boxes]
    return boxes, [a.state for a in wanted]


def read_set(classifier, dataset: Dataset, convention: str) -> tuple[list[str], list[str]]:
    """The true and the read states of every wanted light of ``dataset``, its housing boxes
    given as housings when ``convention`` (``--boxes``) is ``housing``."""
    housed = convention == "housing" and dataset.info.get("box") == "housing"
    truth, found = [], []
    for sample in dataset:
        boxes, states = wanted_boxes(sample, housed)
        if boxes:
            truth += states
            found += [d.state for d in classifier.classify(sample.load(), boxes)]
    return truth, found


def recall(truth: list[str], found: list[str], state: str) -> float:
    """The share of the lights of true ``state`` read ``state`` (nan without any)."""
    of = [f for t, f in zip(truth, found) if t == state]
    return sum(f == state for f in of) / len(of) if of else float("nan")


def summary(truth: list[str], found: list[str]) -> dict:
    """Count, accuracy, per-state recall and the misreads of one set."""
    return {
        "n": len(truth),
        "accuracy": sum(t == f for t, f in zip(truth, found)) / max(len(truth), 1),
        **{state: recall(truth, found, state) for state in STATES},
        "truth": dict(Counter(truth)),
        "misread": dict(Counter(f"{t}>{f}" for t, f in zip(truth, found) if t != f)),
    }


def trained(params: dict, samples: list[Sample], folder: Path):
    """lamp-state with ``params``, fitted on ``samples`` (its own ``fit``), ready to classify."""
    registry = get_registry()
    plugin = registry.create("classifier", "lamp-state", params)
    model = plugin.fit(Dataset("fold", tuple(samples)))
    path = save_model(
        folder / "fold",
        model,
        plugin="lamp-state",
        plugin_version="benchmark",
        params=plugin.params,
        training={},
    )
    return registry.create("classifier", "lamp-state", {**params, "model": str(path)})


def cell(value: float) -> str:
    return "-" if value != value else f"{value:.3f}"


def table(columns: dict[str, dict[str, dict]]) -> None:
    """Print one markdown row per set: accuracy / red recall / amber recall (red+amber recall
    where labelled) of each column."""
    print("\n| set | lights | " + " | ".join(columns) + " |")
    print("|---|---:|" + "---|" * len(columns))
    for key in TABLE:
        rows = [column[key] for column in columns.values() if key in column]
        if not rows:
            continue
        cells = []
        for row in rows:
            text = f"{row['accuracy']:.3f} / {cell(row['red'])} / {cell(row['yellow'])}"
            if row["truth"].get("red_yellow"):
                text += f" (r+a {cell(row['red_yellow'])})"
            cells.append(text)
        print(f"| {key} | {rows[0]['n']} | " + " | ".join(cells) + " |")
    print("(accuracy / red recall / amber recall; r+a: red+amber recall)")


def parse_params(pairs: list[str]) -> dict[str, str]:
    """``NAME=VALUE`` pairs as a dict (the registry validates and converts the values)."""
    out = {}
    for pair in pairs:
        name, sep, value = pair.partition("=")
        if not sep or not name:
            print(f"state_loso: -p wants NAME=VALUE, got {pair!r}", file=sys.stderr)
            raise SystemExit(2)
        out[name] = value
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0, help="lamp-state's training seed")
    parser.add_argument(
        "-p", dest="params", action="append", default=[], help="lamp-state NAME=VALUE"
    )
    parser.add_argument(
        "--boxes",
        choices=("housing", "plain"),
        default="housing",
        help="housing boxes as housings (default) or bare (before layout 4)",
    )
    parser.add_argument("--shipped", action="store_true", help="also read the shipped model")
    args = parser.parse_args()
    params: dict = {**parse_params(args.params), "seed": args.seed}
    try:
        get_registry().create("classifier", "lamp-state", params)
        data = families()
    except TsrkitError as exc:
        print(f"state_loso: {exc}", file=sys.stderr)
        raise SystemExit(2) from None
    harness.announce()
    print("lamp-state parameters:", params, "boxes:", args.boxes, flush=True)
    loso: dict[str, dict] = {}
    with tempfile.TemporaryDirectory() as folder:
        for held, sets in data.items():
            start = time.process_time()
            samples = [s for g, other in data.items() if g != held for s in other["train"]]
            classifier = trained(params, samples, Path(folder))
            fitted = time.process_time() - start
            for key, dataset in sets.items():
                if key != "train":
                    loso[key] = summary(*read_set(classifier, dataset, args.boxes))
                    print(f"held out {held}: {key} {loso[key]}", flush=True)
            print(f"fold {held}: fit {fitted:.0f} s CPU", flush=True)
    columns = {"lamp-state, leave one camera out": loso}
    if args.shipped:
        shipped = get_registry().create("classifier", "lamp-state", params)
        columns["shipped model"] = {
            key: summary(*read_set(shipped, dataset, args.boxes))
            for sets in data.values()
            for key, dataset in sets.items()
            if key != "train"
        }
    table(columns)
    for name, column in columns.items():
        targets = [k for k in ("mit test", "kr", "cinta", "dtld", "japan") if k in column]
        worst = min(column[k]["accuracy"] for k in targets)
        red = min(column[k]["red"] for k in targets)
        print(f"{name}: worst accuracy {worst:.3f}, worst red recall {red:.3f} over {targets}")


if __name__ == "__main__":
    main()
