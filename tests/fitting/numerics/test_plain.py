"""fitting.numerics.plain: numpy's unique, union1d and median, without numpy.ma."""

from __future__ import annotations

import numpy as np
import pytest

from fitting.numerics.plain import median, union, unique


@pytest.mark.parametrize("seed", range(5))
def test_as_numpy_on_values_with_repeats(seed):
    rng = np.random.default_rng(seed)
    for size in (0, 1, 2, 3, 10, 101):
        values = rng.integers(0, 7, size).astype(float) / 3.0
        other = rng.normal(size=(size, 2))
        np.testing.assert_array_equal(unique(values), np.unique(values))
        np.testing.assert_array_equal(union(values, other), np.union1d(values, other))
        if size:
            assert median(values) == np.median(values) and median(other) == np.median(other)
    ints = rng.integers(-5, 5, 50)
    assert unique(ints).dtype == np.unique(ints).dtype
    np.testing.assert_array_equal(unique(ints), np.unique(ints))


def test_median_of_nothing_is_refused():
    with pytest.raises(ValueError, match="`values` must hold at least one value"):
        median([])
