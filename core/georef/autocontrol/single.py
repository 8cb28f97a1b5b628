"""Automatic control of one photo (issue 16 item 3): a single photo, vertical or oblique, with a rough location
and no hand-picked GCP, oriented by space resection from matches against a reference orthophoto and DSM.

1. The reference orthophoto around the rough location (the search radius plus how far the photo may see) is
   matched to the photo: RootSIFT on affine-simulated views of the photo (ASIFT: the photo squeezed along a few
   directions, so that an oblique's foreshortening meets the reference's nadir view; the features are rotation
   invariant, so the heading need not be known), Lowe's ratio test, a RANSAC homography ground -> photo.
2. The photo is rectified onto the reference grid through that homography and matched again at the same
   resolution (``matching.match_orthos``: a similarity, then an affine per tile with a tight threshold); each
   match is a ground point (X, Y from the reference orthophoto, Z from the reference DSM) with its pixel in the
   photo; points on steep relief (walls, roof edges, trees) are left out.
3. Space resection (``core.geometry.resection``, robust; the focal length searched and estimated when the photo
   has none): the camera's pose.
4. Refinement: the photo is re-rendered through that pose onto the reference DSM (a true orthophoto of it on the
   reference grid, so relief and obliquity no longer bias the match), matched again, and resected again.

The result holds the pose and the automatic GCPs (``auto_001`` ...) with their residuals, as a GCP set that the
single-image orthorectification (``core.ortho.single``) uses as its control.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

from ...common.errors import require
from ...common.progress import NullProgress, Progress, check_cancel
from ...geometry import resection as rs
from ...geometry.camera import Intrinsics, Pose, project_points
from ...geometry.crs import transform_points, unit_symbol
from ...io import gcp as gcpmod
from ...io.images import read_image, to_grey
from .errors import AutoControlError
from .matching import Features, match_orthos, ratio_matches, root_features, rootsift
from .options import AUTO, AutoControlOptions
from .reference import Reference

AUTO_PREFIX = "auto_"


@dataclass
class PhotoControlOptions:
    """``reach``: metres beyond the search radius the photo may see (None: 4 x ``height`` when given, else
    ``default_reach``); ``max_pixels``: the reference window's largest side in the first match (coarser beyond);
    ``photo_pixels``: the photo's largest side for the first match; ``max_tilt``: the largest simulated tilt of
    the affine views (1: plain SIFT); ``homography_px``: the first match's RANSAC threshold (reference pixels);
    ``min_matches``: homography inliers needed (``good_matches``: enough without the affine views); ``passes``: re-renderings through the pose; ``max_points``: the
    GCPs kept for the resection (the best of a grid over the photo); ``max_relief``: DSM misfit around a point
    beyond which its height is not trusted, in the DSM's units (None: ``relief_cells`` x the coarser of the match's
    grid and the DSM's cell: 0.62 m at a 0.25 m DSM, as the 0.6 m it was; 25 m at a 10 m DEM, whose cells hold
    whole houses); ``focal_factors``: focal lengths tried (times the photo's long
    side) when the photo has none."""

    reach: Optional[float] = None
    default_reach: float = 200.0
    max_pixels: int = 2000
    photo_pixels: int = 1600
    n_features: int = 8000
    ratio: float = 0.85
    max_tilt: float = 2.0
    homography_px: float = 8.0
    min_matches: int = 15
    good_matches: int = 60
    passes: int = 1
    max_points: int = 200
    max_relief: Optional[float] = None
    relief_cells: float = 2.5
    sigma_px: float = 1.0
    focal_factors: Tuple[float, ...] = (0.6, 0.8, 1.0, 1.25, 1.6, 2.0, 2.6, 3.4)
    match: AutoControlOptions = field(default_factory=lambda: AutoControlOptions(
        n_features=8000, ratio=0.85, ransac_px=4.0, tile_px=128, tile_ransac_px=1.5, min_tile_matches=6))


@dataclass
class PhotoControl:
    """The photo's orientation from the automatic control: ``pose`` (cam_from_world in the local frame: world
    minus ``offset``) and ``camera``; ``centre``: the camera centre in the reference CRS ``crs``; ``gcps``: the
    automatic GCPs used (names ``auto_NNN``, role control, observations in ``image``) and ``residuals`` (name,
    px, py, dx, dy, used) of all candidates; ``figures``: matches found at each step."""

    image: str
    crs: str
    offset: np.ndarray
    pose: Pose
    camera: Intrinsics
    centre: np.ndarray
    gcps: gcpmod.GCPSet
    residuals: List[rs.PointResidual]
    rmse_px: float
    estimated_focal: bool
    figures: dict
    messages: List[str] = field(default_factory=list)
    warnings: List[str] = field(default_factory=list)


@dataclass
class _Photo:
    name: str
    grey: np.ndarray  # full resolution, uint8
    width: int
    height: int


def _read_photo(path: str) -> _Photo:
    arr = read_image(path)
    g = to_grey(arr)
    grey = np.clip(g * 255.0, 0, 255).astype(np.uint8)
    return _Photo(os.path.basename(path), grey, grey.shape[1], grey.shape[0])


def affine_rootsift(grey: np.ndarray, n_features: int, max_tilt: float) -> Features:
    """RootSIFT of ``grey`` and of affine-simulated views of it (ASIFT, tilts up to ``max_tilt``), the
    keypoints in the original image's OpenCV pixels."""
    cv2 = require("cv2", "the automatic control")
    img = cv2.createCLAHE(clipLimit=2.0, tileGridSize=(8, 8)).apply(grey)
    if max_tilt > 1.01:
        n_tilts = int(math.ceil(math.log2(max_tilt) * 2))
        n_views = 1 + sum(int(math.ceil(180.0 / (72.0 / math.sqrt(2.0) ** k))) for k in range(1, n_tilts + 1))
        sift = cv2.SIFT_create(nfeatures=max(500, int(n_features) // n_views))
        det = cv2.AffineFeature_create(sift, maxTilt=n_tilts, minTilt=0, tiltStep=math.sqrt(2.0), rotateStepBase=72.0)
    else:
        det = cv2.SIFT_create(nfeatures=int(n_features))
    kps, desc = det.detectAndCompute(img, None)
    return root_features(kps, desc)


@dataclass
class _Window:
    """The reference over a box at one resolution: grey image, valid mask, geotransform."""

    grey: np.ndarray
    valid: np.ndarray
    gt: Tuple[float, ...]

    def world(self, uv: np.ndarray) -> np.ndarray:
        """OpenCV pixels (N, 2) -> world X, Y."""
        uv = np.asarray(uv, dtype=float)
        return np.column_stack([self.gt[0] + (uv[:, 0] + 0.5) * self.gt[1], self.gt[3] + (uv[:, 1] + 0.5) * self.gt[5]])

    def grid(self) -> Tuple[np.ndarray, np.ndarray]:
        h, w = self.grey.shape
        xs = self.gt[0] + (np.arange(w) + 0.5) * self.gt[1]
        ys = self.gt[3] + (np.arange(h) + 0.5) * self.gt[5]
        return np.meshgrid(xs, ys)


def _pixel_to_world(gt) -> np.ndarray:
    """3 x 3 map of OpenCV pixels of a north-up grid to world X, Y."""
    return np.array([[gt[1], 0.0, gt[0] + 0.5 * gt[1]], [0.0, gt[5], gt[3] + 0.5 * gt[5]], [0.0, 0.0, 1.0]])


def _search_box(ref: Reference, photo: str, location, radius: float, reach: float
                ) -> Tuple[float, float, float, float]:
    bx0, by0, bx1, by1 = ref.bounds
    if location is None:
        return ref.bounds
    x, y = float(location[0]), float(location[1])
    r = float(radius) + float(reach)
    box = (max(bx0, x - r), max(by0, y - r), min(bx1, x + r), min(by1, y + r))
    if box[2] - box[0] < 5 * ref.gsd or box[3] - box[1] < 5 * ref.gsd:
        raise AutoControlError(
            f"automatic control of {photo}: the rough location ({x:.1f}, {y:.1f}) with the search radius "
            f"{radius:g} and a reach of {reach:g} lies outside the reference orthophoto {ref.ortho_path} (it covers "
            f"{bx0:.1f}..{bx1:.1f}, {by0:.1f}..{by1:.1f} in {ref.crs}): give the location in the reference's CRS, "
            "or a reference of this place")
    return box


def _window(ref: Reference, box, res: float) -> _Window:
    grey, valid, gt = ref.grey(box, res)
    return _Window(grey, valid, gt)


def _crop(win: _Window, f: Features, box) -> Tuple[_Window, Features]:
    """The part of ``win`` (and of its features) over ``box``, on the same grid."""
    gt = win.gt
    rows, cols = win.grey.shape
    c0, c1 = max(0, int((box[0] - gt[0]) / gt[1])), min(cols, int(math.ceil((box[2] - gt[0]) / gt[1])))
    r0, r1 = max(0, int((box[3] - gt[3]) / gt[5])), min(rows, int(math.ceil((box[1] - gt[3]) / gt[5])))
    sub = _Window(win.grey[r0:r1, c0:c1], win.valid[r0:r1, c0:c1],
                  (gt[0] + c0 * gt[1], gt[1], 0.0, gt[3] + r0 * gt[5], 0.0, gt[5]))
    xy = f.xy - np.array([c0, r0], dtype=np.float32)
    inside = (xy[:, 0] >= 4) & (xy[:, 1] >= 4) & (xy[:, 0] < c1 - c0 - 4) & (xy[:, 1] < r1 - r0 - 4)
    return sub, Features(xy[inside], f.desc[inside], f.size[inside])


def _first_match(photo: _Photo, win: _Window, opt: PhotoControlOptions, ref: Reference, where: str):
    """(homography photo OpenCV pixel -> window pixel, inlier photo pixels, window pixels, counts)."""
    cv2 = require("cv2", "the automatic control")
    s = min(1.0, opt.photo_pixels / max(photo.width, photo.height))
    small = photo.grey if s >= 1.0 else cv2.resize(photo.grey, (max(1, round(photo.width * s)),
                                                                max(1, round(photo.height * s))),
                                                   interpolation=cv2.INTER_AREA)
    sx, sy = small.shape[1] / photo.width, small.shape[0] / photo.height
    fb = rootsift(win.grey, win.valid, opt.n_features)
    counts: dict = {}
    h, inl, src, dst = None, np.zeros(0, dtype=bool), np.zeros((0, 2)), np.zeros((0, 2))
    # plain SIFT first (enough for a vertical and most obliques), the affine views when it finds too little
    for tilt in ((1.0, opt.max_tilt) if opt.max_tilt > 1.01 else (1.0,)):
        fa = affine_rootsift(small, opt.n_features, tilt)
        ia, ib = ratio_matches(fa, fb, opt.ratio)
        counts = {"features_photo": int(len(fa.xy)), "features_reference": int(len(fb.xy)),
                  "ratio_matches": int(len(ia)), "max_tilt": float(tilt)}
        if len(ia) >= 4:
            src = (fa.xy[ia].astype(np.float64) + 0.5) / [sx, sy] - 0.5  # full-resolution OpenCV pixels
            dst = fb.xy[ib].astype(np.float64)
            h, mask = cv2.findHomography(src, dst, cv2.RANSAC, float(opt.homography_px), maxIters=20000,
                                         confidence=0.999)
            inl = mask.ravel().astype(bool) if h is not None else np.zeros(len(ia), dtype=bool)
        if h is not None and inl.sum() >= opt.good_matches:
            break
    counts["homography_inliers"] = int(inl.sum())
    if h is None or inl.sum() < opt.min_matches:
        raise AutoControlError(
            f"automatic control of {photo.name}: no match with the reference orthophoto {ref.ortho_path} {where} "
            f"({counts['ratio_matches']} ratio-test matches of {counts['features_photo']} photo and "
            f"{counts['features_reference']} reference features, {counts['homography_inliers']} agree on one view; "
            f"{opt.min_matches} needed). Check the rough location and the search radius, and that the reference "
            "shows this place")
    return h, src[inl], dst[inl], counts, fb


def _rectify_homography(photo: _Photo, win: _Window, h: np.ndarray):
    """The photo on the window's grid through the homography photo -> window: (image, valid, map window pixel ->
    photo OpenCV pixel)."""
    hi = np.linalg.inv(h)

    def to_photo(uv):
        p = np.column_stack([uv, np.ones(len(uv))]) @ hi.T
        w = p[:, 2]
        ok = np.abs(w) > 1e-12
        out = np.where(ok[:, None], p[:, :2] / np.where(ok, w, 1.0)[:, None], np.nan)
        return out, w

    rows, cols = win.grey.shape
    uu, vv = np.meshgrid(np.arange(cols, dtype=float), np.arange(rows, dtype=float))
    pix, w = to_photo(np.column_stack([uu.ravel(), vv.ravel()]))
    # the side of the horizon the matches are on (a plane's points behind the camera map with the other sign)
    sign = np.sign(np.median(w[np.isfinite(pix[:, 0])])) if np.isfinite(pix[:, 0]).any() else 1.0
    pix[w * sign <= 0] = np.nan
    img, valid = _remap(photo, pix.reshape(rows, cols, 2))
    return img, valid, lambda uv: to_photo(np.asarray(uv, dtype=float))[0]


def _remap(photo: _Photo, pix: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    cv2 = require("cv2", "the automatic control")
    mx = pix[..., 0].astype(np.float32)
    my = pix[..., 1].astype(np.float32)
    valid = np.isfinite(mx) & np.isfinite(my) & (mx >= 0) & (my >= 0) & (mx <= photo.width - 1) & (
        my <= photo.height - 1)
    mx[~valid] = -10.0
    my[~valid] = -10.0
    img = cv2.remap(photo.grey, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0)
    return img, valid


def _rectify_pose(photo: _Photo, win: _Window, ref: Reference, pose: Pose, cam: Intrinsics, offset: np.ndarray):
    """The photo re-rendered through the pose onto the reference DSM on the window's grid (a true orthophoto of
    it, no occlusion test): (image, valid, map window pixel -> photo OpenCV pixel)."""
    cv2 = require("cv2", "the automatic control")
    xx, yy = win.grid()
    zz = ref.heights(xx.ravel(), yy.ravel())
    xyz = np.column_stack([xx.ravel(), yy.ravel(), zz]) - offset
    px, ok = project_points(pose, cam, xyz)
    px = np.where((ok & np.isfinite(zz))[:, None], px - 0.5, np.nan)
    gsd_photo = np.nanmedian(np.linalg.norm(xyz - pose.centre, axis=1)[ok]) / cam.focal if ok.any() else 0.0
    src = photo
    if gsd_photo > 0 and win.gt[1] > 1.5 * gsd_photo:  # the grid is coarser than the photo: no aliasing
        sigma = 0.5 * win.gt[1] / gsd_photo
        src = _Photo(photo.name, cv2.GaussianBlur(photo.grey, (0, 0), sigma), photo.width, photo.height)
    img, valid = _remap(src, px.reshape(xx.shape + (2,)))

    def to_photo(uv):
        g = win.world(uv)
        z = ref.heights(g[:, 0], g[:, 1])
        p, ok_ = project_points(pose, cam, np.column_stack([g, z]) - offset)
        return np.where((ok_ & np.isfinite(z))[:, None], p - 0.5, np.nan)

    return img, valid, to_photo


def _ground_points(ms, win: _Window, ref: Reference, to_photo, photo: _Photo, opt: PhotoControlOptions):
    """(world XYZ (N, 3), photo COLMAP pixels (N, 2), match residuals) of the matches reference window (src) ->
    rectified photo (dst), on trustworthy heights, thinned to the best per cell of a grid over the photo."""
    xy = win.world(ms.src)
    cell = max(win.gt[1], ref.dsm_gsd)
    z, _slope, misfit = ref.relief(xy[:, 0], xy[:, 1], 2.0 * cell)
    px = to_photo(ms.dst) + 0.5
    max_relief = opt.max_relief if opt.max_relief is not None else opt.relief_cells * cell
    ok = np.isfinite(z) & (misfit <= max_relief) & np.all(np.isfinite(px), axis=1)
    ok &= (px[:, 0] >= 0) & (px[:, 1] >= 0) & (px[:, 0] <= photo.width) & (px[:, 1] <= photo.height)
    xyz, px, res = np.column_stack([xy, z])[ok], px[ok], np.asarray(ms.residual)[ok]
    if len(xyz) > opt.max_points:
        side = math.sqrt(photo.width * photo.height / opt.max_points)
        key = (px[:, 1] // side).astype(int) * 100003 + (px[:, 0] // side).astype(int)
        order = np.lexsort((res, key))
        first = np.concatenate([[True], key[order][1:] != key[order][:-1]])
        keep = order[first]
        xyz, px, res = xyz[keep], px[keep], res[keep]
    return xyz, px, res


def _focal_search(xyz, px, photo: _Photo, opt: PhotoControlOptions, offset) -> Intrinsics:
    """The starting focal length most points agree with (RANSAC PnP at each of ``focal_factors``)."""
    cv2 = require("cv2", "the automatic control")
    best = None
    thr = max(4.0, 0.003 * math.hypot(photo.width, photo.height))
    for f in opt.focal_factors:
        cam = Intrinsics.simple(photo.width, photo.height, f * max(photo.width, photo.height))
        ok, rvec, tvec, inl = cv2.solvePnPRansac(np.ascontiguousarray(xyz - offset, dtype=np.float64),
                                                 np.ascontiguousarray(px - 0.5, dtype=np.float64), cam.matrix, None,
                                                 iterationsCount=500, reprojectionError=thr, confidence=0.999,
                                                 flags=cv2.SOLVEPNP_SQPNP)
        n = 0 if not ok or inl is None else len(inl)
        if best is None or n > best[0]:
            best = (n, cam)
    if best is None or best[0] < rs.MIN_INTRINSICS_POINTS:
        raise AutoControlError(f"automatic control of {photo.name}: no focal length between "
                               f"{min(opt.focal_factors):g} and {max(opt.focal_factors):g} x the photo's long side "
                               f"fits the {len(xyz)} automatic GCPs: give the focal length")
    return best[1]


def _resect(xyz: np.ndarray, px: np.ndarray, camera: Optional[Intrinsics], photo: _Photo, opt: PhotoControlOptions,
            offset: np.ndarray, estimate, ref: Reference) -> rs.ResectionResult:
    """Space resection from the automatic GCPs; with no focal length, the focal lengths of ``focal_factors``
    are tried and the one most points agree with is refined (focal length and k1)."""
    names = [f"{AUTO_PREFIX}{i + 1:03d}" for i in range(len(xyz))]
    if len(xyz) < rs.MIN_INTRINSICS_POINTS:
        raise AutoControlError(f"automatic control of {photo.name}: only {len(xyz)} ground points survived the "
                               f"match with the reference orthophoto {ref.ortho_path} and the height check on the reference DSM "
                               f"({rs.MIN_INTRINSICS_POINTS} needed)")
    if camera is None:  # the focal length searched on a few points spread over the photo, then all of them
        camera, estimate = _focal_search(xyz, px, photo, opt, offset), True
    best, errors = None, []
    for cam in [camera]:
        try:
            r = rs.space_resection(xyz - offset, px, cam, names=names, image=photo.name, estimate_intrinsics=estimate)
        except rs.ResectionError as e:
            errors.append(str(e))
            continue
        key = (r.n_used, -r.rmse_px)
        if best is None or key > best[0]:
            best = (key, r)
    if best is None:
        raise AutoControlError(f"automatic control of {photo.name}: the space resection from {len(xyz)} automatic "
                               f"GCPs failed: {errors[-1] if errors else 'no pose'}")
    return best[1]


@dataclass
class SearchArea:
    """Where a photo is looked for on the reference: ``location``, the rough (x, y) of the ground it shows, in
    ``crs`` (None: the reference's CRS), or None to search the whole reference; ``radius``: how far off it may be
    (metres); ``height``: roughly how high above the ground the photo was taken (only bounds the search)."""

    location: Optional[Sequence[float]] = None
    radius: float = 50.0
    crs: Optional[str] = None
    height: Optional[float] = None


@dataclass
class KnownCamera:
    """What is known of a photo's interior orientation: ``camera`` or ``focal_px`` (neither: the focal length is
    estimated); ``estimate_intrinsics``: True / False / "auto" (as ``core.geometry.resection.space_resection``)."""

    camera: Optional[Intrinsics] = None
    focal_px: Optional[float] = None
    estimate_intrinsics: Any = "auto"


def control_photo(image_path: str, reference_ortho: str, reference_dsm: str, area: Optional[SearchArea] = None,
                  known: Optional[KnownCamera] = None, options: Optional[PhotoControlOptions] = None,
                  progress: Optional[Progress] = None) -> PhotoControl:
    """Orient one photo by automatic control against a reference orthophoto and DSM (module docstring), looked
    for in ``area`` (None: anywhere on the reference) with the interior orientation ``known`` (None: estimated)."""
    progress = progress or NullProgress()
    opt = options or PhotoControlOptions()
    if not image_path or not os.path.isfile(image_path):
        raise AutoControlError(f"automatic control: the photo {image_path!r} does not exist")
    ref = Reference(reference_ortho, reference_dsm)
    try:
        return _control(image_path, ref, area or SearchArea(), known or KnownCamera(), opt, progress)
    finally:
        ref.close()


def _control(image_path, ref: Reference, area: SearchArea, known: KnownCamera, opt: PhotoControlOptions,
             progress: Progress) -> PhotoControl:
    location, search_radius, location_crs, height = area.location, area.radius, area.crs, area.height
    camera, focal_px, estimate_intrinsics = known.camera, known.focal_px, known.estimate_intrinsics
    photo = _read_photo(image_path)
    messages: List[str] = []
    if location is not None and location_crs:
        location = transform_points(np.array([[float(location[0]), float(location[1])]]), location_crs,
                                    ref.crs_wkt)[0]
    reach = opt.reach if opt.reach is not None else (4.0 * float(height) if height else opt.default_reach)
    box = _search_box(ref, photo.name, location, search_radius, reach)
    res = max(ref.gsd, max(box[2] - box[0], box[3] - box[1]) / opt.max_pixels)
    where = (f"within {search_radius:g} of ({location[0]:.1f}, {location[1]:.1f})" if location is not None
             else "anywhere on it")
    win = _window(ref, box, res)
    h, src, dst, counts, f_win = _first_match(photo, win, opt, ref, where)
    messages.append(f"{photo.name}: {counts['ratio_matches']} ratio-test matches with {os.path.basename(ref.ortho_path)}"
                    f" at {res:.3g} {unit_symbol(ref.crs_wkt)} per pixel, {counts['homography_inliers']} agree on one "
                    "view (homography)")
    progress.report(0.3, "first match")
    check_cancel(progress)
    if camera is None and focal_px:
        camera = Intrinsics.simple(photo.width, photo.height, float(focal_px))
    g = win.world(dst)
    offset = np.array([round(float(np.mean(g[:, 0]))), round(float(np.mean(g[:, 1]))), 0.0])
    # the ground the photo sees: the inliers' box, enlarged; at the reference's own resolution (or coarser)
    span = np.ptp(g, axis=0)
    fine_box = (max(box[0], g[:, 0].min() - 0.3 * span[0]), max(box[1], g[:, 1].min() - 0.3 * span[1]),
                min(box[2], g[:, 0].max() + 0.3 * span[0]), min(box[3], g[:, 1].max() + 0.3 * span[1]))
    fine_res = max(ref.gsd, max(fine_box[2] - fine_box[0], fine_box[3] - fine_box[1]) / opt.max_pixels)
    area = (fine_box[2] - fine_box[0]) * (fine_box[3] - fine_box[1])
    if fine_res == res and area >= 0.8 * (box[2] - box[0]) * (box[3] - box[1]):  # nearly all of the first window
        fine, f_ref = _crop(win, f_win, fine_box)
    else:
        fine = _window(ref, fine_box, fine_res)
        f_ref = rootsift(fine.grey, fine.valid, opt.match.n_features)
    h_fine = np.linalg.inv(_pixel_to_world(fine.gt)) @ _pixel_to_world(win.gt) @ h
    img, valid, to_photo = _rectify_homography(photo, fine, h_fine)
    result, figures = None, dict(counts)
    for k in range(opt.passes + 1):
        ms = match_orthos(fine.grey, fine.valid, img, valid, opt.match, ortho_features=f_ref)  # reference -> photo
        xyz, px, _mres = _ground_points(ms, fine, ref, to_photo, photo, opt)
        step = "homography" if k == 0 else f"pose {k}"
        figures[f"matches_{step}"] = int(len(ms.src))
        figures[f"points_{step}"] = int(len(xyz))
        if result is not None and len(xyz) < rs.MIN_INTRINSICS_POINTS:
            break  # keep the pose of the pass before
        est = estimate_intrinsics if camera is not None else True
        cam0 = camera if camera is not None or result is None else result.camera
        result = _resect(xyz, px, cam0, photo, opt, offset, est, ref)
        messages.append(f"{photo.name}, pass {k + 1} (photo rectified by the {step}): {len(ms.src)} matches, "
                        f"{len(xyz)} ground points on firm heights, {result.n_used} agree with the resection, "
                        f"RMSE {result.rmse_px:.2f} px, focal length {result.camera.focal:.1f} px")
        progress.report(0.3 + 0.7 * (k + 1) / (opt.passes + 1), step)
        check_cancel(progress)
        if k < opt.passes:
            img, valid, to_photo = _rectify_pose(photo, fine, ref, result.pose, result.camera, offset)
    return _finish(photo, ref, result, xyz, px, offset, figures, messages)


def _finish(photo: _Photo, ref: Reference, r: rs.ResectionResult, xyz, px, offset, figures, messages
            ) -> PhotoControl:
    crs = ref.crs
    sigma = max(ref.gsd, 1e-3)
    gs = gcpmod.GCPSet(crs, source=f"automatic control against {ref.ortho_path}")
    for (nm, p, q, rr) in zip([x.name for x in r.residuals], xyz, px, r.residuals):
        if not rr.used:
            continue
        gs.points.append(gcpmod.GroundPoint(nm, float(p[0]), float(p[1]), float(p[2]), sigma_xy=sigma,
                                            sigma_z=max(sigma, ref.dsm_gsd), role=gcpmod.CONTROL,
                                            observations=[gcpmod.Observation(photo.name, float(q[0]), float(q[1]))]))
    warnings = [w for w in r.warnings if not w.startswith(f"GCP {AUTO_PREFIX}")]
    n_out = len(r.outliers)
    if n_out:
        messages.append(f"{photo.name}: {n_out} of {len(r.residuals)} automatic GCPs disagree with the resection "
                        "and are left out")
    figures.update(kept=int(r.n_used), candidates=int(len(r.residuals)), rmse_px=float(r.rmse_px))
    centre = r.pose.centre + offset
    messages.append(f"{photo.name}: camera at X {centre[0]:.2f} Y {centre[1]:.2f} Z {centre[2]:.2f} from "
                    f"{r.n_used} automatic GCPs ({AUTO} control)")
    return PhotoControl(photo.name, crs, np.asarray(offset, dtype=float), r.pose, r.camera, centre, gs,
                        list(r.residuals), float(r.rmse_px), bool(r.estimated_intrinsics), figures, messages,
                        warnings)


__all__ = ["AUTO_PREFIX", "KnownCamera", "PhotoControl", "PhotoControlOptions", "SearchArea", "affine_rootsift",
           "control_photo"]
