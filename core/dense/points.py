"""The two drivers that turn the chosen pairs into fused point files (local frame).

Engine ``cpu`` (the default and the tested one): every pair is a unit of work (:func:`stereo.match_pair`, run
through :mod:`core.common.parallel`, cached in ``dense/pairs-<key>/`` so a re-run skips finished pairs), then
every image is one (:func:`fusion.fuse_image`).  Engine ``cuda`` runs COLMAP's patch-match stereo and fusion
instead (only where pycolmap was built with CUDA).  Both return :class:`grid.PointFile` s for the DSM.
"""
from __future__ import annotations

import json
import os
import shutil
import time
from dataclasses import dataclass
from typing import Callable, Dict, List, Optional, Tuple

import numpy as np

from ..common.cancel import CancelWatcher, load_pycolmap
from ..common.files import atomic_write_text, fingerprint, save_npz
from ..common.parallel import cpu_count, describe_executor, make_executor, run_units
from ..common.progress import Progress, SubProgress
from ..io import raster
from ..project.layout import Layout
from .block import DenseBlock
from .fusion import FuseUnit, fuse_image
from .grid import PointFile, stream_point_files
from .journal import Journal
from .options import CACHE_VERSION, DenseError, DenseOptions
from .pairs import PairInfo, View
from .stereo import PairUnit, match_pair, read_pair_summary

Say = Callable[[str], None]


def unit_memory(views: Dict[int, View], scale: float) -> int:
    """Bytes one matching unit needs at most (bounds the number of local workers)."""
    px = max(v.width * v.height for v in views.values()) * scale * scale
    return int(px * 160)  # both images, rectified copies, maps, SGBM buffers, disparities, depth maps


def threads_per_unit(workers: int) -> int:
    return max(1, cpu_count() // max(1, workers))


# ---------------------------------------------------------------------------
# cpu: pairs -> depth maps -> fused points per image
# ---------------------------------------------------------------------------

@dataclass
class DensePoints:
    """The fused points of the block (point files in the local frame) and the pairs matched for them."""

    files: List[PointFile]
    pairs: int  # pairs matched (0 with the cuda engine)
    reused: int  # pairs (cuda: 0) whose depth maps a previous run left

    @property
    def count(self) -> int:
        return sum(pf.count for pf in self.files)

    def write_las(self, path: str, offset: np.ndarray, crs: Optional[str], progress: Progress) -> int:
        """The points as a LAS 1.2 point cloud with RGB in ``crs`` (local frame + ``offset``); how many."""
        return raster.write_las(path, stream_point_files(self.files), offset, crs, progress=progress,
                                total=self.count)


def dense_points(block: DenseBlock, options: DenseOptions, lay: Layout, model_fp: Dict[str, str],
                 progress: Progress, journal: Journal) -> DensePoints:
    """The block's fused points with ``options.engine``; DenseError when no pixel was confirmed."""
    if options.engine == "cuda":
        t0 = time.time()
        files, n_reused = cuda_points(block.views, options.scale, lay.dense_dir, lay.georef_model_dir,
                                      block.images_dir, model_fp, SubProgress(progress, 0.02, 0.88))
        journal.timings["matching"] = time.time() - t0
        points = DensePoints(files, 0, n_reused)
    else:
        points = cpu_points(block, options, lay.dense_dir, model_fp, progress, journal)
    if points.count == 0:
        raise DenseError("dense matching found no consistent surface point: the pairs matched but no pixel was "
                         f"confirmed by {options.min_consistent} independent pairs (too little texture or overlap?)")
    return points


def cpu_points(block: DenseBlock, options: DenseOptions, dense_dir: str, model_fp: Dict[str, str],
               progress: Progress, journal: Journal) -> DensePoints:
    """The OpenCV engine's points (its matching and fusion seconds go to ``journal``)."""
    views, pairs, xyz = block.views, block.pairs, block.xyz
    scale = options.scale
    block_size = options.sgbm_block()
    pair_dir = _pair_cache(dense_dir, model_fp, scale, block_size, options)
    executor = make_executor(options.workers, options.executor, options.scheduler,
                             unit_memory=unit_memory(views, scale))
    workers = getattr(executor, "_max_workers", 1) or 1
    where = describe_executor(executor)
    threads = threads_per_unit(workers)

    # 2. matching, pair by pair
    t0 = time.time()

    def unit(p: PairInfo, out: str) -> PairUnit:
        return PairUnit(f"{p.i}-{p.j}", out, views[p.i], views[p.j], scale, xyz[p.point_idx], block_size,
                        options.uniqueness, options.lr_tolerance, threads,
                        fine_uniqueness=options.fine_uniqueness, equalize=options.equalize,
                        flat_block=options.flat_sgbm_block())

    units, summaries, n_reused = _cached_pairs(pairs, pair_dir, unit, progress)
    sub = SubProgress(progress, 0.02 + 0.73 * (n_reused / len(pairs)), 0.75)
    with executor:
        for _i, summary in run_units(executor, match_pair, units, sub, label="pair",
                                     describe=lambda u: f"{u.vi.name} + {u.vj.name}", cancel_dir=dense_dir):
            summaries.append(summary)
    journal.timings["matching"] = time.time() - t0
    matched = _matched(summaries, journal.warn)
    secs = [s["seconds"] for s in matched if "seconds" in s]
    mp = sum(s.get("megapixels", 0.0) for s in matched)
    journal.info(f"matching: {len(matched)} pairs ({n_reused} reused from a previous run), "
                 f"{np.mean(secs) if secs else 0:.2f} s per pair, {sum(secs) / max(mp, 1e-9):.2f} s per megapixel, "
                 f"{where}")

    # 3. fusion, image by image
    t0 = time.time()
    files = _fuse(block, summaries, pair_dir, options, dense_dir, threads, progress)
    journal.timings["fusion"] = time.time() - t0
    return DensePoints(files, len(matched), n_reused)


def _pair_cache(dense_dir: str, model_fp: Dict[str, str], scale: float, block: int, options: DenseOptions) -> str:
    """The folder of this model's and these settings' depth maps (caches of others removed, partial files too)."""
    key = fingerprint({"v": CACHE_VERSION, "model": model_fp, "scale": scale, "block": block,
                       "uniq": options.uniqueness, "lr": options.lr_tolerance, "fine_uniq": options.fine_uniqueness,
                       "equalize": options.equalize, "flat_block": options.flat_sgbm_block()})
    pair_dir = os.path.join(dense_dir, f"pairs-{key}")
    for name in os.listdir(dense_dir):  # caches of other models / settings
        if name.startswith("pairs-") and name != f"pairs-{key}":
            shutil.rmtree(os.path.join(dense_dir, name), ignore_errors=True)
    os.makedirs(pair_dir, exist_ok=True)
    for name in os.listdir(pair_dir):
        if ".partial" in name:
            os.unlink(os.path.join(pair_dir, name))
    atomic_write_text(os.path.join(pair_dir, "cache.json"),
                      json.dumps({"model": model_fp, "scale": scale, "block": block}, indent=1))
    return pair_dir


def _cached_pairs(pairs: List[PairInfo], pair_dir: str, unit: Callable[[PairInfo, str], PairUnit],
                  progress: Progress) -> Tuple[List[PairUnit], List[dict], int]:
    """(units still to match, summaries of the pairs a previous run matched, how many were reused)."""
    units, done_pairs = [], []
    for p in pairs:
        out = os.path.join(pair_dir, f"{p.i}-{p.j}.npz")
        if os.path.isfile(out):
            done_pairs.append((p, out))
            continue
        units.append(unit(p, out))
    n_reused = len(done_pairs)
    if n_reused:
        progress.info(f"resuming: {n_reused} of {len(pairs)} pairs already matched")
    summaries = []
    for p, out in done_pairs:
        try:
            summaries.append(read_pair_summary(out))
        except (OSError, ValueError, KeyError):  # damaged cache file: match again
            os.unlink(out)
            units.append(unit(p, out))
            n_reused -= 1
    return units, summaries, n_reused


def _matched(summaries: List[dict], warn: Say) -> List[dict]:
    """The summaries of the pairs that matched; a warning for each skipped one; DenseError if none matched."""
    skipped = [s for s in summaries if s.get("skipped")]
    for s in skipped:
        warn(f"pair {s['i']} + {s['j']} skipped: {s['skipped']}")
    matched = [s for s in summaries if not s.get("skipped")]
    if not matched:
        raise DenseError("no stereo pair could be rectified and matched: " + "; ".join(
            s["skipped"] for s in skipped[:5]))
    return matched


def _fuse(block: DenseBlock, summaries: List[dict], pair_dir: str, options: DenseOptions, dense_dir: str,
          threads: int, progress: Progress) -> List[PointFile]:
    """Fuse the depth maps of every image in ``min_consistent`` or more matched pairs -> point files."""
    views, pairs = block.views, block.pairs
    by_key = {s["key"]: s for s in summaries}
    per_image: Dict[int, List[Tuple[str, str, float]]] = {}
    for p in pairs:
        s = by_key.get(f"{p.i}-{p.j}")
        if s is None or s.get("skipped"):
            continue
        path = os.path.join(pair_dir, f"{p.i}-{p.j}.npz")
        per_image.setdefault(p.i, []).append((path, "i", float(s.get("rel_err", 0.01))))
        per_image.setdefault(p.j, []).append((path, "j", float(s.get("rel_err", 0.01))))
    fused_dir = _fresh_fused_dir(dense_dir)
    need = 1 if options.sole_pair else options.min_consistent  # a sole pair's ground needs no second pair
    region = camera_hull(views)  # ... under the block only
    lonely = [views[i].name for i, m in per_image.items() if len(m) < need]
    if lonely:
        progress.info(f"{len(lonely)} image(s) are in fewer than {need} matched pairs and add no "
                      f"points of their own: {', '.join(lonely[:6])}{' ...' if len(lonely) > 6 else ''}")
    funits = [FuseUnit(views[i], options.scale, maps, options.depth_tolerance_px, options.min_consistent,
                       os.path.join(fused_dir, f"{i}.npz"), threads, sky_margin_deg=options.sky_margin_deg,
                       sole_pair=options.sole_pair, sole_region=region)
              for i, maps in sorted(per_image.items()) if len(maps) >= need]
    files: List[PointFile] = []
    executor = make_executor(options.workers, options.executor, options.scheduler,
                             unit_memory=unit_memory(views, options.scale))
    with executor:
        for _i, r in run_units(executor, fuse_image, funits, SubProgress(progress, 0.75, 0.88), label="fusion",
                               describe=lambda u: u.view.name, cancel_dir=dense_dir):
            if r["points"] > 0:
                files.append(PointFile(r["path"], tuple(r["bbox"]), r["points"], tuple(r["robust_bbox"])))
    return files


def camera_hull(views: Dict[int, View]) -> np.ndarray:
    """The convex hull (local x, y, counter-clockwise) of the camera centres; no vertex where they span no area
    (one strip: no ground is under the block, and every pixel needs two pairs as before)."""
    from .grid import convex_hull_xy

    hull = convex_hull_xy(np.array([v.centre[:2] for v in views.values()]))
    if len(hull) < 3:
        return np.zeros((0, 2))
    x, y = hull[:, 0], hull[:, 1]
    area = 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    span = float(np.ptp(x) + np.ptp(y))
    return hull if area > 1e-3 * span * span else np.zeros((0, 2))


def _fresh_fused_dir(dense_dir: str) -> str:
    fused_dir = os.path.join(dense_dir, "fused")
    shutil.rmtree(fused_dir, ignore_errors=True)
    os.makedirs(fused_dir)
    return fused_dir


# ---------------------------------------------------------------------------
# cuda: COLMAP patch-match stereo + fusion
# ---------------------------------------------------------------------------

def cuda_points(views: Dict[int, View], scale: float, dense_dir: str, model_dir: str, images_dir: str,
                model_fp: Dict[str, str], progress: Progress) -> Tuple[List[PointFile], int]:
    """COLMAP patch-match stereo + fusion (CUDA builds of pycolmap only): (points as one point file, 0 reused)."""
    pycolmap = load_pycolmap("dense matching on CUDA")
    mvs = os.path.join(dense_dir, "mvs")
    key = fingerprint({"model": model_fp, "scale": scale})
    key_file = os.path.join(mvs, "archaeoortho-key.txt")
    if os.path.isdir(mvs) and (not os.path.isfile(key_file) or _read_text(key_file).strip() != key):
        shutil.rmtree(mvs, ignore_errors=True)  # built from another model or scale
    fused_dir = _fresh_fused_dir(dense_dir)
    max_size = int(max(max(v.width, v.height) for v in views.values()) * scale)
    with CancelWatcher(progress) as token:
        progress.report(0.0, "undistorting images (COLMAP)")
        if not os.path.isdir(os.path.join(mvs, "stereo")):
            uo = pycolmap.UndistortCameraOptions()
            uo.max_image_size = max_size
            pycolmap.undistort_images(mvs, model_dir, images_dir, undistort_options=uo, cancellation_token=token)
            atomic_write_text(key_file, key)
        progress.report(0.1, "patch-match stereo (COLMAP, CUDA)")
        pm = pycolmap.PatchMatchOptions()
        pm.max_image_size = max_size
        pm.geom_consistency = True
        pycolmap.patch_match_stereo(mvs, options=pm, cancellation_token=token)
        progress.report(0.8, "stereo fusion (COLMAP)")
        fo = pycolmap.StereoFusionOptions()
        fo.max_image_size = max_size
        fused = pycolmap.stereo_fusion(os.path.join(mvs, "fused.ply"), mvs, options=fo, output_type="PLY",
                                       cancellation_token=token)
    pts = [(np.asarray(p.xyz), np.asarray(p.color)) for p in fused.points3D.values()]
    xyz = np.array([p[0] for p in pts], dtype=np.float32).reshape(-1, 3)
    rgb = np.array([p[1] for p in pts], dtype=np.uint8).reshape(-1, 3)
    path = os.path.join(fused_dir, "cuda.npz")
    save_npz(path, xyz=xyz, rgb=rgb)
    if len(xyz) == 0:
        return [], 0
    lo = np.percentile(xyz[:, :2], 0.5, axis=0)
    hi = np.percentile(xyz[:, :2], 99.5, axis=0)
    bbox = (*xyz[:, :2].min(axis=0), *xyz[:, :2].max(axis=0))
    return [PointFile(path, tuple(float(v) for v in bbox), len(xyz), (lo[0], lo[1], hi[0], hi[1]))], 0


def _read_text(path: str) -> str:
    with open(path, encoding="utf-8") as f:
        return f.read()
