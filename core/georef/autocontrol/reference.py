"""The reference: an orthophoto raster (any CRS, any resolution, grey or colour) and a DSM/DTM raster.

The orthophoto is read through a GDAL warp onto the grid the match needs (its own CRS, any box and resolution:
averaged when coarser); the DSM is sampled bilinearly in the orthophoto's CRS (warped on the fly when it has
another one, ``core.io.raster.DsmReader``).
"""
from __future__ import annotations

import os
from typing import List, Tuple

import numpy as np

from ...common.errors import require
from ...geometry.crs import CRSError, crs_identifier, is_mercator, linear_unit, transform_points, utm_epsg_for_lonlat
from ...io.raster import DsmError, DsmReader, RasterError, RasterFile, check_heights, crs_to_wkt, not_heights
from .errors import AutoControlError


def _open(path: str, what: str) -> RasterFile:
    """The reference raster opened read-only; AutoControlError naming it when GDAL cannot read it."""
    try:
        return RasterFile(path, what)
    except RasterError as e:
        raise AutoControlError(str(e)) from e


def _working_crs(path: str, ds, gt, wkt: str) -> Tuple[str, str]:
    """(WKT, note) of the CRS the control is made in: the orthophoto's own, unless it is geographic (degrees) or
    a Mercator (Web Mercator's metres are 1 / cos(latitude) ground metres: 1.3 at 40 degrees), then the UTM zone
    of its centre, with a note that says so ('' otherwise)."""
    unit = linear_unit(wkt)[0]
    if unit != "degree" and not is_mercator(wkt):
        return wkt, ""
    centre = np.array([[gt[0] + 0.5 * ds.RasterXSize * gt[1], gt[3] + 0.5 * ds.RasterYSize * gt[5]]])
    try:
        lon, lat = transform_points(centre, wkt, "EPSG:4326")[0]
    except CRSError as e:
        raise AutoControlError(f"reference orthophoto {path}: its CRS cannot be taken to a metric one: {e}") from e
    code = utm_epsg_for_lonlat(lon, lat)
    kind = "geographic (degrees)" if unit == "degree" else "a Mercator projection (not ground metres)"
    return crs_to_wkt(f"EPSG:{code}"), (f"reference orthophoto {os.path.basename(path)} is in a CRS that is {kind}: "
                                        f"the automatic control works in EPSG:{code} (UTM), and its result is in it")


def result_crs(ortho_path: str) -> str:
    """The CRS the automatic control's result is in for this reference orthophoto ('EPSG:n' or a WKT): its own,
    or the UTM zone of its centre for a geographic or Mercator one; the faces give check points and camera
    positions in it."""
    with _open(ortho_path, "reference orthophoto") as raster:
        wkt = raster.crs_wkt
        if not wkt:
            raise AutoControlError(f"reference orthophoto {ortho_path} has no CRS")
        return crs_identifier(_working_crs(ortho_path, raster.dataset, raster.dataset.GetGeoTransform(), wkt)[0])


def _vrt_sources(ds, path: str) -> List[str]:
    """The files a virtual raster's bands read (GDAL's GetFileList leaves out the missing ones)."""
    import xml.etree.ElementTree as ET

    if ds.GetDriver().ShortName != "VRT":
        return []
    text = (ds.GetMetadata("xml:VRT") or [""])[0]
    try:
        root = ET.fromstring(text)
    except ET.ParseError:
        return []
    out = []
    for el in root.iter("SourceFilename"):
        name = (el.text or "").strip()
        if name and el.get("relativeToVRT") == "1":
            name = os.path.join(os.path.dirname(os.path.abspath(path)), name)
        out.append(name)
    return out


MIN_REFERENCE_PIXELS = 16  # a reference smaller than this on a side cannot be matched


def _is_heights(gdal, ds) -> bool:
    """Whether a raster says it holds heights: one band with a length unit, or one of the plugin's DSM / DTM."""
    product = (ds.GetMetadata() or {}).get("ARCHAEOORTHO_PRODUCT")
    unit = (ds.GetRasterBand(1).GetUnitType() or "").strip().lower()
    return ds.RasterCount == 1 and (product in ("dsm", "dtm") or unit in ("m", "metre", "meter", "metres", "ft",
                                                                          "foot", "feet", "us survey foot"))


def _check_kinds(gdal, ortho_path: str, ortho, dsm_path: str, dsm) -> None:
    """AutoControlError saying which reference is wrong and why, before any work (issue 36 item 12: these all
    ended in '0 candidate(s) kept, 4 needed'): an orthophoto that is a few pixels or has no data, a DSM that is
    not heights (core.io.raster.not_heights: the check every reader of heights makes) or has no data, the two
    swapped."""
    w, h = ortho.RasterXSize, ortho.RasterYSize
    if min(w, h) < MIN_REFERENCE_PIXELS:
        raise AutoControlError(f"reference orthophoto {ortho_path} is {w} x {h} pixels: too small to match photos "
                               f"against (at least {MIN_REFERENCE_PIXELS} x {MIN_REFERENCE_PIXELS})")
    if _is_heights(gdal, ortho) and not_heights(dsm):
        raise AutoControlError(f"the references look swapped: the orthophoto {ortho_path} holds heights and the "
                               f"DSM {dsm_path} is {not_heights(dsm).split(':')[0]}; give the orthophoto as the "
                               "orthophoto and the DSM as the DSM")
    check_heights(dsm, f"reference DSM {dsm_path}", AutoControlError)
    for what, path, ds in (("reference orthophoto", ortho_path, ortho), ("reference DSM", dsm_path, dsm)):
        try:
            ds.GetRasterBand(1).ComputeRasterMinMax(True)  # a sample (overviews); writes nothing beside the file
        except RuntimeError as e:
            if "no valid pixels" in str(e).lower():
                raise AutoControlError(f"{what} {path} has no data: every pixel is nodata") from e
            raise AutoControlError(f"{what} {path} cannot be read: {e}") from e


def _check_sources(path: str, ds, what: str) -> None:
    """AutoControlError naming ``path`` and the missing file when a raster made of other files (a VRT, a
    GeoTIFF with an external mask or overview) refers to one that does not exist (issue 36 item 10: a traceback
    from gdal.Warp, after the matching had started)."""
    for f in _vrt_sources(ds, path) if ds is not None else []:
        if f.startswith("/vsi") or os.path.exists(f):
            continue
        raise AutoControlError(f"{what} {path} refers to {f}, which does not exist (a virtual raster whose source "
                               "file was moved or deleted?): make it point to the file, or give the file itself")


class Reference:
    """``ortho_path``, ``dsm_path``: rasters GDAL reads, north-up, in any CRS (a national one without an EPSG
    code too).  The control is made in the orthophoto's CRS (``crs_wkt``), or in the UTM zone of its centre when
    that CRS is geographic or a Mercator (``notes`` says so); the DSM is read in it, its heights scaled to that
    CRS's unit from the unit the DSM declares (``core.io.raster.height_unit``)."""

    def __init__(self, ortho_path: str, dsm_path: str):
        gdal = require("osgeo.gdal", "reading the reference orthophoto")
        for what, p in (("reference orthophoto", ortho_path), ("reference DSM", dsm_path)):
            if not p or not os.path.isfile(p):
                raise AutoControlError(f"{what} {p!r} does not exist")
        self._ortho = _open(ortho_path, "reference orthophoto")
        ds = self._ortho.dataset
        _check_sources(ortho_path, ds, "reference orthophoto")
        with _open(dsm_path, "reference DSM") as dsm:
            _check_kinds(gdal, ortho_path, ds, dsm_path, dsm.dataset)
            _check_sources(dsm_path, dsm.dataset, "reference DSM")
        gt = ds.GetGeoTransform(can_return_null=True)
        if gt is None:
            raise AutoControlError(f"reference orthophoto {ortho_path} has no georeferencing (geotransform)")
        if gt[2] != 0 or gt[4] != 0:
            raise AutoControlError(f"reference orthophoto {ortho_path} is rotated (geotransform {gt}): warp it "
                                   "north-up first")
        source_wkt = ds.GetProjection() or ""
        if not source_wkt:
            raise AutoControlError(f"reference orthophoto {ortho_path} has no CRS")
        self.notes: List[str] = []
        self.source_crs_wkt = source_wkt
        self.crs_wkt, note = _working_crs(ortho_path, ds, gt, source_wkt)
        self.notes += [note] if note else []
        if self.crs_wkt != source_wkt:  # read through a warped VRT: the grid, its cell and bounds in metres
            ds = gdal.AutoCreateWarpedVRT(ds, source_wkt, self.crs_wkt, gdal.GRA_Bilinear)
            gt = ds.GetGeoTransform()
        self.ortho_path, self.dsm_path = ortho_path, dsm_path
        self.geotransform = tuple(gt)
        self.gsd = float(abs(gt[1]))
        w, h = ds.RasterXSize, ds.RasterYSize
        xs, ys = (gt[0], gt[0] + w * gt[1]), (gt[3], gt[3] + h * gt[5])
        self.bounds = (min(xs), min(ys), max(xs), max(ys))
        self.n_bands = ds.RasterCount
        self._gdal = gdal
        self._ds = ds
        try:
            self.dsm = DsmReader(dsm_path, self.crs_wkt)
        except DsmError as e:
            raise AutoControlError(f"reference DSM {dsm_path}: {e}") from e
        self.dsm_gsd = float(abs(self.dsm.geotransform[1]))
        unit, _metres, where = self.dsm.z_unit
        self.z_scale = self.dsm.z_scale  # applied by the reader (io.raster's one conversion of heights)
        if where and abs(self.z_scale - 1.0) > 1e-9:
            self.notes.append(f"reference DSM heights in {unit} ({where}): scaled by {self.z_scale:.6g} to the "
                              "orthophoto's CRS unit")

    @property
    def crs(self) -> str:
        """'EPSG:n' when the CRS has an EPSG code, else its WKT (a national CRS without one is as good)."""
        return crs_identifier(self.crs_wkt)

    def grey(self, box: Tuple[float, float, float, float], res: float
             ) -> Tuple[np.ndarray, np.ndarray, Tuple[float, ...]]:
        """(grey uint8 image, valid mask, geotransform) of the orthophoto over ``box`` (xmin, ymin, xmax, ymax)
        at ``res`` per pixel (a box beyond the raster gives invalid pixels there)."""
        xmin, ymin, xmax, ymax = box
        w = max(1, int(round((xmax - xmin) / res)))
        h = max(1, int(round((ymax - ymin) / res)))
        alg = "average" if res > 1.2 * self.gsd else "bilinear"
        try:
            out = self._gdal.Warp("", self._ds, format="MEM",
                                  outputBounds=(xmin, ymax - h * res, xmin + w * res, ymax),
                                  width=w, height=h, resampleAlg=alg, dstAlpha=True)
        except RuntimeError as e:  # a source of a virtual raster gone since it was opened, a damaged tile
            raise AutoControlError(f"reference orthophoto {self.ortho_path} cannot be read over the block: {e}") from e
        if out is None:
            raise AutoControlError(f"reference orthophoto {self.ortho_path}: cannot resample it to {res:g} per pixel")
        bands = [out.GetRasterBand(k + 1).ReadAsArray().astype(np.float32) for k in range(out.RasterCount)]
        valid = bands[-1] > 0
        colour = bands[:-1]
        if len(colour) >= 3:
            grey = 0.299 * colour[0] + 0.587 * colour[1] + 0.114 * colour[2]
        else:
            grey = colour[0]
        if grey.dtype != np.uint8 and float(np.nanmax(grey[valid], initial=0.0)) > 255.0:
            lo, hi = np.percentile(grey[valid], [0.5, 99.5]) if valid.any() else (0.0, 1.0)
            grey = (grey - lo) * (255.0 / max(hi - lo, 1e-6))
        grey = np.clip(np.where(valid, grey, 0.0), 0, 255).astype(np.uint8)
        return grey, valid, (xmin, res, 0.0, ymax, 0.0, -res)

    def heights(self, x, y) -> np.ndarray:
        """DSM heights (NaN outside / nodata) at points of the working CRS, in its unit."""
        return self.dsm.sample(x, y)

    def relief(self, x, y, radius: float) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(height, slope, misfit) around each point: a plane through the 3 x 3 DSM samples ``radius`` apart
        gives the height at the centre and the slope; misfit is the samples' largest distance from the plane."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        d = np.array([-1.0, 0.0, 1.0]) * radius
        du, dv = np.meshgrid(d, d)
        du, dv = du.ravel(), dv.ravel()
        z = self.heights(x[:, None] + du[None], y[:, None] + dv[None])  # (N, 9)
        a = np.column_stack([np.ones(9), du, dv])
        coef, *_ = np.linalg.lstsq(a, np.nan_to_num(z).T, rcond=None)  # (3, N)
        fit = (a @ coef).T
        misfit = np.max(np.abs(z - fit), axis=1)
        misfit[~np.all(np.isfinite(z), axis=1)] = np.inf
        slope = np.hypot(coef[1], coef[2])
        return coef[0], slope, misfit

    def check_covers(self, box: Tuple[float, float, float, float], block: str = "the block") -> None:
        """AutoControlError naming the reference that does not cover ``box`` (xmin, ymin, xmax, ymax of the working
        CRS), before any matching (issue 36 item 12: a reference 5 km away or without data there ended in '0
        candidate(s) kept, 4 needed'): the orthophoto or the DSM lying elsewhere (how far, and where each is), or
        holding no data over it."""
        xmin, ymin, xmax, ymax = box
        unit = _unit_name(self.crs_wkt)
        where = f"{block} ({xmin:.0f}..{xmax:.0f}, {ymin:.0f}..{ymax:.0f} {unit} in {_short_crs(self.crs)})"
        dsm_gt = self.dsm.geotransform
        dsm_b = (dsm_gt[0], dsm_gt[3] + self.dsm.height * dsm_gt[5], dsm_gt[0] + self.dsm.width * dsm_gt[1],
                 dsm_gt[3])
        for what, path, b in (("reference orthophoto", self.ortho_path, self.bounds),
                              ("reference DSM", self.dsm_path, dsm_b)):
            gap = max(b[0] - xmax, xmin - b[2], b[1] - ymax, ymin - b[3])
            if gap >= 0:
                raise AutoControlError(
                    f"{what} {path} does not cover {where}: it covers {b[0]:.0f}..{b[2]:.0f}, {b[1]:.0f}..{b[3]:.0f}, "
                    f"{_distance(gap, unit)} away. Is it the reference of this site, and are the photos' GPS "
                    "positions (or the rough positions given) and the reference's CRS right?")
        side = max(xmax - xmin, ymax - ymin)
        _grey, valid, _gt = self.grey(box, max(side / 128.0, self.gsd))
        if not valid.any():
            raise AutoControlError(f"reference orthophoto {self.ortho_path} has no data over {where}: every "
                                   "pixel there is nodata (transparent); give an orthophoto with imagery there")
        gx, gy = np.meshgrid(np.linspace(xmin, xmax, 24), np.linspace(ymin, ymax, 24))
        if not np.isfinite(self.heights(gx.ravel(), gy.ravel())).any():
            raise AutoControlError(f"reference DSM {self.dsm_path} has no data over {where}: every cell there is "
                                   "nodata; give a DSM with heights there")

    def close(self) -> None:
        self.dsm.close()
        self._ds = None
        self._ortho.close()


def _unit_name(wkt: str) -> str:
    name, metres = linear_unit(wkt)
    return "m" if metres == 1.0 else (name or "units")


def _short_crs(crs: str) -> str:
    return crs if len(crs) < 40 else "the orthophoto's CRS"


def _distance(gap: float, unit: str) -> str:
    return f"{gap / 1000.0:.1f} km" if unit == "m" and gap >= 1000.0 else f"{gap:.0f} {unit}"


__all__ = ["Reference", "result_crs"]
