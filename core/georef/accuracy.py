"""Accuracy statistics: residuals, RMSE, NSSDA 95 % figures, ASPRS accuracy classes.

Pure functions on numbers (numpy only).  Lengths are in metres unless a name ends in ``_cm``; the ASPRS
functions report in centimetres as the ASPRS standards do.  Residuals are "data minus reference"
(e.g. orthophoto or adjusted coordinate minus surveyed check point).

Sources and how closely they are followed
-----------------------------------------
* FGDC-STD-007.3-1998, Geospatial Positioning Accuracy Standards Part 3: National Standard for Spatial
  Data Accuracy (NSSDA), section 3.2 and Appendix 3-A:

  - Case 1, RMSE_x = RMSE_y: Accuracy_r = 2.4477 * RMSE_x = 1.7308 * RMSE_r.
  - Case 2, RMSE_x != RMSE_y and 0.6 <= RMSE_min / RMSE_max <= 1.0: the circular standard error is
    approximated by 0.5 * (RMSE_x + RMSE_y), so Accuracy_r ~ 2.4477 * 0.5 * (RMSE_x + RMSE_y).
  - The standard gives no approximation for RMSE_min / RMSE_max < 0.6 (its source, Greenwalt & Schultz
    1968, treats such strongly elliptical errors by their circular error probability).  There we compute
    that probability exactly: the radius holding 95 % of a bivariate normal distribution with independent
    x and y errors of standard deviations RMSE_x and RMSE_y (``circular_error``), and say so (method
    ``"exact"``).
  - Vertical: Accuracy_z = 1.9600 * RMSE_z.
  - Reporting (3.2.3): "Tested ____ (meters, feet) horizontal accuracy at 95% confidence level",
    "Tested ____ (meters, feet) vertical accuracy at 95% confidence level", and for data not tested but
    produced by a method known to reach it "Compiled to meet ____ (meters, feet) horizontal accuracy at 95%
    confidence level".

* ASPRS Positional Accuracy Standards for Digital Geospatial Data, Edition 1, Version 1.0 (2014):
  accuracy classes are open-ended, "X-cm" for any X.  Horizontal (Table 7.1): RMSE_x and RMSE_y <= X,
  RMSE_r <= 1.414 X, mosaic seamline mismatch <= 2 X, accuracy at 95 % <= 2.448 X (NSSDA).  Vertical
  (Table 7.3): RMSE_z <= X in non-vegetated terrain, NVA at 95 % <= 1.96 X, VVA (95th percentile) <= 3.00 X,
  within-swath smooth-surface precision (max difference) <= 0.60 X, swath-to-swath RMSD_z <= 0.80 X,
  swath-to-swath max difference <= 1.60 X.  Table B.5 relates orthoimagery classes to pixel size:
  RMSE_x/RMSE_y of 1 pixel "highest accuracy work", 2 pixels "standard mapping and GIS work", 3 or more
  pixels "visualization and less accurate work" (e.g. 7.5 cm pixels: 7.5 / 15.0 / 22.5 cm classes, with
  RMSE_r 10.6 / 21.2 / 31.8 cm and 95 % accuracy 18.4 / 36.7 / 55.1 cm).  Reporting (7.15) uses the
  "tested to meet" / "produced to meet" sentences built below.
* Edition 2 (2023) differences, implemented with ``edition=2023``: the 95 % confidence figures are gone
  (accuracy is reported as RMSE alone); the horizontal class is set by RMSE_H = sqrt(RMSE_x^2 + RMSE_y^2)
  (a "7.5-cm class" means RMSE_H <= 7.5 cm) instead of by RMSE_x and RMSE_y; the check points' own survey
  error is added in quadrature to the product accuracy (RMSE_H = sqrt(RMSE_H1^2 + RMSE_H2^2), likewise
  RMSE_V); VVA has no pass/fail threshold and is reported as RMSE_V; at least 30 check points are required
  (20 in Edition 1).

The formulas and factors above are the standards'.  The report sentences follow the standards' templates as
we read them; the standards were consulted from memory and secondary sources while writing this module, so
check the wording against the published text before quoting it in a contract deliverable.
"""
from __future__ import annotations

import math
from typing import Any, Dict, Iterable, Optional, Sequence

import numpy as np

NSSDA_CIRCULAR_95 = 2.4477  # sqrt(-2 ln 0.05): 95 % radius / sigma of a circular normal error
NSSDA_HORIZONTAL_FACTOR = 1.7308  # 2.4477 / sqrt(2): 95 % radius / RMSE_r when RMSE_x = RMSE_y
NSSDA_VERTICAL_FACTOR = 1.9600  # two-sided 95 % of a normal error
NSSDA_MIN_RATIO = 0.6  # RMSE_min / RMSE_max at and above which the NSSDA Case 2 approximation applies

ASPRS_2014 = "ASPRS Positional Accuracy Standards for Digital Geospatial Data (2014)"
ASPRS_2023 = "ASPRS Positional Accuracy Standards for Digital Geospatial Data, Edition 2 (2023)"

NSSDA_TEMPLATES = {
    "tested_horizontal": "Tested ____ (meters, feet) horizontal accuracy at 95% confidence level",
    "tested_vertical": "Tested ____ (meters, feet) vertical accuracy at 95% confidence level",
    "compiled_horizontal": "Compiled to meet ____ (meters, feet) horizontal accuracy at 95% confidence level",
    "compiled_vertical": "Compiled to meet ____ (meters, feet) vertical accuracy at 95% confidence level",
}


# --------------------------------------------------------------------------------------------------
# residual statistics
# --------------------------------------------------------------------------------------------------

def _finite(values: Any) -> np.ndarray:
    a = np.asarray(values if values is not None else [], dtype=float).ravel()
    return a[np.isfinite(a)]


def rmse(values: Any) -> float:
    """Root mean square of the finite values (NaN / inf mean "missing" and are skipped); NaN when none."""
    a = _finite(values)
    return float(math.sqrt(np.mean(a * a))) if a.size else float("nan")


def _axis_stats(a: np.ndarray) -> Dict[str, float]:
    nan = float("nan")
    if not a.size:
        return {"rmse": nan, "mean": nan, "std": nan, "max": nan, "n": 0}
    return {"rmse": float(math.sqrt(np.mean(a * a))), "mean": float(np.mean(a)),
            "std": float(np.std(a, ddof=1)) if a.size > 1 else nan, "max": float(np.max(np.abs(a))),
            "n": int(a.size)}


def residual_stats(dx: Any = None, dy: Any = None, dz: Any = None) -> Dict[str, Any]:
    """Statistics of check-point residuals (metres; any of the three may be None or hold NaN for missing).

    Returns a dict with
      ``rmse_x, rmse_y, rmse_z``  per-axis RMSE;
      ``rmse_r``   horizontal radial RMSE = sqrt(rmse_x^2 + rmse_y^2) (ASPRS Edition 2: RMSE_H);
      ``rmse_xyz`` sqrt(rmse_x^2 + rmse_y^2 + rmse_z^2) (Edition 2: RMSE_3D; NaN if an axis is missing);
      ``mean``     {"x", "y", "z"}: mean error per axis (the bias; ASPRS asks |mean| < 25 % of the target
                   RMSE);
      ``std``      {"x", "y", "z"}: sample standard deviation per axis (n - 1);
      ``max``      {"x", "y", "z"}: largest absolute error per axis, "r": largest horizontal radial error,
                   "xyz": largest 3-D error (points with all three components);
      ``n``        number of points with at least one finite residual; ``n_x, n_y, n_z, n_r`` per component
                   (``n_r``: points with both dx and dy).
    Also flat copies ``mean_x`` ... ``max_z`` for convenience.
    """
    cols = [np.asarray(v if v is not None else [], dtype=float).ravel() for v in (dx, dy, dz)]
    n_pts = max(len(c) for c in cols)
    if n_pts == 0:
        cols = [np.zeros(0)] * 3
    full = []
    for c in cols:
        if len(c) not in (0, n_pts):
            raise ValueError("dx, dy and dz must have the same length")
        full.append(c if len(c) else np.full(n_pts, np.nan))
    x, y, z = full
    per = {k: _axis_stats(v[np.isfinite(v)]) for k, v in zip("xyz", full)}
    hmask = np.isfinite(x) & np.isfinite(y)
    radial = np.hypot(x[hmask], y[hmask])
    m3 = hmask & np.isfinite(z)
    d3 = np.sqrt(x[m3] ** 2 + y[m3] ** 2 + z[m3] ** 2)
    rx, ry, rz = per["x"]["rmse"], per["y"]["rmse"], per["z"]["rmse"]
    out: Dict[str, Any] = {
        "rmse_x": rx, "rmse_y": ry, "rmse_z": rz,
        "rmse_r": float(math.hypot(rx, ry)) if per["x"]["n"] and per["y"]["n"] else float("nan"),
        "rmse_xyz": float(math.sqrt(rx * rx + ry * ry + rz * rz))
        if per["x"]["n"] and per["y"]["n"] and per["z"]["n"] else float("nan"),
        "mean": {k: per[k]["mean"] for k in "xyz"},
        "std": {k: per[k]["std"] for k in "xyz"},
        "max": {**{k: per[k]["max"] for k in "xyz"},
                "r": float(radial.max()) if radial.size else float("nan"),
                "xyz": float(d3.max()) if d3.size else float("nan")},
        "n": int(np.sum(np.isfinite(x) | np.isfinite(y) | np.isfinite(z))),
        "n_x": per["x"]["n"], "n_y": per["y"]["n"], "n_z": per["z"]["n"], "n_r": int(hmask.sum()),
    }
    for k in "xyz":
        out[f"mean_{k}"] = per[k]["mean"]
        out[f"std_{k}"] = per[k]["std"]
        out[f"max_{k}"] = per[k]["max"]
    return out


# --------------------------------------------------------------------------------------------------
# NSSDA
# --------------------------------------------------------------------------------------------------

def _norm_cdf_two_sided(r: float, s: float) -> float:
    return math.erf(r / (math.sqrt(2.0) * s))


def circular_error(sigma_x: float, sigma_y: float, p: float = 0.95) -> float:
    """Exact radius holding probability ``p`` of a bivariate normal error with independent zero-mean x and
    y components of standard deviations ``sigma_x`` and ``sigma_y`` (a circular error probable, CEP_p).

    Equal sigmas give sigma * sqrt(-2 ln(1 - p)) (2.4477 sigma at 95 %); one sigma zero gives the
    one-dimensional two-sided quantile (1.9600 sigma at 95 %).  Computed by integrating the density in polar
    coordinates (P(R <= r) = 1/(2 pi sx sy) * integral over theta of (1 - exp(-r^2 a / 2)) / a,
    a = cos^2/sx^2 + sin^2/sy^2) and bisecting on r.
    """
    sx, sy = abs(float(sigma_x)), abs(float(sigma_y))
    if not (0.0 < p < 1.0):
        raise ValueError("p must lie strictly between 0 and 1")
    if not (math.isfinite(sx) and math.isfinite(sy)):
        return float("nan")
    smax, smin = max(sx, sy), min(sx, sy)
    if smax == 0.0:
        return 0.0
    hi = smax * math.sqrt(-2.0 * math.log(1.0 - p))  # the circular case with both sigmas = smax bounds it
    lo = 0.0
    ratio = smin / smax
    if ratio < 1e-4:  # effectively one-dimensional (relative error ~ ratio^2)
        def prob(r: float) -> float:
            return _norm_cdf_two_sided(r, smax)
    else:
        n = int(min(200_000, max(4096, 50.0 / ratio)))
        th = (np.arange(n) + 0.5) * (2.0 * math.pi / n)
        a = np.cos(th) ** 2 / sx ** 2 + np.sin(th) ** 2 / sy ** 2

        def prob(r: float) -> float:
            return float(np.mean(-np.expm1(-0.5 * r * r * a) / a) / (sx * sy))
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if prob(mid) < p:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-12 * smax:
            break
    return 0.5 * (lo + hi)


def nssda_horizontal_report(rmse_x: float, rmse_y: float) -> Dict[str, Any]:
    """NSSDA horizontal accuracy at 95 % with the method used (see the module docstring).

    Returns {"accuracy": metres, "method": "case1" | "case2" | "exact", "ratio": RMSE_min / RMSE_max,
    "rmse_r": metres, "note": text}.
    """
    rx, ry = abs(float(rmse_x)), abs(float(rmse_y))
    rr = math.hypot(rx, ry)
    hi, lo = max(rx, ry), min(rx, ry)
    ratio = lo / hi if hi > 0 else 1.0
    if not (math.isfinite(rx) and math.isfinite(ry)):
        return {"accuracy": float("nan"), "method": "none", "ratio": float("nan"), "rmse_r": float("nan"),
                "note": "RMSE_x or RMSE_y missing"}
    if math.isclose(rx, ry, rel_tol=1e-9, abs_tol=0.0) or hi == 0.0:
        return {"accuracy": NSSDA_HORIZONTAL_FACTOR * rr, "method": "case1", "ratio": ratio, "rmse_r": rr,
                "note": "NSSDA case 1 (RMSE_x = RMSE_y): 1.7308 x RMSE_r"}
    if ratio >= NSSDA_MIN_RATIO:
        return {"accuracy": NSSDA_CIRCULAR_95 * 0.5 * (rx + ry), "method": "case2", "ratio": ratio,
                "rmse_r": rr, "note": "NSSDA case 2 (RMSE_min/RMSE_max between 0.6 and 1.0): "
                                      "2.4477 x 0.5 x (RMSE_x + RMSE_y)"}
    return {"accuracy": circular_error(rx, ry, 0.95), "method": "exact", "ratio": ratio, "rmse_r": rr,
            "note": (f"RMSE_min/RMSE_max = {ratio:.2f} < 0.6, outside the NSSDA approximation: exact 95 % "
                     "circular error of the bivariate normal distribution")}


def nssda_horizontal(rmse_x: float, rmse_y: float) -> float:
    """NSSDA horizontal accuracy at the 95 % confidence level (same unit as the inputs)."""
    return nssda_horizontal_report(rmse_x, rmse_y)["accuracy"]


def nssda_vertical(rmse_z: float) -> float:
    """NSSDA vertical accuracy at the 95 % confidence level: 1.9600 x RMSE_z."""
    return NSSDA_VERTICAL_FACTOR * abs(float(rmse_z))


def nssda_statement(value: float, component: str = "horizontal", *, tested: bool = True,
                    units: str = "meters", decimals: int = 3) -> str:
    """One NSSDA accuracy sentence, e.g. "Tested 0.052 meters horizontal accuracy at 95% confidence level".

    ``component``: "horizontal" or "vertical"; ``tested=False`` gives the "Compiled to meet" form (data not
    tested, produced by a procedure known to reach the value); ``units``: "meters" or "feet" (the value is
    written as given: convert it yourself).
    """
    if component not in ("horizontal", "vertical"):
        raise ValueError("component must be 'horizontal' or 'vertical'")
    if units not in ("meters", "feet"):
        raise ValueError("units must be 'meters' or 'feet'")
    lead = "Tested" if tested else "Compiled to meet"
    return f"{lead} {float(value):.{decimals}f} {units} {component} accuracy at 95% confidence level"


# --------------------------------------------------------------------------------------------------
# ASPRS
# --------------------------------------------------------------------------------------------------

def _class_for(value_cm: float, classes: Optional[Iterable[float]], step_cm: float) -> float:
    """Smallest class >= value: from ``classes`` if given, else ``value`` rounded up to a multiple of
    ``step_cm`` (at least one step)."""
    if not math.isfinite(value_cm):
        raise ValueError("RMSE is not a finite number")
    tol = 1e-9 * max(1.0, value_cm)
    if classes is not None:
        cands = sorted(float(c) for c in classes)
        for c in cands:
            if c >= value_cm - tol:
                return c
        top = f"{cands[-1]} cm" if cands else "none"
        raise ValueError(f"RMSE {value_cm:.2f} cm exceeds the largest class given ({top})")
    if not step_cm > 0:
        raise ValueError("step_cm must be positive")
    k = max(1, math.ceil(value_cm / step_cm - 1e-9))
    return round(k * step_cm, 6)


def asprs_horizontal_class_limits(class_cm: float) -> Dict[str, float]:
    """ASPRS 2014 Table 7.1 limits of an X-cm horizontal accuracy class, in cm: RMSE_x and RMSE_y <= X,
    RMSE_r <= sqrt(2) X, mosaic seamline mismatch <= 2 X, horizontal accuracy at 95 % <= 2.4477 X."""
    x = float(class_cm)
    return {"rmse_x_cm": x, "rmse_y_cm": x, "rmse_r_cm": math.sqrt(2.0) * x,
            "accuracy_95_cm": NSSDA_CIRCULAR_95 * x, "seamline_mismatch_cm": 2.0 * x}


def asprs_vertical_class_limits(class_cm: float) -> Dict[str, float]:
    """ASPRS 2014 Table 7.3 limits of an X-cm vertical accuracy class, in cm."""
    x = float(class_cm)
    return {"rmse_z_cm": x, "nva_95_cm": NSSDA_VERTICAL_FACTOR * x, "vva_95th_percentile_cm": 3.0 * x,
            "within_swath_max_diff_cm": 0.60 * x, "swath_to_swath_rmsdz_cm": 0.80 * x,
            "swath_to_swath_max_diff_cm": 1.60 * x}


def _pixel_use(pixels: float) -> str:
    if pixels <= 1.0 + 1e-6:
        return "highest accuracy work"
    if pixels <= 2.0 + 1e-6:
        return "standard mapping and GIS work"
    return "visualization and less accurate work"


def _cm(v: float) -> str:
    return f"{v:.1f}"


def _edition(edition: Any) -> int:
    e = int(edition)
    if e not in (2014, 2023):
        raise ValueError("edition must be 2014 (Edition 1) or 2023 (Edition 2)")
    return e


def asprs_horizontal_class(rmse_x: float, rmse_y: float, gsd: Optional[float] = None, *,
                           classes: Optional[Sequence[float]] = None, step_cm: float = 1.0,
                           edition: int = 2014, checkpoint_rmse_h: float = 0.0) -> Dict[str, Any]:
    """ASPRS horizontal accuracy class of a product from its check-point RMSEs (metres).

    Edition 1 (``edition=2014``, default): the class X is the smallest class >= max(RMSE_x, RMSE_y).
    Edition 2 (``edition=2023``): the smallest class >= RMSE_H, where RMSE_H = sqrt(RMSE_x^2 + RMSE_y^2)
    combined in quadrature with ``checkpoint_rmse_h`` (the check points' own horizontal survey RMSE, metres).
    Classes are open-ended in both editions: the class is taken from ``classes`` (cm) if given, else the RMSE
    is rounded up to a multiple of ``step_cm`` (default whole centimetres: 3.2 cm -> a 4-cm class).
    ``gsd``: ground sample distance (metres) to relate the class to the pixel size as Edition 1 Table B.5 does
    (1 pixel "highest accuracy work", 2 pixels "standard mapping and GIS work", more "visualization and less
    accurate work").

    Returns a dict (lengths in cm): edition, class_cm, rmse_x_cm, rmse_y_cm, rmse_r_cm, rmse_h_cm (Edition 2,
    with check-point error), accuracy_95_cm (Edition 1: NSSDA value of the actual RMSEs; None in Edition 2),
    nssda_method, class_limits (Table 7.1), gsd_cm, rmse_pixels (max(RMSE_x, RMSE_y) / GSD), class_pixels,
    recommended_use, statement ("tested to meet") and statement_produced ("produced to meet").
    """
    ed = _edition(edition)
    rx, ry = abs(float(rmse_x)) * 100.0, abs(float(rmse_y)) * 100.0
    rr = math.hypot(rx, ry)
    rh = math.hypot(rr, abs(float(checkpoint_rmse_h)) * 100.0)
    metric = max(rx, ry) if ed == 2014 else rh
    cls = _class_for(metric, classes, step_cm)
    nssda = nssda_horizontal_report(rx, ry)
    out: Dict[str, Any] = {
        "edition": ed, "class_cm": cls, "rmse_x_cm": rx, "rmse_y_cm": ry, "rmse_r_cm": rr,
        "rmse_h_cm": rh if ed == 2023 else rr,
        "accuracy_95_cm": nssda["accuracy"] if ed == 2014 else None,
        "nssda_method": nssda["method"] if ed == 2014 else None,
        "class_limits": asprs_horizontal_class_limits(cls) if ed == 2014
        else {"rmse_h_cm": cls, "seamline_mismatch_cm": 2.0 * cls},
        "gsd_cm": None, "rmse_pixels": None, "class_pixels": None, "recommended_use": None,
    }
    if gsd is not None and float(gsd) > 0:
        g = float(gsd) * 100.0
        out.update(gsd_cm=g, rmse_pixels=max(rx, ry) / g, class_pixels=cls / g,
                   recommended_use=_pixel_use(cls / g))
    if ed == 2014:
        acc = _cm(nssda["accuracy"])
        out["statement"] = (
            f"This data set was tested to meet {ASPRS_2014} for a {_cm(cls)} (cm) RMSEx / RMSEy Horizontal "
            f"Accuracy Class. Actual positional accuracy was found to be RMSEx = {_cm(rx)} cm and RMSEy = "
            f"{_cm(ry)} cm which equates to Positional Horizontal Accuracy = +/- {acc} cm at 95% confidence "
            f"level.")
        out["statement_produced"] = (
            f"This data set was produced to meet {ASPRS_2014} for a {_cm(cls)} (cm) RMSEx / RMSEy Horizontal "
            f"Accuracy Class which equates to Positional Horizontal Accuracy = +/- "
            f"{_cm(out['class_limits']['accuracy_95_cm'])} cm at a 95% confidence level.")
    else:
        out["statement"] = (
            f"This data set was tested to meet {ASPRS_2023} for a {_cm(cls)} (cm) RMSEH Horizontal "
            f"Positional Accuracy Class. The tested horizontal positional accuracy was found to be "
            f"RMSEH = {_cm(rh)} (cm).")
        out["statement_produced"] = (
            f"This data set was produced to meet {ASPRS_2023} for a {_cm(cls)} (cm) RMSEH Horizontal "
            f"Positional Accuracy Class.")
    return out


def vva_95th_percentile(dz: Any) -> float:
    """Edition 1 Vegetated Vertical Accuracy: 95th percentile of the absolute vertical errors in vegetated
    terrain (linear interpolation between order statistics, as a spreadsheet's PERCENTILE does)."""
    a = np.abs(_finite(dz))
    return float(np.percentile(a, 95.0)) if a.size else float("nan")


def asprs_vertical_class(rmse_z: float, *, classes: Optional[Sequence[float]] = None, step_cm: float = 1.0,
                         edition: int = 2014, vva: Optional[float] = None,
                         checkpoint_rmse_v: float = 0.0) -> Dict[str, Any]:
    """ASPRS vertical accuracy class from the non-vegetated check-point RMSE_z (metres).

    Edition 1 (2014): class X = smallest class >= RMSE_z; NVA = 1.96 x RMSE_z at 95 % confidence; ``vva``
    (optional, metres) is the 95th percentile of absolute errors in vegetated terrain
    (``vva_95th_percentile``), reported and compared with the 3.00 X limit.
    Edition 2 (2023): RMSE_V = sqrt(RMSE_z^2 + checkpoint_rmse_v^2) sets the class; no 95 % figures; ``vva``
    is the vegetated RMSE_V, reported as found (no pass/fail).
    Class selection as in ``asprs_horizontal_class``.  Returns a dict (cm): edition, class_cm, rmse_z_cm,
    rmse_v_cm, nva_95_cm (Edition 1), vva_cm, vva_within_class (Edition 1, or None), class_limits, statement,
    statement_produced.
    """
    ed = _edition(edition)
    rz = abs(float(rmse_z)) * 100.0
    rv = math.hypot(rz, abs(float(checkpoint_rmse_v)) * 100.0)
    cls = _class_for(rz if ed == 2014 else rv, classes, step_cm)
    vva_cm = None if vva is None else abs(float(vva)) * 100.0
    limits = asprs_vertical_class_limits(cls) if ed == 2014 else {"rmse_v_cm": cls}
    out: Dict[str, Any] = {
        "edition": ed, "class_cm": cls, "rmse_z_cm": rz, "rmse_v_cm": rv if ed == 2023 else rz,
        "nva_95_cm": NSSDA_VERTICAL_FACTOR * rz if ed == 2014 else None,
        "vva_cm": vva_cm,
        "vva_within_class": (vva_cm <= limits["vva_95th_percentile_cm"] + 1e-9)
        if (ed == 2014 and vva_cm is not None) else None,
        "class_limits": limits,
    }
    if ed == 2014:
        s = (f"This data set was tested to meet {ASPRS_2014} for a {_cm(cls)} (cm) RMSEz Vertical Accuracy "
             f"Class. Actual NVA accuracy was found to be RMSEz = {_cm(rz)} cm, equating to "
             f"+/- {_cm(out['nva_95_cm'])} cm at 95% confidence level.")
        if vva_cm is not None:
            s += f" Actual VVA accuracy was found to be +/- {_cm(vva_cm)} cm at the 95th percentile."
        out["statement"] = s
        out["statement_produced"] = (
            f"This data set was produced to meet {ASPRS_2014} for a {_cm(cls)} (cm) RMSEz Vertical Accuracy "
            f"Class equating to NVA = +/- {_cm(limits['nva_95_cm'])} cm at 95% confidence level and "
            f"VVA = +/- {_cm(limits['vva_95th_percentile_cm'])} cm at the 95th percentile.")
    else:
        s = (f"This data set was tested to meet {ASPRS_2023} for a {_cm(cls)} (cm) RMSEV Vertical Accuracy "
             f"Class. NVA accuracy was found to be RMSEV = {_cm(rv)} (cm).")
        if vva_cm is not None:
            s += f" VVA accuracy was found to be RMSEV = {_cm(vva_cm)} (cm)."
        out["statement"] = s
        out["statement_produced"] = (
            f"This data set was produced to meet {ASPRS_2023} for a {_cm(cls)} (cm) RMSEV Vertical Accuracy "
            f"Class.")
    return out


__all__ = [
    "ASPRS_2014", "ASPRS_2023", "NSSDA_CIRCULAR_95", "NSSDA_HORIZONTAL_FACTOR", "NSSDA_MIN_RATIO",
    "NSSDA_TEMPLATES", "NSSDA_VERTICAL_FACTOR", "asprs_horizontal_class", "asprs_horizontal_class_limits",
    "asprs_vertical_class",
    "asprs_vertical_class_limits", "circular_error", "nssda_horizontal", "nssda_horizontal_report",
    "nssda_statement", "nssda_vertical", "residual_stats", "rmse", "vva_95th_percentile",
]
