"""Interleaved before/after timing of the per-candidate stages against another checkout.

The verifier's features (``plugins/verifiers/features.py``), the trees (``forest.py``, on the
shipped verifier's and lamp-state's models) and lamp-state's features
(``plugins/classifiers/lamp_state/features.py``) of the checkout ``--base`` are loaded beside
this tree's, and both run on the same frames and candidates as ``verifier_speed.py``'s (after
the housing stage), one after the other for every frame, in one process: on a shared machine
the spread between processes (20 % and more) hides what a change saves, the ratio within one
process does not. The outputs are compared for equality on every frame (a speed-up must not
change them; ``--changed``, for a change of outputs by design: the frames that differ are
counted instead). Only those three files are taken from ``--base``: what they import comes from
this tree. numba caches compiled functions in a temporary folder for the run (unless
``NUMBA_CACHE_DIR`` is set): a file loaded here under another module name would otherwise leave
a cache entry beside it that its checkout cannot load.

Run: python benchmarks/stage_ab.py --base /tmp/old-checkout [--frames 10] [--repeats 5] [--changed]
(an old checkout: ``git worktree add /tmp/old-checkout <commit>``)
"""

from __future__ import annotations

import os
import tempfile

import harness

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"
if "NUMBA_CACHE_DIR" not in os.environ:  # removed at exit
    _NUMBA_CACHE = tempfile.TemporaryDirectory(prefix="stage_ab_numba_")
    os.environ["NUMBA_CACHE_DIR"] = _NUMBA_CACHE.name

import argparse  # noqa: E402
import importlib.util  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from types import ModuleType  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402
from verifier_speed import candidates  # noqa: E402

import tsrkit_plugins.classifiers.lamp_state.features as lamp_now  # noqa: E402
import tsrkit_plugins.shared.forest as forest_now  # noqa: E402
import tsrkit_plugins.verifiers.features as verifier_now  # noqa: E402
from tsrkit import (  # noqa: E402
    Frame,
    get_registry,
)
from tsrkit.api import SynthOptions, render_frame  # noqa: E402

cv2.setNumThreads(1)


def load(name: str, path: Path) -> ModuleType:
    """The module at ``path``, loaded under ``name`` (beside this tree's own)."""
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise SystemExit(f"cannot load {path}")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def first_file(root: Path, *paths: str) -> Path:
    """The first of ``paths`` under ``root`` that exists (a module that moved between commits)."""
    for path in paths:
        if (root / path).is_file():
            return root / path
    raise SystemExit(f"none of {', '.join(paths)} under {root}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", type=Path, required=True, help="root of the other checkout")
    harness.add_frames(parser, 10)
    harness.add_repeats(parser, 5)
    parser.add_argument("--candidates", type=int, default=50)
    parser.add_argument(
        "--changed", action="store_true", help="outputs differ by design: count, do not stop"
    )
    args = parser.parse_args()
    harness.announce()
    plugins = args.base / "plugins"
    versions = {
        "base": (
            load("base_verifier_features", plugins / "verifiers" / "features.py"),
            load("base_forest", first_file(plugins, "shared/forest.py", "verifiers/forest.py")),
            load("base_lamp_features", plugins / "classifiers" / "lamp_state" / "features.py"),
        ),
        "this tree": (verifier_now, forest_now, lamp_now),
    }
    registry = get_registry()
    verifier = registry.create("verifier", "verifier")
    lamp = registry.create("classifier", "lamp-state")
    forests = {
        tag: (
            forest.Forest.of(verifier.estimator, "verifier"),
            forest.Forest.of(lamp.estimator, "lamp-state", binary=False),
        )
        for tag, (_, forest, _) in versions.items()
    }
    housing = registry.create("verifier", "housing")
    rng = np.random.default_rng(0)
    frames = [
        Frame(render_frame(i, 7, 1280, 720, SynthOptions())[0], f"synth{i}")
        for i in range(args.frames)
    ]
    housed = [housing.verify(frame, candidates(rng, args.candidates)) for frame in frames]
    times: dict[str, list[float]] = {}
    differing = 0

    def timed(name: str, stage, *inputs):
        start = time.process_time()
        out = stage(*inputs)
        times.setdefault(name, []).append((time.process_time() - start) * 1000)
        return out

    for _ in range(args.repeats):
        for frame, cands in zip(frames, housed):
            outputs = []
            for tag, (features, _, lamp_features) in versions.items():
                trees, lamp_trees = forests[tag]
                x = timed(
                    f"verifier features, {tag}", features.candidate_features, frame.image, cands
                )
                p = timed(f"verifier trees, {tag}", trees.raw, x)
                y = timed(
                    f"lamp-state features, {tag}", lamp_features.lamp_features, frame.image, cands
                )
                q = timed(f"lamp-state trees, {tag}", lamp_trees.raw, y)
                outputs.append((x, p, y, q))
            if not all(np.array_equal(a, b) for a, b in zip(*outputs)):
                if not args.changed:
                    raise SystemExit("outputs differ between the two versions")
                differing += 1
    print(
        f"1280x720, {args.candidates} candidates after the housing stage, one thread, "
        f"{args.frames} frames x {args.repeats} repeats, interleaved; median process CPU ms; "
        f"outputs differ on {differing} of {args.frames * args.repeats} frame runs:"
    )
    for name in sorted(times):
        print(f"  {name:34s} {statistics.median(times[name]):6.3f}")
    for tag in versions:
        total = sum(statistics.median(v) for k, v in times.items() if k.endswith(tag))
        print(f"  sum of the four medians, {tag:10s} {total:6.3f}")


if __name__ == "__main__":
    main()
