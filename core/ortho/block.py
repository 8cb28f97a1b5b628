"""The block set-up shared by the mosaic and per-image orthophotos (footprints, checks of the DSM against the
images, the output grid, visibility tables), and one image's true orthophoto."""
from __future__ import annotations

import os
from dataclasses import asdict, dataclass, replace
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.progress import NullProgress, Progress, SubProgress, check_cancel
from ..io import raster as dsmmod
from .cameras import OrthoCamera
from .grid import box_union, cell_centre_coords, format_box, grid_tiles, nice_number, subgrid
from .options import OrthoError, OrthoOptions
from .pixels import ImageMeta, image_meta
from .sampling import sample_camera
from .surface import Dsm
from .visibility import Footprint, Visibility, build_visibility, camera_footprint, resolution_limited
from .writer import RasterWriter


@dataclass
class PreparedBlock:
    cameras: List[OrthoCamera]
    metas: List[ImageMeta]
    footprints: List[Footprint]
    visibility: List[Optional[Visibility]]
    grid: dsmmod.Grid
    gsd: float
    z_range: Tuple[float, float]
    warnings: List[str]


def prepare_block(cameras: Sequence[OrthoCamera], dsm: Dsm, offset: np.ndarray, options: OrthoOptions,
                  workdir: str, progress: Optional[Progress] = None) -> PreparedBlock:
    """Footprints, the output grid (``options.resolution``) and per-image visibility tables (with
    ``options.occlusion``, ``options.height_tolerance``); checks the DSM against the images.
    ``options.gsd_factor`` > 0: each image is used only where its ground resolution is within that factor of its
    best (its footprint trimmed, OrthoCamera.max_gsd set on a copy)."""
    progress = progress or NullProgress()
    resolution, gsd_factor = options.resolution, options.gsd_factor
    warnings: List[str] = []
    offset = np.asarray(offset, dtype=float)
    if not cameras:
        raise OrthoError("no image to orthorectify")
    centres = np.array([c.centre + offset for c in cameras])
    # a first look at the DSM around the cameras (coarse): the ground under them, then its height range
    z_nadir = dsm.sample(centres[:, 0], centres[:, 1])
    if np.isfinite(z_nadir).any():
        above = centres[:, 2] - float(np.nanmedian(z_nadir))
        span = float(np.clip(1.5 * np.max(above), 20.0, 5000.0))
    else:
        span = 1000.0
    box0 = (float(centres[:, 0].min() - span), float(centres[:, 1].min() - span),
            float(centres[:, 0].max() + span), float(centres[:, 1].max() + span))
    z0, _, _ = dsm.coarse(box0, 400_000)
    if z0.size == 0:
        raise OrthoError(
            f"the DSM {dsm.path} does not cover the images: its extent {format_box(dsm.bounds)} and the cameras' area "
            f"{format_box(box0)} (in {dsm.crs or 'the DSM CRS'}) do not overlap. Use a DSM of this area"
            + (" (or check the CRS: the DSM was reprojected)" if dsm.reprojected else ""))
    zf = z0[np.isfinite(z0)]
    if zf.size == 0:
        raise OrthoError(f"the DSM {dsm.path} has no valid height (all nodata) where the images are "
                         f"({format_box(box0)}): it cannot orthorectify them")
    z_lo, z_hi = float(np.percentile(zf, 0.5)), float(np.percentile(zf, 99.9))
    below = [c.name for c, p in zip(cameras, centres) if p[2] <= z_hi]
    if below and len(below) == len(cameras):
        raise OrthoError(f"every camera is below the DSM's surface (highest {z_hi:.1f}, cameras at "
                         f"{centres[:, 2].min():.1f}..{centres[:, 2].max():.1f}): heights of the DSM and the block "
                         "disagree (vertical datum, units or CRS?)")
    footprints: List[Optional[Footprint]] = []
    for c in cameras:
        footprints.append(camera_footprint(c, offset, z_lo, z_hi))
    keep = [i for i, f in enumerate(footprints) if f is not None]
    dropped = [cameras[i].name for i, f in enumerate(footprints) if f is None]
    if dropped:
        warnings.append(f"{len(dropped)} image(s) see no ground below the DSM's heights and are left out: "
                        f"{', '.join(dropped[:8])}")
    cams = [cameras[i] for i in keep]
    fps = [footprints[i] for i in keep]
    if gsd_factor and gsd_factor > 0:
        cams, fps = _limit_resolution(cams, fps, offset, z_lo, z_hi, gsd_factor)
    if not cams:
        raise OrthoError("no image sees the ground of the DSM (cameras below the surface or looking up)")
    # DSM coverage per image
    covered = []
    for f in fps:
        zc, _, _ = dsm.coarse(f.bbox, 4000)
        frac = float(np.isfinite(zc).mean()) if zc.size else 0.0
        covered.append(frac)
    if max(covered) == 0.0:
        raise OrthoError(
            f"the DSM {dsm.path} does not cover the images: no valid height under any of the {len(cams)} images' "
            f"footprints (DSM extent {format_box(dsm.bounds)}, images {format_box(box_union(f.bbox for f in fps))})")
    poor = [c.name for c, f in zip(cams, covered) if f < 0.5]
    if poor:
        warnings.append(f"the DSM covers less than half of the footprint of {len(poor)} image(s) "
                        f"({', '.join(poor[:6])}{' ...' if len(poor) > 6 else ''}): their uncovered parts stay nodata")
    # metadata of the images
    metas = []
    for c in cams:
        if not os.path.isfile(c.path):
            raise OrthoError(f"image {c.name} is missing: {c.path}")
        m = image_meta(c.path)
        if (m.width, m.height) != (c.camera.width, c.camera.height):
            raise OrthoError(f"image {c.path} is {m.width} x {m.height} pixels but its camera model is "
                             f"{c.camera.width} x {c.camera.height}: the file is not the one that was oriented")
        metas.append(m)
    # grid
    gsd = float(np.median([f.gsd for f in fps]))
    res = float(resolution) if resolution and resolution > 0 else nice_number(gsd)
    box = box_union(f.bbox for f in fps)
    zc, gx, gy = dsm.coarse(box, 1_000_000)
    ok = np.isfinite(zc)
    if not ok.any():
        raise OrthoError(f"the DSM {dsm.path} has no valid height under the images (all nodata there)")
    step = abs(gx[0, 1] - gx[0, 0]) if gx.shape[1] > 1 else dsm.res
    vbox = (float(gx[ok].min() - step), float(gy[ok].min() - step), float(gx[ok].max() + step),
            float(gy[ok].max() + step))
    box = (max(box[0], vbox[0]), max(box[1], vbox[1]), min(box[2], vbox[2]), min(box[3], vbox[3]))
    if box[2] <= box[0] or box[3] <= box[1]:
        raise OrthoError("the DSM's valid heights and the images' footprints do not overlap")
    try:
        grid = dsmmod.Grid.covering(*box, res, what="orthophoto")
    except dsmmod.DsmError as e:
        raise OrthoError(f"{e} (or fewer images)") from e
    if grid.width * grid.height > 400_000_000:
        raise OrthoError(f"a {grid.width} x {grid.height} orthophoto at {res:g} is too large: choose a coarser "
                         "RESOLUTION or fewer images")
    # visibility tables
    tol = options.height_tolerance if options.height_tolerance > 0 else max(0.1, dsm.res)
    vis: List[Optional[Visibility]] = [None] * len(cams)
    if options.occlusion:
        _visibility_tables(cams, fps, offset, dsm, tol, workdir, vis, progress)
    return PreparedBlock(cams, metas, fps, vis, grid, gsd, (z_lo, z_hi), warnings)


def _visibility_tables(cams, fps, offset, dsm: Dsm, tol: float, workdir: str, out: List[Optional[Visibility]],
                       progress: Progress) -> None:
    """The visibility tables into ``out``, on one thread per core (at most 4): numpy and OpenCV release the GIL on
    the tables' arrays and the DSM's window reads take turns (toledo_2400: 57 tables, 17 s on one core)."""
    from ..common.parallel import cpu_count, make_executor, run_units

    def one(i, _cancel_path):
        return build_visibility(cams[i], offset, fps[i], dsm, tol, os.path.join(workdir, f"vis_{i:05d}.npy"))

    threads = max(1, min(cpu_count(), 4, len(cams)))  # one image (a single orthophoto): one thread
    with make_executor(threads, kind="thread") as ex:
        for i, v in run_units(ex, one, list(range(len(cams))), progress, label="visibility",
                              describe=lambda i: cams[i].name):
            out[i] = v


# an image whose coarsest ground resolution (on the DSM's low plane) is within the limit / this margin is not tested
# cell by cell: the margin covers ground below that plane (its 0.5th percentile: 25 m below at 50 m over the ground
# is 1.5 x the distance) and the resolution between the sampled rays
UNLIMITED_MARGIN = 2.0


def _limit_resolution(cams: Sequence[OrthoCamera], fps: Sequence[Footprint], offset: np.ndarray, z_lo: float,
                      z_hi: float, factor: float) -> Tuple[List[OrthoCamera], List[Footprint]]:
    """Copies of the cameras with ``max_gsd`` = factor x their best ground resolution, and their trimmed
    footprints (core.ortho.visibility.resolution_limited).  An image that resolves all its ground well within the
    limit (its worst within 1 / UNLIMITED_MARGIN of it: a vertical) keeps no ``max_gsd``: the test per mosaic cell
    (two more projections of every cell) could reject nothing there."""
    out_c, out_f = [], []
    for c, f in zip(cams, fps):
        f2, best, worst = resolution_limited(c, offset, f, z_lo, z_hi, factor)
        limited = np.isfinite(best) and not worst * UNLIMITED_MARGIN <= factor * best
        out_c.append(replace(c, max_gsd=factor * best) if limited else c)
        out_f.append(f2)
    return out_c, out_f


def check_kind(metas: Sequence[ImageMeta], cams: Sequence[OrthoCamera]) -> Tuple[int, str]:
    kinds = {}
    for m, c in zip(metas, cams):
        kinds.setdefault((m.bands, m.dtype), []).append(c.name)
    if len(kinds) > 1:
        desc = "; ".join(f"{b} band(s) {d}: {', '.join(n[:3])}{' ...' if len(n) > 3 else ''}"
                         for (b, d), n in kinds.items())
        raise OrthoError(f"the images differ in bands or data type ({desc}): one mosaic needs one kind; choose a "
                         "subset with IMAGES_FILTER (e.g. group:<camera> for the NIR camera only)")
    (bands, dtype), = kinds.keys()
    return bands, dtype


def write_camera_ortho(prep: PreparedBlock, i: int, dsm: Dsm, offset: np.ndarray, out_path: str,
                       options: OrthoOptions, progress: Optional[Progress] = None) -> Optional[Dict[str, Any]]:
    """The true orthophoto of the block's image ``i`` on the cells of its grid under its footprint, as a COG in
    the DSM's working CRS.  Returns the sub-grid and valid fraction, or None when the image covers no cell."""
    progress = progress or NullProgress()
    cam, meta, vis, fp, grid = prep.cameras[i], prep.metas[i], prep.visibility[i], prep.footprints[i], prep.grid
    sub = subgrid(grid, fp.bbox)
    if sub is None:
        return None
    r0, c0, h, w = sub
    g = dsmmod.Grid(grid.x0 + c0 * grid.resolution, grid.y0 - r0 * grid.resolution, grid.resolution, w, h)
    work = os.path.join(os.path.dirname(os.path.abspath(out_path)), ".work-" + os.path.basename(out_path))
    writer = RasterWriter(work, w, h, meta.bands, meta.dtype, g.geotransform, dsm.crs)
    n_valid = 0
    try:
        tiles = grid_tiles(w, h, options.tile)
        for k, (tr, tc, th, tw) in enumerate(tiles):
            check_cancel(progress)
            x, y = cell_centre_coords(g, tr, tc, th, tw)
            z = dsm.sample(x, y)
            s = sample_camera(cam, meta, offset, x, y, z, vis, options.interpolation)
            writer.write(tr, tc, s.values.reshape(th, tw, -1), s.valid.reshape(th, tw))
            n_valid += int(s.valid.sum())
            progress.report(0.9 * (k + 1) / len(tiles), f"{cam.name}: tile {k + 1}/{len(tiles)}")
        writer.finish(out_path, options.compress, SubProgress(progress, 0.9, 1.0),
                      metadata={"ARCHAEOORTHO_STAGE": "orthophoto", "IMAGE": cam.name})
    except BaseException:
        writer.abort()
        raise
    return {"path": out_path, "grid": asdict(g), "valid_fraction": n_valid / float(w * h)}
