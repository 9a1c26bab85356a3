"""How the recommended pipeline's keep decision should fuse the verifier's probability with the
union's agreement: rules replayed offline on the held-out candidates of a ``camera_loso.py`` run.

A ``camera_loso.py`` run dumps every held-out candidate after the housing stage with its
decision score ``d = (1 - prior) p + prior a`` (``p`` the verifier's probability, ``a`` the
union's agreement) and its reported score; this script recovers ``p`` and replays keep rules
(threshold and the per-frame ``relative`` gate) per held-out camera: Zheng hit, precision
(exhaustive sets), recall at IoU 0.5, and false lights per frame on the held-out camera's empty
frames and on synthetic no-light frames.

Rules that calibrate per camera read only the camera's own candidates, never a label: what a
video's running statistics would give at run time (``a camera``: all frames of the held-out
set; its empty frames are calibrated with the set's frames, as one video would mix them).

Run: python benchmarks/camera_loso.py --out benchmarks/out/camera_loso     # the dumps
     python benchmarks/fusion_study.py benchmarks/out/camera_loso [--rules NAME ...]
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
from camera_loso import FAMILIES, figures

#: Thresholds each rule is read at.
THRESHOLDS = (0.2, 0.25, 0.3, 0.35, 0.4, 0.5, 0.6)


def logit(p: np.ndarray) -> np.ndarray:
    """log(p / (1 - p)), p clipped to [1e-4, 1 - 1e-4]."""
    clipped = np.clip(p, 1e-4, 1 - 1e-4)
    return np.log(clipped / (1 - clipped))


def squash(z: np.ndarray) -> np.ndarray:
    """The logistic function."""
    return 1.0 / (1.0 + np.exp(-z))


#: A rule maps (p, a, the camera's p for calibration) to the decision score.
Rule = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
RULES: dict[str, Rule] = {
    "preset 0.3p+0.7a": lambda p, a, cam: 0.3 * p + 0.7 * a,
    "0.5p+0.5a": lambda p, a, cam: 0.5 * p + 0.5 * a,
    "p alone": lambda p, a, cam: p,
    "a alone": lambda p, a, cam: a,
    "sqrt(p a)": lambda p, a, cam: np.sqrt(p * a),
    "0.3p+0.7a, p >= 0.05": lambda p, a, cam: np.where(p >= 0.05, 0.3 * p + 0.7 * a, 0.0),
    "0.3p+0.7a, p >= 0.1": lambda p, a, cam: np.where(p >= 0.1, 0.3 * p + 0.7 * a, 0.0),
    # per camera: p's logit against the camera's 90th percentile of logits (its negatives)
    "camera-calibrated p": lambda p, a, cam: squash(logit(p) - np.quantile(logit(cam), 0.9)),
    "0.3 cal p + 0.7a": lambda p, a, cam: (
        0.3 * squash(logit(p) - np.quantile(logit(cam), 0.9)) + 0.7 * a
    ),
}


def with_rule(d: dict, rule: Rule, prior: float, camera_p: np.ndarray) -> dict:
    """The dump ``d`` with its decision scores replaced by ``rule``'s."""
    return {**d, "decision": rule(probabilities(d, prior), d["agreement"], camera_p)}


def probabilities(d: dict, prior: float) -> np.ndarray:
    """The verifier's probability of each dumped candidate (its decision score without the
    agreement's share)."""
    return (d["decision"] - prior * d["agreement"]) / (1.0 - prior)


def tables(out: Path, names: list[str], relative: float) -> str:
    results = json.loads((out / "results.json").read_text())
    prior = float(results["verifier_params"].get("prior", 0.0))
    exhaustive = {f.key: f.exhaustive for f in FAMILIES} | {"MIT": True, "VGIS": True}
    lines = [
        f"Run {out} ({results['code']['commit']}), relative {relative}; per held-out set: hit / "
        "precision / recall IoU.5 / empty-frame FP; then mean no-light FP over the folds",
        "",
    ]
    held = []
    for key, fold in results["folds"].items():
        for part in fold["sets"]:
            if part != "no-light" and not part.endswith("-empty"):
                held.append((key, part))
    lines.append("| rule | t | " + " | ".join(p for _, p in held) + " | no-light FP |")
    lines.append("|---|---|" + "---|" * (len(held) + 1))
    dumps = {
        (key, part): dict(np.load(out / f"dump_{key}_{part}.npz"))
        for key, fold in results["folds"].items()
        for part in fold["sets"]
    }
    for name in names:
        rule = RULES[name]
        for t in THRESHOLDS:
            cells, nolight = [], []
            for key, part in held:
                d = dumps[(key, part)]
                camera = probabilities(d, prior)
                f = figures(with_rule(d, rule, prior, camera), t, relative, exhaustive[part])
                empty = dumps.get((key, f"{part}-empty"))
                e = (
                    figures(with_rule(empty, rule, prior, camera), t, relative, True)
                    if empty is not None
                    else None
                )
                cells.append(
                    f"{f['hit']:.2f} / {_f(f['precision'])} / {f['iou50_recall']:.2f} / "
                    f"{_f(e['fp_per_frame'] if e else None)}"
                )
            for key in results["folds"]:
                nl = dumps[(key, "no-light")]
                rows = with_rule(nl, rule, prior, probabilities(nl, prior))
                nolight.append(figures(rows, t, relative, True)["fp_per_frame"])
            lines.append(f"| {name} | {t} | " + " | ".join(cells) + f" | {np.mean(nolight):.2f} |")
    return "\n".join(lines) + "\n"


def _f(value) -> str:
    return "n/a" if value is None else f"{value:.2f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", help="a camera_loso.py output folder")
    parser.add_argument("--rules", nargs="*", default=list(RULES), choices=list(RULES))
    parser.add_argument("--relative", type=float, default=0.6, help="the per-frame gate")
    args = parser.parse_args()
    out = Path(args.run)
    if not (out / "results.json").is_file():
        parser.error(f"{out}: no results.json (run camera_loso.py --out {out} first)")
    print(tables(out, args.rules, args.relative))


if __name__ == "__main__":
    main()
