"""Where every product of a workspace lives, and typed loading and saving of the shared ones.

This module alone spells out product paths.  Stages, the report and the dock ask it for a path or a loaded
product instead of joining folder names themselves::

    lay = Layout(ws)
    rec, frame = lay.load_georef_model()  # frame: GeorefFrame (world = local + frame.offset)
    dsm = lay.dsm()

Paths are absolute.  ``rel()`` turns a path into what the manifest records (relative inside the workspace,
absolute outside it).
"""
from __future__ import annotations

import json
import os
from typing import Any, Dict, Optional, Tuple

from ..common.errors import ArchaeoOrthoError, require
from ..common.files import atomic_write_text
from .frame import GeorefFrame
from .stages import ALIGN, DSM, GEOREFERENCE, MODEL, ORTHOPHOTO, TERRAIN
from .workspace import Workspace

# folder and file names inside a workspace (the workspace format: changing one breaks old workspaces)
MANIFEST = "workspace.json"
PREPARED_DIR = "prepared"
SCREENING_JSON = "screening.json"
SCANS_JSON = "scans.json"
MASKS_DIR = "masks"
SFM_DIR = "sfm"
DATABASE = "database.db"
MODEL_DIR = "model"
ALIGNMENT_JSON = "alignment.json"
CAMERAS_GPKG = "cameras.gpkg"
GEOREF_DIR = "georef"
TRANSFORM_JSON = "transform.json"
RESIDUALS_JSON = "residuals.json"
RESIDUALS_GPKG = "residuals.gpkg"
FOOTPRINTS_GPKG = "footprints.gpkg"  # written by the dock (qgisio/layers.py)
CONTROL_JSON = "control.json"
AUTOCONTROL_JSON = "autocontrol.json"  # the automatic control's candidates (role auto) and figures
AUTOCONTROL_FAILED_JSON = "autocontrol-failed.json"  # the candidates of a run that failed (the record in use stays)
REFERENCE_ORTHO_TIF = "reference-ortho.tif"  # in georef/: a web / virtual reference layer saved for the block
REFERENCE_DSM_TIF = "reference-dsm.tif"
EDITOR_JSON = "gcp_editor.json"
ADJUSTMENT_INPUTS_JSON = "adjustment_inputs.json"
DEM_CONTROL_JSON = "dem_control.json"  # in georef/: the co-registration on a reference DEM and its control points
TARGETS_DIR = "targets"  # in georef/: Find targets' products
TARGETS_GCP_LIST = "gcp_list.txt"  # the observations found (ODM form, read by Georeference)
TARGETS_GPKG = "targets.gpkg"  # the found marks for review
TARGETS_JSON = "targets.json"  # every observation with its quality, the counts and what did not fit
DENSE_DIR = "dense"
DSM_TIF = "dsm.tif"
DSM_SOURCE_TIF = "dsm-source.tif"  # in dense/: 1 measured, 2 interpolated (a hole filled), 3 removed (a blunder), 0 nodata
ORTHOMOSAIC_TIF = "orthomosaic.tif"
ORTHO_RADIOMETRY_JSON = "orthomosaic-radiometry.json"  # the exposure gains / radiometric model applied
REPORT_HTML = "report.html"
UNCERTAINTY_DIR = "uncertainty"
DTM_TIF = "dtm.tif"
TERRAIN_DIR = "terrain"
DTM_SOURCE_TIF = "dtm-source.tif"  # 1 measured ground, 2 interpolated under objects / in holes
RELIEF_DIR = "relief"
CONTOURS_GPKG = "contours.gpkg"
CLASSIFIED_LAS = "points-classified.las"
MODEL3D_DIR = "model3d"  # the textured 3-D model (core.model): model.obj / .glb / .ply, atlases, 3D Tiles


class LayoutError(ArchaeoOrthoError, RuntimeError):
    """A product a stage needs is missing: the message names the stage to run."""


def read_json(path: str) -> Optional[Any]:
    """A JSON product, or None when it does not exist or cannot be read."""
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def write_json(path: str, obj: Any) -> str:
    """Write a JSON product atomically; returns the path."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    atomic_write_text(path, json.dumps(obj, indent=2, default=str))
    return path


class Layout:
    """The products of one workspace."""

    def __init__(self, ws: Workspace):
        self.ws = ws
        self.root = ws.root

    def path(self, *parts: str) -> str:
        return os.path.join(self.root, *parts)

    def rel(self, path: str) -> str:
        """``path`` as the manifest records it: relative inside the workspace, absolute outside."""
        rel = os.path.relpath(os.path.abspath(path), self.root)
        return path if rel.startswith("..") else rel

    def resolve(self, recorded: str) -> str:
        """A path recorded in the manifest as an absolute path."""
        return recorded if os.path.isabs(recorded) else self.path(recorded)

    # --- prepare ---------------------------------------------------------
    @property
    def manifest(self) -> str:
        return self.path(MANIFEST)

    @property
    def prepared_dir(self) -> str:
        return self.path(PREPARED_DIR)

    @property
    def screening_json(self) -> str:
        return self.path(SCREENING_JSON)

    @property
    def scans_json(self) -> str:
        return self.path(SCANS_JSON)

    @property
    def masks_dir(self) -> str:
        return self.path(MASKS_DIR)

    # --- align -----------------------------------------------------------
    @property
    def sfm_dir(self) -> str:
        return self.path(SFM_DIR)

    @property
    def database(self) -> str:
        return self.path(SFM_DIR, DATABASE)

    @property
    def staged_database(self) -> str:
        """The database of an alignment re-run in progress: it replaces ``database`` only when the run succeeds."""
        return self.path(SFM_DIR, "database.staged.db")

    @property
    def aligned_model_dir(self) -> str:
        return self.path(SFM_DIR, MODEL_DIR)

    @property
    def alignment_json(self) -> str:
        return self.path(SFM_DIR, ALIGNMENT_JSON)

    @property
    def cameras_gpkg(self) -> str:
        return self.path(CAMERAS_GPKG)

    def has_aligned_model(self) -> bool:
        return self.ws.stage_done(ALIGN) and os.path.isdir(self.aligned_model_dir)

    def load_aligned_model(self):
        """The aligned model (pycolmap.Reconstruction, model frame); LayoutError if the workspace has none."""
        if not self.has_aligned_model():
            raise LayoutError(f"workspace {self.root} has no aligned model: run 'Align images' first")
        return self._read_model(self.aligned_model_dir)

    def alignment(self) -> Dict[str, Any]:
        """sfm/alignment.json (figures of the alignment), {} if absent."""
        return read_json(self.alignment_json) or {}

    def camera_intrinsics(self) -> Dict[int, Dict[str, Any]]:
        """camera id -> what the alignment recorded of its interior orientation (``intrinsics`` in
        sfm/alignment.json, core.align.calibrated.intrinsics_record: mode fixed / refined / estimated, source,
        COLMAP model, given values and sigmas by parameter name, final values); {} for an alignment without it."""
        rows = self.alignment().get("intrinsics") or []
        return {int(r["camera_id"]): r for r in rows if isinstance(r, dict) and "camera_id" in r}

    # --- georeference ----------------------------------------------------
    @property
    def georef_dir(self) -> str:
        return self.path(GEOREF_DIR)

    @property
    def georef_model_dir(self) -> str:
        return self.path(GEOREF_DIR, MODEL_DIR)

    @property
    def transform_json(self) -> str:
        return self.path(GEOREF_DIR, TRANSFORM_JSON)

    @property
    def residuals_json(self) -> str:
        return self.path(GEOREF_DIR, RESIDUALS_JSON)

    @property
    def residuals_gpkg(self) -> str:
        return self.path(GEOREF_DIR, RESIDUALS_GPKG)

    @property
    def footprints_gpkg(self) -> str:
        return self.path(GEOREF_DIR, FOOTPRINTS_GPKG)

    @property
    def control_json(self) -> str:
        return self.path(GEOREF_DIR, CONTROL_JSON)

    @property
    def autocontrol_json(self) -> str:
        return self.path(GEOREF_DIR, AUTOCONTROL_JSON)

    @property
    def autocontrol_failed_json(self) -> str:
        """The candidates of the last automatic control that failed: autocontrol.json stays the record of the
        control in use."""
        return self.path(GEOREF_DIR, AUTOCONTROL_FAILED_JSON)

    @property
    def reference_ortho_tif(self) -> str:
        return self.path(GEOREF_DIR, REFERENCE_ORTHO_TIF)

    @property
    def reference_dsm_tif(self) -> str:
        return self.path(GEOREF_DIR, REFERENCE_DSM_TIF)

    @property
    def editor_json(self) -> str:
        return self.path(GEOREF_DIR, EDITOR_JSON)

    @property
    def adjustment_inputs_json(self) -> str:
        return self.path(GEOREF_DIR, ADJUSTMENT_INPUTS_JSON)

    @property
    def targets_dir(self) -> str:
        return self.path(GEOREF_DIR, TARGETS_DIR)

    @property
    def targets_gcp_list(self) -> str:
        return self.path(GEOREF_DIR, TARGETS_DIR, TARGETS_GCP_LIST)

    @property
    def targets_gpkg(self) -> str:
        return self.path(GEOREF_DIR, TARGETS_DIR, TARGETS_GPKG)

    @property
    def targets_json(self) -> str:
        return self.path(GEOREF_DIR, TARGETS_DIR, TARGETS_JSON)

    @property
    def dem_control_json(self) -> str:
        return self.path(GEOREF_DIR, DEM_CONTROL_JSON)

    def is_georeferenced(self) -> bool:
        return self.ws.stage_done(GEOREFERENCE) and os.path.isdir(self.georef_model_dir)

    def require_georeferenced(self, why: str = "") -> None:
        if not self.is_georeferenced():
            state = self.ws.stage(GEOREFERENCE).get("status", "pending")
            raise LayoutError(f"workspace {self.root} is not georeferenced (georeference stage: {state}): run "
                              f"'Georeference' first{'; ' + why if why else ''}")

    def load_transform(self) -> GeorefFrame:
        """georef/transform.json as a typed frame (world = local + offset, in its CRS)."""
        t = read_json(self.transform_json)
        if t is None:
            raise LayoutError(f"{self.transform_json} is missing or damaged: run 'Georeference' again")
        return GeorefFrame.from_dict(t, self.transform_json)

    def load_georef_model(self) -> Tuple[Any, GeorefFrame]:
        """(pycolmap.Reconstruction in the local frame, its GeorefFrame) of a georeferenced workspace."""
        self.require_georeferenced()
        return self._read_model(self.georef_model_dir), self.load_transform()

    def newest_model_dir(self) -> str:
        """The georeferenced model if there is one, else the aligned model."""
        return self.georef_model_dir if self.is_georeferenced() else self.aligned_model_dir

    def residuals(self) -> Optional[Dict[str, Any]]:
        return read_json(self.residuals_json)

    # --- dense -----------------------------------------------------------
    @property
    def dense_dir(self) -> str:
        return self.path(DENSE_DIR)

    @property
    def default_dsm(self) -> str:
        return self.path(DSM_TIF)

    @property
    def dsm_source(self) -> str:
        """Beside the DSM, on its grid: which cells are measured (1) and which interpolated (2, holes filled)."""
        return self.path(DENSE_DIR, DSM_SOURCE_TIF)

    def dsm(self) -> Optional[str]:
        """The workspace's DSM: the DSM stage's recorded output, else <workspace>/dsm.tif; None if absent."""
        out = (self.ws.stage(DSM).get("outputs") or {}).get("dsm")
        if out:
            p = self.resolve(out)
            if os.path.isfile(p):
                return p
        return self.default_dsm if os.path.isfile(self.default_dsm) else None

    # --- ortho / report --------------------------------------------------
    @property
    def default_orthomosaic(self) -> str:
        return self.path(ORTHOMOSAIC_TIF)

    def orthomosaic(self) -> Optional[str]:
        """The workspace's orthomosaic: the orthophoto stage's recorded output, else <workspace>/orthomosaic.tif;
        None if absent."""
        out = (self.ws.stage(ORTHOPHOTO).get("outputs") or {}).get("orthomosaic")
        if out:
            p = self.resolve(out)
            if os.path.isfile(p):
                return p
        return self.default_orthomosaic if os.path.isfile(self.default_orthomosaic) else None

    @property
    def ortho_radiometry_json(self) -> str:
        """The orthophoto's radiometric correction (core.ortho.radiometry_record), for the model's texture."""
        return self.path(ORTHO_RADIOMETRY_JSON)

    @property
    def default_report(self) -> str:
        return self.path(REPORT_HTML)

    @property
    def uncertainty_dir(self) -> str:
        return self.path(UNCERTAINTY_DIR)

    # --- terrain ---------------------------------------------------------
    @property
    def default_dtm(self) -> str:
        return self.path(DTM_TIF)

    @property
    def dtm_source(self) -> str:
        """Beside the DTM: which cells are measured ground (1) and which interpolated (2)."""
        return self.path(TERRAIN_DIR, DTM_SOURCE_TIF)

    @property
    def contours_gpkg(self) -> str:
        return self.path(TERRAIN_DIR, CONTOURS_GPKG)

    @property
    def classified_point_cloud(self) -> str:
        return self.path(TERRAIN_DIR, CLASSIFIED_LAS)

    def relief(self, key: str, source: str = "dtm") -> str:
        """A relief visualisation (core.terrain.options.VISUALISATIONS) of the DTM or DSM."""
        return self.path(TERRAIN_DIR, RELIEF_DIR, f"{source}-{key}.tif")

    def dtm(self) -> Optional[str]:
        """The workspace's DTM: the terrain stage's recorded output, else <workspace>/dtm.tif; None if absent."""
        out = (self.ws.stage(TERRAIN).get("outputs") or {}).get("dtm")
        if out:
            p = self.resolve(out)
            if os.path.isfile(p):
                return p
        return self.default_dtm if os.path.isfile(self.default_dtm) else None

    def point_cloud(self) -> Optional[str]:
        """The DSM stage's point cloud (LAS), None if it wrote none."""
        out = (self.ws.stage(DSM).get("outputs") or {}).get("point_cloud")
        p = self.resolve(out) if out else None
        return p if p and os.path.isfile(p) else None

    # --- 3-D model -------------------------------------------------------
    @property
    def default_model3d_dir(self) -> str:
        return self.path(MODEL3D_DIR)

    def model3d_dir(self) -> Optional[str]:
        """The folder of the workspace's textured 3-D model: the model stage's recorded output; None if absent."""
        out = (self.ws.stage(MODEL).get("outputs") or {}).get("folder")
        p = self.resolve(out) if out else None
        return p if p and os.path.isdir(p) else None

    # --- helpers ---------------------------------------------------------
    def model_fingerprints(self, model_dir: Optional[str] = None, prefix: str = "model/") -> Dict[str, str]:
        """Fingerprints of a model's .bin files (what a stage built on it records as inputs), keyed
        ``prefix`` + file name (the DSM stage records bare names: prefix "")."""
        from ..common.files import file_fingerprint

        model_dir = model_dir or self.georef_model_dir
        return {prefix + n: file_fingerprint(os.path.join(model_dir, n))
                for n in sorted(os.listdir(model_dir)) if n.endswith(".bin")}

    @staticmethod
    def _read_model(folder: str):
        pycolmap = require("pycolmap", "reading the sparse model")
        rec = pycolmap.Reconstruction()
        rec.read_binary(folder)
        return rec
