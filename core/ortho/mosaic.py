"""The orthomosaic of a set of oriented images on a DSM: block set-up, planning, tiles in parallel, the COG,
per-image orthophotos and the which-image GeoPackage."""
from __future__ import annotations

import ctypes
import math
import os
import shutil
import time
from dataclasses import asdict, dataclass, field, replace
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common import parallel
from ..common.files import owned_tempdir
from ..common.progress import NullProgress, Progress, SubProgress
from ..geometry.crs import unit_symbol
from ..io import raster as dsmmod
from .block import PreparedBlock, check_kind, prepare_block, write_camera_ortho
from .cameras import OrthoCamera
from .grid import box_intersects, grid_tiles
from .hotspot import shadow_margin_px, shadow_zones
from .options import OrthoError, OrthoOptions
from .pixels import PHOTO_CACHE
from .planning import MosaicPlan, plan_mosaic, planning_gsd
from .radiometry_fit import fit_radiometry_model, radiometry_lines
from .seamlines import read_seamline_edits, write_seamlines
from .surface import Dsm, fill_dsm_gaps
from .tiles import DSM_CACHE, TileUnit, render_tile
from .writer import RasterWriter, calibrated_reflectance, gdal_cache, photo_band_names

# the work folders of a run, beside its output (a killed run's are removed by the next: files.clean_debris)
WORK_PREFIX = ".ortho-work-"


@dataclass
class MosaicResult:
    path: str
    crs: Optional[str]
    resolution: float
    gsd: float
    width: int
    height: int
    images: List[str]
    valid_fraction: float
    per_image: Dict[str, str] = field(default_factory=dict)
    seamlines_path: Optional[str] = None
    gains: Dict[str, float] = field(default_factory=dict)
    radiometry: Dict[str, Any] = field(default_factory=dict)  # the fitted model's figures (core.ortho.radiometry)
    radiometry_model: Optional[Any] = None  # the RadiometryModel applied (None: the scalar gains alone)
    timings: Dict[str, float] = field(default_factory=dict)
    warnings: List[str] = field(default_factory=list)
    log_lines: List[str] = field(default_factory=list)


def build_orthomosaic(cameras: Sequence[OrthoCamera], crs: Optional[str], offset: Sequence[float],
                      options: OrthoOptions, progress: Optional[Progress] = None) -> MosaicResult:
    """The orthomosaic of ``cameras`` (poses in the local frame, world = local + ``offset``) on the DSM
    ``options.dsm_path``.

    Writes a COG at ``options.output`` (atomically), optionally one true orthophoto per image into
    ``options.per_image_folder`` and the which-image polygons into the GeoPackage ``options.seamlines``."""
    if not options.dsm_path or not options.output:
        raise OrthoError("an orthomosaic needs a DSM and an output path (OrthoOptions.dsm_path and .output)")
    dsm_path, output = options.dsm_path, options.output
    per_image_folder, seamlines_path = options.per_image_folder, options.seamlines
    progress = progress or NullProgress()
    edits = read_seamline_edits(options.seamlines_in, [c.name for c in cameras], crs) if options.seamlines_in else None
    for note in edits.notes if edits is not None else []:
        progress.info(note)
    offset = np.asarray(offset, dtype=float)
    t_start = time.time()
    timings: Dict[str, float] = {}
    log: List[str] = []
    out_dir = os.path.dirname(os.path.abspath(output))
    os.makedirs(out_dir, exist_ok=True)
    workdir = owned_tempdir(WORK_PREFIX, out_dir)
    PHOTO_CACHE.max_bytes = options.cache_mb << 20
    source_dsm = dsm_path
    try:
        dsm_path, filled = fill_dsm_gaps(dsm_path, os.path.join(workdir, "dsm-gaps-filled.tif"),
                                         options.fill_dsm_gaps_m)
        dsm = Dsm(dsm_path, crs, name=source_dsm)
    except BaseException:
        shutil.rmtree(workdir, ignore_errors=True)
        raise
    if filled:
        log.append(f"DSM gaps: {filled} cells without a height, inside the hull of the measured ones and at most "
                   f"{options.fill_dsm_gaps_m:g} m from one, took interpolated heights for the orthophoto (the DSM "
                   "file is unchanged)")
        progress.info(log[-1])
    try:
        with gdal_cache(64):
            t0 = time.time()
            prep = prepare_block(cameras, dsm, offset, options, workdir, SubProgress(progress, 0.0, 0.12))
            for w_ in prep.warnings:
                progress.warning(w_)
            if dsm.reprojected:
                log.append(f"DSM {source_dsm} reprojected on the fly into {crs}")
            bands, dtype = check_kind(prep.metas, prep.cameras)
            # the photos the mosaic takes (read and found over the DSM by prepare_block) hold calibrated reflectance
            if (options.exposure or options.radiometry) and calibrated_reflectance([c.path for c in prep.cameras]):
                options = replace(options, exposure=False, radiometry=False)
                log.append("the photos hold calibrated reflectance (their bands' RADIOMETRIC_UNIT): mosaicked as they "
                           "are, without exposure gains or the radiometric model, which would change them")
                progress.info(log[-1])
            grid = prep.grid
            timings["visibility"] = time.time() - t0
            unit = unit_symbol(crs)
            log.append(f"{len(prep.cameras)} images, GSD {prep.gsd:.3f} {unit}, mosaic {grid.width} x {grid.height} "
                       f"cells at {grid.resolution:g} {unit} ({bands} band(s) {dtype}), blending {options.blending}")
            progress.info(log[-1])
            fitted = _before_planning(prep, dsm, offset, crs, options, log, timings, SubProgress(progress, 0.12, 0.16))
            t0 = time.time()
            plan = plan_mosaic(prep, dsm, offset, options, workdir, SubProgress(progress, 0.16, 0.2), edits)
            timings["planning"] = time.time() - t0
            log.append(f"seamlines: planned on cells of {plan.k * grid.resolution:.3g} m ({plan.k} mosaic cells); "
                       f"{plan.relief_blobs} raised objects, {plan.relief_reassigned} given whole to one "
                       f"image; mean brightness difference across the seams {100 * plan.seam_before:.1f} % before and "
                       f"{100 * plan.seam_after:.1f} % after moving them to where the images agree; exposure gains "
                       f"{min(plan.gains):.3f}..{max(plan.gains):.3f}")
            progress.info(log[-1])
            for note in plan.notes:
                log.append(note)
                progress.info(note)
            model, summary = _radiometry(prep, dsm, offset, plan, fitted, log, timings, progress)
            t0 = time.time()
            n_valid, fill_cells = _run_tiles(prep, plan, dsm, offset, options,
                                             SubProgress(progress, 0.25, 0.85 if per_image_folder else 0.97), model)
            timings["mosaic"] = time.time() - t0
            valid_fraction = n_valid / float(grid.width * grid.height)
            labels = np.load(plan.labels_path)
            if seamlines_path:
                _write_sources_gpkg(seamlines_path, labels, prep, plan, crs)
            del labels
            per_image: Dict[str, str] = {}
            if per_image_folder:
                t0 = time.time()
                os.makedirs(per_image_folder, exist_ok=True)
                sp = SubProgress(progress, 0.85, 1.0)
                for i, cam in enumerate(prep.cameras):
                    path = os.path.join(per_image_folder, os.path.splitext(os.path.basename(cam.name))[0] + ".tif")
                    info = write_camera_ortho(prep, i, dsm, offset, path, options,
                                              SubProgress(sp, i / len(prep.cameras), (i + 1) / len(prep.cameras)))
                    if info:
                        per_image[cam.name] = path
                timings["per_image"] = time.time() - t0
            timings["total"] = time.time() - t_start
            log.append(f"mosaic {output}: {100 * valid_fraction:.1f} % of the cells have data, {fill_cells} cells "
                       f"filled from another image where the planned one is occluded ({plan.hidden_cells} of them "
                       "hidden from every image by the DSM: from the image that hides them least)")
            progress.report(1.0, "orthomosaic done")
            return MosaicResult(path=output, crs=crs, resolution=grid.resolution, gsd=prep.gsd, width=grid.width,
                                height=grid.height, images=[c.name for c in prep.cameras],
                                valid_fraction=valid_fraction, per_image=per_image, seamlines_path=seamlines_path,
                                gains={c.name: g for c, g in zip(prep.cameras, plan.gains)}, radiometry=summary,
                                radiometry_model=model,
                                timings={k: round(v, 3) for k, v in timings.items()}, warnings=prep.warnings,
                                log_lines=log)
    finally:
        dsm.close()
        DSM_CACHE.clear()
        PHOTO_CACHE.clear()
        shutil.rmtree(workdir, ignore_errors=True)


def _before_planning(prep: PreparedBlock, dsm: Dsm, offset, crs: Optional[str], options: OrthoOptions,
                     log: List[str], timings: Dict[str, float], progress: Progress):
    """The radiometric model fitted from the overlaps (when asked for) and each photo's shadow zone around its
    antisolar point (core.ortho.hotspot: the drone's shadow and the hot spot's core, left to the other photos where
    they see that ground), set on ``prep.cameras`` before the plan; (model, its summary) for :func:`_radiometry`."""
    model, summary = None, {}
    if options.radiometry:
        t0 = time.time()
        model, summary = fit_radiometry_model(prep, dsm, offset, options.hot_spot, SubProgress(progress, 0.0, 0.9))
        timings["radiometry"] = time.time() - t0
    if options.avoid_shadow:
        margin = shadow_margin_px(options.feather_gsd if options.blending == "feather" else 0.0,
                                  planning_gsd(prep.metas))
        zones, shadow, lines = shadow_zones(prep.cameras, crs, model, margin)
        for cam, zone in zip(prep.cameras, zones):
            cam.shadow = zone
        if shadow["images"]:  # recorded where a zone was set (the record of a block without one is unchanged)
            summary["shadow"] = shadow
        for line in lines:
            log.append(line)
            progress.info(line)
    return model, summary


def _radiometry(prep: PreparedBlock, dsm: Dsm, offset, plan: MosaicPlan, fitted, log: List[str],
                timings: Dict[str, float], progress: Progress):
    """The radiometric model fitted before the plan (``fitted``: the model and its summary) checked on the plan's
    seams, its lines in ``log``; with a model the plan's exposure gains become the model's gains at the images'
    centres (the which-image layer's).  (model or None, the figures for the record)."""
    model, summary = fitted
    shadow = summary.pop("shadow", None)
    extra = {"shadow": shadow} if shadow is not None else {}
    if "pairs" not in summary:  # no model was fitted (radiometry off)
        return None, extra
    t0 = time.time()
    model, lines = radiometry_lines(model, summary, prep, dsm, offset, np.load(plan.labels_path), plan.k,
                                    plan.gains)
    timings["radiometry"] = timings.get("radiometry", 0.0) + time.time() - t0
    for line in lines:
        log.append(line)
        progress.info(line)
    if model is None:
        return None, extra
    plan.gains = [model.scalar_gain(i) for i in range(len(prep.cameras))]
    return model, {**model.summary, **extra}


def _run_tiles(prep: PreparedBlock, plan: MosaicPlan, dsm: Dsm, offset, options: OrthoOptions, progress: Progress,
               radiometry=None) -> Tuple[int, int]:
    """The mosaic's tiles (core.ortho.tiles.render_tile, on the workers) written into ``options.output``, from
    the DSM file ``dsm.file`` in ``dsm.crs``; (valid cells, cells filled from another image)."""
    grid, output, crs = prep.grid, options.output, dsm.crs
    bands, dtype = check_kind(prep.metas, prep.cameras)
    work = os.path.join(os.path.dirname(os.path.abspath(output)), ".work-" + os.path.basename(output))
    writer = RasterWriter(work, grid.width, grid.height, bands, dtype, grid.geotransform, crs)
    writer.describe(*photo_band_names([c.path for c in prep.cameras]))  # a multispectral block's band names
    halo = 0
    if options.blending == "multiband":
        halo = 64
    labels = np.load(plan.labels_path, mmap_mode="r")
    units = []
    k = plan.k
    for i, (r0, c0, h, w) in enumerate(grid_tiles(grid.width, grid.height, options.tile)):
        m = plan.feather_cells + 1 + (halo // k + 1)
        pr0, pc0 = max(0, r0 // k - m), max(0, c0 // k - m)
        pr1, pc1 = min(plan.height, (r0 + h - 1) // k + 1 + m), min(plan.width, (c0 + w - 1) // k + 1 + m)
        present = [int(v) for v in np.unique(labels[pr0:pr1, pc0:pc1]) if v >= 0]
        tb = (grid.x0 + c0 * grid.resolution, grid.y0 - (r0 + h) * grid.resolution,
              grid.x0 + (c0 + w) * grid.resolution, grid.y0 - r0 * grid.resolution)
        cx, cy = 0.5 * (tb[0] + tb[2]), 0.5 * (tb[1] + tb[3])
        others = [j for j, fp in enumerate(prep.footprints) if j not in present and box_intersects(fp.bbox, tb)]
        others.sort(key=lambda j: math.hypot(prep.cameras[j].centre[0] + offset[0] - cx,
                                             prep.cameras[j].centre[1] + offset[1] - cy))
        if not present and not others:
            continue
        units.append(TileUnit(i, r0, c0, h, w, halo, asdict(grid), dsm.file, crs, [float(v) for v in offset],
                               prep.cameras, prep.metas, prep.visibility, present, others, plan.gains,
                               plan.labels_path, k, (plan.height, plan.width), plan.feather_cells, options.blending,
                               options.interpolation, options.cache_mb, radiometry, fill_hidden=options.fill_hidden))
    del labels
    n_valid = 0
    fill = 0
    try:
        workers = options.workers if options.workers and options.workers > 0 else 0
        with parallel.make_executor(workers, "auto", options.scheduler) as ex:
            for _i, res in parallel.run_units(ex, render_tile, units, progress, label="tile"):
                writer.write(res["r0"], res["c0"], res["values"], res["valid"])
                n_valid += int(res["valid"].sum())
                fill += res["fill_cells"]
                plan.hidden_cells += res.get("hidden_cells", 0)
                del res
                _trim_heap()
        writer.finish(output, options.compress, None,
                      metadata={"ARCHAEOORTHO_STAGE": "orthophoto", "BLENDING": options.blending,
                                "IMAGES": len(prep.cameras), "RESOLUTION": grid.resolution})
    except BaseException:
        writer.abort()
        raise
    return n_valid, fill


_LIBC: Any = None


def _trim_heap() -> None:
    """Give freed heap memory back to the system between tiles (glibc keeps it otherwise, and the peak memory
    would creep up with the number of tiles instead of staying at one tile's worth)."""
    global _LIBC
    if _LIBC is None:
        try:
            _LIBC = ctypes.CDLL("libc.so.6")
            _LIBC.malloc_trim.argtypes = [ctypes.c_size_t]
        except (OSError, AttributeError):
            _LIBC = False
    if _LIBC:
        _LIBC.malloc_trim(0)


def _write_sources_gpkg(path: str, labels: np.ndarray, prep: PreparedBlock, plan: MosaicPlan, crs: Optional[str]) -> str:
    """One polygon per image of the part of the mosaic it gives (the seamlines are their borders): editable, and
    taken back by Build orthophoto's SEAMLINES_IN (core.ortho.seamlines)."""
    grid = prep.grid
    pgrid = dsmmod.Grid(grid.x0, grid.y0, plan.k * grid.resolution, plan.width, plan.height)
    return write_seamlines(path, labels, pgrid, [c.name for c in prep.cameras],
                           [c.camera_id for c in prep.cameras], plan.gains, crs)
