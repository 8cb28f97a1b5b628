"""A synthetic multispectral rig block whose truth is known (issue 37): tests/synthetic.py's vertical block flown
by a four-band rig in the Parrot Sequoia's form.

- **Scene**: the synthetic terrain (hills, buildings, a ditch); each band's reflectance is a function of the
  scene's texture T (0..1) and of a buried ring-ditch M (0..1, a crop mark 2 m wide) that only the red edge and
  the near infrared see (:data:`REFLECTANCE`): green and red show the field, the ring raises NIR by 0.12 and red
  edge by 0.05, so NDVI is higher over it (the ditch's damper soil: greener crop).
- **Rig**: Green is the reference camera (no ``RigRelatives``); Red, Red edge and NIR are turned by fractions of
  a degree (:data:`RELATIVES`) and their principal points moved by a few pixels; every band has the Sequoia's
  fisheye polynomial; each band file carries its own vignetting (Sequoia ``VignettingPolynomial2D``), dark level
  75, exposure time and ISO, and the sunshine sensor's ``IrradianceList`` with its calibration measurement.
- **Light**: the sun's irradiance changes from capture to capture (:func:`light`), the exposure follows it
  (auto-exposure) and the red edge runs at ISO 200 on every other capture: raw DN are neither flat over the frame
  nor steady across captures.

Every band file is 16-bit (DN = dark + K_b x reflectance x irradiance x exposure x ISO/100 x vignetting +
noise), with its XMP and EXIF as the camera writes them; ``camera_positions.csv`` holds the captures' positions
(the stacked photos' names) for the georeference.  The truth (:meth:`RigBlock.reflectance`,
:meth:`RigBlock.ndvi`) is the scene's, at any world position.
"""
from __future__ import annotations

import base64
import math
import os
import struct
from dataclasses import dataclass
from typing import Dict, List, Tuple

import cv2
import numpy as np

from core.geometry.lens import FisheyeLens, rig_rotation
from tests import synthetic as syn

# band name -> (file suffix, central wavelength nm, FWHM nm, rig camera index)
BANDS = {"Green": ("GRE", 550, 40, 0), "Red": ("RED", 660, 40, 1), "Red edge": ("REG", 735, 10, 2),
         "NIR": ("NIR", 790, 40, 3)}
RELATIVES = {"Red": (0.35, -0.2, 0.1), "Red edge": (-0.3, 0.25, -0.15), "NIR": (0.2, 0.4, 0.05)}  # degrees
PP_SHIFT = {"Green": (0.0, 0.0), "Red": (3.2, -2.1), "Red edge": (-2.5, 1.7), "NIR": (1.4, 2.9)}  # px
POLYNOMIAL = (0.0, 1.0, 0.010754389, -0.147354298)  # the real Sequoia's FisheyePolynomial
# reflectance = a + b T + c M per band (T: the scene's texture 0..1, M: the ring ditch 0..1)
REFLECTANCE = {"Green": (0.05, 0.10, 0.0), "Red": (0.04, 0.09, 0.0), "Red edge": (0.20, 0.12, 0.05),
               "NIR": (0.30, 0.18, 0.12)}
VIGNETTING_DEPTH = {"Green": 0.55, "Red": 0.6, "Red edge": 0.5, "NIR": 0.65}  # 1 - V at the corners, x 2
DARK = 75
PX_PER_MM = 266.667  # the Sequoia's focal plane resolution (3.75 um pixels)
CALIBRATION = "0,600,35,17,1,600,857,437,2,600,14302,7152,3,600,65535,65535"  # the real Sequoia's
SUN_PER_MS = 857 / 600  # ch0 per ms of the calibration light at gain index 1
RING_WIDTH = 2.0  # m


def light(k: int) -> float:
    """The sun's irradiance at capture ``k``, relative (clouds passing: 0.7 .. 1.3)."""
    return 1.0 + 0.3 * math.sin(0.9 * k + 0.4)


@dataclass
class RigBlock:
    block: syn.SyntheticBlock
    width: int
    height: int
    focal: float
    ring: Tuple[float, float, float]  # local x, y, radius (m)

    # ---- truth
    def mark(self, x, y) -> np.ndarray:
        """The ring ditch's crop mark (0..1) at local x, y: 1 on the ring, smooth edges."""
        cx, cy, r = self.ring
        d = np.abs(np.hypot(np.asarray(x) - cx, np.asarray(y) - cy) - r)
        return np.clip(1.5 - 1.5 * d / (RING_WIDTH / 2), 0.0, 1.0)

    def band_raster(self, band: str) -> np.ndarray:
        """The band's reflectance on the scene's texture grid."""
        scene = self.block.scene
        tex = np.clip(scene.texture_raster(), 0.0, 1.0)
        xs, ys = scene._grid(scene.texture_res)
        gx, gy = np.meshgrid(xs, ys)
        a, b, c = REFLECTANCE[band]
        return (a + b * tex + c * self.mark(gx, gy)).astype(np.float32)

    def reflectance(self, band: str, x_world, y_world) -> np.ndarray:
        """The true reflectance of ``band`` at world x, y (the ground's, as the orthophoto sees it)."""
        scene = self.block.scene
        x, y = np.asarray(x_world) - syn.ORIGIN[0], np.asarray(y_world) - syn.ORIGIN[1]
        mx, my = scene.raster_coords(x, y, scene.texture_res)
        return syn._sample(self._rasters()[band], mx, my)

    def ndvi(self, x_world, y_world) -> np.ndarray:
        n, r = self.reflectance("NIR", x_world, y_world), self.reflectance("Red", x_world, y_world)
        return (n - r) / (n + r)

    def _rasters(self) -> Dict[str, np.ndarray]:
        if not hasattr(self, "_cache"):
            self._cache = {b: self.band_raster(b) for b in BANDS}
        return self._cache

    # ---- the rig
    def lens(self, band: str) -> FisheyeLens:
        c = self.focal * math.pi / 2.0  # focal at the centre = 2 / pi * p1 * C
        dx, dy = PP_SHIFT[band]
        return FisheyeLens(self.width / 2.0 + dx, self.height / 2.0 + dy, (c, 0.0, 0.0, c), POLYNOMIAL)

    def vignetting(self, band: str) -> Tuple[Tuple[float, ...], str]:
        """(coefficients, powers) of V = 1 - a ((x - 1/2)^2 + (y - 1/2)^2) in Sequoia's VignettingPolynomial2D form."""
        a = VIGNETTING_DEPTH[band]
        return (1.0 - 0.5 * a, a, -a, a, -a), "0,0,1,0,2,0,0,1,0,2"

    def falloff(self, band: str) -> np.ndarray:
        yy, xx = np.mgrid[0:self.height, 0:self.width].astype(np.float64)
        x, y = xx / self.width, yy / self.height
        return 1.0 - VIGNETTING_DEPTH[band] * ((x - 0.5) ** 2 + (y - 0.5) ** 2)


def rig_block(n_strips: int = 3, per_strip: int = 6, seed: int = 7, width: int = 640, height: int = 480,
              altitude: float = 50.0) -> RigBlock:
    """The block: a vertical flight (tests/synthetic.py) with a pinhole camera of the bands' size; the ring in
    the open field nearest the block's centre."""
    focal = 0.8125 * width  # 650 px at 800 px: the synthetic camera's field
    camera = syn.CameraModel(width, height, focal, focal, width / 2.0, height / 2.0)
    block = syn.vertical_block(seed=seed, camera=camera, altitude=altitude, n_strips=n_strips,
                               per_strip=per_strip, n_buildings=3)
    scene = block.scene
    best = None
    for r in (6.0, 5.0, 4.0):
        for cx in np.linspace(-10, 10, 9):
            for cy in np.linspace(-6, 6, 7):
                t = np.linspace(0, 2 * math.pi, 72)
                clear = not np.any(scene.near_feature(cx + r * np.cos(t), cy + r * np.sin(t), 2.0))
                if clear and (best is None or math.hypot(cx, cy) < math.hypot(best[0], best[1])):
                    best = (float(cx), float(cy), r)
        if best:
            break
    if best is None:
        raise RuntimeError("no open ground for the ring ditch in the synthetic scene")
    return RigBlock(block, width, height, focal, best)


def _irradiance_list(irradiance: float, t_us: int, n: int = 4) -> str:
    ch0 = int(round(irradiance * SUN_PER_MS * 100))
    raw = b"".join(struct.pack("<QHHHHfff", t_us - 100000 * (n - k), ch0, ch0 // 2, 1, 100, 0.0, 0.0, 0.0)
                   for k in range(n))
    return base64.b64encode(raw).decode()


def _xmp(rig: RigBlock, band: str, capture: str, irradiance: float, t_us: int) -> str:
    suffix, nm, fwhm, index = BANDS[band]
    lens = rig.lens(band)
    coeffs, powers = rig.vignetting(band)
    attrs = {"Camera:BandName": band, "Camera:RigName": "SynthRig", "Camera:RigCameraIndex": str(index),
             "Camera:CaptureUUID": capture, "Camera:ModelType": "fisheye",
             "Camera:PrincipalPoint": f"{lens.cx / PX_PER_MM:.6f},{lens.cy / PX_PER_MM:.6f}",
             "Camera:FisheyeAffineMatrix": ",".join(f"{v:.9f}" for v in lens.affine),
             "Camera:FisheyePolynomial": ",".join(repr(v) for v in POLYNOMIAL),
             "Camera:IrradianceList": _irradiance_list(irradiance, t_us),
             "Camera:IrradianceCalibrationMeasurement": CALIBRATION}
    if band in RELATIVES:
        attrs["Camera:RigRelatives"] = ",".join(repr(v) for v in RELATIVES[band])
    seqs = {"Camera:CentralWavelength": [nm], "Camera:WavelengthFWHM": [fwhm], "Camera:BlackCurrent": [DARK],
            "Camera:VignettingPolynomial2DName": [powers],
            "Camera:VignettingPolynomial2D": [",".join(repr(c) for c in coeffs)]}
    ns = {"Camera": "http://pix4d.com/camera/1.0/"}
    decl = " ".join(f'xmlns:{p}="{u}"' for p, u in ns.items())
    att = " ".join(f'{k}="{v}"' for k, v in attrs.items())
    body = "".join(f"<{k}><rdf:Seq>" + "".join(f"<rdf:li>{i}</rdf:li>" for i in items) + f"</rdf:Seq></{k}>"
                   for k, items in seqs.items())
    return ('<x:xmpmeta xmlns:x="adobe:ns:meta/"><rdf:RDF xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#">'
            f'<rdf:Description rdf:about="" {decl} {att}>{body}</rdf:Description></rdf:RDF></x:xmpmeta>')


def _band_maps(rig: RigBlock, band: str, canvas: Tuple[float, float, float, float, float]):
    """cv2.remap maps from the reference pinhole canvas (x0, y0 normalised; step; columns, rows) to the band's
    fisheye pixels turned by its rig rotation."""
    x0, y0, step, _cw, _ch = canvas
    jj, ii = np.meshgrid(np.arange(rig.width, dtype=float) + 0.5, np.arange(rig.height, dtype=float) + 0.5)
    rays = rig.lens(band).unproject(np.stack([jj, ii], axis=-1))
    rays = rays @ rig_rotation(RELATIVES.get(band)).T  # band ray -> the reference camera's
    xn, yn = rays[..., 0] / rays[..., 2], rays[..., 1] / rays[..., 2]
    return (((xn - x0) / step) - 0.5).astype(np.float32), (((yn - y0) / step) - 0.5).astype(np.float32)


# the rig's RGB camera (with ``rgb``): a frame RGB_SCALE x the bands' size, a slightly wider pinhole lens with a
# little barrel distortion, 1.34 um pixels (the Sequoia's), fired RGB_DELAY_M along the track after the bands and
# turned by RGB_TURN_DEG from the reference band (its own mount); Blue is the scene's green reflectance x 0.8
RGB_SCALE = 1.5
RGB_FIELD = 0.9  # its focal over the bands' focal x RGB_SCALE
RGB_PX_PER_MM = 1000.0 / 1.34
RGB_DELAY_M = (0.3, 0.05, 0.02)
RGB_TURN_DEG = (0.4, -0.3, 0.6)
RGB_DN = 1300.0  # 8-bit DN per unit of reflectance (the RGB camera's auto-exposure keeps the frames alike)


def rgb_camera(rig: RigBlock) -> "syn.CameraModel":
    w, h = int(round(rig.width * RGB_SCALE)), int(round(rig.height * RGB_SCALE))
    f = rig.focal * RGB_SCALE * RGB_FIELD
    return syn.CameraModel(w, h, f, f, w / 2.0, h / 2.0, k1=-0.04)


def rgb_shot(shot: "syn.Shot") -> "syn.Shot":
    """The RGB frame's pose beside the capture's reference band (the truth)."""
    turn, _ = cv2.Rodrigues(np.radians(np.asarray(RGB_TURN_DEG, dtype=float)))
    return syn.Shot(shot.name, turn @ shot.rotation, shot.centre + np.asarray(RGB_DELAY_M), shot.kind, shot.strip)


def _render_rgb(rig: RigBlock, shot: "syn.Shot", k: int, supersample: int) -> np.ndarray:
    """(rows, cols, 3) uint8 of the RGB frame of capture ``k``: Red, Green, and 0.8 x Green as blue."""
    camera = rgb_camera(rig)
    canvas_xn, map_x, map_y, vignetting = syn._canvas_geometry(camera, supersample)
    scene = rig.block.scene
    xyz = syn._ray_cast(scene, shot.centre, shot.rays(canvas_xn))
    texture = scene.texture_raster()
    out = []
    for band, factor in (("Red", 1.0), ("Green", 1.0), ("Green", 0.8)):
        scene._rasters["texture"] = rig._rasters()[band]
        try:
            value = syn._surface_value(scene, xyz).astype(np.float32) * factor
        finally:
            scene._rasters["texture"] = texture
        value = cv2.GaussianBlur(value, (0, 0), 0.45 * supersample)
        img = cv2.remap(value, map_x, map_y, cv2.INTER_CUBIC, borderMode=cv2.BORDER_REPLICATE) * vignetting * RGB_DN
        img += np.random.default_rng(5000 + k).normal(0.0, 1.5, img.shape)
        out.append(np.clip(np.round(img), 0, 255).astype(np.uint8))
    return np.dstack(out)


def _rgb_xmp(capture: str) -> str:
    return ('<x:xmpmeta xmlns:x="adobe:ns:meta/"><rdf:RDF xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#">'
            '<rdf:Description rdf:about="" xmlns:Camera="http://pix4d.com/camera/1.0/" Camera:RigName="SynthRig" '
            f'Camera:CaptureUUID="{capture}"><Camera:BandName><rdf:Seq><rdf:li>Red</rdf:li><rdf:li>Green</rdf:li>'
            '<rdf:li>Blue</rdf:li></rdf:Seq></Camera:BandName></rdf:Description></rdf:RDF></x:xmpmeta>')


def _write_rgb(gdal, path: str, rig: RigBlock, rgb: np.ndarray, capture: str, k: int) -> None:
    camera = rgb_camera(rig)
    exif = {"EXIF_DateTimeOriginal": f"2024:06:01 10:{k // 60:02d}:{k % 60:02d}", "EXIF_Make": "Synth",
            "EXIF_Model": "SynthRGB", "EXIF_FocalLength": f"{camera.fx / RGB_PX_PER_MM:.4f}",
            "EXIF_FocalPlaneXResolution": f"{RGB_PX_PER_MM:.3f}", "EXIF_FocalPlaneYResolution": f"{RGB_PX_PER_MM:.3f}",
            "EXIF_FocalPlaneResolutionUnit": "4"}
    ds = gdal.GetDriverByName("GTiff").Create(path, rgb.shape[1], rgb.shape[0], 3, gdal.GDT_Byte,
                                              ["PHOTOMETRIC=RGB", "COMPRESS=DEFLATE"])
    for i in range(3):
        ds.GetRasterBand(i + 1).WriteArray(rgb[:, :, i])
    ds.SetMetadata(exif, "EXIF")
    ds.SetMetadata([_rgb_xmp(capture)], "xml:XMP")
    ds = None


def render(rig: RigBlock, folder: str, supersample: int = 2, noise: float = 3.0, rgb: bool = False) -> List[str]:
    """Write every capture's four band files into ``folder`` and the captures' positions beside it; returns the
    band files.  The photo a capture becomes is named IMG_<k>.tif (core.prepare.captures.photo_names).  With
    ``rgb`` each capture also has the rig's RGB frame, IMG_<k>_RGB.TIF (:func:`rgb_camera`, :func:`rgb_shot`), with
    its position in the positions file (returned too)."""
    os.makedirs(folder, exist_ok=True)
    from osgeo import gdal

    gdal.UseExceptions()
    step = 1.0 / (rig.focal * supersample)
    corners = []
    for band in BANDS:
        jj, ii = np.meshgrid(np.linspace(0, rig.width, 9), np.linspace(0, rig.height, 9))
        rays = rig.lens(band).unproject(np.stack([jj, ii], axis=-1)) @ rig_rotation(RELATIVES.get(band)).T
        corners.append(np.stack([rays[..., 0] / rays[..., 2], rays[..., 1] / rays[..., 2]], axis=-1).reshape(-1, 2))
    pts = np.concatenate(corners)
    x0, y0 = pts.min(axis=0) - 4 * step
    x1, y1 = pts.max(axis=0) + 4 * step
    cw, ch = int(math.ceil((x1 - x0) / step)), int(math.ceil((y1 - y0) / step))
    canvas = (float(x0), float(y0), step, cw, ch)
    cu, cv_ = np.meshgrid(x0 + (np.arange(cw) + 0.5) * step, y0 + (np.arange(ch) + 0.5) * step)
    canvas_xn = np.stack([cu, cv_], axis=-1)
    maps = {b: _band_maps(rig, b, canvas) for b in BANDS}
    scene = rig.block.scene
    texture = scene.texture_raster()
    paths = []
    rows = []
    for k, shot in enumerate(rig.block.shots):
        xyz = syn._ray_cast(scene, shot.centre, shot.rays(canvas_xn))
        irradiance = light(k)
        capture = f"SYNTHCAPTURE{k:04d}"
        for band, (suffix, _nm, _fwhm, index) in BANDS.items():
            scene._rasters["texture"] = rig._rasters()[band]
            try:
                value = syn._surface_value(scene, xyz).astype(np.float32)
            finally:
                scene._rasters["texture"] = texture
            value = cv2.GaussianBlur(value, (0, 0), 0.45 * supersample)
            img = cv2.remap(value, *maps[band], cv2.INTER_CUBIC, borderMode=cv2.BORDER_REPLICATE)
            exposure = round(0.0015 / irradiance, 6)  # auto-exposure follows the light
            iso = 200 if band == "Red edge" and k % 2 else 100
            sensitivity = 0.55 * 65535 / (0.5 * 0.0015)
            dn = DARK + sensitivity * img * irradiance * exposure * (iso / 100.0) * rig.falloff(band)
            dn += np.random.default_rng(1000 * k + index).normal(0.0, noise, dn.shape)
            path = os.path.join(folder, f"IMG_{k:04d}_{suffix}.TIF")
            _write(gdal, path, np.clip(np.round(dn), 0, 65535).astype(np.uint16),
                   _xmp(rig, band, capture, irradiance, 1_000_000 * (k + 1)), _exif(k, exposure, iso))
            paths.append(path)
        w = shot.centre + syn.ORIGIN
        rows.append(f"IMG_{k:04d}.tif,{w[0]:.3f},{w[1]:.3f},{w[2]:.3f},0.05")
        if rgb:
            frame = rgb_shot(shot)
            path = os.path.join(folder, f"IMG_{k:04d}_RGB.TIF")
            _write_rgb(gdal, path, rig, _render_rgb(rig, frame, k, supersample), capture, k)
            paths.append(path)
            w = frame.centre + syn.ORIGIN
            rows.append(f"IMG_{k:04d}_RGB.TIF,{w[0]:.3f},{w[1]:.3f},{w[2]:.3f},0.05")
    with open(os.path.join(os.path.dirname(os.path.abspath(folder)), "camera_positions.csv"), "w") as f:
        f.write(f"{syn.CRS}\nimage,x,y,z,sigma\n" + "\n".join(rows) + "\n")
    return paths


def _exif(k: int, exposure: float, iso: int) -> Dict[str, str]:
    return {"EXIF_DateTimeOriginal": f"2024:06:01 10:{k // 60:02d}:{k % 60:02d}", "EXIF_SubSecTime": "000",
            "EXIF_ExposureTime": f"{exposure:.6g}", "EXIF_ISOSpeedRatings": str(iso), "EXIF_FNumber": "2.2",
            "EXIF_FocalPlaneXResolution": f"{PX_PER_MM}", "EXIF_FocalPlaneYResolution": f"{PX_PER_MM}",
            "EXIF_FocalPlaneResolutionUnit": "4", "EXIF_Make": "Synth", "EXIF_Model": "SynthRig"}


def _write(gdal, path: str, array: np.ndarray, packet: str, exif: Dict[str, str]) -> None:
    ds = gdal.GetDriverByName("GTiff").Create(path, array.shape[1], array.shape[0], 1, gdal.GDT_UInt16)
    ds.GetRasterBand(1).WriteArray(array)
    ds.SetMetadata(exif, "EXIF")
    ds.SetMetadata([packet], "xml:XMP")
    ds = None


# ---------------------------------------------------------------- checks of an orthomosaic against the truth
def _ortho_bands(path: str):
    """(bands by name as float64, world x and y of the cell centres, cells where every band has a value)."""
    from core.io.raster import RasterFile

    with RasterFile(path) as r:
        names = [r.band(i + 1).GetDescription() for i in range(r.count)]
        data = {n: r.read(i + 1).astype(np.float64) for i, n in enumerate(names) if n in BANDS}
        gt = r.geotransform
        masks = [r.band(i + 1).GetMaskBand().ReadAsArray() > 0 for i in range(r.count)]
    rows, cols = next(iter(data.values())).shape
    jj, ii = np.meshgrid(np.arange(cols) + 0.5, np.arange(rows) + 0.5)
    x, y = gt[0] + jj * gt[1] + ii * gt[2], gt[3] + jj * gt[4] + ii * gt[5]
    valid = np.logical_and.reduce(masks + [v > 0 for v in data.values()])
    return data, x, y, valid


def evaluate(rig: RigBlock, ortho_path: str, window: int = 64) -> Dict[str, object]:
    """The orthomosaic of the stacked rig photos against the truth, over open ground (1.5 m from buildings and
    the ditch, every band valid):

    - ``reflectance``: per band, the ortho's value over the true reflectance: its median (the band's constant: a
      calibration panel would fix it) and the deviation from it per cell (median, 95th and 99th percentile,
      fraction: resampling and sensor noise included) and over patches of window / 4 cells (the radiometry's
      error: light, exposure, vignetting; 95th percentile);
    - ``registration_px``: NIR, Red and Red edge against Green, phase correlation on gradients in windows of
      ``window`` cells laid over the open ground (median and 90th percentile of the shift's length, windows);
    - ``ndvi``: the ring ditch's crop mark in NDVI (mean on the ring minus the mean 2-4 m beside it), the truth's,
      that of the bands as written, and that of the bands divided by their constants."""
    from core.prepare.bands import gradient_image, phase_shift

    data, x, y, valid = _ortho_bands(ortho_path)
    scene = rig.block.scene
    lx, ly = x - syn.ORIGIN[0], y - syn.ORIGIN[1]
    ground = valid & ~scene.near_feature(lx, ly, 1.5)
    out: Dict[str, object] = {"cells": int(ground.sum())}
    consts, refl = {}, {}
    for band, values in data.items():
        truth = rig.reflectance(band, x, y)
        ratio = values[ground] / truth[ground]
        c = float(np.median(ratio))
        dev = np.abs(ratio / c - 1.0)
        consts[band] = c
        patches = _patch_ratios(values, truth, ground, window // 4) / c
        refl[band] = {"constant": round(c, 1), "median_dev": round(float(np.median(dev)), 4),
                      "p95_dev": round(float(np.percentile(dev, 95)), 4),
                      "p99_dev": round(float(np.percentile(dev, 99)), 4),
                      "patches": int(patches.size),
                      "patch_p95_dev": round(float(np.percentile(np.abs(patches - 1.0), 95)), 4)}
    out["reflectance"] = refl
    rows, cols = valid.shape
    grads = {b: gradient_image(v.astype(np.float32)) for b, v in data.items()}
    reg = {}
    for band in ("Red", "Red edge", "NIR"):
        shifts = []
        for r0 in range(0, rows - window, window):
            for c0 in range(0, cols - window, window):
                if not ground[r0:r0 + window, c0:c0 + window].all():
                    continue
                dx, dy, peak = phase_shift(grads["Green"][r0:r0 + window, c0:c0 + window],
                                           grads[band][r0:r0 + window, c0:c0 + window])
                if peak > 0.05:
                    shifts.append(math.hypot(dx, dy))
        reg[band] = {"windows": len(shifts), "median": round(float(np.median(shifts)), 3) if shifts else None,
                     "p90": round(float(np.percentile(shifts, 90)), 3) if shifts else None}
    out["registration_px"] = reg
    cx, cy, r = rig.ring
    dist = np.abs(np.hypot(lx - cx, ly - cy) - r)
    on = ground & (rig.mark(lx, ly) > 0.8)
    beside = ground & (dist > 2.0) & (dist < 4.0)

    def contrast(ndvi):
        return round(float(np.mean(ndvi[on]) - np.mean(ndvi[beside])), 4) if on.any() and beside.any() else None

    n, red = data["NIR"], data["Red"]
    ncal, rcal = n / consts["NIR"], red / consts["Red"]
    with np.errstate(divide="ignore", invalid="ignore"):  # outside the mosaic 0 / 0: never in ``on``, ``beside``
        out["ndvi"] = {"ring_cells": int(on.sum()), "truth": contrast(rig.ndvi(x, y)),
                       "as_written": contrast((n - red) / (n + red)),
                       "calibrated": contrast((ncal - rcal) / (ncal + rcal))}
    return out


def _patch_ratios(values: np.ndarray, truth: np.ndarray, ground: np.ndarray, size: int) -> np.ndarray:
    """The ortho over the truth, summed over each patch of ``size`` x ``size`` cells that is all open ground."""
    out = []
    rows, cols = values.shape
    for r0 in range(0, rows - size, size):
        for c0 in range(0, cols - size, size):
            if ground[r0:r0 + size, c0:c0 + size].all():
                out.append(values[r0:r0 + size, c0:c0 + size].sum() / truth[r0:r0 + size, c0:c0 + size].sum())
    return np.asarray(out, dtype=np.float64)


def shift_to_truth(rig: RigBlock, ortho_path: str, band: int, truth_band: str = "Green",
                   window: int = 64) -> Dict[str, object]:
    """How far a mosaic's ``band`` (1-based; the RGB mosaic's green, the multi-band mosaic's Green) lies from where
    the truth puts the scene: phase correlation on gradients between the band and the true ``truth_band``
    reflectance sampled at the mosaic's cell centres, in windows of ``window`` cells over open ground (1.5 m from
    buildings and the ditch); the median and 90th percentile of the shift's length in cells, and the cell size."""
    from core.io.raster import RasterFile
    from core.prepare.bands import gradient_image, phase_shift

    with RasterFile(ortho_path) as r:
        values = r.read(band).astype(np.float32)
        valid = r.band(band).GetMaskBand().ReadAsArray() > 0
        gt = r.geotransform
    rows, cols = values.shape
    jj, ii = np.meshgrid(np.arange(cols) + 0.5, np.arange(rows) + 0.5)
    x, y = gt[0] + jj * gt[1] + ii * gt[2], gt[3] + jj * gt[4] + ii * gt[5]
    truth = rig.reflectance(truth_band, x, y).astype(np.float32)
    ground = valid & (values > 0) & ~rig.block.scene.near_feature(x - syn.ORIGIN[0], y - syn.ORIGIN[1], 1.5)
    ga, gb = gradient_image(truth), gradient_image(values)
    shifts = []
    for r0 in range(0, rows - window, window):
        for c0 in range(0, cols - window, window):
            if ground[r0:r0 + window, c0:c0 + window].all():
                dx, dy, peak = phase_shift(ga[r0:r0 + window, c0:c0 + window], gb[r0:r0 + window, c0:c0 + window])
                if peak > 0.05:
                    shifts.append((dx, dy))
    v = np.asarray(shifts, dtype=float).reshape(-1, 2)
    length = np.hypot(v[:, 0], v[:, 1])
    return {"cell": abs(gt[1]), "windows": len(v),
            "median": round(float(np.median(length)), 3) if len(v) else None,
            "p90": round(float(np.percentile(length, 90)), 3) if len(v) else None,
            # the median shift as a ground vector (m, x east, y north): where the mosaic puts the scene
            "shift_m": tuple(round(float(c), 4) for c in np.median(v, axis=0) * (gt[1], gt[5])) if len(v) else None}
