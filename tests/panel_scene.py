"""A calibration panel's capture for the synthetic rig of tests/rig_scene.py (issue 37 item 2), and the truth of a
stacked photo's pixels.

:func:`render_panel` writes one capture of the rig photographing a panel of known reflectance that fills the centre
of the frame (a square of ``fraction`` x the frame's short side, on ground of reflectance ``BACKGROUND``), through
the same band model as the flight's captures: DN = dark + K x reflectance x irradiance x exposure x ISO/100 x
vignetting + noise, the exposure following the light (auto-exposure), the sunshine sensor's IrradianceList and
every tag in the rig's form (rig_scene's own XMP and EXIF writers).  The panel is a flat target under the camera,
drawn in each band's own pixels: no geometry is needed to measure it.

:func:`photo_truth` is the true reflectance of each pixel of a stacked capture's photo (the reference band's
pinhole frame, core.prepare.bands.reference_frame), ray-cast into the scene; NaN off the open ground (buildings,
walls: their rendered values are not a band's reflectance).
"""
from __future__ import annotations

import os
from typing import Dict, List, Optional, Union

import numpy as np

from tests import rig_scene as rs
from tests import synthetic as syn

BACKGROUND = 0.06  # the ground around the panel
SENSITIVITY = 0.55 * 65535 / (0.5 * 0.0015)  # rig_scene.render's K


def render_panel(rig: rs.RigBlock, folder: str, tag: str, reflectance: Union[float, Dict[str, float]],
                 light: float = 1.0, fraction: float = 0.5, noise: float = 3.0, seed: int = 0) -> List[str]:
    """Write one panel capture's four band files ``PANEL<tag>_<band>.TIF`` into ``folder`` (capture id
    ``PANELCAPTURE<tag>``, the sun's irradiance ``light``); returns them."""
    from osgeo import gdal

    gdal.UseExceptions()
    os.makedirs(folder, exist_ok=True)
    side = int(round(fraction * min(rig.width, rig.height)))
    r0, c0 = (rig.height - side) // 2, (rig.width - side) // 2
    exposure = round(0.0015 / light, 6)
    paths = []
    for band, (suffix, _nm, _fwhm, index) in rs.BANDS.items():
        rho = reflectance[band] if isinstance(reflectance, dict) else reflectance
        img = np.full((rig.height, rig.width), BACKGROUND, np.float64)
        img[r0:r0 + side, c0:c0 + side] = rho
        dn = rs.DARK + SENSITIVITY * img * light * exposure * rig.falloff(band)
        dn += np.random.default_rng(seed * 10 + index).normal(0.0, noise, dn.shape)
        path = os.path.join(folder, f"PANEL{tag}_{suffix}.TIF")
        rs._write(gdal, path, np.clip(np.round(dn), 0, 65535).astype(np.uint16),
                  rs._xmp(rig, band, f"PANELCAPTURE{tag}", light, 500_000_000 + 1_000_000 * seed),
                  rs._exif(50 + seed, exposure, 100))
        paths.append(path)
    return paths


def photo_truth(rig: rs.RigBlock, k: int, band: str, shape, frame=None) -> np.ndarray:
    """The true reflectance of ``band`` at each pixel of capture ``k``'s stacked photo (rows, cols ``shape``), in the
    reference band's pinhole frame ``frame`` (core.prepare.bands.PinholeLens; default: the Green band's, as the
    rig has it); NaN within 1.5 m of a building or the ditch."""
    from core.geometry.lens import PinholeLens

    if frame is None:
        lens = rig.lens("Green")
        frame = PinholeLens(lens.focal_px, lens.cx, lens.cy)
    v, u = np.mgrid[0:shape[0], 0:shape[1]].astype(np.float64)
    rays = frame.unproject(np.stack([u, v], axis=-1))
    xn = rays[..., :2] / rays[..., 2:3]
    shot = rig.block.shots[k]
    scene = rig.block.scene
    xyz = syn._ray_cast(scene, shot.centre, shot.rays(xn))
    truth = rig.reflectance(band, xyz[..., 0] + syn.ORIGIN[0], xyz[..., 1] + syn.ORIGIN[1])
    return np.where(scene.near_feature(xyz[..., 0], xyz[..., 1], 1.5), np.nan, truth)


def reflectance_error(photo: str, rig: rs.RigBlock, k: int, frame=None, bands: Optional[List[str]] = None
                      ) -> Dict[str, float]:
    """band -> the stacked photo's value over the truth, the median over its open ground (1 = reflectance right
    in absolute terms), minus 1."""
    from core.io.raster import RasterFile

    out = {}
    with RasterFile(photo) as r:
        for i in range(r.count):
            name = r.band(i + 1).GetDescription()
            if bands is not None and name not in bands:
                continue
            values = r.read(i + 1).astype(np.float64)
            truth = photo_truth(rig, k, name, values.shape, frame)
            ok = np.isfinite(truth) & (values > 0)
            out[name] = float(np.median(values[ok] / truth[ok]) - 1.0)
    return out
