"""The orientation of one image read from a file (JSON or a text table as Pix4D writes it) or a dict."""
from __future__ import annotations

import json
import os
from typing import Any, Dict, List, Optional

from .options import OrthoError

_ORIENTATION_KEYS = {
    "x": ("x", "easting", "e", "lon", "x_m"), "y": ("y", "northing", "n", "lat", "y_m"),
    "z": ("z", "height", "h", "alt", "altitude", "elevation", "z_m"),
    "omega": ("omega", "o", "omega_deg"), "phi": ("phi", "p", "phi_deg"), "kappa": ("kappa", "k", "kappa_deg"),
    "image": ("image", "imagename", "name", "image_name", "file", "filename", "photo"),
    "focal_mm": ("focal_mm", "focal", "f_mm", "focallength"), "sensor_width_mm": ("sensor_width_mm", "sensor_mm",
                                                                                 "sensorwidth"),
    "focal_px": ("focal_px", "f_px"), "cx": ("cx", "ppx", "cx_px"), "cy": ("cy", "ppy", "cy_px"),
    "k1": ("k1",), "k2": ("k2",), "p1": ("p1",), "p2": ("p2",), "crs": ("crs", "epsg", "srs"),
}


def _orientation_key(name: str) -> Optional[str]:
    n = name.strip().lower().replace(" ", "").replace("-", "_")
    for key, aliases in _ORIENTATION_KEYS.items():
        if n in aliases:
            return key
    return None


def normalise_orientation(d: Dict[str, Any], source: str, exterior: bool = True) -> Dict[str, Any]:
    out: Dict[str, Any] = {}
    for k, v in d.items():
        key = _orientation_key(str(k))
        if key is None or v is None or v == "":
            continue
        if key in ("image", "crs"):
            out[key] = str(v).strip()
        else:
            try:
                out[key] = float(v)
            except (TypeError, ValueError) as e:
                raise OrthoError(f"{source}: {k} = {v!r} is not a number") from e
    missing = [k for k in ("x", "y", "z", "omega", "phi", "kappa") if k not in out]
    if missing and not exterior and len(missing) == 6 and ("focal_px" in out or "focal_mm" in out):
        return out  # interior orientation only (with GCPs: space resection with a calibrated camera)
    if missing:
        raise OrthoError(f"{source}: the orientation lacks {', '.join(missing)} (needs x, y, z, omega, phi, kappa "
                         "in degrees; optional focal_mm, sensor_width_mm, focal_px, cx, cy, k1, k2, p1, p2, crs)")
    return out


def read_orientation(path: str, image_name: Optional[str] = None, exterior: bool = True) -> Dict[str, Any]:
    """Exterior (and optionally interior) orientation of one image from a file.

    JSON: ``{"x": .., "y": .., "z": .., "omega": .., "phi": .., "kappa": .., "crs": "EPSG:..", "focal_mm": ..}``
    (or ``{"images": {name: {...}}}``).  Text: an optional CRS line (``EPSG:xxxx`` or ``# crs: ...``), a header
    row naming the columns (``imageName X Y Z Omega Phi Kappa`` as Pix4D writes it, comma or white space
    separated, more columns allowed), then one row per image; the row of ``image_name`` (case-insensitive, with
    or without extension) is taken, or the only row.  A file without header holds ``x y z omega phi kappa``
    or ``image x y z omega phi kappa``.  Angles in degrees, photogrammetric convention (see core.resection)."""
    if not os.path.isfile(path):
        raise OrthoError(f"orientation file {path} does not exist")
    with open(path, encoding="utf-8-sig") as f:
        text = f.read()
    want = (image_name or "").lower()

    def name_ok(n: str) -> bool:
        n = os.path.basename(n.replace("\\", "/")).lower()
        return bool(want) and (n == want or os.path.splitext(n)[0] == os.path.splitext(want)[0])

    if text.lstrip().startswith("{"):
        try:
            d = json.loads(text)
        except json.JSONDecodeError as e:
            raise OrthoError(f"{path}: not valid JSON ({e})") from e
        if isinstance(d.get("images"), dict):
            rows = d["images"]
            hit = [v for k, v in rows.items() if name_ok(k)]
            if not hit and len(rows) == 1:
                hit = list(rows.values())
            if not hit:
                raise OrthoError(f"{path} holds no orientation for {image_name} (images: {', '.join(list(rows)[:6])})")
            merged = {k: v for k, v in d.items() if k != "images"}
            merged.update(hit[0])
            return normalise_orientation(merged, path, exterior)
        return normalise_orientation(d, path, exterior)
    crs = None
    header: Optional[List[str]] = None
    rows: List[List[str]] = []
    for raw in text.splitlines():
        line = raw.strip()
        if not line:
            continue
        low = line.lower()
        if line.startswith("#"):
            body = line.lstrip("#").strip()
            if body.lower().startswith("crs:") or body.lower().startswith("crs="):
                crs = body[4:].strip()
            continue
        if low.startswith("epsg:") or low.startswith("+proj") or low.startswith("wgs84 utm"):
            crs = line
            continue
        cells = [c.strip() for c in (line.split(",") if "," in line else line.split("\t") if "\t" in line
                                     else line.split())]
        if header is None and not rows and any(_orientation_key(c) in ("x", "omega") for c in cells):
            header = cells
            continue
        rows.append(cells)
    if not rows:
        raise OrthoError(f"{path} holds no orientation row")
    parsed = []
    for cells in rows:
        if header:
            d = dict(zip(header, cells))
        elif len(cells) == 6:
            d = dict(zip(("x", "y", "z", "omega", "phi", "kappa"), cells))
        elif len(cells) >= 7:
            d = dict(zip(("image", "x", "y", "z", "omega", "phi", "kappa"), cells))
        else:
            raise OrthoError(f"{path}: a row needs x y z omega phi kappa (optionally the image name first); got "
                             f"{' '.join(cells)!r}")
        parsed.append(d)
    hit = [d for d in parsed if name_ok(str(next((v for k, v in d.items() if _orientation_key(k) == "image"), "")))]
    if not hit and len(parsed) == 1:
        hit = parsed
    if not hit:
        raise OrthoError(f"{path} holds {len(parsed)} orientations but none for {image_name}")
    d = dict(hit[0])
    if crs and "crs" not in {_orientation_key(k) for k in d}:
        d["crs"] = crs
    return normalise_orientation(d, path, exterior)
