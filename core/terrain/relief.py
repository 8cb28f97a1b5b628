"""Relief visualisations of a DTM (or DSM) with rvt-py, the Relief Visualization Toolbox's Python library
(``rvt.vis``; Kokalj & Somrak 2019, Zakšek et al. 2011, Hesse 2010).

RVT's published defaults (``rvt.default.DefaultValues``) are radii in cells of the 1 m lidar DEMs RVT was
made for; here they are metres (cells x ``reference_cell``) converted to cells of the actual raster, so a sky-view
factor over a 10 cm photogrammetric DTM looks 10 m far as RVT's does over a 1 m DEM (capped at
``max_radius_cells`` where the run time grows with the radius).  Only ``rvt.vis`` is used (NumPy + SciPy): RVT's
blender module needs matplotlib's removed ``cm.get_cmap``, so VAT is blended here with RVT's "VAT -
Archaeological" recipe (rvt.blend: sky-view factor 0.7-1 multiply 25 %, positive openness 68-93 deg overlay 50 %,
slope 0-50 deg luminosity 50 %, hillshade 0-1 normal), RVT's blend formulas for one band.
"""
from __future__ import annotations

from typing import Callable, Dict

import numpy as np

from ..common.errors import require
from ..common.progress import NullProgress, Progress, check_cancel
from .options import VISUALISATION_KEYS, ReliefOptions, TerrainError

# the display range of each product (RVT's byte-scale defaults; the QGIS style uses them)
DISPLAY_RANGE: Dict[str, tuple] = {
    "svf": (0.6375, 1.0), "openness_pos": (60.0, 95.0), "openness_neg": (60.0, 95.0), "slrm": (-2.0, 2.0),
    "msrm": (-2.5, 2.5), "mhs": (0.0, 1.0), "ld": (0.5, 1.8), "vat": (0.0, 1.0)}
UNITS = {"svf": "0..1", "openness_pos": "degrees", "openness_neg": "degrees", "slrm": "m", "msrm": "m",
         "mhs": "0..1", "ld": "0..", "vat": "0..1"}


def _rvt():
    return require("rvt.vis", "relief visualisations (sky-view factor, openness, local relief model, VAT)")


def cells(options: ReliefOptions, reference_cells: float, cell: float, cap: bool = True, lo: int = 1) -> int:
    """RVT's radius of ``reference_cells`` (cells at ``options.reference_cell``) in cells of ``cell`` metres."""
    n = int(round(reference_cells * options.reference_cell / cell))
    if cap:
        n = min(n, options.max_radius_cells)
    return max(lo, n)


def compute(key: str, dem: np.ndarray, cell: float, options: ReliefOptions = None,
            progress: Progress = None) -> np.ndarray:
    """The visualisation ``key`` (see options.VISUALISATIONS) of ``dem`` (metres, NaN = nodata)."""
    options = options or ReliefOptions()
    progress = progress or NullProgress()
    if key not in VISUALISATION_KEYS:
        raise TerrainError(f"unknown relief visualisation {key!r}: one of {', '.join(VISUALISATION_KEYS)}")
    check_cancel(progress)
    out = _COMPUTE[key](_rvt(), dem.astype(np.float32), cell, options)
    out = np.asarray(out, dtype=np.float32)
    out[~np.isfinite(dem)] = np.nan
    return out


def reach(key: str, cell: float, options: ReliefOptions) -> int:
    """How many cells from a cell the visualisation ``key`` looks (its largest radius; 1 for the slope of a
    hillshade): a tile computed with this margin around it is the whole raster's."""
    o = options
    svf = cells(o, o.svf_radius, cell, lo=3)
    if key in ("svf", "openness_pos", "openness_neg", "vat"):
        return svf + 1
    if key == "slrm":
        return cells(o, o.slrm_radius, cell, cap=False, lo=2) + 1
    if key == "msrm":  # rvt.vis.msrm's largest mean filter: n ** scaling cells
        fmin = max(o.msrm_feature_min, 2 * cell)
        n = int(np.ceil(((max(o.msrm_feature_max, fmin) - cell) / (2 * cell)) ** (1 / int(o.msrm_scaling))))
        return n ** int(o.msrm_scaling) + 1
    if key == "ld":
        return max(cells(o, o.ld_min_radius, cell, lo=2) + 1, cells(o, o.ld_max_radius, cell, lo=3)) + 1
    return 1


def tile_cells(key: str, cell: float, options: ReliefOptions) -> int:
    """The side of the tiles ``key`` is computed by: ``options.tile``, at least four times its margin (the
    margin is computed again around each tile)."""
    return max(int(options.tile), 4 * reach(key, cell, options))


def tiled(key: str, elev, options: ReliefOptions, progress: Progress) -> Callable:
    """A function of a tile (r0, r1, c0, c1) giving the visualisation ``key`` of the elevation raster ``elev``
    (core.terrain.rasters.Elevation, read by windows) there: computed on the tile and the margin its radius
    reaches (:func:`reach`), so a tile is as it is in the whole raster, which is never in memory."""
    h, w = elev.shape
    margin = reach(key, elev.cell, options) + 1
    tile = tile_cells(key, elev.cell, options)
    n_tiles = max(1, -(-h // tile) * -(-w // tile))
    done = [0]

    def values(r0: int, r1: int, c0: int, c1: int) -> np.ndarray:
        a0, a1, b0, b1 = max(0, r0 - margin), min(h, r1 + margin), max(0, c0 - margin), min(w, c1 + margin)
        image = compute(key, elev.read(a0, a1, b0, b1), elev.cell, options, progress)
        done[0] += 1
        progress.report(done[0] / n_tiles, f"relief visualisation: {key}, tile {done[0]} of {n_tiles}")
        return image[r0 - a0:r1 - a0, c0 - b0:c1 - b0]

    return values


def _svf(vis, dem, cell, o, opns=False):
    r = cells(o, o.svf_radius, cell, lo=3)
    res = vis.sky_view_factor(dem=dem.copy(), resolution=cell, compute_svf=not opns, compute_opns=opns,
                              svf_n_dir=o.svf_directions, svf_r_max=r, svf_noise=o.svf_noise,
                              ve_factor=o.vertical_exaggeration, no_data=None)
    return res["opns"] if opns else res["svf"]


def _openness_neg(vis, dem, cell, o):
    return _svf(vis, -dem, cell, o, opns=True)


def _slrm(vis, dem, cell, o):
    # rvt.vis.slrm's own formula (DEM minus its mean over the radius) through rvt.vis.mean_filter: rvt.vis.slrm
    # refuses radii above 50 cells, and RVT's 20 m are 200 cells at 10 cm
    r = cells(o, o.slrm_radius, cell, cap=False, lo=2)
    z = dem * o.vertical_exaggeration
    return z - vis.mean_filter(dem=z.copy(), kernel_radius=r)


def _msrm(vis, dem, cell, o):
    fmin = max(o.msrm_feature_min, 2 * cell)
    return vis.msrm(dem=dem.copy(), resolution=cell, feature_min=fmin, feature_max=o.msrm_feature_max,
                    scaling_factor=o.msrm_scaling, ve_factor=o.vertical_exaggeration, no_data=None)


def _mhs(vis, dem, cell, o):
    # RVT's multi-direction hillshade (16 suns at 35 deg) as one band: the mean of the directions.  Each through
    # rvt.vis.hillshade: rvt 2.2.3's multi_hillshade trims a cell off every edge when it passes its slope on
    out = np.zeros(dem.shape, dtype=np.float64)
    for i in range(o.mhs_directions):
        out += vis.hillshade(dem=dem.copy(), resolution_x=cell, resolution_y=cell,
                             sun_azimuth=360.0 * i / o.mhs_directions, sun_elevation=o.hs_sun_elevation,
                             ve_factor=o.vertical_exaggeration, no_data=None)
    return out / o.mhs_directions


def _ld(vis, dem, cell, o):
    lo = cells(o, o.ld_min_radius, cell, lo=2)
    hi = max(lo + 1, cells(o, o.ld_max_radius, cell, lo=3))
    inc = max(1, (hi - lo) // 10)  # RVT: 10 rings (radius step 1 cell between 10 and 20)
    # local dominance works in cells: the observer height in cells of this raster
    return vis.local_dominance(dem=dem.copy() / cell, min_rad=lo, max_rad=hi, rad_inc=inc, angular_res=15,
                               observer_height=o.ld_observer_height / cell, ve_factor=o.vertical_exaggeration,
                               no_data=None)


def _norm(image, lo, hi):
    return np.clip((image - lo) / (hi - lo), 0.0, 1.0)


def _vat(vis, dem, cell, o):
    """RVT's "VAT - Archaeological" blend, greyscale (rvt.blend.create_blender_file_example, rvt.blend_func)."""
    svf = _svf(vis, dem, cell, o)
    opns = _svf(vis, dem, cell, o, opns=True)
    slope = vis.slope_aspect(dem=dem.copy(), resolution_x=cell, resolution_y=cell, output_units="degree",
                             ve_factor=o.vertical_exaggeration, no_data=None)["slope"]
    hs = vis.hillshade(dem=dem.copy(), resolution_x=cell, resolution_y=cell, sun_azimuth=315,
                       sun_elevation=o.hs_sun_elevation, ve_factor=o.vertical_exaggeration, no_data=None)
    background = _norm(hs, 0.0, 1.0)  # layer 4: hillshade, normal, 100 %
    layers = ((1.0 - _norm(slope, 0.0, 50.0), "luminosity", 0.5),  # slope: inverted (steep = dark)
              (_norm(opns, 68.0, 93.0), "overlay", 0.5),
              (_norm(svf, 0.7, 1.0), "multiply", 0.25))
    for active, mode, opacity in layers:
        if mode == "multiply":
            blended = active * background
        elif mode == "overlay":
            blended = np.where(background > 0.5, 1 - (1 - 2 * (background - 0.5)) * (1 - active),
                               2 * background * active)
        else:  # luminosity of one band: the active layer
            blended = active
        background = blended * opacity + background * (1 - opacity)
    return background


_COMPUTE: Dict[str, Callable] = {
    "svf": _svf, "openness_pos": lambda v, d, c, o: _svf(v, d, c, o, opns=True), "openness_neg": _openness_neg,
    "slrm": _slrm, "msrm": _msrm, "mhs": _mhs, "ld": _ld, "vat": _vat}
