"""Uncertainty of the headline figures: bootstrap 95 % intervals and a paired method comparison.

Frames are the resampling unit. ``bootstrap_interval`` is the percentile bootstrap (NumPy:
SciPy's ``stats`` module would add over a second of import to every run);
``paired_test`` runs the Wilcoxon signed-rank test on per-frame differences of two methods
evaluated on the same frames.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["ALPHA", "bootstrap_interval", "format_p", "paired_test", "quantile7"]

ALPHA = 0.05


def bootstrap_interval(
    values: Sequence[float], resamples: int = 1000, seed: int = 0
) -> list[float] | None:
    """95 % percentile-bootstrap interval of the mean of ``values``; None for fewer than 2 or
    for values that are not all finite.

    Examples
    --------
    >>> bootstrap_interval([1.0, 1.0, 1.0])
    [1.0, 1.0]
    """
    data = np.asarray(values, dtype=float)
    if data.size < 2 or not np.isfinite(data).all():
        return None
    if np.all(data == data[0]):
        return [float(data[0])] * 2
    # SciPy's stats.bootstrap(method="percentile", random_state=seed), resample for resample
    # (its legacy RandomState stream), without the second of importing scipy.stats
    rng = np.random.RandomState(seed)
    batch = max(1, 4_000_000 // data.size)  # bounded memory for long runs
    means = np.concatenate(
        [
            data[rng.randint(0, data.size, (min(batch, resamples - done), data.size))].mean(axis=-1)
            for done in range(0, resamples, batch)
        ]
    )
    alpha = (1 - (1 - ALPHA)) / 2  # as SciPy computes it from the confidence level
    return [quantile7(means, alpha), quantile7(means, 1 - alpha)]


def quantile7(values: np.ndarray, p: float) -> float:
    """The ``p`` quantile by Hyndman and Fan's (1996) definition 7, linear between order
    statistics, in the arithmetic of ``scipy.stats.quantile`` (``np.quantile`` may differ in
    the last digit).

    Examples
    --------
    >>> quantile7(np.array([4.0, 1.0, 3.0, 2.0]), 0.5), quantile7(np.array([1.0, 2.0]), 0.25)
    (2.5, 1.25)
    """
    ordered = np.sort(values)
    position = p * ordered.size + (1 - p)  # 1-based
    upper = int(position // 1)
    g = position % 1
    lower, upper = min(max(upper - 1, 0), ordered.size - 1), min(upper, ordered.size - 1)
    return float((1 - g) * ordered[lower] + g * ordered[upper])


def format_p(p_value: float | None) -> str:
    """A p-value for a reader: three decimals, or two significant digits below 0.001.

    Examples
    --------
    >>> format_p(0.0421), format_p(7.430843875383497e-14), format_p(1.0), format_p(None)
    ('0.042', '7.4e-14', '1.000', '-')
    """
    if p_value is None:
        return "-"
    return f"{p_value:.1e}" if p_value < 0.001 else f"{p_value:.3f}"


def paired_test(
    a: Sequence[float], b: Sequence[float], name_a: str = "A", name_b: str = "B"
) -> dict:
    """Does method A beat method B on the same frames? Wilcoxon signed-rank, two-sided.

    Returns the frame count, the mean difference ``a - b``, the p-value and a verdict naming
    the better method when ``p < 0.05`` (else ``"no significant difference"``).
    """
    x, y = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if x.shape != y.shape:
        raise ValueError(f"paired values differ in length: {x.size} and {y.size}")
    diff = x - y
    # SciPy's statistics: only when a comparison is tested
    from scipy.stats import wilcoxon

    p_value = 1.0 if not np.any(diff) else float(wilcoxon(x, y, zero_method="wilcox").pvalue)
    mean = float(diff.mean()) if diff.size else 0.0
    if p_value < ALPHA:
        verdict = f"{name_a} better" if mean > 0 else f"{name_b} better"
    else:
        verdict = "no significant difference"
    return {
        "frames": int(diff.size),
        "mean_difference": mean,
        "p_value": p_value,
        "test": "wilcoxon signed-rank",
        "verdict": verdict,
    }
