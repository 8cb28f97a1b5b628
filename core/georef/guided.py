"""Guided GCP placement: where a ground point probably falls in each photo of a block.

Pure functions over a pycolmap reconstruction (no qgis / Qt), used by the GCP dock (ui/).

Three sources of a predicted position, best first:

``rays``
    the point has observations in at least two registered photos: it is triangulated in the block
    (``core.georef.triangulate.triangulate_observations``, full camera model) and projected into every other photo.
    This needs no world coordinates at all and agrees with the photos to the precision of the clicks.
``georef``
    the block is georeferenced (adjusted model in the local frame, ``world = local + offset``): the
    point's world coordinates minus the offset are projected.
``helmert``
    the block is only aligned, but at least three non-collinear points with world coordinates are
    triangulated: a 7-parameter similarity world -> model is fitted to them (Umeyama) and the
    point's world coordinates are projected through it.

Placeholder heights (every point given the same Z, as in OpenDroneMap files whose heights were never
surveyed: COPR's 0, Toledo's 400) would put a point metres above or below the ground it marks, tens of
pixels off in an oblique ray.  Then the height comes from the block itself: the median height of the
tie points nearest to the point's X, Y; and the similarity of an aligned block is fitted to X and Y only.

A projection counts only where the point is in front of the camera, lands inside the image (with a
margin) and the lens model is trusted there (``geometry.camera.project_in_image``, the rule every stage
uses), which rejects the wrap-around of distortion polynomials far outside the frame.

Pixel convention: COLMAP's, origin at the upper-left corner of the upper-left pixel.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import require
from ..common.files import atomic_output
from ..geometry.camera import project_in_image
from ..geometry.similarity import fit_similarity, helmert_fit
from ..io.gcp import GCPSet, GroundPoint, Observation
from .errors import GeorefError
from .triangulate import triangulate_observations

RAYS = "rays"
GEOREF = "georef"
HELMERT = "helmert"


@dataclass
class Prediction:
    name: str  # ground point
    image: str
    x: float  # pixel, COLMAP convention
    y: float
    source: str  # RAYS, GEOREF or HELMERT
    centrality: float  # 0 at the image centre, 1 at a corner: smaller is a better view

    @property
    def xy(self) -> Tuple[float, float]:
        return (self.x, self.y)


def _registered(rec) -> Dict[str, object]:
    out = {}
    for iid in rec.reg_image_ids():
        im = rec.image(iid)
        out[im.name] = im
    return out


def project_point(rec, xyz, images: Optional[Sequence[str]] = None, margin: float = 0.0,
                  _lookup: Optional[Dict[str, object]] = None) -> Dict[str, Tuple[float, float, float]]:
    """Project one point (in the reconstruction's frame) into the registered images.

    Returns {image: (x, y, centrality)} for the images where the point lies in front of the camera,
    at least ``margin`` pixels inside the frame, and where the camera model round-trips (see module
    docstring).  ``images`` restricts the images considered.
    """
    xyz = np.asarray(xyz, dtype=float).reshape(3)
    lookup = _registered(rec) if _lookup is None else _lookup
    names = lookup.keys() if images is None else [n for n in images if n in lookup]
    out: Dict[str, Tuple[float, float, float]] = {}
    for name in names:
        im = lookup[name]
        px, seen, centrality = project_in_image(rec.cameras[im.camera_id], im.cam_from_world().matrix(), xyz, margin)
        if seen[0]:
            out[name] = (float(px[0, 0]), float(px[0, 1]), float(centrality[0]))
    return out


class Predictor:
    """Predicted GCP positions in the photos of one block.

    ``rec``: a pycolmap.Reconstruction; ``offset``: for a georeferenced model in the local frame,
    the (3,) vector with world = local + offset; None for a model that is only aligned (arbitrary
    frame).  ``max_ray_error_px``: observations further than this from the other rays are left out
    of the triangulation (a wrong click must not drag the predictions along).
    """

    def __init__(self, rec, offset: Optional[Sequence[float]] = None, max_ray_error_px: float = 4.0,
                 surface_neighbours: int = 12):
        self.rec = rec
        self.offset = None if offset is None else np.asarray(offset, dtype=float).reshape(3)
        self.max_ray_error_px = float(max_ray_error_px)
        self.surface_neighbours = int(surface_neighbours)
        self._lookup = _registered(rec)
        self._all = {im.name for im in rec.images.values()}
        self._world_to_model = None  # (Similarity world - centre -> model, centre), aligned blocks only
        self.helmert_points: List[str] = []
        self.helmert_rms: Optional[float] = None  # metres (world units), on the fitted points
        self.placeholder_z: Optional[float] = None  # the common Z of the points when heights are placeholders
        self._tie = np.array([p.xyz for p in rec.points3D.values()], dtype=float).reshape(-1, 3)
        self._tree = None  # KD-tree over the tie points' horizontal coordinates (world-aligned frame)
        self._tree_xyz = None

    @property
    def georeferenced(self) -> bool:
        return self.offset is not None

    @property
    def image_names(self) -> List[str]:
        return sorted(self._lookup)

    def triangulate(self, observations: Sequence[Observation]):
        """Triangulation in the model frame (``georef.Triangulation``) or None with fewer than 2 usable views."""
        obs = [o for o in observations if o.image in self._lookup]
        if len(obs) < 2:
            return None
        tri = triangulate_observations(self.rec, obs, max_error_px=self.max_ray_error_px,
                                       _lookup=self._lookup, _all_names=self._all)
        return tri if tri.xyz is not None else None

    def fit(self, gcps: GCPSet) -> None:
        """Prepare the world -> model similarity of an aligned block from the points already placed, and
        notice placeholder heights."""
        self._world_to_model = None
        self.helmert_points = []
        self.helmert_rms = None
        zs = [p.z for p in gcps.points if all(math.isfinite(v) for v in (p.x, p.y, p.z))]
        self.placeholder_z = zs[0] if len(zs) >= 2 and max(zs) - min(zs) < 1e-6 else None
        if self.georeferenced:
            self._set_surface(self._tie)
            return
        src, dst, names = [], [], []
        for p in gcps.points:
            if not all(math.isfinite(v) for v in (p.x, p.y, p.z)):
                continue
            tri = self.triangulate(p.observations)
            if tri is None:
                continue
            src.append([p.x, p.y, p.z])
            dst.append(tri.xyz)
            names.append(p.name)
        if len(src) < 3:
            return
        src_a, dst_a = np.asarray(src, dtype=float), np.asarray(dst, dtype=float)
        centre = src_a.mean(axis=0)  # keep UTM-size numbers out of the fit
        try:
            if self.placeholder_z is None:
                sim = helmert_fit(src_a - centre, dst_a)
                res = sim.apply(src_a - centre) - dst_a
                rms = float(np.sqrt(np.mean(np.sum(res ** 2, axis=1)))) / sim.scale
            else:  # heights unknown: model -> world on X and Y only, then inverted
                m2w, r = fit_similarity(dst_a, src_a - centre, xy_only=True)
                sim = m2w.inverse()
                rms = float(np.sqrt(np.mean(r ** 2)))
        except (ValueError, np.linalg.LinAlgError):  # collinear or coincident points
            return
        self._world_to_model = (sim, centre)
        self.helmert_points = names
        self.helmert_rms = rms
        if self.placeholder_z is not None:
            self._set_surface(sim.inverse().apply(self._tie))

    def _set_surface(self, xyz_world_aligned: np.ndarray) -> None:
        self._tree_xyz = xyz_world_aligned
        self._tree = None
        if len(xyz_world_aligned) >= 1:
            from scipy.spatial import cKDTree

            self._tree = cKDTree(xyz_world_aligned[:, :2])

    def surface_height(self, x: float, y: float) -> Optional[float]:
        """Median height of the tie points nearest to (x, y), in the frame of ``_set_surface`` (local
        for a georeferenced block, world minus the fit's centre for an aligned one)."""
        if self._tree is None:
            return None
        k = min(self.surface_neighbours, len(self._tree_xyz))
        _, idx = self._tree.query([x, y], k=k)
        idx = np.atleast_1d(idx)
        return float(np.median(self._tree_xyz[idx, 2]))

    def model_point(self, point: GroundPoint) -> Tuple[Optional[np.ndarray], Optional[str]]:
        """(xyz in the model frame, source) of a point, or (None, None) when it cannot be located yet."""
        tri = self.triangulate(point.observations)
        if tri is not None:
            return np.asarray(tri.xyz, dtype=float), RAYS
        if not all(math.isfinite(v) for v in (point.x, point.y, point.z)):
            return None, None
        world = np.array([point.x, point.y, point.z], dtype=float)
        if self.georeferenced:
            local = world - self.offset
            if self.placeholder_z is not None:
                z = self.surface_height(local[0], local[1])
                local[2] = local[2] if z is None else z
            return local, GEOREF
        if self._world_to_model is not None:
            sim, centre = self._world_to_model
            w = world - centre
            if self.placeholder_z is not None:
                z = self.surface_height(w[0], w[1])
                w[2] = w[2] if z is None else z
            return sim.apply(w[None])[0], HELMERT
        return None, None

    def predict_point(self, point: GroundPoint, images: Optional[Sequence[str]] = None,
                      margin: float = 0.0) -> Dict[str, Prediction]:
        """{image: Prediction} for every registered image (or ``images``) that probably sees the point,
        observed images included (their prediction shows how far the click is from the other rays).
        Call ``fit`` first (``predict`` does) so that the similarity and placeholder heights are known."""
        xyz, source = self.model_point(point)
        if xyz is None:
            return {}
        proj = project_point(self.rec, xyz, images, margin, _lookup=self._lookup)
        return {name: Prediction(point.name, name, x, y, source, c) for name, (x, y, c) in proj.items()}

    def leave_one_out(self, point: GroundPoint) -> Dict[str, float]:
        """{image: pixels between the observation and where the point's other observations put it}, for
        points placed in at least 3 registered photos: a wrong click stands out."""
        obs = [o for o in point.observations if o.image in self._lookup]
        out: Dict[str, float] = {}
        if len(obs) < 3:
            return out
        for k, o in enumerate(obs):
            tri = self.triangulate(obs[:k] + obs[k + 1:])
            if tri is None:
                continue
            proj = project_point(self.rec, tri.xyz, [o.image], margin=-1e9, _lookup=self._lookup)
            if o.image in proj:
                out[o.image] = float(math.hypot(proj[o.image][0] - o.x, proj[o.image][1] - o.y))
        return out

    def predict(self, gcps: GCPSet, names: Optional[Sequence[str]] = None,
                margin: float = 0.0) -> Dict[str, Dict[str, Prediction]]:
        """{point name: {image: Prediction}}; fits the world -> model similarity first when needed."""
        self.fit(gcps)
        out = {}
        for p in gcps.points:
            if names is not None and p.name not in names:
                continue
            out[p.name] = self.predict_point(p, margin=margin)
        return out


def images_seeing(predictions: Mapping[str, Prediction], observed: Sequence[str] = ()) -> List[str]:
    """Image names ordered for the thumbnail strip: observed images first (in their order), then the
    predicted ones from the most central view outwards."""
    first = [n for n in observed]
    rest = sorted((p for n, p in predictions.items() if n not in first), key=lambda p: (p.centrality, p.image))
    return first + [p.image for p in rest]


def ground_sample_distance(rec, scale: float = 1.0) -> Optional[float]:
    """Median ground sample distance of the block (model units per pixel, times ``scale``): for each
    image the median depth of its tie points over the focal length."""
    values = []
    pts = rec.points3D
    for name, im in _registered(rec).items():
        del name
        cam = rec.cameras[im.camera_id]
        m = np.asarray(im.cam_from_world().matrix())
        ids = [p.point3D_id for p in im.points2D if p.has_point3D()]
        if not ids:
            continue
        if len(ids) > 400:
            ids = ids[:: len(ids) // 400]
        xyz = np.array([pts[i].xyz for i in ids], dtype=float)
        depth = xyz @ m[:, :3].T[:, 2] + m[2, 3]
        depth = depth[depth > 0]
        if len(depth):
            values.append(float(np.median(depth)) / float(cam.mean_focal_length()))
    return float(np.median(values)) * scale if values else None


def image_footprints(rec, ground_z: float, samples_per_side: int = 4,
                     max_range: Optional[float] = None) -> Dict[str, List[Tuple[float, float]]]:
    """Ground footprint of each registered image on the horizontal plane z = ``ground_z`` (model /
    local frame): the image border (``samples_per_side`` points per side, lens model included) cast
    onto the plane.  Rays that miss the plane or reach beyond ``max_range`` (default: 20 times the
    camera height above the plane) are clipped at that range, so oblique views stay bounded."""
    out = {}
    for name, im in _registered(rec).items():
        cam = rec.cameras[im.camera_id]
        w, h = float(cam.width), float(cam.height)
        n = max(1, int(samples_per_side))
        t = np.linspace(0.0, 1.0, n, endpoint=False)
        border = np.concatenate([
            np.column_stack([t * w, np.zeros(n)]), np.column_stack([np.full(n, w), t * h]),
            np.column_stack([w - t * w, np.full(n, h)]), np.column_stack([np.zeros(n), h - t * h])])
        m = np.asarray(im.cam_from_world().matrix())
        rot, tr = m[:, :3], m[:, 3]
        centre = -rot.T @ tr
        height = centre[2] - ground_z
        if height <= 0:
            continue
        reach = max_range if max_range is not None else 20.0 * height
        rays_cam = np.column_stack([np.asarray(cam.cam_from_img(border), dtype=float), np.ones(len(border))])
        rays = rays_cam @ rot  # world directions (rows): R^T d
        poly = []
        for d in rays:
            d = d / np.linalg.norm(d)
            s = -height / d[2] if d[2] < -1e-9 else math.inf
            if not math.isfinite(s) or s * math.hypot(d[0], d[1]) > reach:
                horiz = np.array([d[0], d[1]])
                norm = np.linalg.norm(horiz)
                if norm < 1e-12:
                    continue
                p = centre[:2] + reach * horiz / norm
            else:
                p = centre[:2] + s * d[:2]
            poly.append((float(p[0]), float(p[1])))
        if len(poly) >= 3:
            out[name] = poly
    return out


def write_footprints_gpkg(path: str, footprints: Mapping[str, Sequence[Tuple[float, float]]],
                          offset: Sequence[float] = (0.0, 0.0, 0.0), crs: Optional[str] = None) -> str:
    """Footprint polygons (local frame + ``offset``) to a GeoPackage layer ``footprints`` (field ``image``),
    written atomically."""
    from osgeo import ogr, osr

    ogr.UseExceptions()
    srs = None
    if crs:
        srs = osr.SpatialReference()
        srs.SetFromUserInput(crs)
        srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    ox, oy = float(offset[0]), float(offset[1])
    with atomic_output(path) as tmp:
        ds = ogr.GetDriverByName("GPKG").CreateDataSource(tmp)
        lyr = ds.CreateLayer("footprints", srs, ogr.wkbPolygon)
        lyr.CreateField(ogr.FieldDefn("image", ogr.OFTString))
        defn = lyr.GetLayerDefn()
        for name in sorted(footprints):
            ring = ogr.Geometry(ogr.wkbLinearRing)
            pts = list(footprints[name])
            for x, y in pts + pts[:1]:
                ring.AddPoint_2D(x + ox, y + oy)
            poly = ogr.Geometry(ogr.wkbPolygon)
            poly.AddGeometry(ring)
            f = ogr.Feature(defn)
            f.SetField("image", name)
            f.SetGeometry(poly)
            lyr.CreateFeature(f)
        ds = None
    return path




# --------------------------------------------------------------------------------------------------
# refinement by image matching
# --------------------------------------------------------------------------------------------------


@dataclass
class Match:
    x: float  # refined pixel in the target photo
    y: float
    score: float  # normalised cross-correlation of the best match, -1..1
    margin: float  # best score minus the best score away from that peak (ambiguity: small is bad)
    shift: float  # distance from the prediction (pixels)


@dataclass
class PhotoPoint:
    """A point in a photo: the image's name in the model, its pixel (x, y), and the photo as a 2-D uint8 / float
    array (pixel centres at +0.5, as everywhere)."""

    image: str
    xy: Sequence[float]
    gray: np.ndarray


@dataclass(frozen=True)
class MatchSearch:
    """How a point is looked for in a photo: within ``radius`` pixels of its prediction, with a template of
    2 x ``half`` + 1 pixels, accepted at a score of at least ``min_score`` and ``min_margin`` above any other peak."""

    radius: float = 250.0
    half: int = 20
    min_score: float = 0.6
    min_margin: float = 0.08


def read_gray(path: str) -> np.ndarray:
    """A photo as an 8-bit grey array, pixels as stored (EXIF orientation not applied, as in COLMAP)."""
    cv2 = require("cv2", "reading the photos for guided placement")
    img = cv2.imread(path, cv2.IMREAD_GRAYSCALE | cv2.IMREAD_IGNORE_ORIENTATION)
    if img is None:
        raise GeorefError(f"cannot read {path}: missing, or not an image OpenCV reads")
    return img


def _camera_geometry(rec, name: str):
    im = next(i for i in rec.images.values() if i.name == name)
    cam = rec.cameras[im.camera_id]
    m = np.asarray(im.cam_from_world().matrix())
    return cam, m[:, :3], m[:, 3]


def refine_by_matching(rec, ref: PhotoPoint, tgt: PhotoPoint, xyz_model: Sequence[float],
                       search: Optional[MatchSearch] = None, normal: Optional[Sequence[float]] = None
                       ) -> Optional[Match]:
    """Look for the point observed at ``ref.xy`` in ``ref.image`` around its predicted position ``tgt.xy``
    in ``tgt.image``: the reference photo's neighbourhood of the point is re-projected into the target
    photo's geometry through the plane that faces the reference camera at the point's depth (``xyz_model``
    gives the depth), or through the plane of ``normal`` (model coordinates: the ground's up for obliques, whose
    views of the ground differ by more than a turn), then searched by normalised cross-correlation within
    ``search.radius`` pixels.

    Returns the sub-pixel match, or None when it is weak (score < ``search.min_score``), ambiguous (another peak
    within ``search.min_margin`` of the best), at the edge of the search window, or out of the image."""
    cv2 = require("cv2", "matching the GCP marks between photos")
    search = search or MatchSearch()
    ref_image, ref_xy, ref_gray = ref.image, ref.xy, ref.gray
    tgt_image, tgt_xy, tgt_gray = tgt.image, tgt.xy, tgt.gray
    radius, half, min_score, min_margin = search.radius, search.half, search.min_score, search.min_margin
    cam_r, rot_r, t_r = _camera_geometry(rec, ref_image)
    cam_t, rot_t, t_t = _camera_geometry(rec, tgt_image)
    c_r = -rot_r.T @ t_r
    c_t = -rot_t.T @ t_t
    xyz = np.asarray(xyz_model, dtype=float)
    depth = float((rot_r @ xyz + t_r)[2])
    if not depth > 0:
        return None
    ray = np.r_[np.asarray(cam_r.cam_from_img(np.asarray(ref_xy, dtype=float).reshape(1, 2))).reshape(2), 1.0]
    x0 = c_r + depth * (rot_r.T @ ray)  # the observed point at the predicted depth
    if normal is None:
        normal = rot_r.T @ np.array([0.0, 0.0, 1.0])  # plane facing the reference camera
    else:
        normal = np.asarray(normal, dtype=float) / max(float(np.linalg.norm(normal)), 1e-12)
    p0 = project_point(rec, x0, [tgt_image], margin=-1e9)  # no frame test: the window is checked below
    if tgt_image not in p0:
        return None
    p0 = np.array(p0[tgt_image][:2])
    shift0 = np.asarray(tgt_xy, dtype=float) - p0  # search around the prediction, template centred on p0
    r = int(math.ceil(radius + np.linalg.norm(shift0)))
    ref = np.asarray(ref_gray, dtype=np.float32)  # the arrays from here on
    tgt = np.asarray(tgt_gray, dtype=np.float32)
    # template: target pixels p0 + (du, dv) -> ray -> plane -> reference pixel; smaller near the frame's edge
    for h in (half, (3 * half) // 4, half // 2):
        if h < 6:
            return None
        du = np.arange(-h, h + 1, dtype=float)
        uu, vv = np.meshgrid(du, du)
        pix = np.column_stack([(p0[0] + uu).ravel(), (p0[1] + vv).ravel()])
        rays = np.column_stack([np.asarray(cam_t.cam_from_img(pix), dtype=float), np.ones(len(pix))]) @ rot_t
        denom = rays @ normal
        if np.any(np.abs(denom) < 1e-9):
            return None
        s = ((x0 - c_t) @ normal) / denom
        pts = c_t + s[:, None] * rays
        xc = (pts @ rot_r.T) + t_r
        if np.any(xc[:, 2] <= 0):
            return None
        ref_px = np.asarray(cam_r.img_from_cam(xc, check_cheirality=False), dtype=float)
        mx = (ref_px[:, 0] - 0.5).reshape(uu.shape).astype(np.float32)
        my = (ref_px[:, 1] - 0.5).reshape(uu.shape).astype(np.float32)
        if mx.min() >= 0 and my.min() >= 0 and mx.max() <= ref.shape[1] - 1 and my.max() <= ref.shape[0] - 1:
            half = h
            break
    else:
        return None
    templ = cv2.remap(ref, mx, my, cv2.INTER_LINEAR)
    if float(templ.std()) < 2.0:
        return None  # no texture to match
    # search window in the target (integer pixel grid; pixel k has its centre at k + 0.5)
    cx, cy = int(round(p0[0] - 0.5)), int(round(p0[1] - 0.5))
    x_lo, x_hi = max(0, cx - r - half), min(tgt.shape[1], cx + r + half + 1)
    y_lo, y_hi = max(0, cy - r - half), min(tgt.shape[0], cy + r + half + 1)
    if x_hi - x_lo < 2 * half + 3 or y_hi - y_lo < 2 * half + 3:
        return None
    window = tgt[y_lo:y_hi, x_lo:x_hi]
    ncc = cv2.matchTemplate(window, templ, cv2.TM_CCOEFF_NORMED)
    _, best, _, (bx, by) = cv2.minMaxLoc(ncc)
    if best < min_score:
        return None
    if not (0 < bx < ncc.shape[1] - 1 and 0 < by < ncc.shape[0] - 1):
        return None  # on the edge of the window: the true peak may lie outside
    masked = ncc.copy()
    masked[max(0, by - half):by + half + 1, max(0, bx - half):bx + half + 1] = -1.0
    second = float(masked.max()) if masked.size else -1.0
    if best - second < min_margin:
        return None
    # sub-pixel: parabola through the peak and its neighbours
    def vertex(a, b, c):
        d = a - 2 * b + c
        return 0.0 if abs(d) < 1e-12 else float(np.clip(0.5 * (a - c) / d, -0.5, 0.5))

    sx = vertex(ncc[by, bx - 1], ncc[by, bx], ncc[by, bx + 1])
    sy = vertex(ncc[by - 1, bx], ncc[by, bx], ncc[by + 1, bx])
    # the template was sampled at p0 + (i - half, j - half); matched at window offset (bx, by), its centre
    # sample (the point) sits on the centre of target pixel (x_lo + bx + half, y_lo + by + half)
    x = x_lo + bx + half + 0.5 + sx
    y = y_lo + by + half + 0.5 + sy
    if not (0 <= x <= tgt.shape[1] and 0 <= y <= tgt.shape[0]):
        return None
    return Match(float(x), float(y), float(best), float(best - second),
                 float(np.hypot(x - tgt_xy[0], y - tgt_xy[1])))


__all__ = ["GEOREF", "HELMERT", "RAYS", "Match", "MatchSearch", "PhotoPoint", "Prediction", "Predictor",
           "ground_sample_distance", "image_footprints", "images_seeing", "project_point", "read_gray", "refine_by_matching",
           "write_footprints_gpkg"]
