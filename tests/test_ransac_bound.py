"""helmert_ransac's adaptive bound (core/geometry/similarity.py): the random draws stop once one all-inlier
3-point sample has been drawn with the given confidence at the best inlier ratio found, and still find the truth."""
import math

import numpy as np
import pytest

from core.geometry import similarity as sim


def test_draws_needed_is_the_standard_bound():
    # log(1 - 0.99) / log(1 - 0.5^3) = 34.5 -> 35 draws; the floor keeps at least 50
    assert sim._draws_needed(0.5, 0.99, floor=1) == 35
    assert sim._draws_needed(0.5, 0.99) == 50
    assert sim._draws_needed(0.2, 0.9999) == math.ceil(math.log(1e-4) / math.log(1 - 0.008))
    assert sim._draws_needed(1.0, 0.9999) == 50
    assert sim._draws_needed(0.0, 0.9999) > 10 ** 9


@pytest.mark.parametrize("outliers", [0.1, 0.4, 0.6])
def test_the_bound_finds_the_same_inliers_as_every_draw(outliers):
    rng = np.random.default_rng(3)
    n = 80
    src = rng.normal(0.0, 40.0, (n, 3))
    rot = sim.rodrigues(np.array([0.1, -0.2, 0.7]))[0]
    dst = 1.7 * src @ rot.T + np.array([500.0, -20.0, 3.0]) + rng.normal(0.0, 0.02, (n, 3))
    bad = rng.choice(n, int(outliers * n), replace=False)
    dst[bad] += rng.normal(0.0, 15.0, (len(bad), 3))
    truth = np.ones(n, dtype=bool)
    truth[bad] = False
    every = sim.helmert_ransac(src, dst, 0.2, confidence=1.0)
    bound = sim.helmert_ransac(src, dst, 0.2)
    np.testing.assert_array_equal(bound.inliers, truth)
    np.testing.assert_array_equal(every.inliers, truth)
    assert abs(bound.transform.scale - 1.7) < 1e-3
