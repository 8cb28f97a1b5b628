"""The options of the DSM stage (defaults in this one place), its qualities and engines, and its error."""
from __future__ import annotations

import math
import os
from dataclasses import asdict, dataclass
from typing import Optional

from ..common.errors import ArchaeoOrthoError

QUALITIES = {"full": 1.0, "half": 0.5, "quarter": 0.25}  # QUALITY -> image downscale for matching
ENGINES = ("cpu", "cuda")
CACHE_VERSION = 7  # of the per-pair depth map cache (dense/pairs-<key>/); 2: coarse-to-fine; 3: tiled pyramid;
# 4: uint16 depth maps (x step_i / step_j), stored; 5: equalised pairs, fine_uniqueness; 6: COARSE_FLAT_PX 3;
# 7: window-end minima and streaks dropped (issue 46)

# the automatic flat_block spans about this many of the photo's own pixels: 7 at full quality, 5 at half as the block
# always was (issue 46: a block of 5 px at full quality spans half the ground it spans at half, and the photos' own
# noise and 8 px JPEG blocks weigh on it; 9 matched more of seneca_south's pairs, 0.67 -> 0.82 of their overlap, and
# 98 % of the synthetic farmland, but took its RMSE beyond the cameras' hull from 2.6 to 3.1 GSD; 7: 97.2 %, 2.7)
# 5, the block as it was: 7 took the fixed-wing scene's RMSE under the block from 1.95 to 2.68 GSD and on the
# ground two photos alone see from 2.4 to 4.6 GSD (tests/test_dense_lowtexture.py): kept at 5 until the edges are cleaned
FLAT_BLOCK_PHOTO_PX = 5

# options that say where the work runs, not what it computes (not recorded among the stage's parameters)
EXECUTION_OPTIONS = ("workers", "executor", "scheduler")
# options recorded among the stage's parameters beside the options (the outputs as absolute paths)
STAGE_SETTINGS = ("resolution", "engine", "output_dsm", "output_point_cloud")


class DenseError(ArchaeoOrthoError, RuntimeError):
    """Dense matching cannot run with these inputs; the message says why."""


@dataclass
class DenseOptions:
    """The settings of the DSM stage, checked when made (DenseError naming the bad one)."""

    quality: str = "half"  # QUALITIES: the image downscale for matching
    resolution: float = 0.0  # DSM cell size in metres; 0 = automatic (2 x the median GSD, see pairs.auto_resolution)
    engine: str = "cpu"  # ENGINES: cpu (OpenCV SGBM) or cuda (COLMAP patch-match, pycolmap built with CUDA)
    output_dsm: Optional[str] = None  # the DSM GeoTIFF; None = <workspace>/dsm.tif
    output_point_cloud: Optional[str] = None  # a LAS point cloud; None = none
    partners: int = 5  # at most this many pairs chosen per image (greedy two-fold cover of its tie points)
    min_shared_points: int = 15
    min_baseline_ratio: float = 0.03
    max_baseline_ratio: float = 1.2
    ideal_baseline_ratio: float = 0.3
    max_view_angle: float = 40.0  # degrees between the optical axes
    block_size: int = 0  # SGBM block; 0 = auto (5 at full/half, 3 at quarter)
    uniqueness: int = 10  # SGBM's uniqueness ratio where a level searches the whole range (the coarsest)
    # ... and on the finer levels away from depth edges, which search only around what their coarser level found (a
    # periodic texture's second minimum a period away lies outside that window). Measured for issue 33 (3 against
    # 10, with the equalisation): the full-size farmland block (20 photos of 10 MP, quality half) fields' RMSE 2.46
    # -> 1.90 GSD and cells more than 1 m off 123 -> 0; the small one 90.5 -> 90.7 % measured, RMSE inside the
    # cameras' hull 1.47 -> 1.49 GSD, over its whole DSM 2.10 -> 2.51 GSD (its edge, fewer views)
    fine_uniqueness: int = 3
    # SGBM's block on the coarsest level and, on the finer ones, away from the coarser level's depth edges (where
    # block_size stays: a larger block fattens a crown or a roof); 0 = auto (flat_sgbm_block: 7 at full quality)
    flat_block: int = 0
    equalize: bool = True  # local contrast equalisation (CLAHE) of each rectified pair before matching
    lr_tolerance: float = 1.0  # px
    min_consistent: int = 2  # pairs that must agree on a pixel
    # ... except where one pair alone covers the ground of an image (fusion.sole_pair_depth: two photos alone see it,
    # or the other pairs do not reach it): there its dense matches are kept (issue 46: 17 % of a real fixed-wing
    # block's hull was such ground, all of it interpolated); False: every pixel needs min_consistent pairs
    sole_pair: bool = True
    depth_tolerance_px: float = 1.0  # agreement tolerance, in disparity pixels of the weakest pair
    max_hole_cells: int = 16
    # holes inside the convex hull of the camera centres (or enclosed by data, for one strip) are filled with a smooth
    # 2.5-D surface (push-pull from their borders) up to this many metres from a measured cell, and flagged
    # interpolated in dense/dsm-source.tif; 0 = no such fill (the holes stay nodata)
    fill_max_distance: float = 50.0
    # no dense point from the sky: pixels whose ray points less than this many degrees below the horizontal (the
    # horizon of the georeferenced pose, core.prepare.sky.horizon_keep) are dropped, as are the black pixels of
    # the images' masks; None = keep everything above the horizon (terrain rising above the cameras)
    sky_margin_deg: Optional[float] = 1.0
    workers: int = 0  # 0 = one per core (bounded by memory)
    executor: str = "auto"  # auto / serial / process / thread
    scheduler: Optional[str] = None  # Dask scheduler address

    def __post_init__(self):
        self.quality = (self.quality or "half").lower()
        if self.quality not in QUALITIES:
            raise DenseError(f"unknown QUALITY {self.quality!r}; choose one of {', '.join(QUALITIES)}")
        self.engine = (self.engine or "cpu").lower()
        if self.engine not in ENGINES:
            raise DenseError(f"unknown ENGINE {self.engine!r}; choose one of {', '.join(ENGINES)}")
        if self.resolution is None or not math.isfinite(self.resolution) or self.resolution < 0:
            raise DenseError(f"RESOLUTION must be 0 (automatic) or a positive number of metres, got {self.resolution}")
        self.resolution = float(self.resolution)
        self.output_dsm = os.path.abspath(self.output_dsm) if self.output_dsm else None
        self.output_point_cloud = os.path.abspath(self.output_point_cloud) if self.output_point_cloud else None

    def stage_parameters(self, dsm_path: str) -> dict:
        """What the workspace records of these options (``dsm_path``: the DSM written; where the work runs left
        out)."""
        return {"resolution": self.resolution, "quality": self.quality, "engine": self.engine,
                "output_dsm": dsm_path, "output_point_cloud": self.output_point_cloud,
                "options": {k: v for k, v in asdict(self).items() if k not in EXECUTION_OPTIONS + STAGE_SETTINGS}}

    @property
    def scale(self) -> float:
        """The image downscale of ``quality``."""
        return QUALITIES[self.quality]

    def flat_sgbm_block(self) -> int:
        """SGBM's block away from depth edges: ``flat_block``, or one spanning about FLAT_BLOCK_PHOTO_PX of the
        photo's own pixels (7 at full quality, 5 at half, 3 at quarter); never under :meth:`sgbm_block`; odd."""
        block = max(self.sgbm_block(), self.flat_block or int(round(FLAT_BLOCK_PHOTO_PX * self.scale)))
        return block + 1 if block % 2 == 0 else block

    def sgbm_block(self) -> int:
        """The SGBM block size: ``block_size``, or 3 at quarter quality and 5 above; always odd."""
        block = self.block_size or (3 if self.scale <= 0.25 else 5)
        return block + 1 if block % 2 == 0 else block
