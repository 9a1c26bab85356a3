"""Mutation fuzzing of tsrkit's input surfaces: counts the cases that end in an exception other
than tsrkit's own clear errors (the target is 0).

Surfaces:
- ``image``: a small PNG and a small JPEG with random byte flips, insertions, deletions,
  truncations and header-size rewrites, through ``tsrkit.core.images.read_image`` (allowed:
  ``ImageReadError``);
- ``coco``, ``normalized``, ``voc``, ``yolo``: the annotation files tsrkit writes for a 4-frame
  synthetic set, mutated the same way, through ``open_dataset`` (allowed: ``TsrkitError``);
- ``gtsrb``, ``lisa``, ``bosch``, ``crops``, ``dtld``, ``lara``: a small valid file of each
  read-only format (:data:`SEED_FILES`), mutated the same way;
- ``config``: a run configuration YAML through ``load_config`` (allowed: ``ParamError``);
- ``model``: the ``.json`` and ``.npz`` of a saved model through ``load_model`` (allowed:
  ``ModelError``);
- ``params``: random strings and numbers for every parameter type (allowed: ``ParamError``).

    python benchmarks/fuzz.py [--cases 10000] [--seed 0] [--only model,config]
"""

from __future__ import annotations

import argparse
import itertools
import shutil
import tempfile
import time
import traceback
from collections import Counter
from collections.abc import Callable
from pathlib import Path

import cv2
import harness
import numpy as np

from tsrkit import Dataset, Param, TsrkitError, get_registry, read_image
from tsrkit.api import open_dataset, validate
from tsrkit.synth import generate


def mutate(data: bytes, rng: np.random.Generator) -> bytes:
    """One to four random byte-level mutations of ``data``; new bytes of a text file are
    printable ASCII 9 times in 10 (so that parsers, not only the UTF-8 decoder, are reached)."""
    out = bytearray(data)
    try:
        data.decode("utf-8")
        low = 32 if rng.random() < 0.9 else 0
    except UnicodeDecodeError:
        low = 0
    high = 127 if low else 256
    for _ in range(int(rng.integers(1, 5))):
        kind = int(rng.integers(0, 5))
        at = int(rng.integers(0, max(len(out), 1)))
        if kind == 0 and out:  # flip a byte
            out[at] = int(rng.integers(low, high))
        elif kind == 1:  # insert random bytes
            out[at:at] = rng.integers(low, high, int(rng.integers(1, 9)), dtype=np.uint8).tobytes()
        elif kind == 2 and out:  # delete a run
            del out[at : at + int(rng.integers(1, 17))]
        elif kind == 3:  # truncate
            del out[at:]
        else:  # a digit or quote changed (structured text) / a size field made huge (binary)
            for symbol in (b'"', b"0", b"1", b"<", b","):
                index = out.find(symbol, at)
                if index >= 0:
                    out[index : index + 1] = rng.choice([b"9999999999", b"-1", b"nan", b"", b'"'])
                    break
    return bytes(out)


def fuzz(name: str, seeds: list[bytes], target, cases: int, rng, allowed) -> Counter:
    """Run ``cases`` mutations of ``seeds`` through ``target(bytes)``; count outcomes."""
    counts: Counter = Counter()
    for k in range(cases):
        data = mutate(seeds[k % len(seeds)], rng)
        try:
            target(data)
            counts["accepted"] += 1
        except allowed as exc:
            counts["clear error"] += 1
            # the reader let a Python error through and read_dataset's safety net named it
            counts["net"] += "data (" in str(exc) and "malformed" in str(exc)
        except Exception as exc:
            key = f"UNCAUGHT {type(exc).__name__}: {str(exc)[:80]}"
            if counts[key] == 0:
                print(f"[{name}] {key}\n{traceback.format_exc(limit=3)}")
            counts[key] += 1
    return counts


def rotating_target(files: list[Path], read) -> Callable[[bytes], None]:
    """A fuzz target that writes each case over the next of ``files`` in turn, calls ``read()``
    and puts the file's original bytes back."""
    turn = itertools.count()

    def target(data: bytes) -> None:
        victim = files[next(turn) % len(files)]
        original = victim.read_bytes()
        victim.write_bytes(data)
        try:
            read()
        finally:
            victim.write_bytes(original)

    return target


def image_surface(folder: Path):
    seeds = []
    image = np.random.default_rng(1).integers(0, 255, (24, 32, 3), dtype=np.uint8)
    for ext in (".png", ".jpg"):
        ok, encoded = cv2.imencode(ext, image)
        assert ok
        seeds.append(encoded.tobytes())
    path = folder / "case.img"

    def target(data: bytes) -> None:
        path.write_bytes(data)
        read_image(path)

    return seeds, target, TsrkitError


def format_surface(folder: Path, fmt: str, dataset: Dataset):
    out = folder / fmt
    get_registry().create("format", fmt).write(
        dataset, out / ("annotations.json" if fmt in ("coco", "normalized") else "data")
    )
    files = sorted(
        p for p in out.rglob("*") if p.is_file() and p.suffix in (".json", ".xml", ".txt", ".yaml")
    )
    seeds = [p.read_bytes() for p in files]
    ref = out / ("annotations.json" if fmt in ("coco", "normalized") else "data")

    return seeds, rotating_target(files, lambda: open_dataset(ref, format=fmt)), TsrkitError


#: A small valid annotation file of each read-only format (one 24x24 image ``a.png``).
SEED_FILES = {
    "gtsrb": (
        "GT-00000.csv",
        "Filename;Width;Height;Roi.X1;Roi.Y1;Roi.X2;Roi.Y2;ClassId\na.png;24;24;1;1;20;20;0\n"
        "a.png;24;24;2;2;9;9;14\n",
    ),
    "lisa": (
        "frameAnnotationsBOX.csv",
        "Filename;Annotation tag;Upper left corner X;Upper left corner Y;Lower right corner X;"
        "Lower right corner Y;Origin file;Origin frame number;Origin track;Origin track frame "
        "number\na.png;go;1;1;10;10;x;0;x;0\na.png;stopLeft;3;3;12;12;x;0;x;0\n",
    ),
    "bosch": (
        "test.yaml",
        "- path: a.png\n  boxes:\n  - {label: Red, occluded: false, x_min: 1, y_min: 1, "
        "x_max: 10, y_max: 10}\n  - {label: off, occluded: true, x_min: 2, y_min: 2, x_max: 5, "
        "y_max: 9}\n",
    ),
    "crops": ("labels.csv", "file,label,split,width,height,condition\na.png,red,train,24,24,day\n"),
    "dtld": (
        "dtld.json",
        '{"images": [{"image_path": "a.png", "time_stamp": 1.5, "labels": [{"x": 1, "y": 1, '
        '"w": 9, "h": 9, "unique_id": 3, "attributes": {"state": "red_yellow", '
        '"direction": "front"}}]}]}',
    ),
    "lara": ("gt.txt", "# LaRA\n0.5 / 0 1 1 10 10 0 'Traffic Light' 'go'\n"),
}


def seed_file_surface(folder: Path, fmt: str):
    """Mutations of :data:`SEED_FILES`' file of ``fmt`` read through ``open_dataset``."""
    out = folder / f"seed-{fmt}"
    out.mkdir()
    image = np.zeros((24, 24, 3), np.uint8)
    for name in ("a.png", "Lara3D_UrbanSeq1_JPG/frame_000000.jpg"):
        (out / name).parent.mkdir(exist_ok=True)
        cv2.imwrite(str(out / name), image)
    name, text = SEED_FILES[fmt]
    path = out / name

    def target(data: bytes) -> None:
        path.write_bytes(data)
        open_dataset(path, format=fmt)

    return [text.encode()], target, TsrkitError


def config_surface(folder: Path):
    from tsrkit import ParamError
    from tsrkit.plugin.params import load_config

    path = folder / "run.yaml"
    seeds = [
        b"detector: {name: lab-frst, params: {top: 15}}\nverifier: {name: verifier, params: "
        b"{threshold: 0.3}}\nclassifier: ab-hist\ndescription: a run\n"
    ]

    def target(data: bytes) -> None:
        path.write_bytes(data)
        load_config(path)

    return seeds, target, ParamError


def model_surface(folder: Path):
    from tsrkit import Model, ModelError, load_model, save_model

    base = folder / "model"
    save_model(
        base,
        Model({"w": np.arange(6.0).reshape(2, 3)}, {"classes": ["red"]}),
        plugin="p",
        plugin_version="1",
        params={"bins": 8},
        training={"samples": 3},
    )
    files = [folder / "model.json", folder / "model.npz"]
    seeds = [f.read_bytes() for f in files]

    return seeds, rotating_target(files, lambda: load_model(base, plugin="p")), ModelError


def params_surface():
    schema = [
        Param("f", "float", 0.5, min=0, max=1),
        Param("i", "int", 3, min=1),
        Param("fs", "floats", (1.0, 1.0), length=2),
        Param("is", "ints", (1, 2)),
        Param("b", "bool", True),
        Param("s", "str", "max", choices=("max", "min")),
    ]
    names = [p.name for p in schema]
    seeds = [b"0.5", b"3", b"1,1", b"1..3", b"true", b"max"]

    def target(data: bytes) -> None:
        text = data.decode("utf-8", "replace")
        validate(schema, {names[target.k % len(names)]: text}, "fuzz")  # type: ignore[attr-defined]
        target.k += 1  # type: ignore[attr-defined]

    target.k = 0  # type: ignore[attr-defined]
    from tsrkit import ParamError

    return seeds, target, ParamError


def run_surface(name, seeds, target, cases: int, rng, allowed) -> int:
    """Fuzz one surface, print its line of counts and return how many cases went uncaught."""
    start = time.perf_counter()
    counts = fuzz(name, seeds, target, cases, rng, allowed)
    uncaught = sum(n for k, n in counts.items() if k.startswith("UNCAUGHT"))
    print(
        f"{name:10s} {cases} cases in {time.perf_counter() - start:5.1f} s: "
        f"accepted {counts['accepted']}, clear error {counts['clear error']} "
        f"(of which by the readers' safety net {counts['net']}), uncaught {uncaught}",
        flush=True,
    )
    return uncaught


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=10000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--only", default=None, help="Comma-separated surfaces to run (default all)."
    )
    args = parser.parse_args()
    harness.announce()
    rng = np.random.default_rng(args.seed)
    folder = Path(tempfile.mkdtemp(prefix="tsrkit-fuzz-"))
    try:
        data = generate(folder / "synth", 4, seed=5, width=96, height=64)
        surfaces = {"image": image_surface(folder)}
        for fmt in ("coco", "normalized", "voc", "yolo"):
            surfaces[fmt] = format_surface(folder, fmt, data)
        for fmt in SEED_FILES:
            surfaces[fmt] = seed_file_surface(folder, fmt)
        surfaces["config"] = config_surface(folder)
        surfaces["model"] = model_surface(folder)
        surfaces["params"] = params_surface()
        total_uncaught = 0
        chosen = args.only.split(",") if args.only else list(surfaces)
        for name, (seeds, target, allowed) in surfaces.items():
            if name not in chosen:
                continue
            total_uncaught += run_surface(name, seeds, target, args.cases, rng, allowed)
        print(f"total uncaught: {total_uncaught}")
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
