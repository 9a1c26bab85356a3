"""Is a held-out camera's state separable by colour from what the other cameras show?

Evidence for the target of lamp-state (accuracy and red recall >= 0.95 on every set, leave one set
out): for each of the six sets of ``state_loso.py`` (MIT test, VGIS day and night deduplicated,
KR, cinTA, DTLD test), beside the others' training parts that leave-one-set-out (LOSO) trains on.

* **Lamp hue** of every light (its own pixels, no jitter): the CIELab hue angle (degrees,
  ``atan2(b, a)``) of lamp-state's Lab means, of the brightest disk pixels (the core) and of the
  most chromatic rim pixels (the rim), per set and state; and, per set and state, the share of
  its lights whose nearest lamps in colour (those four Lab means) among the other sets' lights
  are mostly red, amber, green or red+amber (their own pixels, and the jittered training rows
  LOSO learns from): a light whose neighbours are of another state is not told apart by its
  lamp colour from what the other cameras show.
* **Accuracy with and without the camera's own data**, lamp-state's protocol (its parameters,
  jittered training copies, red prior and red+amber rule) with its full model alone (its
  ``colour_weight`` not applied: the evidence the colour model was built on): LOSO on all
  features and on the lamp colour only (the 27 lens columns: hue histograms, Lab means,
  over-exposure), and 5-fold cross-validation inside the set (folds by image,
  stratified by state): the colour model trained on the set's own lights alone ("colour,
  own"), and all features trained on the other sets plus the set's own other folds ("in-domain
  CV"). Where "colour, own" is high and colour LOSO low, the set's colours separate its states
  but by a boundary of its own camera; where in-domain CV is low too, no amount of training
  data from this camera fixes it with these features.

    python benchmarks/state_separability.py [--seed N]
"""

from __future__ import annotations

import harness

harness.single_thread(opencv=False)

import argparse  # noqa: E402

import numpy as np  # noqa: E402
from state_loso import families, wanted_boxes  # noqa: E402

from tsrkit import (  # noqa: E402
    Dataset,
    get_registry,
)
from tsrkit.api import open_dataset  # noqa: E402
from tsrkit_plugins.classifiers.lamp_state import (  # noqa: E402
    STATES,
    blend,
    fit_estimator,
    labelled_features,
    prefer_red,
    red_yellow,
)
from tsrkit_plugins.classifiers.lamp_state.features import (  # noqa: E402
    N_HUE,
    N_LENS,
    red_amber_rows,
)

#: Column of the core's (brightest disk pixels') CIELab a; b, then the rim's a and b follow.
LAB = 2 * N_HUE
#: The six held-out sets: (group of :func:`parts`, key).
SETS = (
    ("mit", "mit test"),
    ("vgis", "vgis day"),
    ("vgis", "vgis night"),
    ("kr", "kr"),
    ("cinta", "cinta"),
    ("dtld", "dtld test"),
)
#: The single-lamp states whose hue ranges are compared.
LAMPS = ("red", "yellow", "green")


def parts() -> dict[str, dict[str, Dataset]]:
    """The camera families of ``state_loso.py`` this evidence was measured on (all but Japan),
    DTLD's training part its train split only, as when it was first measured."""
    data = families()
    del data["japan"]
    data["dtld"]["train"] = open_dataset("dtld_fridtjofs").split("train")
    return data


def bare_boxes(sample) -> list:
    """The annotated lights of ``sample`` that lamp-state reads, as bare boxes."""
    return wanted_boxes(sample, housed=False)[0]


def scores(truth: np.ndarray, predicted: list[str]) -> tuple[float, float, int]:
    """Accuracy, red recall and count over lights whose true state is in :data:`STATES`."""
    names = [STATES[i] for i in truth]
    right = sum(t == p for t, p in zip(names, predicted))
    reds = [p for t, p in zip(names, predicted) if t == "red"]
    red = sum(p == "red" for p in reds) / len(reds) if reds else float("nan")
    return right / max(len(names), 1), red, len(names)


def rule_rows(dataset: Dataset, features: np.ndarray) -> np.ndarray:
    """The ``features`` of the lights of ``dataset`` (in order, no copies) as lamp-state's
    red+amber rule reads them (:func:`red_amber_rows`: squarer boxes' two lamps too)."""
    out, start = [], 0
    for sample in dataset:
        boxes = bare_boxes(sample)
        if boxes:
            rows = features[start : start + len(boxes)]
            out.append(red_amber_rows(sample.load().image, boxes, rows))
            start += len(boxes)
    return np.concatenate(out)


def read(probability: np.ndarray, states: list[str], rule: np.ndarray, params) -> list[str]:
    """lamp-state's reading of its learned ``probability`` (columns ``states``), with its
    red+amber rule (:func:`red_yellow`) on the ``rule`` rows (:func:`rule_rows`)."""
    table = blend(probability, states, np.zeros((len(probability), len(STATES))), 0.0)
    table = red_yellow(table, rule, params["red_yellow_ratio"])
    return [STATES[i] for i in np.argmax(table, axis=1)]


def hue_angles(features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """CIELab hue angles in degrees of the core and of the rim of each row of lamp-state
    ``features``, in [-90, 270): 0 the +a (magenta-red) axis, 90 +b (yellow), 180 -a (green),
    so that reds, ambers and greens each lie in one unbroken range.

    Examples
    --------
    >>> row = np.zeros((2, LAB + 4)); row[:, LAB:] = ((1.0, 1.0, 0.0, 0.5), (-1, -0.1, 0.1, -1))
    >>> np.round(hue_angles(row), 1)
    array([[ 45. , 185.7],
           [ 90. , -84.3]])
    """
    core = np.degrees(np.arctan2(features[:, LAB + 1], features[:, LAB]))
    rim = np.degrees(np.arctan2(features[:, LAB + 3], features[:, LAB + 2]))
    return (core + 90) % 360 - 90, (rim + 90) % 360 - 90


def light_ids(dataset: Dataset, copies: int) -> tuple[np.ndarray, np.ndarray]:
    """For the rows :func:`labelled_features` gives of ``dataset`` with ``copies`` (per image,
    its lights' views one after another): the index of each row's light (in the order of the
    unjittered rows) and of its image."""
    lights, images, start = [], [], 0
    for image, sample in enumerate(dataset):
        n = len(bare_boxes(sample))
        if n:
            lights.append(np.tile(np.arange(start, start + n), copies + 1))
            images.append(np.full(n * (copies + 1), image))
            start += n
    if not lights:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    return np.concatenate(lights), np.concatenate(images)


def folds(images: np.ndarray, labels: np.ndarray, k: int, seed: int) -> np.ndarray:
    """A fold (0 to ``k`` - 1) per light: whole images to a fold, stratified by each image's
    first label, shuffled by ``seed``."""
    rng = np.random.default_rng(seed)
    fold = np.zeros(len(images), np.int64)
    first = {int(i): int(labels[np.argmax(images == i)]) for i in np.unique(images)}
    for state in sorted(set(first.values())):
        chosen = np.array([i for i, s in first.items() if s == state])
        rng.shuffle(chosen)
        for position, image in enumerate(chosen.tolist()):
            fold[images == image] = position % k
    return fold


def predict(train_x, train_y, x, rule, params) -> list[str]:
    """lamp-state's reading (red prior and red+amber rule) of ``x`` by a model of the rows
    ``train_x`` / ``train_y``."""
    estimator, states = fit_estimator(train_x, train_y, params)
    probability = prefer_red(estimator.predict_proba(x), states, params["red_prior"])
    return read(probability, states, rule, params)


def neighbour_states(x: np.ndarray, rows: np.ndarray, labels: np.ndarray, k: int) -> np.ndarray:
    """For each row of ``x``, the state (index into :data:`STATES`) most common among its ``k``
    nearest ``rows`` (``labels``) in the lamp's CIELab a / b of core and rim (the four Lab
    columns of lamp-state's features)."""
    own, other = x[:, LAB : LAB + 4], rows[:, LAB : LAB + 4]
    distance = ((own[:, None, :] - other[None, :, :]) ** 2).sum(axis=2)
    nearest = labels[np.argsort(distance, axis=1)[:, :k]]
    counts = np.stack([(nearest == i).sum(axis=1) for i in range(len(STATES))], axis=1)
    return np.argmax(counts, axis=1)


def others(rows: dict, group: str) -> tuple[np.ndarray, np.ndarray]:
    """The ``rows`` ((x, y) per group) of every group but ``group``, concatenated."""
    x = np.concatenate([rows[g][0] for g in rows if g != group])
    return x, np.concatenate([rows[g][1] for g in rows if g != group])


def share_cell(found: np.ndarray) -> str:
    """Shares of the states (:data:`STATES`) in ``found`` as a table cell."""
    return " / ".join(f"{np.mean(found == i):.2f}" for i in range(len(STATES)))


def hue_table(view0: dict, train0: dict, jittered: dict, k: int) -> None:
    """Print the hue angles per set and state and the states of its lamps' colour neighbours
    among the other sets' lights (``train0``) and among the jittered training rows LOSO learns
    from (``jittered``): :func:`neighbour_states`."""
    print(
        "| set | state | n | core angle p10 / p50 / p90 | rim angle p10 / p50 / p90 "
        f"| {k} nearest of the others' lights: red / amber / green / red+amber "
        "| the same among their training rows (jittered) |"
    )
    print("|---|---|---:|---|---|---|---|")
    agree = []
    for group, key in SETS:
        x, y = view0[key]
        core, rim = hue_angles(x)
        plain = neighbour_states(x, *others(train0, group), k)
        rows = neighbour_states(x, *others(jittered, group), k)
        agree.append(f"{key} {np.mean(plain == y):.3f} / {np.mean(rows == y):.3f}")
        for state in STATES:
            mask = y == STATES.index(state)
            if not mask.any():
                continue
            c = np.percentile(core[mask], [10, 50, 90])
            r = np.percentile(rim[mask], [10, 50, 90])
            print(
                f"| {key} | {state} | {int(mask.sum())} | {c[0]:.0f} / {c[1]:.0f} / {c[2]:.0f} "
                f"| {r[0]:.0f} / {r[1]:.0f} / {r[2]:.0f} | {share_cell(plain[mask])} "
                f"| {share_cell(rows[mask])} |"
            )
    print(
        "share of lights whose colour neighbours are mostly of their own state (others' "
        "lights / training rows): " + ", ".join(agree)
    )
    for group in train0:
        x, y = train0[group]
        rim = hue_angles(x)[1]
        ranges = [
            "{}: {:.0f} to {:.0f}".format(s, *np.percentile(rim[y == STATES.index(s)], [10, 90]))
            for s in LAMPS
            if (y == STATES.index(s)).any()
        ]
        print(f"training part of {group}, rim angle 10-90 %: " + ", ".join(ranges))


def accuracy_table(data, features, view0, params, k: int) -> None:
    """Print LOSO and in-set cross-validated accuracy / red recall per set (see the module)."""
    copies, seed = params["copies"], params["seed"]
    print("\n| set | LOSO, all | LOSO, colour | colour, own (CV) | in-domain CV, all |")
    print("|---|---|---|---|---|")
    summary: dict[str, list[float]] = {}
    for group, key in SETS:
        x0, y0 = view0[key]
        rule = rule_rows(data[group][key], x0)
        others = [features[g] for g in data if g != group]
        ox = np.concatenate([o[0] for o in others])
        oy = np.concatenate([o[1] for o in others])
        found = {
            "LOSO, all": predict(ox, oy, x0, rule, params),
            "LOSO, colour": predict(ox[:, :N_LENS], oy, x0[:, :N_LENS], rule, params),
        }
        jx, jy = labelled_features(data[group][key], copies, seed=seed)
        light, image = light_ids(data[group][key], copies)
        of_light = np.zeros(len(y0), np.int64)
        of_light[light] = image
        fold = folds(of_light, y0, k, seed)
        own, domain = [""] * len(y0), [""] * len(y0)
        for f in range(k):
            test = np.flatnonzero(fold == f)
            train = fold[light] != f
            if len(set(jy[train].tolist())) < 2 or not len(test):
                continue
            colour = predict(jx[train, :N_LENS], jy[train], x0[test, :N_LENS], rule[test], params)
            both = predict(
                np.concatenate([ox, jx[train]]),
                np.concatenate([oy, jy[train]]),
                x0[test],
                rule[test],
                params,
            )
            for i, a, b in zip(test.tolist(), colour, both):
                own[i], domain[i] = a, b
        found["colour, own (CV)"], found["in-domain CV, all"] = own, domain
        cells = []
        for name, predicted in found.items():
            accuracy, red, _ = scores(y0, predicted)
            summary.setdefault(name, []).append(accuracy)
            cells.append(f"{accuracy:.3f} / {red:.3f}")
        print(f"| {key} | " + " | ".join(cells) + " |", flush=True)
    for name, values in summary.items():
        print(f"{name}: mean {np.mean(values):.3f}, worst {min(values):.3f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0, help="jitter, boosting and fold seed")
    parser.add_argument("--folds", type=int, default=5, help="folds of the in-set CV")
    parser.add_argument("--neighbours", type=int, default=15, help="colour neighbours counted")
    args = parser.parse_args()
    harness.announce()
    params = get_registry().create("classifier", "lamp-state", {"seed": args.seed}).params
    data = parts()
    features = {
        g: labelled_features(sets["train"], params["copies"], seed=params["seed"])
        for g, sets in data.items()
    }
    train0 = {g: labelled_features(sets["train"]) for g, sets in data.items()}
    view0 = {key: labelled_features(data[g][key]) for g, key in SETS}
    hue_table(view0, train0, features, args.neighbours)
    accuracy_table(data, features, view0, params, args.folds)


if __name__ == "__main__":
    main()
