"""numpy's order of adding floats, compiled: for compiled statistics equal to numpy's to the bit.

numpy adds along an outer axis one value after the other, and a contiguous run (a reduction
along the innermost axis, or along an axis that is contiguous because the others have length
1) pairwise (:func:`pairwise_sum`); the two orders give different last bits.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def pairwise_sum(values: np.ndarray) -> float:
    """numpy's sum of a contiguous run of floats (its ``pairwise_sum``, in the values' type):
    under 8 values one after the other from 0; up to 128 in eight interleaved sums, combined as
    ``((0 + 1) + (2 + 3)) + ((4 + 5) + (6 + 7))``, then the rest one after the other; above that
    the two halves (the first a multiple of 8 long) summed so and added."""
    n = len(values)
    total = np.zeros(1, values.dtype)  # held in the values' type at every step
    if n < 8:
        for i in range(n):
            total[0] += values[i]
        return total[0]
    if n > 128:
        half = n // 2 - (n // 2) % 8
        total[0] = pairwise_sum(values[:half])
        total[0] += pairwise_sum(values[half:])
        return total[0]
    r = values[:8].copy()
    end = n - n % 8
    for i in range(8, end, 8):
        for j in range(8):
            r[j] += values[i + j]
    total[0] = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
    for i in range(end, n):
        total[0] += values[i]
    return total[0]
