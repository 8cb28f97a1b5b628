"""Accuracy statistics and standards (core/accuracy.py).

Expected values are written out as numbers from the standards' text and tables or worked by hand, never
recomputed here with the module's own formulas.
"""
import math

import numpy as np
import pytest

from core.georef.accuracy import (
    NSSDA_TEMPLATES,
    asprs_horizontal_class,
    asprs_horizontal_class_limits,
    asprs_vertical_class,
    asprs_vertical_class_limits,
    circular_error,
    nssda_horizontal,
    nssda_horizontal_report,
    nssda_statement,
    nssda_vertical,
    residual_stats,
    rmse,
    vva_95th_percentile,
)

A14 = "ASPRS Positional Accuracy Standards for Digital Geospatial Data (2014)"


def test_rmse():
    assert rmse([3.0, 4.0]) == pytest.approx(3.5355339, abs=1e-7)
    assert rmse([3.0, np.nan, 4.0, np.inf]) == pytest.approx(3.5355339, abs=1e-7)  # missing values skipped
    assert rmse([-2.0]) == 2.0
    assert math.isnan(rmse([])) and math.isnan(rmse(None))


def test_residual_stats_worked_example():
    s = residual_stats([0.1, -0.2, 0.3], [0.0, 0.1, -0.1], [0.05, -0.05, np.nan])
    assert s["rmse_x"] == pytest.approx(0.2160247, abs=1e-7)
    assert s["rmse_y"] == pytest.approx(0.0816497, abs=1e-7)
    assert s["rmse_z"] == pytest.approx(0.05, abs=1e-12)
    assert s["rmse_r"] == pytest.approx(0.2309401, abs=1e-7)
    assert s["rmse_xyz"] == pytest.approx(0.2362908, abs=1e-7)
    assert s["mean"] == pytest.approx({"x": 0.0666667, "y": 0.0, "z": 0.0}, abs=1e-7)
    assert s["mean_x"] == s["mean"]["x"]
    assert s["std"]["x"] == pytest.approx(0.2516611, abs=1e-7)  # sample std, n - 1
    assert s["max"]["x"] == pytest.approx(0.3) and s["max"]["y"] == pytest.approx(0.1)
    assert s["max"]["r"] == pytest.approx(0.3162278, abs=1e-7)
    assert s["max"]["xyz"] == pytest.approx(0.2291288, abs=1e-7)  # only points with all three components
    assert (s["n"], s["n_x"], s["n_y"], s["n_z"], s["n_r"]) == (3, 3, 3, 2, 3)


def test_residual_stats_partial_inputs():
    s = residual_stats(dz=[0.1, -0.1])
    assert s["rmse_z"] == pytest.approx(0.1) and s["n"] == 2
    assert math.isnan(s["rmse_x"]) and math.isnan(s["rmse_r"]) and math.isnan(s["rmse_xyz"])
    s = residual_stats()
    assert s["n"] == 0 and math.isnan(s["rmse_x"])
    with pytest.raises(ValueError):
        residual_stats([1.0, 2.0], [1.0])


# ------------------------------------------------------------------ NSSDA

def test_nssda_case1_equal_rmse():
    # FGDC-STD-007.3-1998 Appendix 3-A, case 1: RMSE_x = RMSE_y = 1.0 -> RMSE_r = 1.4142,
    # Accuracy_r = 1.7308 x 1.4142 = 2.4477
    r = nssda_horizontal_report(1.0, 1.0)
    assert r["method"] == "case1" and r["rmse_r"] == pytest.approx(1.41421, abs=1e-5)
    assert r["accuracy"] == pytest.approx(2.4477, abs=2e-4)
    assert nssda_horizontal(0.05, 0.05) == pytest.approx(0.12239, abs=1e-4)


def test_nssda_case2_elliptical():
    # case 2: RMSE_min/RMSE_max between 0.6 and 1.0 -> 2.4477 x 0.5 x (RMSE_x + RMSE_y)
    r = nssda_horizontal_report(1.0, 0.8)
    assert r["method"] == "case2" and r["ratio"] == pytest.approx(0.8)
    assert r["accuracy"] == pytest.approx(2.20293, abs=1e-5)
    assert nssda_horizontal(0.6, 1.0) == pytest.approx(1.95816, abs=1e-5)  # ratio exactly 0.6 still case 2
    assert nssda_horizontal(0.03, 0.04) == pytest.approx(0.0856695, abs=1e-7)


def test_nssda_ratio_below_06_uses_exact_circular_error():
    r = nssda_horizontal_report(1.0, 0.5)
    assert r["method"] == "exact" and "0.6" in r["note"]
    assert r["accuracy"] == pytest.approx(2.0359, abs=5e-4)
    # the NSSDA approximation would have understated it (2.4477 x 0.75 = 1.8358)
    assert r["accuracy"] > 1.9


def test_circular_error_limits_and_monte_carlo():
    assert circular_error(1.0, 1.0) == pytest.approx(2.447747, abs=1e-5)  # sqrt(-2 ln 0.05)
    assert circular_error(2.0, 0.0) == pytest.approx(2 * 1.959964, abs=1e-5)  # one-dimensional 95 %
    assert circular_error(1.0, 1.0, 0.5) == pytest.approx(1.177410, abs=1e-5)  # CEP50 = sqrt(2 ln 2)
    assert circular_error(1.0, 1e-6) == pytest.approx(1.959964, abs=1e-5)
    assert circular_error(0.0, 0.0) == 0.0
    rng = np.random.default_rng(42)
    for sx, sy in ((1.0, 0.5), (0.3, 1.0), (1.0, 0.1)):
        r = np.hypot(rng.normal(0, sx, 1_000_000), rng.normal(0, sy, 1_000_000))
        assert circular_error(sx, sy) == pytest.approx(np.quantile(r, 0.95), rel=4e-3)


def test_nssda_vertical():
    assert nssda_vertical(1.0) == pytest.approx(1.96)
    assert nssda_vertical(0.10) == pytest.approx(0.196)


def test_nssda_statements():
    assert nssda_statement(0.0523) == "Tested 0.052 meters horizontal accuracy at 95% confidence level"
    assert nssda_statement(0.196, "vertical", decimals=2) == \
        "Tested 0.20 meters vertical accuracy at 95% confidence level"
    assert nssda_statement(1.5, tested=False, units="feet", decimals=1) == \
        "Compiled to meet 1.5 feet horizontal accuracy at 95% confidence level"
    assert NSSDA_TEMPLATES["tested_horizontal"] == \
        "Tested ____ (meters, feet) horizontal accuracy at 95% confidence level"
    with pytest.raises(ValueError):
        nssda_statement(1.0, "diagonal")


# ------------------------------------------------------------------ ASPRS 2014

@pytest.mark.parametrize("cls,rmse_r,acc95,seam", [
    # ASPRS 2014 Table B.5 (orthoimagery; 1.25 cm and 7.5 cm pixels, 1 / 2 / 3 pixel classes)
    (1.25, 1.8, 3.1, 2.5),
    (7.5, 10.6, 18.4, 15.0),
    (15.0, 21.2, 36.7, 30.0),
    (22.5, 31.8, 55.1, 45.0),
])
def test_asprs_horizontal_class_limits_table(cls, rmse_r, acc95, seam):
    lim = asprs_horizontal_class_limits(cls)
    assert round(lim["rmse_r_cm"], 1) == rmse_r
    assert round(lim["accuracy_95_cm"], 1) == acc95
    assert round(lim["seamline_mismatch_cm"], 1) == seam


def test_asprs_horizontal_7_5_cm_class():
    r = asprs_horizontal_class(0.075, 0.075, gsd=0.075, step_cm=0.5)
    assert r["class_cm"] == 7.5
    assert round(r["rmse_r_cm"], 1) == 10.6 and round(r["accuracy_95_cm"], 1) == 18.4
    assert r["class_pixels"] == pytest.approx(1.0) and r["recommended_use"] == "highest accuracy work"
    assert r["statement"] == (
        f"This data set was tested to meet {A14} "
        "for a 7.5 (cm) RMSEx / RMSEy Horizontal Accuracy Class. Actual positional accuracy was found to be "
        "RMSEx = 7.5 cm and RMSEy = 7.5 cm which equates to Positional Horizontal Accuracy = +/- 18.4 cm "
        "at 95% confidence level.")
    assert r["statement_produced"] == (
        f"This data set was produced to meet {A14} "
        "for a 7.5 (cm) RMSEx / RMSEy Horizontal Accuracy Class which equates to Positional Horizontal "
        "Accuracy = +/- 18.4 cm at a 95% confidence level.")


def test_asprs_horizontal_rounds_up_and_relates_to_gsd():
    r = asprs_horizontal_class(0.032, 0.021, gsd=0.02)
    assert r["class_cm"] == 4.0  # max(3.2, 2.1) rounded up to the next whole cm
    assert r["rmse_pixels"] == pytest.approx(1.6) and r["class_pixels"] == pytest.approx(2.0)
    assert r["recommended_use"] == "standard mapping and GIS work"
    assert r["nssda_method"] == "case2" and r["accuracy_95_cm"] == pytest.approx(6.4864, abs=1e-3)
    assert "+/- 6.5 cm at 95% confidence level" in r["statement"]
    r = asprs_horizontal_class(0.07, 0.02, gsd=0.02)
    assert r["recommended_use"] == "visualization and less accurate work"
    assert asprs_horizontal_class(0.07, 0.07)["class_cm"] == 7.0  # exact values are not bumped up
    assert asprs_horizontal_class(0.001, 0.0)["class_cm"] == 1.0
    assert asprs_horizontal_class(0.051, 0.02, classes=[2.5, 5.0, 7.5, 10.0])["class_cm"] == 7.5
    with pytest.raises(ValueError):
        asprs_horizontal_class(0.2, 0.2, classes=[2.5, 5.0])


@pytest.mark.parametrize("cls,nva,vva", [
    # ASPRS 2014 vertical classes (Table 7.3 factors; examples of Table B.7)
    (1.0, 2.0, 3.0),
    (2.5, 4.9, 7.5),
    (5.0, 9.8, 15.0),
    (10.0, 19.6, 30.0),
    (20.0, 39.2, 60.0),
    (15.0, 29.4, 45.0),
])
def test_asprs_vertical_class_limits_table(cls, nva, vva):
    lim = asprs_vertical_class_limits(cls)
    assert round(lim["nva_95_cm"], 1) == nva and round(lim["vva_95th_percentile_cm"], 1) == vva


def test_asprs_vertical_10_cm_class():
    r = asprs_vertical_class(0.10, vva=0.25)
    assert r["class_cm"] == 10.0 and r["nva_95_cm"] == pytest.approx(19.6)
    lim = r["class_limits"]
    assert lim["within_swath_max_diff_cm"] == pytest.approx(6.0)
    assert lim["swath_to_swath_rmsdz_cm"] == pytest.approx(8.0)
    assert lim["swath_to_swath_max_diff_cm"] == pytest.approx(16.0)
    assert r["vva_within_class"] is True  # 25 cm <= 30 cm
    assert r["statement"] == (
        f"This data set was tested to meet {A14} "
        "for a 10.0 (cm) RMSEz Vertical Accuracy Class. Actual NVA accuracy was found to be RMSEz = 10.0 cm, "
        "equating to +/- 19.6 cm at 95% confidence level. Actual VVA accuracy was found to be +/- 25.0 cm "
        "at the 95th percentile.")
    assert r["statement_produced"] == (
        f"This data set was produced to meet {A14} "
        "for a 10.0 (cm) RMSEz Vertical Accuracy Class equating to NVA = +/- 19.6 cm at 95% confidence "
        "level and VVA = +/- 30.0 cm at the 95th percentile.")
    assert asprs_vertical_class(0.083)["class_cm"] == 9.0
    assert asprs_vertical_class(0.10, vva=0.31)["vva_within_class"] is False


def test_vva_95th_percentile():
    # 95th percentile of 1..20 cm with linear interpolation (spreadsheet PERCENTILE): 19.05
    dz = np.arange(1, 21) / 100.0 * np.where(np.arange(20) % 2, 1, -1)
    assert vva_95th_percentile(dz) == pytest.approx(0.1905, abs=1e-9)


# ------------------------------------------------------------------ ASPRS Edition 2 (2023)

def test_asprs_edition2_adds_checkpoint_error_and_drops_95():
    # Edition 2 Table 7.4, first row: a 1.00 cm product RMSE with 2.0 cm check points is a 2.24 cm accuracy
    v = asprs_vertical_class(0.01, edition=2023, checkpoint_rmse_v=0.02)
    assert v["rmse_v_cm"] == pytest.approx(2.236, abs=1e-3) and v["class_cm"] == 3.0
    assert v["nva_95_cm"] is None and "95" not in v["statement"]
    assert v["statement"] == (
        "This data set was tested to meet ASPRS Positional Accuracy Standards for Digital Geospatial Data, "
        "Edition 2 (2023) for a 3.0 (cm) RMSEV Vertical Accuracy Class. NVA accuracy was found to be "
        "RMSEV = 2.2 (cm).")
    # the horizontal class is set by RMSE_H, not by the larger of RMSE_x and RMSE_y
    h = asprs_horizontal_class(0.03, 0.04, edition=2023)
    assert h["rmse_h_cm"] == pytest.approx(5.0) and h["class_cm"] == 5.0 and h["accuracy_95_cm"] is None
    assert asprs_horizontal_class(0.03, 0.04, edition=2014)["class_cm"] == 4.0
    h = asprs_horizontal_class(0.03, 0.04, edition=2023, checkpoint_rmse_h=0.012)
    assert h["rmse_h_cm"] == pytest.approx(5.142, abs=1e-3) and h["class_cm"] == 6.0
    assert "RMSEH Horizontal Positional Accuracy Class" in h["statement"]
    with pytest.raises(ValueError):
        asprs_horizontal_class(0.03, 0.04, edition=2020)
