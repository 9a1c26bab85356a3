"""Training the network with PyTorch (the ``train`` extra), exported to ONNX and checked.

The network (:func:`network`) is four 3x3 convolution blocks (batch norm, ReLU; max pooling
after the first three) over the 32x32 crop, a 64-unit layer, and three heads: the logit of a
lit traffic light, the housing box in window units (:mod:`.windows`) and the logits of the
states of :data:`~.data.STATE_NAMES`. Its loss: binary cross-entropy of the light, smooth L1 of
the box on positives with a housing box, cross-entropy of the state on positives with a known
state. Every epoch sees the positives (at most ``per_camera`` of each camera) and
``negative_ratio`` times as many negatives drawn anew, from the second epoch on a share ``hard``
of them the negatives the network scores highest in a random pool three times as large
(hard-negative mining); each crop under a fresh camera augmentation (:mod:`.augment`). With a
validation set (a camera the training never sees) the epoch whose validation average precision
of the light is best is kept, and training stops after ``patience`` epochs without a better
one.

The exported model outputs probabilities: ``light`` (N), ``box`` (N, 4), ``state`` (N, 5).
Before it is returned, ONNX Runtime runs it on validation (or training) crops and its outputs
must equal PyTorch's to :data:`TOLERANCE`.

PyTorch is imported here only; inference never imports this module.
"""

from __future__ import annotations

import io
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from tsrkit.api import TsrkitError
from tsrkit_plugins.verifiers.cnn.augment import augment, centre
from tsrkit_plugins.verifiers.cnn.data import STATE_NAMES, CropSet
from tsrkit_plugins.verifiers.cnn.windows import INPUT, to_input

#: The largest difference allowed between ONNX Runtime's and PyTorch's outputs.
TOLERANCE = 1e-4
#: Loss weights of the box and state heads.
BOX_WEIGHT, STATE_WEIGHT = 2.0, 0.5


@dataclass(frozen=True)
class Settings:
    """Training settings (the plugin's parameters of the same names)."""

    width: int = 8
    epochs: int = 14
    patience: int = 4
    batch: int = 256
    learning_rate: float = 3e-3
    negative_ratio: float = 3.0
    per_camera: int = 1000
    hard: float = 0.5
    turn: float = 0.2
    seed: int = 0
    threads: int = 1


@dataclass
class Trained:
    """The exported model, the epoch kept and each epoch's figures."""

    onnx: bytes
    epoch: int
    difference: float
    weights: dict[str, np.ndarray] = field(default_factory=dict)
    history: list[dict[str, float]] = field(default_factory=list)


def _torch() -> Any:
    try:
        import torch
    except ImportError:  # the extra is not installed
        raise TsrkitError(
            "cnn-verifier: training needs PyTorch: pip install torch==2.13.0 "
            "'tsrkit[train]' (inference does not)"
        ) from None
    return torch


def network(width: int) -> Any:
    """The untrained network (a ``torch.nn.Module``) of ``width`` channels in its first block."""
    torch = _torch()
    nn = torch.nn

    def block(a: int, b: int) -> Any:
        return nn.Sequential(
            nn.Conv2d(a, b, 3, padding=1, bias=False), nn.BatchNorm2d(b), nn.ReLU()
        )

    class Net(nn.Module):  # type: ignore[name-defined]
        def __init__(self) -> None:
            super().__init__()
            c = width
            self.features = nn.Sequential(
                block(3, c),
                nn.MaxPool2d(2),
                block(c, 2 * c),
                nn.MaxPool2d(2),
                block(2 * c, 4 * c),
                nn.MaxPool2d(2),
                block(4 * c, 4 * c),
                nn.Flatten(),
                nn.Linear(4 * c * (INPUT // 8) ** 2, 64),
                nn.ReLU(),
            )
            self.light = nn.Linear(64, 1)
            self.box = nn.Linear(64, 4)
            self.state = nn.Linear(64, len(STATE_NAMES))

        def forward(self, x: Any) -> tuple[Any, Any, Any]:
            f = self.features(x)
            return self.light(f).squeeze(1), self.box(f), self.state(f)

    return Net()


def _per_camera(
    rows: np.ndarray, camera: np.ndarray, cap: int
) -> Callable[[np.random.Generator], np.ndarray]:
    """A draw of ``rows`` holding at most ``cap`` of each camera (a fresh subset of a larger
    camera at every draw), so that no camera's look dominates an epoch.

    Examples
    --------
    >>> draw = _per_camera(np.arange(5), np.array(["a", "a", "a", "b", "b"]), 2)
    >>> sorted(draw(np.random.default_rng(0)).tolist())[-2:]
    [3, 4]
    >>> len(draw(np.random.default_rng(0)))
    4
    """
    groups = [rows[camera[rows] == c] for c in np.unique(camera[rows])]

    def draw(rng: np.random.Generator) -> np.ndarray:
        return np.concatenate([rng.permutation(g)[:cap] for g in groups])

    return draw


def _batch(data: CropSet, rows: np.ndarray, rng: np.random.Generator | None, turn: float):
    """Network input and box targets of ``rows``: augmented views, or the plain centres
    (``rng`` None)."""
    if rng is None:
        images = np.stack([centre(data.crops[row], INPUT) for row in rows])
        return to_input(images), data.box[rows].copy()
    images, boxes = augment(data.crops[rows], data.box[rows], INPUT, rng, turn)
    return to_input(images), boxes


def _average_precision(scores: np.ndarray, labels: np.ndarray) -> float:
    """Average precision of ``scores`` for ``labels`` (the area under the step
    precision-recall curve, as scikit-learn's ``average_precision_score``)."""
    order = np.argsort(-scores, kind="stable")
    hits = labels[order] == 1
    if not hits.any():
        return float("nan")
    precision = np.cumsum(hits) / np.arange(1, len(hits) + 1)
    return float(precision[hits].sum() / hits.sum())


def predict(model: Any, x: np.ndarray, batch: int = 1024) -> tuple[np.ndarray, ...]:
    """PyTorch's probabilities (light, box, state) for the input ``x``."""
    torch = _torch()
    model.eval()
    outs: list[list[np.ndarray]] = [[], [], []]
    with torch.no_grad():
        for k in range(0, len(x), batch):
            light, box, state = model(torch.from_numpy(x[k : k + batch]))
            outs[0].append(torch.sigmoid(light).numpy())
            outs[1].append(box.numpy())
            outs[2].append(torch.softmax(state, 1).numpy())
    return tuple(np.concatenate(o) for o in outs)


def train(
    data: CropSet,
    settings: Settings,
    validation: CropSet | None = None,
    progress: Callable[[str], None] | None = None,
) -> Trained:
    """Fit the network on ``data`` (early stopping on ``validation``), export it to ONNX and
    check ONNX Runtime against PyTorch.

    Raises
    ------
    TsrkitError
        No positive or no negative crop; ONNX Runtime disagrees with PyTorch.
    """
    torch = _torch()
    positives = np.flatnonzero(data.light == 1)
    negatives = np.flatnonzero(data.light == 0)
    if not len(positives) or not len(negatives):
        raise TsrkitError(
            f"cnn-verifier: {len(positives)} positive and {len(negatives)} negative crops; "
            "need both (is the detector finding the annotated lights?)"
        )
    torch.manual_seed(settings.seed)
    torch.set_num_threads(settings.threads)
    rng = np.random.default_rng(settings.seed)
    model = network(settings.width)
    optimiser = torch.optim.AdamW(model.parameters(), lr=settings.learning_rate, weight_decay=1e-4)
    draw_positives = _per_camera(positives, data.camera, settings.per_camera)
    n_pos = len(draw_positives(rng))
    per_epoch = n_pos + min(len(negatives), int(settings.negative_ratio * n_pos))
    steps = settings.epochs * -(-per_epoch // settings.batch)
    schedule = torch.optim.lr_scheduler.OneCycleLR(
        optimiser, settings.learning_rate, total_steps=max(steps, 1)
    )
    # positives weighted by the square root of the draw's imbalance: recall first
    weight = torch.tensor(max(settings.negative_ratio, 1.0) ** 0.5)
    held = validation if validation is not None and (validation.light == 1).any() else None
    held_x = _batch(held, np.arange(len(held)), None, 0.0)[0] if held is not None else None
    best: tuple[float, int, dict[str, Any]] | None = None
    history: list[dict[str, float]] = []
    for epoch in range(settings.epochs):
        chosen = draw_positives(rng)
        wanted = per_epoch - len(chosen)
        if epoch == 0 or settings.hard <= 0:
            drawn = rng.permutation(negatives)[:wanted]
        else:  # half drawn at random, half the hardest of a fresh random pool
            pool = rng.permutation(negatives)[: min(len(negatives), 3 * wanted)]
            scores = predict(model, _batch(data, pool, None, 0.0)[0])[0]
            hard = pool[np.argsort(-scores, kind="stable")[: int(settings.hard * wanted)]]
            rest = np.setdiff1d(negatives, hard)
            drawn = np.concatenate([hard, rng.permutation(rest)[: wanted - len(hard)]])
        rows = rng.permutation(np.concatenate([chosen, drawn]))
        model.train()
        total, seen = 0.0, 0
        for k in range(0, len(rows), settings.batch):
            chunk = rows[k : k + settings.batch]
            x, boxes = _batch(data, chunk, rng, settings.turn)
            light, box, state = model(torch.from_numpy(x))
            y = torch.from_numpy(data.light[chunk].astype(np.float32))
            loss = torch.nn.functional.binary_cross_entropy_with_logits(light, y, pos_weight=weight)
            has_box = torch.from_numpy(np.isfinite(boxes).all(axis=1) & (data.light[chunk] == 1))
            if has_box.any():
                target = torch.from_numpy(np.nan_to_num(boxes))
                loss = loss + BOX_WEIGHT * torch.nn.functional.smooth_l1_loss(
                    box[has_box], target[has_box], beta=0.05
                )
            states = torch.from_numpy(data.state[chunk].astype(np.int64))
            known = states >= 0
            if known.any():
                loss = loss + STATE_WEIGHT * torch.nn.functional.cross_entropy(
                    state[known], states[known]
                )
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
            schedule.step()
            total += float(loss.detach()) * len(chunk)
            seen += len(chunk)
            if progress is not None:
                progress(f"epoch {epoch + 1}/{settings.epochs} loss {total / seen:.4f}")
        figures = {"epoch": epoch + 1, "loss": total / max(seen, 1)}
        if held is not None and held_x is not None:
            light_p = predict(model, held_x)[0]
            figures["validation_ap"] = _average_precision(light_p, held.light)
            score = figures["validation_ap"]
            if best is None or score > best[0]:
                best = (score, epoch + 1, {k: v.clone() for k, v in model.state_dict().items()})
            elif epoch + 1 - best[1] >= settings.patience:
                history.append(figures)
                break
        history.append(figures)
    kept = settings.epochs if best is None else best[1]
    if best is not None:
        model.load_state_dict(best[2])
    check = held_x if held_x is not None else _batch(data, positives[:256], None, 0.0)[0]
    onnx, difference = export(model, check)
    return Trained(onnx, min(kept, len(history)), difference, weights(model), history)


def weights(model: Any) -> dict[str, np.ndarray]:
    """The network's parameters and batch-norm statistics as plain arrays (the model's
    ``.npz``: what :func:`adapt` starts from)."""
    return {k: v.detach().numpy().copy() for k, v in model.state_dict().items()}


def export(model: Any, check: np.ndarray) -> tuple[bytes, float]:
    """``model`` as ONNX bytes (probabilities out, any batch size) and the largest difference
    between ONNX Runtime's outputs and PyTorch's on ``check``.

    Raises
    ------
    TsrkitError
        The outputs differ by more than :data:`TOLERANCE`.
    """
    torch = _torch()

    class Probabilities(torch.nn.Module):  # type: ignore[name-defined]
        def __init__(self, inner: Any) -> None:
            super().__init__()
            self.inner = inner

        def forward(self, x: Any) -> tuple[Any, Any, Any]:
            light, box, state = self.inner(x)
            return torch.sigmoid(light), box, torch.softmax(state, 1)

    model.eval()
    wrapped = Probabilities(model).eval()
    buffer = io.BytesIO()
    axes = {"crops": {0: "n"}, "light": {0: "n"}, "box": {0: "n"}, "state": {0: "n"}}
    with warnings.catch_warnings():  # the TorchScript exporter needs no onnxscript; it warns
        warnings.simplefilter("ignore", DeprecationWarning)
        torch.onnx.export(
            wrapped,
            (torch.from_numpy(check[:2]),),
            buffer,
            input_names=["crops"],
            output_names=["light", "box", "state"],
            dynamic_axes=axes,
            opset_version=17,
            dynamo=False,
        )
    onnx = buffer.getvalue()
    from tsrkit_plugins.verifiers.cnn.runtime import session

    runtime = session(onnx, "the exported model")
    expected = predict(model, check)
    got = runtime.run(None, {"crops": check})
    worst = max(float(np.abs(np.asarray(g) - e).max()) for g, e in zip(got, expected))
    if worst > TOLERANCE:
        raise TsrkitError(
            f"cnn-verifier: ONNX Runtime's outputs differ from PyTorch's by {worst:.2e} "
            f"(tolerance {TOLERANCE:g}); the model was not saved"
        )
    return onnx, worst


def adapt(
    arrays: dict[str, np.ndarray], width: int, crops: np.ndarray, batch: int = 256
) -> tuple[bytes, dict[str, np.ndarray]]:
    """The network of ``arrays`` with its batch-norm statistics re-estimated on ``crops``
    (``(N, 32, 32, 3)`` uint8: candidates of the user's own camera, no labels), exported
    again: the means and variances every layer normalises by become the new camera's, the
    learned weights stay (test-time adaptation by batch-norm statistics).

    Returns the ONNX bytes and the new arrays.
    """
    torch = _torch()
    model = network(width)
    model.load_state_dict({k: torch.from_numpy(np.asarray(v)) for k, v in arrays.items()})
    norms = [m for m in model.modules() if isinstance(m, torch.nn.BatchNorm2d)]
    for m in norms:
        m.reset_running_stats()
        m.momentum = None  # a cumulative average over every batch
    model.train()
    x = to_input(crops)
    with torch.no_grad():
        for k in range(0, len(x), batch):
            model(torch.from_numpy(x[k : k + batch]))
    onnx, _ = export(model, x[:256])
    return onnx, weights(model)
