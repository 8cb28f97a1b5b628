"""The images to orthorectify: their orientation in the local frame, from a model, chosen by IMAGES_FILTER."""
from __future__ import annotations

import fnmatch
import os
from collections import OrderedDict
from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple

import numpy as np

from ..geometry.camera import Intrinsics, Pose
from ..prepare.masks import find_mask
from .options import OrthoError


@dataclass
class OrthoCamera:
    """One image with its orientation in the local frame (world = local + offset)."""

    name: str
    path: str
    camera: Intrinsics
    pose: Pose
    camera_id: int = 0
    mask_path: Optional[str] = None
    max_gsd: Optional[float] = None  # ground points this image resolves coarser than this (m/px) are not used
    # the drone's shadow (core.ortho.hotspot): antisolar x, y, z (local frame), the radius (rad) of the view rays
    # that cost SHADOW_PENALTY more (another image takes that ground wherever one sees it) and the hot spot's width
    # (rad) of the view cost that grows towards it; None = none
    shadow: Optional[Tuple[float, float, float, float, float]] = None

    def ground_resolution(self, xyz_local: np.ndarray, projected: Optional[Tuple[np.ndarray, np.ndarray]] = None
                          ) -> np.ndarray:
        """Ground sample distance (N,) of this image at local points (N, 3): metres of level ground per pixel in
        the worst direction (1 / the smallest singular value of d pixel / d (x, y)), by finite differences through
        the full camera model; inf where a point does not project.  ``projected``: (pixels, depth) of the points
        from :meth:`project` where the caller has them (points that project: saves one projection)."""
        xyz = np.atleast_2d(np.asarray(xyz_local, dtype=float))
        xc = self.pose.to_camera(xyz)
        if projected is None:
            p0, depth, ok0 = self._project_camera_frame(xc)
        else:
            (p0, depth), ok0 = projected, True
        depth = np.maximum(depth, 1e-6)
        h = (depth / max(self.camera.focal, 1e-9))[:, None]  # about one pixel on the ground
        # the points moved by h along world x and y, in the camera frame: xc + h R e (one rotation, not three)
        rot = self.pose.rotation
        px, _, okx = self._project_camera_frame(xc + h * rot[:, 0])
        py, _, oky = self._project_camera_frame(xc + h * rot[:, 1])
        a, c = (px - p0).T / h[:, 0]
        b, d = (py - p0).T / h[:, 0]
        t = a * a + b * b + c * c + d * d
        det = np.abs(a * d - b * c)
        s_min2 = 0.5 * (t - np.sqrt(np.maximum(t * t - 4.0 * det * det, 0.0)))
        with np.errstate(divide="ignore"):
            g = 1.0 / np.sqrt(np.maximum(s_min2, 0.0))
        return np.where(ok0 & okx & oky, g, np.inf)

    @property
    def centre(self) -> np.ndarray:
        return self.pose.centre

    def project(self, xyz_local: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(pixels (N, 2), depth (N,), ok (N,): in front, trusted by the lens model and inside the image)."""
        return self._project_camera_frame(self.pose.to_camera(xyz_local))

    def _project_camera_frame(self, xc: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`project` of points already in the camera frame."""
        px, ok = self.camera.project(xc)
        ok &= self.camera.inside(px) & np.all(np.isfinite(px), axis=-1)
        return px, xc[..., 2], ok


def cameras_from_reconstruction(rec, images_dir: str, masks_dir: Optional[str] = None) -> List[OrthoCamera]:
    """OrthoCameras of the registered images of a pycolmap.Reconstruction (its frame = the local frame)."""
    out = []
    for im in sorted(rec.images.values(), key=lambda i: i.name):
        if not im.has_pose:
            continue
        cam = rec.cameras[im.camera_id]
        p = im.cam_from_world()
        pose = Pose(np.asarray(p.rotation.matrix(), dtype=float), np.asarray(p.translation, dtype=float))
        out.append(OrthoCamera(im.name, os.path.join(images_dir or "", im.name), Intrinsics.from_pycolmap(cam), pose,
                               int(im.camera_id), find_mask(masks_dir, im.name)))
    return out


def select_cameras(cameras: Sequence[OrthoCamera], images_filter: Optional[str],
                   camera_groups: Sequence[dict] = ()) -> List[OrthoCamera]:
    """The cameras an IMAGES_FILTER names.

    The filter is a list separated by commas, semicolons or new lines; each item is an image name, a wildcard
    (``DJI_00*.JPG``, case-insensitive), or ``group:<n>`` / ``group:<text>`` for a camera group by id or by a
    part of its make, model or key (``group:2``, ``group:FC300X``, ``group:NIR``).  An item starting with ``!``
    removes what it matches.  Empty: all."""
    if not images_filter or not images_filter.strip():
        return list(cameras)
    items = [s.strip() for s in images_filter.replace(";", ",").replace("\n", ",").split(",") if s.strip()]
    chosen: "OrderedDict[str, OrthoCamera]" = OrderedDict()
    positive = [i for i in items if not i.startswith("!")]
    negative = [i[1:].strip() for i in items if i.startswith("!")]
    unmatched = []

    def matches(item: str) -> List[OrthoCamera]:
        if item.lower().startswith("group:"):
            key = item.split(":", 1)[1].strip().lower()
            ids = set()
            for g in camera_groups:
                gid = str(g.get("camera_id", ""))
                text = " ".join(str(g.get(k, "")) for k in ("key", "make", "model")).lower()
                if key == gid or (key and key in text):
                    ids.add(int(g.get("camera_id")))
            names = {n for g in camera_groups if int(g.get("camera_id", -1)) in ids for n in g.get("images", [])}
            return [c for c in cameras if c.camera_id in ids or c.name in names]
        pat = item.lower()
        return [c for c in cameras if fnmatch.fnmatchcase(c.name.lower(), pat)
                or fnmatch.fnmatchcase(os.path.basename(c.name).lower(), pat)]

    for item in positive or ["*"]:
        found = matches(item)
        if not found:
            unmatched.append(item)
        for c in found:
            chosen[c.name] = c
    for item in negative:
        for c in matches(item):
            chosen.pop(c.name, None)
    if not chosen:
        examples = ", ".join(c.name for c in list(cameras)[:5])
        groups = ", ".join(f"{g.get('camera_id')}: {g.get('model') or g.get('key')}" for g in camera_groups)
        raise OrthoError(f"IMAGES_FILTER {images_filter!r} matches none of the {len(cameras)} oriented images "
                         f"(for example {examples}{'; camera groups ' + groups if groups else ''})")
    return list(chosen.values())
