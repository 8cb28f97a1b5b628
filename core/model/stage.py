"""The model stage (Build 3-D model) of a workspace: the DSM's surface as a mesh within a face budget, textured
from the oriented photos, written as OBJ / GLB / PLY and OGC 3D Tiles in ``<workspace>/model3d/`` (or
``options.output_dir``).

The folder is written whole beside the old one and swapped in at the end: a failed or cancelled run leaves the
previous model as it was."""
from __future__ import annotations

import os
import time
from dataclasses import asdict, dataclass, field
from typing import Dict, List, Optional

import numpy as np

from ..common.files import atomic_output, file_fingerprint, fingerprint
from ..common.progress import NullProgress, Progress, SubProgress, check_cancel
from ..ortho.radiometry_record import photo_correction
from ..ortho.surface import Dsm
from ..project.layout import Layout, read_json
from ..project.stages import MODEL, ORTHOPHOTO, run_stage
from ..project.workspace import Workspace
from .geometry import PRE_DECIMATION, dsm_mesh, vertex_normals
from .inputs import SIDECAR, check_memory, check_output, resolve_geometry, workspace_cameras, workspace_dsm
from .options import ModelError, ModelOptions
from .texture import corrected_reader, read_rgb, texture_mesh
from .tiles import check_georeferenced, write_model_tiles
from .types import MeshPart, TexturedMesh
from .writers import encode_image, write_frame, write_glb, write_obj, write_ply

BASE = "model"


@dataclass
class ModelResult:
    workspace: str
    folder: str
    files: List[str]
    faces: int
    textured_faces: int
    atlases: List[List[int]]
    notes: List[str] = field(default_factory=list)
    timings: Dict[str, float] = field(default_factory=dict)


def stage(workspace_dir: str, options: Optional[ModelOptions] = None,
          progress: Optional[Progress] = None) -> ModelResult:
    """Build the workspace's textured 3-D model (see the module docstring).  Bad input is refused before any work
    (ModelError naming the fix)."""
    options = options or ModelOptions()
    progress = progress or NullProgress()
    lay = Layout(Workspace.open(workspace_dir))
    dsm_path = workspace_dsm(lay)
    cams, frame = workspace_cameras(lay)
    folder = os.path.abspath(options.output_dir) if options.output_dir else lay.default_model3d_dir
    check_output(folder, lay, [dsm_path, lay.ws.data.get("images_dir"), *(c.path for c in cams)])
    geometry, notes = resolve_geometry(options, cams)
    check_memory(options, options.face_budget * PRE_DECIMATION, max(c.camera.width * c.camera.height for c in cams))
    for n in notes:
        progress.warning(n)
    crs = frame.crs or lay.ws.crs
    if "tiles" in options.formats:
        check_georeferenced(crs)  # a block in a model frame has no place on the globe: before any work
    params = {"geometry": geometry, "output_dir": folder,
              "options": {k: v for k, v in asdict(options).items() if k != "output_dir"}}
    inputs = {"dsm": file_fingerprint(dsm_path), "images": fingerprint(sorted(c.name for c in cams)),
              **lay.model_fingerprints()}
    radiometry = _radiometry(lay) if options.texture else None
    if radiometry:
        inputs["radiometry"] = fingerprint(radiometry)
        progress.info("the photos are corrected as the orthophoto's (exposure, vignetting, hot spot)")
    timings: Dict[str, float] = {}
    with run_stage(lay.ws, MODEL, params, inputs) as run:
        t0 = time.time()
        mesh, step = _dsm_surface(dsm_path, crs, frame.offset, options.face_budget)
        timings["mesh"] = time.time() - t0
        progress.report(0.1, f"mesh: {mesh.face_count} faces (DSM grid reduced {step} x)")
        check_cancel(progress)
        t0 = time.time()
        textured, extra = 0, {}
        if options.texture:
            part = mesh.parts[0]
            reader = corrected_reader(read_rgb, photo_correction(radiometry))
            tex = texture_mesh(part.vertices.astype(np.float64), part.faces.astype(np.int64), part.normals, cams,
                               options.atlas_size, options.max_atlases, SubProgress(progress, 0.1, 0.85), reader)
            mesh.parts, textured = tex.parts, tex.textured_faces
            extra = {"seen_faces": tex.seen_faces, "charts": tex.charts, "texture_scale": round(tex.scale, 4)}
            timings["texture"] = time.time() - t0
        t0 = time.time()
        figures = {"faces": mesh.face_count, "textured_faces": textured, "geometry": geometry, "dsm_step": step,
                   "atlases": [[int(p.atlas.shape[1]), int(p.atlas.shape[0])] for p in mesh.parts
                               if p.atlas is not None], **extra}
        with atomic_output(folder) as tmp:
            os.makedirs(tmp)
            files = _write(mesh, tmp, options, figures)
        files = [os.path.join(folder, os.path.relpath(f, tmp)) for f in files]
        timings["write"] = time.time() - t0
        for k, v in timings.items():
            lay.ws.record_timing(MODEL, k, v)
        run.finish(outputs={"folder": lay.rel(folder), **{os.path.splitext(f)[1][1:]: lay.rel(f) for f in files
                                                           if f.endswith((".obj", ".glb", ".ply"))}},
                   results={**figures, "textured_fraction": textured / max(mesh.face_count, 1), "notes": notes,
                            "radiometry": bool(radiometry)})
    progress.report(1.0, "3-D model done")
    return ModelResult(lay.root, folder, files, mesh.face_count, textured, figures["atlases"], notes, timings)


def _dsm_surface(dsm_path: str, crs: Optional[str], origin: np.ndarray, budget: int):
    """(a one-part TexturedMesh of the DSM's surface in the local frame, the grid step), read at most about the
    cells the decimation takes (a coarser grid where the DSM is larger)."""
    dsm = Dsm(dsm_path, crs)
    try:
        z, gx, gy = dsm.coarse(dsm.bounds, max_cells=PRE_DECIMATION * budget)
        if z.size < 4:
            raise ModelError(f"DSM {dsm_path} has too few cells for a surface")
        dx, dy = gx[0, 1] - gx[0, 0] if z.shape[1] > 1 else dsm.res, gy[1, 0] - gy[0, 0] if z.shape[0] > 1 else -dsm.res
        gt = (gx[0, 0] - dx / 2, dx, 0.0, gy[0, 0] - dy / 2, 0.0, dy)
        verts, faces, step = dsm_mesh(z, gt, origin, budget)
        if not len(faces):
            raise ModelError(f"DSM {dsm_path} has no two neighbouring cells with heights: no surface to mesh")
        wkt = dsm.info.crs_wkt or None
    finally:
        dsm.close()
    part = MeshPart(verts.astype(np.float32), faces.astype(np.uint32), normals=vertex_normals(verts, faces))
    return TexturedMesh(np.asarray(origin, dtype=np.float64), [part], wkt if crs else None, crs or ""), step


def _radiometry(lay: Layout) -> Optional[dict]:
    """The orthophoto's radiometric correction when the workspace has a current one (its stage done after the
    DSM it was made on), else None (the photos as they are)."""
    if not lay.ws.stage_done(ORTHOPHOTO):  # never run, failed, or stale (the DSM or the model ran again)
        return None
    return read_json(lay.ortho_radiometry_json)


def _write(mesh: TexturedMesh, folder: str, options: ModelOptions, figures: dict) -> List[str]:
    images = [encode_image(p.atlas, "jpeg", options.jpeg_quality) if p.atlas is not None else None
              for p in mesh.parts]
    files: List[str] = []
    if "obj" in options.formats:
        files += write_obj(mesh, os.path.join(folder, BASE + ".obj"), images)
    if "glb" in options.formats:
        files.append(write_glb(mesh, os.path.join(folder, BASE + ".glb"), options.jpeg_quality, images))
    if "ply" in options.formats:
        files.append(write_ply(mesh, os.path.join(folder, BASE + ".ply")))
    if "tiles" in options.formats:
        files += write_model_tiles(mesh, folder, min(options.atlas_size, 2048), options.jpeg_quality)
    files += write_frame(mesh, folder, os.path.splitext(SIDECAR)[0], figures)
    return files
