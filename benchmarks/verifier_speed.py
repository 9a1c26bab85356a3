"""Single-thread speed of the learned verifier on 1280x720 frames at 50 candidates.

Candidates are 50 circles of radius 2-20 px at random places of synthetic 1280x720 road scenes
(half of them given a 1:3 housing box, as a housing stage would); the verifier (features +
shipped model, after its housing stage) runs on each frame, then the recommended preset's state
classifier (``--classifier``, ab-hist) on all 50 candidates (the worst case: none rejected);
medians over frames and repeats are reported, with the features alone beside them.

Run: python benchmarks/verifier_speed.py [--frames 20] [--repeats 5] [--candidates 50]
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from tsrkit.registry import get_registry  # noqa: E402
from tsrkit.synth import SynthOptions, render_frame  # noqa: E402
from tsrkit.types import Candidate, Frame  # noqa: E402
from tsrkit_plugins.verifiers.features import candidate_features  # noqa: E402

cv2.setNumThreads(1)


def candidates(rng: np.random.Generator, n: int) -> list[Candidate]:
    """``n`` circles in a 1280x720 frame, every other one with a 1:3 housing around it."""
    out = []
    for i in range(n):
        r = float(rng.uniform(2, 20))
        c = Candidate.from_circle(rng.uniform(0, 1280), rng.uniform(0, 720), r, rng.random())
        if i % 2:
            box = (c.x - 1.3 * r, c.y - 1.3 * r, c.x + 1.3 * r, c.y + 6.5 * r)
            c = dataclasses.replace(c, housing=box, housing_score=0.5)
        out.append(c)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=20)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--candidates", type=int, default=50)
    parser.add_argument("--classifier", default="ab-hist", help="state classifier timed after")
    args = parser.parse_args()
    verifier = get_registry().create("verifier", "verifier", {"threshold": 0.5})
    rng = np.random.default_rng(0)
    frames = [
        Frame(render_frame(i, 7, 1280, 720, SynthOptions())[0], f"synth{i}")
        for i in range(args.frames)
    ]
    sets = [candidates(rng, args.candidates) for _ in frames]
    classifier = get_registry().create("classifier", args.classifier)
    verifier.verify(frames[0], sets[0])  # load the models once
    classifier.classify(frames[0], sets[0])
    whole, feats, states = [], [], []
    for _ in range(args.repeats):
        for frame, cands in zip(frames, sets):
            t0 = time.perf_counter()
            verifier.verify(frame, cands)
            t1 = time.perf_counter()
            candidate_features(frame.image, cands)
            t2 = time.perf_counter()
            classifier.classify(frame, cands)
            t3 = time.perf_counter()
            whole.append((t1 - t0) * 1000)
            feats.append((t2 - t1) * 1000)
            states.append((t3 - t2) * 1000)
    print(
        f"verifier on 1280x720, {args.candidates} candidates, one thread: "
        f"median {statistics.median(whole):.2f} ms/frame (features alone "
        f"{statistics.median(feats):.2f} ms); {len(whole)} timings"
    )
    total = [w + s for w, s in zip(whole, states)]
    print(
        f"+ {args.classifier} on all {args.candidates} candidates: median "
        f"{statistics.median(states):.2f} ms; housing + verifier + state: median "
        f"{statistics.median(total):.2f} ms/frame"
    )


if __name__ == "__main__":
    main()
