"""Is an interior orientation one a camera can have?  The checks a surveyor makes by eye before trusting a given
focal length or distortion, made before any work (issue 47, items 3 and 9): each returns the problem in words (or
None), the caller names the file or the option it came from.

- the field of view a focal length gives on its image: a focal length in pixels is a ratio to the image's size,
  so the bounds are ratios (focal length / long side), not pixels;
- the radial distortion within the image's corners: r_d = r (1 + k1 r^2 + k2 r^4 + k3 r^6) must grow with r out
  to the farthest corner (else the image folds over itself: two radii map to one), and the corner may not move
  by more than a factor that no lens the models hold has;
- a focal length given in mm against the photos' EXIF (the real focal length and its 35 mm equivalent).
"""
from __future__ import annotations

import math
from typing import Optional, Sequence

import numpy as np

FULL_FRAME_DIAGONAL_MM = math.hypot(36.0, 24.0)  # what a "35 mm equivalent" focal length is relative to

# focal length / long side of the image: 0.15 is a field of view of 146 degrees across the long side (wider is a
# fisheye, which none of the models here holds; a 14 mm lens on a full frame is 0.39, a drone's 20 mm equivalent
# 0.56); 100 is 0.57 degrees (a 2,000 mm lens on a full frame is 56)
MIN_FOCAL_PER_SIDE = 0.15
MAX_FOCAL_PER_SIDE = 100.0
# the farthest corner moved by the radial distortion by more than this factor (or less than its inverse): no lens
# the Brown model holds does that (a strong wide angle's barrel moves its corner by 0.7 to 0.8)
MAX_CORNER_FACTOR = 3.0
# a focal length given (or a calibration's) this many times the EXIF one (or its inverse) is another camera, a
# 35 mm equivalent or a unit mistaken; the EXIF focal length is a rounded value as a rule (a few percent)
FOCAL_RATIO_REFUSED = 1.5
# two focal lengths this close are "the same value" in an explanation (a 35 mm equivalent is rounded to 1 mm)
SAME_VALUE = 0.08


def field_of_view_deg(focal_px: float, width: int, height: int) -> float:
    """The field of view across the image's long side, in degrees."""
    return math.degrees(2.0 * math.atan(max(width, height) / 2.0 / float(focal_px)))


def focal_problem(focal_px: float, width: int, height: int) -> Optional[str]:
    """Why a focal length of ``focal_px`` on a ``width`` x ``height`` image is not a camera's (None: it may be)."""
    side = max(int(width), int(height))
    if not (focal_px and math.isfinite(focal_px) and focal_px > 0) or side <= 0:
        return f"a focal length of {focal_px!r} px is not a positive number"
    ratio = float(focal_px) / side
    if MIN_FOCAL_PER_SIDE <= ratio <= MAX_FOCAL_PER_SIDE:
        return None
    fov = field_of_view_deg(focal_px, width, height)
    lo = field_of_view_deg(MAX_FOCAL_PER_SIDE * side, width, height)
    hi = field_of_view_deg(MIN_FOCAL_PER_SIDE * side, width, height)
    return (f"a focal length of {focal_px:,.6g} px on {width} x {height} px images is {ratio:.3g} times their long "
            f"side: a field of view of {fov:.3g} degrees, outside what a camera has ({lo:.2g} to {hi:.0f} degrees: "
            f"{MIN_FOCAL_PER_SIDE * side:,.0f} to {MAX_FOCAL_PER_SIDE * side:,.0f} px); is its unit wrong (mm, "
            f"or a focal length normalised by the image width, for pixels), or is it another image size's?")


def corner_radius(fx: float, fy: float, cx: float, cy: float, width: int, height: int) -> float:
    """The normalised radius (x = X/Z) of the image corner farthest from the principal point."""
    return max(math.hypot((x - cx) / fx, (y - cy) / fy) for x in (0.0, float(width)) for y in (0.0, float(height)))


def distortion_problem(fx: float, fy: float, cx: float, cy: float, width: int, height: int,
                       k: Sequence[float]) -> Optional[str]:
    """Why the radial distortion ``k`` = (k1[, k2[, k3]]) cannot be a lens's within the image (None: it may be):
    the image folds (r_d stops growing before the farthest corner) or the corner moves by a factor beyond
    MAX_CORNER_FACTOR."""
    ks = [float(v) for v in list(k)[:3]] + [0.0] * (3 - len(list(k)[:3]))
    if not any(ks):
        return None
    k1, k2, k3 = ks
    rc = corner_radius(fx, fy, cx, cy, width, height)
    r = np.linspace(0.0, rc, 2001)
    slope = 1.0 + 3.0 * k1 * r ** 2 + 5.0 * k2 * r ** 4 + 7.0 * k3 * r ** 6
    terms = ", ".join(f"{n} = {v:g}" for n, v in zip(("k1", "k2", "k3"), ks) if v)
    if np.any(slope <= 0.0):
        at = float(r[int(np.argmax(slope <= 0.0))])
        return (f"its radial distortion ({terms}) folds the image: the distorted radius stops growing at "
                f"{100.0 * at / rc:.0f} % of the way to the farthest corner ({at * fx:,.0f} px from the principal "
                f"point, the corner at {rc * fx:,.0f} px), so two points of the scene would land on one pixel; no lens "
                f"does that: are the coefficients of another model or scaled for another unit (mm, not normalised "
                f"coordinates)?")
    factor = 1.0 + k1 * rc ** 2 + k2 * rc ** 4 + k3 * rc ** 6
    if not (1.0 / MAX_CORNER_FACTOR <= factor <= MAX_CORNER_FACTOR):
        return (f"its radial distortion ({terms}) moves the farthest image corner {factor:.3g} times its distance "
                f"from the principal point ({rc * fx:,.0f} px to {rc * fx * factor:,.0f} px); no lens the model holds "
                f"does more than {MAX_CORNER_FACTOR:g} times either way: are the coefficients of another model or "
                f"scaled for another unit (mm, not normalised coordinates)?")
    return None


def ratio_text(a: float, b: float) -> str:
    """'5.6 times' or '1/5.6 of': ``a`` against ``b`` in words."""
    q = a / b
    return f"{q:.3g} times" if q >= 1.0 else f"1/{1.0 / q:.3g} of"


def far_apart(a: float, b: float, limit: float = FOCAL_RATIO_REFUSED) -> bool:
    """Whether two focal lengths differ by more than the factor ``limit`` (either way)."""
    return a > 0 and b > 0 and max(a / b, b / a) > limit


def same_value(a: Optional[float], b: Optional[float], tol: float = SAME_VALUE) -> bool:
    return bool(a and b and abs(a / b - 1.0) <= tol)


__all__ = ["FOCAL_RATIO_REFUSED", "FULL_FRAME_DIAGONAL_MM", "MAX_CORNER_FACTOR", "MAX_FOCAL_PER_SIDE",
           "MIN_FOCAL_PER_SIDE", "corner_radius", "distortion_problem", "far_apart", "field_of_view_deg",
           "focal_problem", "ratio_text", "same_value"]
