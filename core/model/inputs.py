"""What the model stage reads, checked before any work: the DSM, the oriented photos, the output folder, memory."""
from __future__ import annotations

import math
import os
from typing import List, Optional, Sequence, Tuple

import numpy as np

from ..align.photos import check_photos
from ..common.files import same_path
from ..common.parallel import available_memory
from ..io.images import ImageError
from ..ortho.cameras import OrthoCamera, cameras_from_reconstruction
from ..project.layout import Layout, LayoutError
from ..project.stages import DSM, STALE
from .options import VERTICAL_TILT_DEG, ModelError, ModelOptions

SIDECAR = "model.json"  # the file that marks a folder as a model's (the only kind of folder replaced whole)


def workspace_dsm(lay: Layout) -> str:
    """The workspace's DSM; ModelError when there is none or it is stale."""
    dsm = lay.dsm()
    if not dsm:
        raise ModelError(f"workspace {lay.root} has no DSM: run 'Build DSM' first")
    rec = lay.ws.stage(DSM)
    if rec.get("status") == STALE:
        raise ModelError(f"the DSM of workspace {lay.root} is stale: an earlier stage ran again after it was made; "
                         "run 'Build DSM' again first")
    return dsm


def workspace_cameras(lay: Layout) -> Tuple[List[OrthoCamera], object]:
    """(the oriented photos in the local frame, the GeorefFrame); ModelError when the workspace is not georeferenced
    or a photo is missing or changed."""
    try:
        rec, frame = lay.load_georef_model()
    except LayoutError as e:
        raise ModelError(f"{e}; the 3-D model is built on the DSM, which needs it") from e
    cams = cameras_from_reconstruction(rec, lay.ws.data.get("images_dir") or "", lay.masks_dir)
    if not cams:
        raise ModelError(f"the model of {lay.root} has no oriented photo")
    try:
        check_photos(lay.ws, {c.name: c.path for c in cams})
    except ImageError as e:
        raise ModelError(str(e)) from e
    return cams, frame


def median_tilt_deg(cams: Sequence[OrthoCamera]) -> float:
    """The median angle (degrees) of the photos' optical axes from the nadir (local z is up)."""
    axes = np.array([c.pose.rotation[2] for c in cams])  # the camera's +z (viewing direction) in the local frame
    return float(np.median(np.degrees(np.arccos(np.clip(-axes[:, 2], -1.0, 1.0)))))


def resolve_geometry(options: ModelOptions, cams: Sequence[OrthoCamera]) -> Tuple[str, List[str]]:
    """('dsm', notes): the geometry to build.  The 3-D mesh from the dense points is not built yet: asked for, it
    is refused; an oblique block on 'auto' gets the DSM's surface with a note saying what it lacks."""
    tilt = median_tilt_deg(cams)
    if options.geometry == "points":
        raise ModelError("the 3-D mesh from the fused dense points (geometry 'points') is not available yet: use "
                         "geometry 'dsm' (or 'auto'), the 2.5-D surface of the DSM")
    if options.geometry == "auto" and tilt > VERTICAL_TILT_DEG:
        return "dsm", [f"the photos look {tilt:.0f} degrees from the nadir (an oblique block): the 3-D mesh of the "
                       "dense points is not available yet, so the model is the DSM's 2.5-D surface (no overhangs; "
                       "walls as steep slopes)"]
    return "dsm", []


def check_output(folder: str, lay: Layout, inputs: Sequence[Optional[str]]) -> None:
    """ModelError when the output folder would replace an input or a folder that is not a model's (the stage
    replaces the folder whole)."""
    folder = os.path.abspath(folder)
    for p in [lay.root, *inputs]:
        if not p:
            continue
        p = os.path.abspath(p)
        if same_path(folder, p) or p.startswith(folder.rstrip(os.sep) + os.sep):
            raise ModelError(f"the model's folder {folder} would replace {p}, an input of the model: choose a new "
                             "or empty folder for the model")
    if os.path.isdir(folder) and os.listdir(folder) and not os.path.isfile(os.path.join(folder, SIDECAR)):
        raise ModelError(f"the model's folder {folder} holds other files (it is not a model's folder: no "
                         f"{SIDECAR}): the stage replaces the folder whole; choose a new or empty folder")
    if os.path.exists(folder) and not os.path.isdir(folder):
        raise ModelError(f"the model's folder {folder} is a file: choose a folder")


def check_memory(options: ModelOptions, n_faces: int, largest_photo: int) -> None:
    """ModelError when the atlases, the mesh and one photo would not fit in the memory available now."""
    need = options.atlas_bytes() + n_faces * 400 + largest_photo * 4
    free = available_memory()
    if free is not None and need > free:
        raise ModelError(f"the model needs about {math.ceil(need / 2 ** 20)} MiB ({options.max_atlases} atlases of "
                         f"{options.atlas_size} px, {n_faces} faces) and {free // 2 ** 20} MiB are available: choose a "
                         "smaller atlas size, fewer atlases or a smaller face budget")
