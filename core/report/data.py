"""Everything the report reads from a workspace, loaded once, and the figures derived from the model.

Every path comes from :class:`core.project.layout.Layout`.  A JSON product that exists but cannot be read is
a :class:`ReportError` (a missing one is None: its section says the stage has not run).
"""
from __future__ import annotations

import json
import os
from typing import Any, Dict, Optional, Tuple

import numpy as np

from ..common.errors import require
from ..common.files import read_json_record
from ..common.progress import Progress
from ..georef.uncertainty import collect_observations
from ..io.raster import RasterError, RasterFile
from ..project.layout import Layout
from ..project.stages import ALIGN, ORTHOPHOTO
from ..project.workspace import Workspace
from .errors import ReportError
from .figures import hull
from .html import crs_label


def _read_json(path: str) -> Optional[Dict[str, Any]]:
    return read_json_record(path, ReportError)


class ReportData:
    """The workspace's manifest (as it was before the report stage), alignment, residuals, transform,
    screening and sparse model with its observations."""

    def __init__(self, ws: Workspace, progress: Progress):
        self.ws = ws
        self.layout = lay = Layout(ws)
        self.manifest = json.loads(json.dumps(ws.data, default=str))  # as it was before the report stage
        self.alignment = _read_json(lay.alignment_json)
        self.georeferenced = lay.is_georeferenced()
        self.residuals = _read_json(lay.residuals_json) if self.georeferenced else None
        self.frame = lay.load_transform() if self.georeferenced else None
        self.offset = self.frame.offset if self.frame is not None else np.zeros(3)
        self.crs = ws.crs if self.georeferenced else None
        self.crs_label = crs_label(self.crs) if self.crs else None
        self.screening = _read_json(lay.screening_json)
        self.rec = None
        self.obs = None
        model = lay.newest_model_dir()
        if ws.stage_done(ALIGN) and os.path.isdir(model):
            pycolmap = require("pycolmap", "reading the sparse model")
            progress.report(0.0, "reading the sparse model")
            self.rec = pycolmap.Reconstruction()
            self.rec.read_binary(model)
            self.obs = collect_observations(self.rec)
        self.model_dir = model
        self.unit = "m" if self.georeferenced else "model units"

    # --- products --------------------------------------------------------------------------------
    def stage_record(self, name: str) -> Dict[str, Any]:
        return self.manifest.get("stages", {}).get(name, {})

    def dsm_path(self) -> Optional[str]:
        return self.layout.dsm()

    def orthomosaic_path(self) -> Optional[str]:
        """The orthophoto stage's recorded output, else <workspace>/orthomosaic.tif; None if absent."""
        rel = (self.stage_record(ORTHOPHOTO).get("outputs") or {}).get("orthomosaic")
        for path in ([self.layout.resolve(rel)] if rel else []) + [self.layout.default_orthomosaic]:
            if os.path.isfile(path):
                return path
        return None

    def ortho_resolution(self) -> Optional[float]:
        path = self.orthomosaic_path()
        if not path:
            return None
        try:
            with RasterFile(path, "orthomosaic") as r:
                return abs(r.geotransform[1]) if r.geotransform else None
        except RasterError:
            return None

    # --- derived ---------------------------------------------------------------------------------
    def centres(self) -> np.ndarray:
        rec, obs = self.rec, self.obs
        return np.array([np.asarray(rec.image(int(i)).projection_center(), dtype=float) for i in obs.image_ids]
                        ).reshape(-1, 3) + self.offset

    def tie_xyz(self) -> np.ndarray:
        return self.obs.xyz + self.offset

    def gsd(self) -> Optional[float]:
        """Median over images of (median depth of the image's tie points / focal length in pixels)."""
        if self.rec is None or not len(self.obs.img):
            return None
        vals = []
        o = self.obs
        order = np.argsort(o.img, kind="stable")
        bounds = np.searchsorted(o.img[order], np.arange(len(o.image_ids) + 1))
        for k, iid in enumerate(o.image_ids):
            rows = order[bounds[k]:bounds[k + 1]]
            if not len(rows):
                continue
            im = self.rec.image(int(iid))
            mat = np.asarray(im.cam_from_world().matrix())
            depth = o.xyz[o.pt[rows]] @ mat[2, :3] + mat[2, 3]
            depth = depth[depth > 0]
            cam = self.rec.cameras[im.camera_id]
            f = float(np.mean([cam.params[i] for i in cam.focal_length_idxs()]))
            if len(depth) and f > 0:
                vals.append(float(np.median(depth)) / f)
        return float(np.median(vals)) if vals else None

    def footprint(self) -> Optional[np.ndarray]:
        if self.rec is None or not len(self.obs.xyz):
            return None
        return hull(self.tie_xyz()[:, :2])

    def shared_points(self) -> np.ndarray:
        import scipy.sparse as sp

        o = self.obs
        n_i, n_p = len(o.image_ids), len(o.point_ids)
        a = sp.csr_matrix((np.ones(len(o.img)), (o.pt, o.img)), shape=(n_p, n_i))
        a.data[:] = 1.0
        c = (a.T @ a).toarray()
        np.fill_diagonal(c, 0)
        return c

    def per_image_error(self) -> Tuple[np.ndarray, np.ndarray]:
        o = self.obs
        err = o.error
        ok = np.isfinite(err)
        n = np.bincount(o.img[ok], minlength=len(o.image_ids))
        s = np.bincount(o.img[ok], weights=err[ok], minlength=len(o.image_ids))
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(n > 0, s / np.maximum(n, 1), np.nan), n

