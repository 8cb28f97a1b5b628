"""DEM control (issue 32 item 4): a reference DEM fed back into the adjustment as control points.

A block georeferenced by camera positions (EXIF GPS, a positions file) or by a few control points can be tilted,
offset in height or domed in ways its photos cannot see.  With a reference DEM (``GeorefOptions.reference_dem``)
the georeference stage (``core.georef.stage``) then:

1. before the long work, places the aligned block by its control alone (the Helmert step, no adjustment) and checks
   that the reference covers it with enough cells (:func:`precheck`): a file that is missing, in degrees, all
   nodata, off the block or too coarse for it is refused by name here;
2. after the adjustment, co-registers the block's sparse points (world CRS of the workspace; the reference is read
   over the block, reprojected into that CRS, heights in feet converted: ``core.georef.coregister``) against the
   reference: Nuth & Kääb's shift with a tilt and a dome (:func:`coregister_block`);
3. turns the co-registration into DEM control points (:func:`dem_control`): up to ``reference_dem_points``
   well-spread sparse points on flat, stable terrain (``control_points_from_coregistration``) whose tracks' image
   observations become the observations of control points ``dem001``, ``dem002``... at the reference's position
   and height;
4. re-runs the adjustment with them added to the control (check points untouched): :func:`with_dem_control`.

Heights.  The reference's heights are in its vertical datum (orthometric for most national DEMs), GPS camera
positions are ellipsoidal or above mean sea level, surveyed control in its own datum.  One set of heights wins and
the log says which:

- with control points (3 or more with observations) whose mean height disagrees with the DEM's beyond 3 sigma (the
  control's residual RMS over sqrt(n), the DEM control's sigma Z over sqrt(n), the reference's stated accuracy):
  their heights win; the DEM control points' heights are moved by the co-registration's vertical offset ``dz``
  (the datum difference between the control and the DEM) and stay at the block's horizontal position (the DEM's
  own horizontal error is not the block's), so they add the block's shape only (the tilt and dome between the
  control points);
- with control points that agree with the DEM within that: both hold the heights, weighed by their sigmas (the DEM
  control points at the block's horizontal position and the DEM's heights): metre-level archive control does not
  hold the block's level against a good DEM;
- without, the reference DEM's heights win: the DEM control points sit at the shifted position and the reference's
  height, and the camera positions' heights are moved by ``dz`` (one constant: the datum difference and the GPS's
  bias), so that a geoid undulation of tens of metres does not make every camera an outlier; what remains between
  cameras and DEM (a tilt, a dome) is settled by their sigmas.

Sigmas.  sigma_z of a DEM control point is the co-registration's: hypot(NMAD after it, tan(slope) x sigma_xy,
``reference_dem_sigma_z``) (the reference's stated accuracy).  Its sigma_xy is the shift's (a quarter of the
reference's cell, or 3 standard errors; the cell where the terrain cannot fix the shift) times sqrt(n): the n
points share one shift, so together they fix the block's horizontal position as well as the shift is known, not
sqrt(n) times better.

The DEM control points' tracks stay in the adjustment as tie points too (their observations count twice: a few
dozen among thousands).
"""
from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import ArchaeoOrthoError
from ..common.progress import NullProgress, Progress
from ..io.gcp import CONTROL, CameraPosition, GCPSet, GroundPoint, Observation
from ..io.raster import RasterError, RasterFile, bilinear, check_heights_file
from .coregister import (
    DEM_MARGIN_CELLS,
    MIN_CELLS,
    OUTLIER_NMAD,
    CoregError,
    CoregOptions,
    CoregResult,
    HeightGrid,
    control_points_from_coregistration,
    coregister_points,
    nmad,
    reference_window,
    shorth,
)
from .errors import GeorefError
from .options import GeorefOptions

DEM_PREFIX = "dem"  # DEM control points are named dem001, dem002, ...
FORMAT = "archaeoortho-dem-control"
MAX_WINDOW_CELLS = 4_000_000  # the reference is averaged onto a coarser grid beyond this many cells under the block
HEIGHTS_CONTROL = "control points"
HEIGHTS_DEM = "reference DEM"
HEIGHTS_BOTH = "control points and reference DEM"


class DemControlError(GeorefError):
    """The reference DEM cannot control this block (too coarse, off the block); the message names the file."""


@dataclass
class DemControl:
    """The DEM control of one block: the co-registration, the control points made from it, and which heights won."""

    reference: str
    crs: str
    coregistration: CoregResult
    points: List[GroundPoint]
    heights: str  # HEIGHTS_CONTROL, HEIGHTS_BOTH or HEIGHTS_DEM
    level_sigma: float = math.nan  # the 3-sigma test's sigma of the control's and the DEM's mean heights (m)
    camera_dz: float = 0.0  # added to the camera positions' heights (HEIGHTS_DEM)
    cells: int = 0  # reference cells under the block's sparse points
    vertical_datum: str = ""
    messages: List[str] = field(default_factory=list)
    after: Optional[CoregResult] = None  # the co-registration of the block adjusted with the DEM control

    def as_dict(self) -> Dict[str, Any]:
        """What georef/dem_control.json holds."""
        return {"format": FORMAT, "version": 1, "reference_dem": self.reference, "crs": self.crs,
                "vertical_datum": self.vertical_datum, "heights": self.heights, "level_sigma": self.level_sigma,
                "camera_dz": self.camera_dz,
                "cells": self.cells, "n_points": len(self.points),
                "coregistration": self.coregistration.as_dict(),
                "after": self.after.as_dict() if self.after is not None else None,
                "points": [{"name": p.name, "x": p.x, "y": p.y, "z": p.z, "sigma_xy": p.sigma_xy,
                            "sigma_z": p.sigma_z, "n_obs": len(p.observations)} for p in self.points],
                "messages": list(self.messages)}


# ---------------------------------------------------------------------------
# the block's sparse points
# ---------------------------------------------------------------------------

def sparse_points(rec, offset: Sequence[float]) -> Tuple[np.ndarray, np.ndarray]:
    """(world xyz (N x 3), point3D ids (N,)) of a reconstruction in the local frame world - ``offset``."""
    ids = np.array(sorted(rec.points3D.keys()), dtype=np.int64)
    if ids.size == 0:
        return np.zeros((0, 3)), ids
    xyz = np.array([rec.points3D[int(i)].xyz for i in ids], dtype=float) + np.asarray(offset, dtype=float)[:3]
    return xyz, ids


def track_observations(rec, point_id: int) -> List[Observation]:
    """The image observations (stored pixel grid, COLMAP's convention, as GCP observations) of a sparse point."""
    out = []
    for el in rec.points3D[int(point_id)].track.elements:
        im = rec.images[el.image_id]
        xy = im.points2D[el.point2D_idx].xy
        out.append(Observation(im.name, float(xy[0]), float(xy[1])))
    return out


def block_points(xyz: np.ndarray) -> np.ndarray:
    """The rows of ``xyz`` that are the block: finite, and inside the box of the 1st to 99th percentiles grown by
    a quarter of its size on each side (a few stray points far off would make the reference window huge)."""
    ok = np.all(np.isfinite(xyz), axis=1)
    if ok.sum() < 10:
        return ok
    lo, hi = np.percentile(xyz[ok, :2], [1.0, 99.0], axis=0)
    grow = 0.25 * np.maximum(hi - lo, 1e-6)
    return ok & np.all((xyz[:, :2] >= lo - grow) & (xyz[:, :2] <= hi + grow), axis=1)


def _window(xyz: np.ndarray, ref_path: str, crs: str) -> Tuple[np.ndarray, Tuple[float, ...], List[str]]:
    """The reference over the points' box in ``crs`` (metres), averaged onto a coarser grid in the reference's own
    CRS first where the box holds more than MAX_WINDOW_CELLS of its cells (a 10 km archive block on a 1 m DEM)."""
    import tempfile

    lo, hi = xyz[:, :2].min(axis=0), xyz[:, :2].max(axis=0)
    with tempfile.TemporaryDirectory(prefix="archaeoortho-demcontrol-") as tmp:
        path, note = _coarsened(ref_path, lo, hi, crs, os.path.join(tmp, "reference.vrt"))
        try:
            arr, gt, messages = reference_window(path, lo[0], lo[1], hi[0], hi[1], crs=crs)
        except CoregError as e:  # named by the user's file, not the coarser copy
            raise CoregError(str(e).replace(path, ref_path)) from e
    return arr, gt, [m.replace(path, ref_path) for m in messages] + ([note] if note else [])


def _coarsened(ref_path: str, lo: np.ndarray, hi: np.ndarray, crs: str, out: str) -> Tuple[str, str]:
    """(``ref_path``, '') when the box holds at most MAX_WINDOW_CELLS of the reference's cells, else (a warped VRT
    ``out`` averaging the reference onto a grid k times coarser over the box, in its own CRS and units, a message)."""
    try:
        raster = RasterFile(os.path.abspath(ref_path), "reference DEM")
    except RasterError:
        return ref_path, ""  # reference_window names what is wrong with it
    with raster:
        return _coarsened_raster(raster, ref_path, lo, hi, crs, out)


def _coarsened_raster(raster: RasterFile, ref_path: str, lo: np.ndarray, hi: np.ndarray, crs: str, out: str
                      ) -> Tuple[str, str]:
    """:func:`_coarsened` on the open reference."""
    from osgeo import gdal

    from ..geometry.crs import transform_points

    wkt, gt = raster.crs_wkt, raster.geotransform
    if not wkt or gt is None:
        return ref_path, ""  # reference_window names what is wrong with it
    corners = np.array([[lo[0], lo[1], 0.0], [hi[0], lo[1], 0.0], [lo[0], hi[1], 0.0], [hi[0], hi[1], 0.0]])
    try:
        c = transform_points(corners, crs, wkt)
    except ArchaeoOrthoError:
        return ref_path, ""
    cell = abs(gt[1])
    cells = (np.ptp(c[:, 0]) / cell + 2 * DEM_MARGIN_CELLS) * (np.ptp(c[:, 1]) / abs(gt[5]) + 2 * DEM_MARGIN_CELLS)
    if cells <= MAX_WINDOW_CELLS:
        return ref_path, ""
    k = int(math.ceil(math.sqrt(cells / MAX_WINDOW_CELLS)))
    m = DEM_MARGIN_CELLS * cell * k
    band = raster.band(1)
    nodata = band.GetNoDataValue()
    bounds = (c[:, 0].min() - m, c[:, 1].min() - m, c[:, 0].max() + m, c[:, 1].max() + m)
    warped = gdal.Warp(out, raster.dataset, format="VRT", outputBounds=bounds,
                       xRes=cell * k, yRes=abs(gt[5]) * k, resampleAlg="average", outputType=gdal.GDT_Float32,
                       srcNodata=nodata, dstNodata=nodata if nodata is not None else -9999.0)
    if warped is None:  # read it whole as before
        return ref_path, ""
    warped.GetRasterBand(1).SetUnitType(band.GetUnitType() or "")
    warped = None
    return out, (f"the reference DEM {ref_path} is read averaged onto {k} x its cell ({cell * k:.3g} CRS units) over "
                 f"the block: {cells:,.0f} of its cells lie under it, more than {MAX_WINDOW_CELLS:,}")


def check_metric(crs: str, ref_path: str) -> None:
    """DemControlError unless the workspace's CRS is projected in metres (the co-registration's slopes and shifts)."""
    from osgeo import osr

    srs = osr.SpatialReference()
    try:
        srs.SetFromUserInput(crs)
    except RuntimeError as e:
        raise DemControlError(f"the target CRS {_short(crs)!r} is unknown: {e}") from e
    if srs.IsGeographic() or abs((srs.GetLinearUnits() or 1.0) - 1.0) > 1e-9:
        unit = "degrees" if srs.IsGeographic() else f"units of {srs.GetLinearUnits():g} m"
        raise DemControlError(f"DEM control with the reference DEM {ref_path} needs a target CRS in metres; "
                              f"{_short(crs)} is in {unit}: give a projected metric CRS (CRS), e.g. the UTM zone")


def cells_under(xyz: np.ndarray, ref: np.ndarray, gt: Sequence[float]) -> int:
    """How many reference cells with a height hold at least one of the points."""
    c = np.floor((xyz[:, 0] - gt[0]) / gt[1]).astype(np.int64)
    r = np.floor((xyz[:, 1] - gt[3]) / gt[5]).astype(np.int64)
    ok = (c >= 0) & (r >= 0) & (c < ref.shape[1]) & (r < ref.shape[0])
    c, r = c[ok], r[ok]
    ok = np.isfinite(ref[r, c])
    return int(np.unique(r[ok] * ref.shape[1] + c[ok]).size)


def check_coverage(xyz: np.ndarray, ref_path: str, crs: str) -> Tuple[np.ndarray, Tuple[float, ...], List[str], int]:
    """(reference window, its geotransform, messages, cells under the block): DemControlError (or the
    co-registration's CoregError) naming the file when the reference is off the block or too coarse for it: fewer
    than the co-registration's MIN_CELLS cells with a height under the block's points."""
    pts = xyz[block_points(xyz)]
    if len(pts) < 3:
        raise DemControlError(f"the block has {len(pts)} sparse point(s): nothing to co-register with the reference "
                              f"DEM {ref_path}")
    ref, gt, messages = _window(pts, ref_path, crs)
    n = cells_under(pts, ref, gt)
    span = np.ptp(pts[:, :2], axis=0)
    cell = abs(float(gt[1]))
    if n == 0:
        raise DemControlError(f"the reference DEM {ref_path} does not overlap the block ({span[0]:.0f} x "
                              f"{span[1]:.0f} m in {_short(crs)}): no cell with a height under its points; is the "
                              "CRS of each right?")
    if n < MIN_CELLS:
        finer = math.sqrt(MIN_CELLS / n)
        raise DemControlError(f"the reference DEM {ref_path} is too coarse for a block this small: {n} cells under it "
                              f"({cell:.3g} m cells over {span[0]:.0f} x {span[1]:.0f} m), at least {MIN_CELLS} "
                              f"needed: a DEM with cells about {finer:.1f} x finer, or a larger block")
    return ref, gt, messages, n


FOOT_RATIO = 1.0 / 0.3048  # heights in feet read as metres have this many times the relief (US survey foot: 3.28083)


def _detrended(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """``z`` less its plane (offset and tilt) by least squares over the values within OUTLIER_NMAD spreads of
    the residuals' shortest half, iterated (a tilt of the block or of the terrain is not relief)."""
    a = np.column_stack([np.ones_like(x), x - x.mean(), y - y.mean()])
    inl = np.ones(len(z), dtype=bool)
    r = z - z.mean()
    for _ in range(10):
        p = np.linalg.lstsq(a[inl], z[inl], rcond=None)[0]
        r = z - a @ p
        centre, spread = shorth(r)
        new = np.abs(r - centre) <= OUTLIER_NMAD * max(spread, 1e-9)
        if np.array_equal(new, inl) or new.sum() < MIN_CELLS:
            break
        inl = new
    return r


def relief_ratio(xyz: np.ndarray, ref: np.ndarray, gt: Sequence[float]) -> Tuple[float, float, int]:
    """(the reference's relief over the block / the block's own, their correlation, points compared): the
    heights of the block's points and the reference's under them, each less its plane (a tilt, the terrain's
    slope), compared by their spreads (NMAD) over the points that are neither's outlier.  Unit-free: about 1
    for a reference in the block's unit, 3.28 for heights in feet read as metres, 0.30 for metres read as feet."""
    pts = np.asarray(xyz, dtype=float)
    h = bilinear(ref, (pts[:, 0] - gt[0]) / gt[1] - 0.5, (pts[:, 1] - gt[3]) / gt[5] - 0.5)
    ok = np.isfinite(h) & np.all(np.isfinite(pts), axis=1)
    if ok.sum() < MIN_CELLS:
        return math.nan, math.nan, int(ok.sum())
    x, y = pts[ok, 0], pts[ok, 1]
    rz, rh = _detrended(x, y, pts[ok, 2]), _detrended(x, y, h[ok])
    (cz, sz), (ch, sh) = shorth(rz), shorth(rh)
    inl = (np.abs(rz - cz) <= OUTLIER_NMAD * max(sz, 1e-9)) & (np.abs(rh - ch) <= OUTLIER_NMAD * max(sh, 1e-9))
    if inl.sum() < MIN_CELLS or not (np.std(rz[inl]) > 0 and np.std(rh[inl]) > 0):
        return math.nan, math.nan, int(inl.sum())
    rho = float(np.corrcoef(rz[inl], rh[inl])[0, 1])
    return float(nmad(rh[inl]) / max(nmad(rz[inl]), 1e-12)), rho, int(inl.sum())


def check_height_unit(xyz: np.ndarray, ref: np.ndarray, gt: Sequence[float], ref_path: str) -> None:
    """DemControlError when the reference's heights are evidently in another unit than it was read in (issue 47
    item 4: a DEM in feet without a unit label, read as metres, tilted a block 36.6 mm/m and lifted it 40.6 m):
    its relief over the block against the block's own (:func:`relief_ratio`) is nearer 3.28 (feet read as
    metres) than 1, or nearer 0.30 (metres labelled feet), on the log scale: beyond sqrt(3.28) = 1.81 either way.
    Judged only where the two reliefs correlate beyond 1 / sqrt(3.28) = 0.55: noise in one of them alone then
    cannot carry the ratio across (its ratio is at most 1 / correlation), so a block on flat ground or a DTM under
    a block of roofs (the reliefs unrelated) is never called wrong."""
    from ..io.raster import height_unit

    k, rho, n = relief_ratio(xyz, ref, gt)
    mid = math.sqrt(FOOT_RATIO)
    if not (math.isfinite(k) and rho > 1.0 / mid):
        return
    unit, metres, where = height_unit(ref_path)
    evidence = (f"its relief over the block (each less its tilt) is {k:.2f} x the block's own, correlation "
                f"{rho:.2f} over {n} sparse points")
    if k > mid and not where:
        raise DemControlError(
            f"the reference DEM {ref_path} seems to be in feet, not metres: {evidence} (heights in feet read as "
            f"metres give {FOOT_RATIO:.2f} x), and nothing in the file states its unit, so it was read in metres. "
            f"Label its heights (gdal_edit.py -units ft {ref_path}, or -units 'US survey foot'; or give it a "
            "vertical CRS in feet) or convert them to metres, and run again")
    if k < 1.0 / mid and metres < 1.0:
        raise DemControlError(
            f"the reference DEM {ref_path} seems to be in metres, not in {unit} as {where} says: {evidence} "
            f"(heights in metres read as feet give {1.0 / FOOT_RATIO:.2f} x). Correct its unit (gdal_edit.py "
            f"-units m {ref_path}, or its vertical CRS) and run again")


def _short(crs: str) -> str:
    return crs if len(crs) < 40 else crs[:37] + "..."


def vertical_datum(ref_path: str) -> str:
    """The reference's vertical CRS as its file states it, else ''."""
    from osgeo import osr

    with RasterFile(ref_path, "reference DEM") as raster:
        wkt = raster.crs_wkt
    if not wkt:
        return ""
    srs = osr.SpatialReference(wkt=wkt)
    if srs.IsCompound():
        return srs.GetAttrValue("VERT_CS") or srs.GetAttrValue("VERTCRS") or "a compound CRS's vertical part"
    return ""


# ---------------------------------------------------------------------------
# before the long work, after the adjustment
# ---------------------------------------------------------------------------

def precheck(rec, gcps: Optional[GCPSet], cams: Sequence[CameraPosition], options, ref_path: str, crs: str) -> int:
    """The block placed by its control alone (the Helmert step, no adjustment) against the reference DEM: the
    errors of :func:`check_coverage` before the adjustment runs.  Returns the cells under the block."""
    from .adjust import georeference

    check_heights_file(ref_path, "reference DEM", DemControlError)  # an orthophoto given as the DEM (issue 47)
    check_metric(crs, ref_path)
    opt = dataclasses.replace(options, adjust=False, crs=crs)
    placed = georeference(rec, gcps, list(cams) or None, progress=NullProgress(), options=opt)
    xyz, _ = sparse_points(placed.reconstruction, placed.offset)
    ref, gt, _, cells = check_coverage(xyz, ref_path, crs)
    check_height_unit(xyz[block_points(xyz)], ref, gt, ref_path)
    return cells


def heights_only(xyz: np.ndarray, ref: np.ndarray, gt: Sequence[float], dome: bool = True) -> CoregResult:
    """The co-registration of the points' heights alone (dx = dy = 0 held): dz, tilt and dome by least squares
    over the stable points (within OUTLIER_NMAD spreads of the residuals' shortest half, iterated)."""
    pts = np.asarray(xyz, dtype=float)
    dh = bilinear(ref, (pts[:, 0] - gt[0]) / gt[1] - 0.5, (pts[:, 1] - gt[3]) / gt[5] - 0.5) - pts[:, 2]
    ok = np.isfinite(dh)
    if ok.sum() < MIN_CELLS:
        raise CoregError(f"too few points on the reference DEM: {int(ok.sum())} with a reference height (at least "
                         f"{MIN_CELLS} needed)")
    x0, y0 = (float(v) for v in pts[ok, :2].mean(axis=0))
    scale = max(float(np.max(np.ptp(pts[ok, :2], axis=0))) / 2.0, 1.0)
    u, v = (pts[:, 0] - x0) / scale, (pts[:, 1] - y0) / scale
    cols = [np.ones_like(u), u, v] + ([u * u, u * v, v * v] if dome else [])
    a = np.stack(cols, axis=1)
    inl, p, it = ok.copy(), np.zeros(a.shape[1]), 0
    while it < 20:
        it += 1
        p = np.linalg.lstsq(a[inl], dh[inl], rcond=None)[0]
        r = dh - a @ p
        centre, spread = shorth(r[ok])
        new = ok & (np.abs(r - centre) <= OUTLIER_NMAD * max(spread, 1e-6))
        if np.array_equal(new, inl) or new.sum() < MIN_CELLS:
            break
        inl = new
    r = dh - a @ p
    p[0] += float(np.median(r[inl]))
    r = dh - a @ p
    sdz = nmad(r[inl]) / math.sqrt(max(int(inl.sum()), 1))
    dome_c = (float(p[3] / scale ** 2), float(p[4] / scale ** 2), float(p[5] / scale ** 2)) if dome else (0.0,) * 3
    return CoregResult(shift=(0.0, 0.0, float(p[0])), tilt=(float(p[1] / scale), float(p[2] / scale)), dome=dome_c,
                       origin=(x0, y0), iterations=it, converged=True, nmad_before=nmad(dh[ok]),
                       nmad_after=nmad(r[ok]), median_before=float(np.median(dh[ok])),
                       median_after=float(np.median(r[ok])), n_cells=int(inl.sum()), n_compared=int(ok.sum()),
                       stable_fraction=float(inl.sum()) / max(int(ok.sum()), 1), cell=abs(float(gt[1])),
                       shift_sigma=(math.nan, math.nan, sdz), horizontal_determined=False)


def _shift_trusted(full: CoregResult, plain: CoregResult) -> Tuple[bool, str]:
    """Whether the horizontal shift of the co-registration with tilt and dome can be used: it converged, the terrain
    determined it, and the fit with a tilt alone finds the same shift (within half a cell or 3 standard errors: on
    gentle, curved terrain a shift and a tilt or a dome mimic each other and the shift wanders)."""
    if not (full.converged and full.horizontal_determined):
        return False, "the co-registration did not " + ("converge" if not full.converged else "determine it")
    if not (plain.converged and plain.horizontal_determined):
        return False, "the fit with a tilt alone did not " + ("converge" if not plain.converged else "determine it")
    d = math.hypot(full.shift[0] - plain.shift[0], full.shift[1] - plain.shift[1])
    tol = max(0.5 * full.cell, 3.0 * math.hypot(full.shift_sigma[0], full.shift_sigma[1]))
    if not d <= tol:
        return False, (f"it differs by {d:.2f} m from the fit with a tilt alone (dx {plain.shift[0]:.2f} m, dy "
                       f"{plain.shift[1]:.2f} m): the terrain does not tell a shift from a tilt or a dome")
    return True, ""


def coregister_block(rec, offset: Sequence[float], ref_path: str, crs: str, progress: Optional[Progress] = None
                     ) -> Tuple[CoregResult, np.ndarray, np.ndarray, np.ndarray, Tuple[float, ...], int]:
    """(co-registration, world points, their point3D ids, reference window, its geotransform, cells under the block)
    of an adjusted block (local frame world - ``offset``) against the reference DEM, in ``crs``: Nuth & Kääb with a
    tilt and a dome where the horizontal shift holds (:func:`_shift_trusted`), else the heights alone
    (:func:`heights_only`, a message says why)."""
    xyz, ids = sparse_points(rec, offset)
    keep = block_points(xyz)
    xyz, ids = xyz[keep], ids[keep]
    ref, gt, messages, cells = check_coverage(xyz, ref_path, crs)
    result = coregister_xyz(xyz, ref, gt, f"reference DEM {ref_path}", progress)
    result.messages[:0] = messages
    return result, xyz, ids, ref, gt, cells


def coregister_xyz(xyz: np.ndarray, ref: np.ndarray, gt: Sequence[float], name: str = "reference DEM",
                   progress: Optional[Progress] = None) -> CoregResult:
    """Points (N x 3, the reference's CRS) on the reference window: the co-registration with a tilt and a dome
    where its horizontal shift holds (:func:`_shift_trusted`), else the heights alone (:func:`heights_only`)."""
    try:
        grid = HeightGrid(ref, gt, name=name)
        full = coregister_points(xyz, grid, options=CoregOptions(tilt=True, dome=True), progress=progress)
        plain = coregister_points(xyz, grid, options=CoregOptions(tilt=True, dome=False))
    except CoregError as e:  # the shift's fit failed (too few stable points once shifted): the heights may hold
        full, (trusted, why) = None, (False, str(e))
    else:
        trusted, why = _shift_trusted(full, plain)
        if trusted:
            return full
    result = heights_only(xyz, ref, gt)
    if result.n_cells < MIN_CELLS:
        raise CoregError(f"cannot co-register the block on the {name}: {result.n_cells} stable points "
                         f"(at least {MIN_CELLS} needed); {why}")
    shift = f" (dx {full.shift[0]:.2f} m, dy {full.shift[1]:.2f} m)" if full is not None else ""
    result.messages.append(f"the horizontal shift{shift} is not used: {why}; the heights alone were co-registered "
                           "(dz, tilt, dome)")
    return result


def _names(n: int, taken: Sequence[str]) -> List[str]:
    taken_set, out, k = set(taken), [], 0
    while len(out) < n:
        k += 1
        name = f"{DEM_PREFIX}{k:03d}"
        if name not in taken_set:
            out.append(name)
    return out


def _heights(control: Optional[Tuple[float, int]], dz: float, sigma_z: np.ndarray, ref_sigma_z: float
             ) -> Tuple[str, float]:
    """(which heights win, the sigma of the test) from the control's (residual RMS Z, n) or None (module notes)."""
    if control is None:
        return HEIGHTS_DEM, math.nan
    rms, n = control
    sig = math.sqrt(max(rms, 1e-3) ** 2 / max(n, 1) + float(np.median(sigma_z)) ** 2 / max(len(sigma_z), 1)
                    + float(ref_sigma_z) ** 2)
    return (HEIGHTS_CONTROL if abs(dz) > 3.0 * sig else HEIGHTS_BOTH), sig


def dem_control(rec, offset: Sequence[float], options: GeorefOptions, *, control: Optional[Tuple[float, int]],
                taken: Sequence[str] = (), progress: Optional[Progress] = None) -> DemControl:
    """The DEM control of an adjusted block (local frame world - ``offset``): co-registration on
    ``options.reference_dem`` in ``options.crs`` (the target CRS) and up to ``options.reference_dem_points`` control
    points (``options.reference_dem_sigma_z``: the reference's own height error).  ``control``: (RMS Z of the
    control points' residuals, their number) when 3 or more control points fix the block's heights, else None (the
    module notes say which heights win).  ``taken``: ground point names already in use."""
    ref_path, crs = options.reference_dem, options.crs
    if not ref_path or not crs:
        raise DemControlError(f"DEM control needs a reference DEM and a target CRS (got {ref_path!r} and {crs!r})")
    n, ref_sigma_z = options.reference_dem_points, options.reference_dem_sigma_z
    progress = progress or NullProgress()
    co, xyz, ids, ref, gt, cells = coregister_block(rec, offset, ref_path, crs, progress)
    pc = control_points_from_coregistration(co, HeightGrid(ref, gt), points=xyz, n=n, ref_sigma_z=ref_sigma_z)
    if len(pc) < 3:
        raise DemControlError(f"the reference DEM {ref_path}: {len(pc)} DEM control point(s) on flat, stable terrain "
                              f"after the co-registration ({co.summary()}), at least 3 needed")
    k = len(pc)
    sxy = pc.sigma_xy * math.sqrt(k)
    dz = float(co.shift[2])
    heights, level_sigma = _heights(control, dz, pc.sigma_z, ref_sigma_z)
    pts = []
    for name, i, b, q, sx, sz in zip(_names(k, taken), pc.index, pc.block_xyz, pc.xyz, sxy, pc.sigma_z):
        x, y, z = (q[0], q[1], q[2]) if heights == HEIGHTS_DEM else (b[0], b[1], q[2] - (dz if heights ==
                                                                                          HEIGHTS_CONTROL else 0.0))
        pts.append(GroundPoint(name, float(x), float(y), float(z), float(sx), float(sz), CONTROL,
                               track_observations(rec, int(ids[int(i)])), sigma_given=True))
    dc = DemControl(ref_path, crs, co, pts, heights, camera_dz=dz if heights == HEIGHTS_DEM else 0.0, cells=cells,
                    vertical_datum=vertical_datum(ref_path), level_sigma=level_sigma)
    dc.messages = _messages(dc, pc.sigma_z)
    return dc


def _messages(dc: DemControl, sigma_z: np.ndarray) -> List[str]:
    co = dc.coregistration
    datum = dc.vertical_datum or "not stated in the file"
    out = list(co.messages)
    out.append(f"co-registration of the block's sparse points on the reference DEM {dc.reference} ({dc.cells} "
               f"cells of {co.cell:.3g} m under the block): {co.summary()}")
    if not co.horizontal_determined:
        out.append("no horizontal shift: the DEM control points sit where the block has them and hold heights "
                   f"(sigma XY {dc.points[0].sigma_xy:.3g} m)")
    out.append(f"DEM control: {len(dc.points)} points {dc.points[0].name}-{dc.points[-1].name}, sigma XY "
               f"{dc.points[0].sigma_xy:.3g} m (sqrt(n) x the shift's: one shift for all of them), sigma Z "
               f"{float(np.min(sigma_z)):.3g}-{float(np.max(sigma_z)):.3g} m (the co-registration's NMAD "
               f"{co.nmad_after:.3g} m, the slope over the reference's {co.cell:.3g} m cells)")
    if dc.heights == HEIGHTS_CONTROL:
        out.append(f"heights: the control points' win; the reference DEM (vertical datum: {datum}) lies "
                   f"{abs(co.shift[2]):.2f} m {'above' if co.shift[2] > 0 else 'below'} them on average (beyond 3 x "
                   f"{dc.level_sigma:.2g} m: another datum), removed from the DEM control points, which add the "
                   "block's shape (tilt, dome) between the control points")
    elif dc.heights == HEIGHTS_BOTH:
        out.append(f"heights: the control points and the reference DEM (vertical datum: {datum}) agree within their "
                   f"accuracy ({co.shift[2]:+.2f} m, within 3 x {dc.level_sigma:.2g} m): both hold the block's "
                   "heights, weighed by their sigmas")
    else:
        out.append(f"heights: the reference DEM's win (vertical datum: {datum}); the camera positions' heights "
                   f"(GPS: ellipsoidal, or above mean sea level) lay {abs(co.shift[2]):.2f} m "
                   f"{'below' if co.shift[2] > 0 else 'above'} it on average and are moved by {co.shift[2]:+.2f} m; "
                   "what remains between them (tilt, dome) follows the sigmas")
    return out


def with_dem_control(gcps: Optional[GCPSet], cams: Sequence[CameraPosition], dc: DemControl
                     ) -> Tuple[GCPSet, List[CameraPosition]]:
    """The control of the re-run: the given ground points (check points untouched) plus the DEM control points,
    and the camera positions moved onto the reference's heights (HEIGHTS_DEM)."""
    base = list(gcps.points) if gcps is not None else []
    out = GCPSet(gcps.crs if gcps is not None and gcps.crs else dc.crs, base + list(dc.points),
                 list(gcps.warnings) if gcps is not None else [], gcps.source if gcps is not None else "")
    moved = [dataclasses.replace(c, z=c.z + dc.camera_dz) if math.isfinite(c.z) else c for c in cams]
    return out, moved


def has_height_control(gcps: Optional[GCPSet]) -> bool:
    """Whether the ground control fixes the block's heights (3 or more control points with observations)."""
    if gcps is None:
        return False
    return sum(1 for p in gcps.points if p.role == CONTROL and p.observations) >= 3


def after_messages(dc: DemControl, before: Dict[str, Any], after: Dict[str, Any]) -> List[str]:
    """Log lines comparing the block without and with the DEM control (check points, the co-registration)."""
    out = []
    if dc.after is not None:
        out.append(f"with the DEM control, the block against the reference DEM: NMAD {dc.after.nmad_after:.3g} m "
                   f"(was {dc.coregistration.nmad_before:.3g} m), remaining tilt {dc.after.tilt[0] * 1e3:.3f} / "
                   f"{dc.after.tilt[1] * 1e3:.3f} mm/m, dz {dc.after.shift[2]:+.3f} m")
    if before.get("CHECK_N") and after.get("CHECK_N"):
        out.append(f"check points without / with the DEM control: RMSE XY {_f(before.get('CHECK_RMSE_XY'))} / "
                   f"{_f(after.get('CHECK_RMSE_XY'))} m, Z {_f(before.get('CHECK_RMSE_Z'))} / "
                   f"{_f(after.get('CHECK_RMSE_Z'))} m")
    return out


def after_warning(dc: DemControl) -> Optional[str]:
    """A warning when the block adjusted with the DEM control still departs from the reference by more than 3 x
    what the DEM control points allow (their median sigma Z, at least the co-registration's residual NMAD): its
    shape could not follow them (a camera calibration held fixed and wrong, or other control far stronger)."""
    if dc.after is None or not dc.points:
        return None
    allowed = max(float(np.median([p.sigma_z for p in dc.points])), dc.coregistration.nmad_after, 1e-3)
    final = dc.after.nmad_before
    if not final > 3.0 * allowed:
        return None
    return (f"the block adjusted with the DEM control still departs from the reference DEM by {final:.3g} m (NMAD), "
            f"more than 3 x the DEM control points' sigma Z ({allowed:.3g} m): its shape could not follow them; a "
            "camera calibration held fixed and wrong (refine it), or other control given far stronger sigmas?")


def _f(v) -> str:
    return "n/a" if v is None else f"{v:.3f}"


__all__ = ["DEM_PREFIX", "DemControl", "DemControlError", "HEIGHTS_BOTH", "HEIGHTS_CONTROL", "HEIGHTS_DEM",
           "after_messages",
           "after_warning", "block_points", "cells_under", "check_coverage", "check_height_unit", "check_metric",
           "coregister_block", "coregister_xyz", "heights_only", "dem_control", "has_height_control", "precheck",
           "relief_ratio", "sparse_points", "track_observations", "vertical_datum", "with_dem_control"]
