"""Single-thread speed of the learned verifier on 1280x720 frames at 50 candidates.

Candidates are 50 circles of radius 2-20 px at random places of synthetic 1280x720 road scenes
(half of them given a 1:3 housing box, as a housing stage would); the verifier (its housing
stage, features, shipped model) runs on each frame, then the recommended preset's state
classifier (``--classifier``, lamp-state) on all 50 candidates as the housing stage left them
(the worst case: none rejected).
Medians over frames and repeats are reported, wall clock and process CPU time, with the
stages timed one by one beside them: the housing stage, the features, the model's prediction
(one pass over its trees, and scikit-learn's ``predict_proba`` for comparison) and the state.

Run: python benchmarks/verifier_speed.py [--frames 20] [--repeats 5] [--candidates 50]
"""

from __future__ import annotations

import harness

harness.single_thread()

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402
from functools import partial  # noqa: E402

import numpy as np  # noqa: E402

from tsrkit import (  # noqa: E402
    Candidate,
    Frame,
    get_registry,
)
from tsrkit.api import SynthOptions, render_frame  # noqa: E402
from tsrkit.plugin.params import load_config  # noqa: E402
from tsrkit_plugins.verifiers.features import candidate_features  # noqa: E402


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


def timed(stage: Callable[[], object]) -> tuple[float, float]:
    """Wall clock and process CPU time of one call, in ms."""
    wall, cpu = time.perf_counter(), time.process_time()
    stage()
    return (time.perf_counter() - wall) * 1000, (time.process_time() - cpu) * 1000


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    harness.add_frames(parser, 20)
    harness.add_repeats(parser, 5)
    parser.add_argument("--candidates", type=int, default=50)
    parser.add_argument(
        "--classifier",
        default=load_config("recommended")["classifier"]["name"],
        help="state classifier timed after (default: the recommended preset's)",
    )
    args = parser.parse_args()
    harness.announce()
    verifier = get_registry().create("verifier", "verifier", {"threshold": 0.5})
    housing = get_registry().create("verifier", "housing")
    rng = np.random.default_rng(0)
    frames = [
        Frame(render_frame(i, 7, 1280, 720, SynthOptions())[0], f"synth{i}")
        for i in range(args.frames)
    ]
    sets = [candidates(rng, args.candidates) for _ in frames]
    classifier = get_registry().create("classifier", args.classifier)
    verifier.verify(frames[0], sets[0])  # load the models once
    classifier.classify(frames[0], housing.verify(frames[0], sets[0]))
    times: dict[str, list[tuple[float, float]]] = {}
    cpu_start = time.process_time()
    for _ in range(args.repeats):
        for frame, cands in zip(frames, sets):
            housed = housing.verify(frame, cands)
            features = candidate_features(frame.image, housed)
            stages = {
                "verifier (housing + features + model)": partial(verifier.verify, frame, cands),
                f"{args.classifier} on all candidates": partial(classifier.classify, frame, housed),
                "  housing stage": partial(housing.verify, frame, cands),
                "  features": partial(candidate_features, frame.image, housed),
                "  model (one pass over the trees)": partial(verifier.forest.probability, features),
                "  model (scikit-learn predict_proba)": partial(
                    verifier.estimator.predict_proba, features
                ),
            }
            for name, stage in stages.items():
                times.setdefault(name, []).append(timed(stage))
    cpu_total = time.process_time() - cpu_start

    def median(name: str, k: int) -> float:
        return statistics.median(t[k] for t in times[name])

    print(
        f"1280x720, {args.candidates} candidates, one thread, {args.frames} frames x "
        f"{args.repeats} repeats; median ms per frame (wall / process CPU):"
    )
    for name in times:
        print(f"  {name:40s} {median(name, 0):7.2f} / {median(name, 1):7.2f}")
    total = [(v[0] + s[0], v[1] + s[1]) for v, s in zip(*(times[n] for n in list(times)[:2]))]
    print(
        f"housing + verifier + state: median {statistics.median(t[0] for t in total):.2f} ms "
        f"wall, {statistics.median(t[1] for t in total):.2f} ms CPU per frame (all stages and "
        f"the comparison runs: {cpu_total:.1f} s CPU)"
    )


if __name__ == "__main__":
    main()
