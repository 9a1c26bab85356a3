"""numpy's pairwise float sum, compiled (plugins/verifiers/reductions.py), equals numpy's own sum
of a contiguous run, to the bit, at every length around its block sizes (8, 128, 256)."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from tsrkit_plugins.verifiers.reductions import pairwise_sum


@njit
def summed(values, out):
    """The sum kept in the values' type (numba returns a float32 to Python as a float)."""
    out[0] = pairwise_sum(values)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_pairwise_sum_is_numpys(dtype):
    rng = np.random.default_rng(7)
    out = np.zeros(1, dtype)
    for n in [*range(0, 300), 511, 512, 513, 1100]:
        values = (rng.standard_normal(n) * rng.uniform(0.1, 1e4)).astype(dtype)
        summed(values, out)
        assert out[0] == np.add.reduce(values), n
