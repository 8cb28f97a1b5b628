"""core.ortho.visibility's point-in-polygon test (the footprint check of the visibility tables): plain NumPy since
matplotlib's first import from the orthophoto stage's worker threads raced on QGIS 3.40 / Python 3.13."""
import math

import numpy as np

from core.ortho import visibility


def _star(rng, n=11, cx=3.0, cy=-2.0):
    """A concave (star-shaped) polygon around (cx, cy)."""
    ang = np.sort(rng.uniform(0, 2 * math.pi, n))
    rad = rng.uniform(0.3, 2.0, n)
    return np.column_stack([cx + rad * np.cos(ang), cy + rad * np.sin(ang)])


def test_point_in_polygon_agrees_with_matplotlib_on_concave_polygons():
    from matplotlib.path import Path

    rng = np.random.default_rng(7)
    checked = inside = 0
    for _ in range(40):
        poly = _star(rng)
        path = Path(poly)
        for x, y in rng.uniform([1.0, -4.0], [5.0, 0.0], (60, 2)):
            expected = bool(path.contains_point((x, y)))
            assert visibility._point_in_polygon(poly, float(x), float(y)) == expected, (poly, x, y)
            checked += 1
            inside += expected
    assert 0.1 * checked < inside < 0.9 * checked  # both answers were tested


def test_point_in_polygon_square_and_degenerate_edges():
    square = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]])
    assert visibility._point_in_polygon(square, 2.0, 2.0)
    assert not visibility._point_in_polygon(square, 5.0, 2.0)
    assert not visibility._point_in_polygon(square, -1.0, 2.0)
    assert not visibility._point_in_polygon(square, 2.0, 4.5)
    # a horizontal edge at the ray's height (division by zero) does not count as a crossing
    notch = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 2.0], [2.0, 2.0], [2.0, 4.0], [0.0, 4.0]])
    assert visibility._point_in_polygon(notch, 1.0, 2.0)
    assert not visibility._point_in_polygon(notch, 3.0, 3.0)
