"""The orthophoto's radiometric correction as the workspace keeps it (``orthomosaic-radiometry.json``): the
exposure gain of each image and the fitted :class:`~.radiometry.RadiometryModel` (vignetting, hot spot, exposure,
gain field), so that another product made from the photos (the 3-D model's texture) is corrected the same way."""
from __future__ import annotations

from dataclasses import asdict
from typing import Any, Callable, Dict, Optional, Sequence

import numpy as np

from .cameras import OrthoCamera
from .radiometry import RadiometryModel, point_gains

FORMAT = 1


def radiometry_record(images: Sequence[str], gains: Dict[str, float], model: Optional[RadiometryModel]) -> dict:
    """The record of a mosaic's correction: its images in the model's order, their gains, the model (or None)."""
    m = None
    if model is not None:
        m = {k: np.asarray(v).tolist() for k, v in asdict(model).items() if k != "summary"}
    return {"format": FORMAT, "images": list(images), "gains": {n: float(g) for n, g in gains.items()}, "model": m}


def photo_correction(record: Optional[Dict[str, Any]]) -> Optional[Callable[[OrthoCamera, np.ndarray], np.ndarray]]:
    """f(camera, pixels (N, 2)) -> (N,) the mosaic's multiplicative correction of that photo at those pixels (1 for
    a photo the mosaic did not take); None without a record."""
    if not record or record.get("format") != FORMAT:
        return None
    index = {n: i for i, n in enumerate(record.get("images") or [])}
    gains = record.get("gains") or {}
    model = RadiometryModel(**record["model"]) if record.get("model") else None

    def correction(cam: OrthoCamera, px: np.ndarray) -> np.ndarray:
        i = index.get(cam.name)
        if i is None:
            return np.ones(len(px), dtype=np.float32)
        xn = cam.camera.unproject(px)  # a point one unit along each pixel's ray: the view direction is all it uses
        rays = np.column_stack([xn, np.ones(len(px))]) @ cam.pose.rotation
        xyz = cam.centre[None, :] + rays / np.linalg.norm(rays, axis=1, keepdims=True)
        return point_gains(model, float(gains.get(cam.name, 1.0)), i, cam, xyz, np.ones(len(px), bool), px)[:, 0]
    return correction
