"""Bootstrap intervals and the paired comparison test."""

import numpy as np
import pytest

from tsrkit.eval.stats import bootstrap_interval, paired_test


def test_bootstrap_interval_brackets_the_mean():
    values = [0.0, 1.0] * 50
    low, high = bootstrap_interval(values)
    assert low < 0.5 < high and high - low < 0.3
    assert bootstrap_interval([0.3]) is None
    assert bootstrap_interval([0.1, float("nan"), 0.9]) is None
    assert bootstrap_interval([1.0, float("inf")]) is None


def test_paired_test_names_the_better_method():
    a = [1.0] * 30
    b = [0.0] * 25 + [1.0] * 5
    assert paired_test(a, b, "x", "y")["verdict"] == "x better"
    assert paired_test(b, a, "x", "y")["verdict"] == "y better"
    assert paired_test(a, a)["verdict"] == "no significant difference"
    with pytest.raises(ValueError, match="differ in length"):
        paired_test([1.0], [1.0, 2.0])


@pytest.mark.parametrize("n", [2, 7, 37, 300, 20_000])
def test_bootstrap_interval_is_scipys_percentile_bootstrap_to_the_last_digit(n):
    from scipy import stats

    values = np.random.default_rng(n).random(n) ** 2
    scipys = stats.bootstrap(
        (values,), np.mean, n_resamples=1000, method="percentile", random_state=0
    ).confidence_interval
    assert bootstrap_interval(values) == [float(scipys.low), float(scipys.high)]
