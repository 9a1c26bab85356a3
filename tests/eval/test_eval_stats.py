"""Bootstrap intervals and the paired comparison test."""

import numpy as np
import pytest

from tsrkit.eval.stats import bootstrap_interval, paired_test


def test_bootstrap_interval_brackets_the_mean():
    values = [0.0, 1.0] * 50
    low, high = bootstrap_interval(values)
    assert low < 0.5 < high and high - low < 0.3
    assert bootstrap_interval([0.3]) is None


def test_paired_test_names_the_better_method():
    a = [1.0] * 30
    b = [0.0] * 25 + [1.0] * 5
    assert paired_test(a, b, "x", "y")["verdict"] == "x better"
    assert paired_test(b, a, "x", "y")["verdict"] == "y better"
    assert paired_test(a, a)["verdict"] == "no significant difference"
    with pytest.raises(ValueError, match="differ in length"):
        paired_test([1.0], [1.0, 2.0])


def test_bootstrap_interval_agrees_with_scipys_percentile_bootstrap():
    from scipy import stats

    values = np.random.default_rng(3).random(200) ** 2
    ours = bootstrap_interval(values, resamples=4000)
    scipys = stats.bootstrap(
        (values,), np.mean, n_resamples=4000, method="percentile", random_state=1
    ).confidence_interval
    assert ours == pytest.approx([scipys.low, scipys.high], abs=0.006)
    assert ours == bootstrap_interval(values, resamples=4000)  # seeded: the same every run
