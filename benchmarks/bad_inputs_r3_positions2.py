"""Issue 47, group "positions2" (items 2 and 17 on the automatic control's path; issue 49: one place reads and
checks control): Georeference with a reference orthophoto and DSM (the demo's own orthomosaic and DSM) and camera
positions or GCPs beside it, whose numbers are valid but whose meaning is not (latitude in the x column, the next
UTM zone) or that hold a photo twice.  The automatic control reads them through the georeference stage's reader
(``core.georef.control_checks.read_checked_control``), so it refuses and warns as Georeference without a
reference does; run through ``qgis_process`` by ``benchmarks/bad_inputs_r3.py``."""
import os

from bad_inputs import Spec, case
from bad_inputs_r3_positions import _duplicated, _latlon_swapped, _model_gcps, _placed_near_gps


def _automatic(ws, **params):
    """Georeference with the automatic control: the demo's orthomosaic and DSM as the reference pair."""
    return ("georeference", dict({"WORKSPACE": ws, "REFERENCE_ORTHO": os.path.join(ws, "orthomosaic.tif"),
                                  "REFERENCE_DSM": os.path.join(ws, "dsm.tif")}, **params))


@case(2, "automatic control (reference ortho + DSM) with camera positions in EPSG:4326, latitude in the x column",
      r"camera positions in \S+ \(EPSG:4326\) land .* latitude and longitude look swapped")
def auto_positions_latlon_swapped(ws, tmp):
    p = _latlon_swapped(ws, tmp)
    return Spec([_automatic(ws, CAMERA_POSITIONS=p)], protected=[p], check=_placed_near_gps)


@case(2, "automatic control (reference ortho + DSM) with GCPs of zone 17N labelled EPSG:32618 (the next zone)",
      r"control points of the GCP file \S+ \(EPSG:32618\) land .*EPSG:32617")
def auto_gcps_wrong_zone(ws, tmp):
    p = _model_gcps(ws, tmp, crs_line="EPSG:32618")

    def check(out, _tmp):  # the points become check points: 900 km off they spoil the check figures unsaid
        res = out.get("results", {})
        rms = float(res.get("CHECK_RMSE_XY") or "nan")
        return rms < 1.0, f"exit 0: check points RMSE XY {rms:,.1f} m"
    return Spec([_automatic(ws, GCPS=p)], protected=[p], check=check)


@case(17, "automatic control (reference ortho + DSM) with a photo's camera position twice (the same values)")
def auto_positions_duplicate_same(ws, tmp):
    first, p = _duplicated(ws, tmp, 0.0)

    def check(out, _tmp):
        ok, note = _placed_near_gps(out, _tmp)
        warned = any(first in ln and "line" in ln for ln in out.get("text", "").splitlines())
        return ok and warned, f"{note}; duplicate {'named' if warned else 'not named'} in the log"
    return Spec([_automatic(ws, CAMERA_POSITIONS=p)], protected=[p], check=check)
