"""Calibrated cameras: which camera of the block takes which given interior orientation, and what the
adjustments may change of it.

Sources of a given interior orientation, per camera group (core.io.images.group_cameras):

- a calibration file (``AlignOptions.calibration``, read by :func:`core.io.calibration.read_calibration`): one
  calibration applies to every image; several are matched per image by their ``images`` glob patterns, else by
  their name against the photo's EXIF camera model, else by the image size (a calibration with patterns takes only
  the images they match).  Images of one group that take different calibrations make separate cameras.  A photo
  whose size differs from the calibration's (a scan at another resolution) takes it ``scaled_to`` its size;
- a film scan restituted by Prepare images (``scans.json``: its ``interior_orientation``, the principal point at
  the prepared image's centre and the focal length in pixels where it is known), for the prepared images;
- FOCAL_MM + SENSOR_WIDTH_MM (or a focal length in pixels) when ``intrinsics`` is ``fixed`` or ``refined``: the
  focal length, the principal point at the image centre, no distortion.

The mode (``AlignOptions.intrinsics``, overridden per camera by the file's ``adjust``): ``fixed`` keeps the given
values through the alignment and the georeference; ``refined`` keeps them through the alignment (COLMAP has no
priors on intrinsics) and lets the georeference refine them with priors at the given values weighted by their
sigmas; ``estimated`` starts the self-calibration from them (today's behaviour where nothing is given).  ``auto``
is ``fixed`` where something is given, ``estimated`` elsewhere.

Before any work (issue 47): a focal length given (FOCAL_MM / SENSOR_WIDTH_MM, in pixels) or a calibration's that is
:data:`core.geometry.plausible.FOCAL_RATIO_REFUSED` times the photos' EXIF one (either way) is refused with the likely
cause (a 35 mm equivalent, a wrong sensor width, a focal length in mm read as normalised); a photo that two
calibrations without patterns fit by size alone is refused naming both (the file does not say which).

The alignment records per camera (``sfm/alignment.json``, ``intrinsics``: :func:`intrinsics_record`) the mode,
the source, the given values and sigmas and the final values; the georeference reads it back
(``core.project.layout.Layout.camera_intrinsics``).
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field, replace
from typing import Dict, List, Optional, Sequence, Tuple

from ..common.progress import Progress
from ..geometry import plausible
from ..io.images import CameraGroup, ImageInfo
from ..project.layout import read_json
from .options import HELD, AlignError, AlignOptions

FOCAL_SOURCE = "FOCAL_MM / SENSOR_WIDTH_MM"
RECORD_FORMAT = 1
# the names a calibration's sigmas may use for a COLMAP parameter (the first that is given counts)
SIGMA_ALIASES = {
    "f": ("f", "focal", "focal_px"), "fx": ("fx", "focal_x", "focal", "focal_px"),
    "fy": ("fy", "focal_y", "focal_y_px", "focal", "focal_px"), "cx": ("cx", "cx_px"), "cy": ("cy", "cy_px"),
    "k": ("k", "k1"),
}


@dataclass
class GivenCamera:
    """A camera's given interior orientation as the alignment uses it (COLMAP model and parameters)."""

    mode: str  # fixed / refined / estimated
    source: str  # the calibration file, the scans.json, or FOCAL_SOURCE
    name: str
    model: str
    params: List[float]
    sigmas: Dict[str, float] = field(default_factory=dict)  # COLMAP parameter name -> sigma (px: focal, pp)
    matched_by: str = ""
    scaled_from: Optional[Tuple[int, int]] = None
    note: str = ""  # what the alignment changed of the calibration (for the log)
    pixel_size_mm: Optional[float] = None  # the x pixel size where the calibration gives one (the report's mm)

    @property
    def held(self) -> bool:
        return self.mode in HELD


def source_label(source: str) -> str:
    """A given interior orientation's source for the log: a calibration file's name, else the source as it is
    (``FOCAL_MM / SENSOR_WIDTH_MM``, ``scans.json``: a basename would cut the options' name in two)."""
    return source if source in (FOCAL_SOURCE, "scans.json") else os.path.basename(source or "")


def read_calibrations(options: AlignOptions) -> list:
    """The calibrations of ``options.calibration`` (empty without one).  CalibrationError (an ArchaeoOrthoError)
    naming the file, the line and the field for a bad file; AlignError for a file that is not there."""
    if not options.calibration:
        return []
    path = options.calibration
    if not os.path.isfile(path):
        raise AlignError(f"calibration file {path} does not exist" if not os.path.exists(path)
                         else f"calibration file {path} is a folder, not a file")
    from ..io.calibration import read_calibration

    cals = list(read_calibration(path))
    if not cals:
        raise AlignError(f"calibration file {path}: no camera in it")
    return cals


def scan_interior(scans_json: str, infos: Sequence[ImageInfo]) -> Dict[str, dict]:
    """image name -> the restituted interior orientation of the film scans Prepare images wrote (``scans.json``)
    for the images of ``infos`` it made whose size is the frame's, where the focal length in pixels or the frame's
    pixel size in mm is known (a calibration file's millimetre values then give the prepared images' camera)."""
    data = read_json(scans_json) if os.path.isfile(scans_json) else None
    io = (data or {}).get("interior_orientation") or {}
    if not io.get("focal_px") and not (io.get("frame_units") == "mm" and io.get("pixel_size")):
        return {}
    prepared = {s.get("prepared_name") for s in (data or {}).get("scans", [])}
    size = (io.get("width"), io.get("height"))
    return {im.name: io for im in infos if im.name in prepared and (im.width, im.height) == size}


def match_calibration(info: ImageInfo, cals: Sequence) -> Tuple[Optional[object], str]:
    """(the calibration of a photo, how it was matched) or (None, ""): the one whose ``images`` patterns match
    its name (a calibration with patterns takes only those images), else the only calibration of the file, else
    the one named as the photo's EXIF camera model, else the only one of the photo's size."""
    hit = [c for c in cals if c.images and c.applies_to(info.name)]
    if len(hit) > 1:
        raise AlignError(f"calibration file {hit[0].source}: image {info.name} matches the images patterns of both "
                         f"{hit[0].label()} and {hit[1].label()}")
    if hit:
        return hit[0], "its images patterns"
    free = [c for c in cals if not c.images]
    if len(cals) == 1 and free:
        return free[0], "the only calibration"
    model = (info.model or "").strip().lower()
    hit = [c for c in free if model and (c.name or "").strip().lower() == model]
    if hit:
        return hit[0], "the EXIF camera model"
    hit = [c for c in free if (c.width, c.height) == (info.width, info.height)]
    if len(hit) == 1:
        return hit[0], "the image size"
    if len(hit) > 1:  # the file does not say which: guessing one holds a camera the photos may not be
        raise AlignError(_ambiguous(info, hit))
    return None, ""


def _ambiguous(info: ImageInfo, hit: Sequence) -> str:
    """The message of a photo that two or more calibrations without patterns fit by size alone."""
    source = os.path.basename(hit[0].source or "")
    listed = "; ".join(f"{c.label()}: focal {c.fx:.1f} px" for c in hit[:-1]) + f" and {hit[-1].label()}: " \
        f"focal {hit[-1].fx:.1f} px"
    colmap = source.lower().endswith(".txt") and all((c.name or "").isdigit() for c in hit)
    how = ("A COLMAP cameras file names its cameras by number only: delete the others' lines (keep the camera "
           "these photos were taken with), or give that camera in a file of its own" if colmap else
           f"Name the camera these photos were taken with after their EXIF camera model "
           f"({repr(info.model) if info.model else 'the photos have none'}), or give it images patterns matching "
           f"the photos' names (images: [...]), or delete the others")
    return (f"calibration file {source}: {len(hit)} of its cameras fit the photo {info.name} ({info.width} x "
            f"{info.height} px): {listed}; none is named after the photo's EXIF camera model or has images patterns "
            f"matching it, so the file does not say which one these photos take. {how}")


def _param_names(pycolmap, model: str) -> List[str]:
    cam = pycolmap.Camera.create_from_model_name(1, model, 1.0, 2, 2)
    return [s.strip() for s in cam.params_info.split(",")]


def _sigmas(names: Sequence[str], given: Dict[str, float]) -> Dict[str, float]:
    out = {}
    for n in names:
        for alias in SIGMA_ALIASES.get(n, (n,)):
            v = given.get(alias) if given else None
            if v is not None and math.isfinite(float(v)) and float(v) > 0:
                out[n] = float(v)
                break
    return out


def _in_prepared_frame(cal, info: ImageInfo, frame: Optional[dict]):
    """The calibration for a film scan Prepare images restituted into a frame of known pixel size (mm): a
    certificate's focal length in mm over the prepared pixel size, the principal point at the image centre (where
    the restitution puts it), the distortion unchanged; None where the calibration or the frame lacks millimetres."""
    if (not frame or frame.get("frame_units") != "mm" or not frame.get("pixel_size")
            or getattr(cal, "focal_mm", None) is None or getattr(cal, "pixel_size_mm", None) is None):
        return None
    return cal.for_resampled_frame(info.width, info.height, float(frame["pixel_size"]))


def _from_calibration(pycolmap, cal, info: ImageInfo, mode: str, how: str, frame: Optional[dict] = None
                      ) -> GivenCamera:
    source = getattr(cal, "source", "") or ""
    scaled_from = None
    prepared = _in_prepared_frame(cal, info, frame)
    if prepared is not None:
        # a certificate's image size is the raw scan's: the prepared images are cut to the frame, not rescaled
        how += (f", in the frame Prepare images restituted ({prepared.pixel_size_mm:.6g} mm pixels: "
                f"{prepared.focal_mm:.6g} mm = {prepared.focal_px:.2f} px)")
        cal = prepared
    elif (cal.width, cal.height) != (info.width, info.height):
        scaled_from = (cal.width, cal.height)
        cal = cal.scaled_to(info.width, info.height, info.name)  # CalibrationError: the file, line, field, photo
    model, params = cal.colmap_model()
    mode = cal.adjust or mode
    note = ""
    if mode == "estimated" and model == "FULL_OPENCV":
        params_k3 = params[8]
        # COLMAP's only model with k3 also has the rational terms k4..k6, and its self-calibration frees all
        # the extra parameters together: a few photos cannot tell k1..k3 from k4..k6 (4 archive frames came
        # out with k1 = 55, k4 = 55).  A first guess does not need k3: RADIAL (k1, k2; one focal length for square
        # pixels without tangential terms: OPENCV's fx, fy drifted apart, -1.73 / -2.13 %) or OPENCV from it
        fx, fy, cx, cy, k1, k2, p1, p2 = params[:8]
        if p1 == 0.0 and p2 == 0.0 and fx == fy:  # square pixels, no tangential terms: one focal length
            model, params, kept = "RADIAL", [fx, cx, cy, k1, k2], "RADIAL: f, k1, k2"
        else:
            model, params, kept = "OPENCV", params[:8], "OPENCV: k1, k2, p1, p2"
        note = (f"k3 = {params_k3:.6g} of the calibration left out of the self-calibration ({kept}; COLMAP's "
                f"model with k3 would estimate the rational terms k4..k6 along with it)")
    names = _param_names(pycolmap, model)
    return GivenCamera(mode=mode, source=source, name=cal.name or "", model=model,
                       params=[float(v) for v in params], sigmas=_sigmas(names, cal.sigmas or {}), matched_by=how,
                       scaled_from=scaled_from, note=note, pixel_size_mm=getattr(cal, "pixel_size_mm", None))


def _simple(focal: float, width: int, height: int, cx: Optional[float] = None, cy: Optional[float] = None):
    return "SIMPLE_RADIAL", [float(focal), float(width / 2.0 if cx is None else cx),
                             float(height / 2.0 if cy is None else cy), 0.0]


def _given_for(pycolmap, info: ImageInfo, cals, scans: Dict[str, dict], options: AlignOptions,
               ) -> Optional[GivenCamera]:
    """The given interior orientation of one photo (None: nothing given, self-calibrated as always)."""
    chosen = options.intrinsics
    if cals:
        cal, how = match_calibration(info, cals)
        if cal is not None:
            return _from_calibration(pycolmap, cal, info, "fixed" if chosen == "auto" else chosen, how,
                                     scans.get(info.name))
    if info.name in scans and scans[info.name].get("focal_px"):
        io = scans[info.name]
        pp = io.get("principal_point_px") or [None, None]
        model, params = _simple(io["focal_px"], info.width, info.height, pp[0], pp[1])
        return GivenCamera("fixed" if chosen == "auto" else chosen, "scans.json", "film scan interior orientation",
                           model, params, matched_by="Prepare images restituted it")
    if chosen in HELD and info.focal_source == "manual" and info.focal_px:
        model, params = _simple(info.focal_px, info.width, info.height)
        return GivenCamera(chosen, FOCAL_SOURCE, "focal length given", model, params, matched_by="the focal length")
    return None


def plan_cameras(pycolmap, groups: List[CameraGroup], infos: Sequence[ImageInfo], cals, scans: Dict[str, dict],
                 options: AlignOptions, progress: Progress) -> Tuple[List[CameraGroup], Dict[str, GivenCamera]]:
    """(the camera groups, split where their photos take different calibrations, renumbered; group key -> its
    given interior orientation, for the groups that have one).  AlignError when ``fixed`` or ``refined`` is asked
    and no camera has anything given."""
    by_name = {im.name: im for im in infos}
    check_given_focal(infos, options)
    for cal in cals:
        for note in getattr(cal, "notes", None) or []:
            progress.info(f"calibration {cal.source}, {cal.label()}: {note}")
        for doubt in getattr(cal, "warnings", None) or []:
            progress.warning(f"calibration {os.path.basename(cal.source)}, {cal.label()}: {doubt}")
    _check_calibrations_used(cals, infos, progress)
    out: List[CameraGroup] = []
    plan: Dict[str, GivenCamera] = {}
    for g in groups:
        parts: Dict[str, Tuple[Optional[GivenCamera], List[str]]] = {}
        for n in g.images:
            given = _given_for(pycolmap, by_name[n], cals, scans, options)
            tag = "" if given is None else f"{given.source}|{given.name}|{given.model}|{given.params}"
            parts.setdefault(tag, (given, []))[1].append(n)
        for tag, (given, names) in parts.items():
            key = g.key if len(parts) == 1 else f"{g.key}|{tag}"
            sub = replace(g, camera_id=len(out) + 1, key=key, images=list(names))
            out.append(sub)
            if given is not None:
                plan[key] = given
    if options.intrinsics in HELD and not plan:
        raise AlignError(f"intrinsics {options.intrinsics!r} needs a given interior orientation: a calibration file "
                         "(CALIBRATION), or the focal length and sensor width (FOCAL_MM, SENSOR_WIDTH_MM), or film "
                         "scans restituted by 'Prepare images' with a known focal length")
    for g in out:
        given = plan.get(g.key)
        what = (f"{given.mode}, {given.model} from {given.source}"
                + (f" ({given.name!r}, matched by {given.matched_by})" if given.name else "")
                + (f", scaled from {given.scaled_from[0]} x {given.scaled_from[1]} px" if given.scaled_from else "")
                + (f"; {given.note}" if given.note else "")
                if given else "estimated (self-calibration), no calibration given")
        progress.info(f"camera {g.camera_id} ({len(g.images)} image(s), {g.width} x {g.height} px): interior "
                      f"orientation {what}")
        _check_focal_agrees(g, given, progress, by_name[g.images[0]])
    return out, plan


def check_given_focal(infos: Sequence[ImageInfo], options: AlignOptions) -> None:
    """AlignError before any work when the focal length given (FOCAL_MM with SENSOR_WIDTH_MM, or in pixels) is far
    from the photos' EXIF focal length (plausible.FOCAL_RATIO_REFUSED times either way, in mm and in pixels), with
    the likely cause (a 35 mm equivalent given for the lens's focal length, a wrong sensor width); and when it gives
    no camera's field of view (core.geometry.plausible.focal_problem)."""
    seen = set()
    for im in infos:
        key = (im.width, im.height, im.focal_mm, im.focal_35mm)
        if im.focal_source != "manual" or not im.focal_px or key in seen:
            continue
        seen.add(key)
        problem = _given_against_exif(im, options)
        if problem is None:  # no EXIF to compare with (or one it agrees with): a camera's field of view at least
            problem = plausible.focal_problem(im.focal_px, im.width, im.height)
            if problem:
                problem = f"the focal length given ({_given_text(im, options)}): {problem}"
        if problem:
            raise AlignError(problem)


def _given_text(im: ImageInfo, options: AlignOptions) -> str:
    if options.focal_px:
        return f"FOCAL_PX {options.focal_px:g} px"
    if not (options.focal_mm and options.sensor_width_mm):
        return f"{im.focal_px:.0f} px on the {im.width} x {im.height} px photos"
    return (f"FOCAL_MM {options.focal_mm:g} mm on a sensor SENSOR_WIDTH_MM {options.sensor_width_mm:g} mm wide: "
            f"{im.focal_px:.0f} px on the {im.width} x {im.height} px photos")


def _given_against_exif(im: ImageInfo, options: AlignOptions) -> Optional[str]:
    """Why the focal length given cannot be these photos' (None: it may be): far from their EXIF one."""
    w, h, px = im.width, im.height, float(im.focal_px)
    exif_px = im.focal_35mm / plausible.FULL_FRAME_DIAGONAL_MM * math.hypot(w, h) if im.focal_35mm else None
    given_mm = options.focal_mm if not options.focal_px else None
    mm_far = bool(given_mm and im.focal_mm and plausible.far_apart(given_mm, im.focal_mm))
    px_far = bool(exif_px and plausible.far_apart(px, exif_px))
    if not (mm_far or px_far):
        return None
    exif = "; ".join(v for v in (f"{im.focal_mm:g} mm" if im.focal_mm else "",
                                 f"{exif_px:.0f} px from its 35 mm equivalent {im.focal_35mm:g} mm" if exif_px
                                 else "") if v)
    ratio = plausible.ratio_text(px, exif_px) if exif_px else plausible.ratio_text(given_mm, im.focal_mm)
    camera = " ".join(v for v in (im.make, im.model) if v)
    exif_of = f"the EXIF focal length of {im.name} ({exif}{f'; camera {camera}' if camera else ''})"
    camera = f" (camera {camera})" if camera else ""
    if given_mm and not mm_far and im.focal_mm:  # the focal length is right: the sensor width is not
        sensor = im.focal_mm * max(w, h) / exif_px
        return (f"FOCAL_MM {given_mm:g} mm agrees with the EXIF focal length of {im.name} ({im.focal_mm:g} mm), "
                f"but with SENSOR_WIDTH_MM {options.sensor_width_mm:g} mm it makes {px:.0f} px on the {w} x {h} px "
                f"photos, {plausible.ratio_text(px, exif_px)} the {exif_px:.0f} px the EXIF's 35 mm equivalent "
                f"({im.focal_35mm:g} mm) gives{camera}: by the EXIF, the photos were taken on a sensor about "
                f"{sensor:.3g} mm wide (SENSOR_WIDTH_MM is the sensor's long side in mm); check SENSOR_WIDTH_MM, or "
                f"leave FOCAL_MM and SENSOR_WIDTH_MM empty to take the EXIF's")
    text = f"the focal length given ({_given_text(im, options)}) is {ratio} {exif_of}. "
    sensor_diag = (options.sensor_width_mm * math.hypot(w, h) / max(w, h)) if options.sensor_width_mm else None
    equivalent = (im.focal_mm * plausible.FULL_FRAME_DIAGONAL_MM / sensor_diag
                  if im.focal_mm and sensor_diag else None)
    if given_mm and (plausible.same_value(given_mm, im.focal_35mm) or plausible.same_value(given_mm, equivalent)):
        real = f"FOCAL_MM={im.focal_mm:g} (the EXIF FocalLength)" if im.focal_mm else "the lens's focal length"
        return text + (f"{given_mm:g} mm is the photos' 35 mm equivalent focal length (the focal length on a 36 x 24 "
                       f"mm frame giving the same field of view: EXIF FocalLengthIn35mmFilm), not the lens's: give "
                       f"{real}, or leave FOCAL_MM and SENSOR_WIDTH_MM empty to take the EXIF's")
    return text + ("Is it another camera's or lens's, or in another unit? Give the focal length of the lens these "
                   "photos were taken with (FOCAL_MM in mm, SENSOR_WIDTH_MM the sensor's long side in mm), or leave "
                   "them empty to take the EXIF's")


# a calibration file's focal length further than this (relative) from the one typed in (FOCAL_MM) or read from
# EXIF is named in a warning: one of the two belongs to another camera or lens, or a unit is wrong.  EXIF's focal
# length (often a rounded 35 mm equivalent) is a few percent off a calibrated one as a rule: 10 % there
FOCAL_DISAGREES = 0.02
EXIF_FOCAL_DISAGREES = 0.10


def _check_focal_agrees(g: CameraGroup, given: Optional[GivenCamera], progress: Progress,
                        info: Optional[ImageInfo] = None) -> None:
    """A calibration's focal length against the one typed in or the photos' EXIF: a warning beyond a few percent;
    an AlignError beyond plausible.FOCAL_RATIO_REFUSED times the EXIF one (another camera's calibration, or a
    unit misread: Orthority's focal_len in mm without sensor_size), before any work."""
    if given is None or given.source in ("scans.json", FOCAL_SOURCE) or not g.focal_px:
        return
    if g.focal_source == "manual":
        other, limit = "the focal length given (FOCAL_MM / SENSOR_WIDTH_MM)", FOCAL_DISAGREES
    elif g.focal_source.startswith("exif"):
        other, limit = "the photos' EXIF focal length", EXIF_FOCAL_DISAGREES
    else:
        return
    f = float(given.params[0])
    if g.focal_source.startswith("exif") and plausible.far_apart(f, g.focal_px):
        raise AlignError(_calibration_against_exif(g, given, f, info))
    if abs(g.focal_px / f - 1.0) > limit:
        progress.warning(f"camera {g.camera_id}: the calibration {os.path.basename(given.source)} gives a focal "
                         f"length of {f:.1f} px, {other} {g.focal_px:.1f} px ({100.0 * (g.focal_px / f - 1.0):+.1f} "
                         f"%); the calibration's is used: check that it is this camera's and that its units are "
                         f"right")


def _calibration_against_exif(g: CameraGroup, given: GivenCamera, f: float, info: Optional[ImageInfo]) -> str:
    exif_mm = info.focal_mm if info is not None else None
    exif = f"{g.focal_px:.1f} px" + (f", {exif_mm:g} mm" if exif_mm else "")
    what = f"camera {given.name!r}" if given.name else "its camera"
    text = (f"calibration file {os.path.basename(given.source)}: {what} gives a focal length of {f:.1f} px, "
            f"{plausible.ratio_text(f, g.focal_px)} the photos' EXIF focal length ({exif}) of camera {g.camera_id} "
            f"({len(g.images)} photo(s) of {g.width} x {g.height} px, e.g. {g.images[0]}): ")
    if plausible.same_value(f / g.width, exif_mm, 0.02):
        return text + (f"{f:.1f} px is {f / g.width:g} times the image width, and {f / g.width:g} is the photos' "
                       f"EXIF focal length in mm: a focal length in mm read as one normalised by the image width "
                       f"(Orthority's focal_len without sensor_size is). Add the sensor's size in mm (sensor_size: "
                       f"[width, height]) or give the focal length in pixels")
    return text + ("the calibration is another camera's or lens's, or one of its values is in another unit (mm for "
                   "pixels, another image size's pixels): check it, or align without it (the EXIF focal length is "
                   "then the start of the self-calibration)")


def _describe_calibration(cal) -> str:
    """How a calibration is matched to photos, for a message: its name, images patterns or size."""
    how = (f"images {', '.join(cal.images)}" if cal.images
           else f"{cal.width} x {cal.height} px" + (f", EXIF camera model '{cal.name}'" if cal.name else ""))
    return f"{cal.label()} ({how})"


def _check_calibrations_used(cals: Sequence, infos: Sequence[ImageInfo], progress: Progress) -> None:
    """A calibration file whose cameras match no photo is an error (it was given to be used: a wrong file, or
    images patterns or a camera name that miss the photos' names); a camera of the file no photo takes is a
    warning (a file of several cameras may hold more than this block uses)."""
    if not cals or not infos:
        return
    used = set()
    for im in infos:
        cal, _ = match_calibration(im, cals)
        if cal is not None:
            used.add(id(cal))
    if used:
        for cal in cals:
            if id(cal) not in used:
                progress.warning(f"calibration file {os.path.basename(cal.source)}: no photo matches "
                                 f"{_describe_calibration(cal)}; it is not used")
        return
    sizes = sorted({(im.width, im.height) for im in infos})
    models = sorted({(im.model or "").strip() for im in infos} - {""})
    names = [im.name for im in infos]
    photos = (f"{len(infos)} photo(s): {', '.join(names[:3])}{', ...' if len(names) > 3 else ''}; "
              f"{', '.join(f'{w} x {h}' for w, h in sizes)} px; EXIF camera model "
              + (", ".join(f"'{m}'" for m in models) if models else "none"))
    raise AlignError(f"calibration file {os.path.basename(cals[0].source)}: no photo matches "
                     f"{'' if len(cals) == 1 else 'any of its cameras: '}"
                     f"{'; '.join(_describe_calibration(c) for c in cals)}. A camera is matched by its images "
                     f"patterns, else (without patterns) by its name against the photos' EXIF camera model, else "
                     f"by the image size; one camera without patterns applies to every photo. The {photos}")


def colmap_camera(pycolmap, group: CameraGroup, given: Optional[GivenCamera], model: str):
    """The database camera of ``group``: the given model and parameters where a calibration is given (its focal
    length a prior), else ``model`` from the group's focal prior (today's camera)."""
    if given is None:
        cam = pycolmap.Camera.create_from_model_name(group.camera_id, model, group.focal_px, group.width,
                                                     group.height)
        cam.has_prior_focal_length = group.focal_source != "default"
        return cam
    cam = pycolmap.Camera.create_from_model_name(group.camera_id, given.model, given.params[0], group.width,
                                                 group.height)
    cam.params = [float(v) for v in given.params]
    cam.has_prior_focal_length = True
    return cam


def held_cameras(groups: Sequence[CameraGroup], plan: Dict[str, GivenCamera]) -> Dict[int, GivenCamera]:
    """camera id -> given, of the cameras whose intrinsics the alignment keeps constant."""
    return {g.camera_id: plan[g.key] for g in groups if g.key in plan and plan[g.key].held}


def restore_held(rec, held: Dict[int, GivenCamera]) -> None:
    """Set the held cameras of ``rec`` back to exactly their given values (a mapping whose adjustments refine the
    other cameras' intrinsics moves them too: COLMAP's refinement switches are global)."""
    for cid, given in held.items():
        if cid in rec.cameras:
            rec.cameras[cid].params = [float(v) for v in given.params]


def intrinsics_record(pycolmap, groups: Sequence[CameraGroup], plan: Dict[str, GivenCamera], rec) -> List[dict]:
    """Per camera of the block: its mode, source, given values and sigmas, and the final values."""
    rows = []
    for g in groups:
        given = plan.get(g.key)
        cam = rec.cameras[g.camera_id] if g.camera_id in rec.cameras else None
        row = {"camera_id": g.camera_id, "images": len(g.images), "width": g.width, "height": g.height,
               "mode": given.mode if given else "estimated", "source": given.source if given else None,
               "name": given.name if given else None, "matched_by": given.matched_by if given else None,
               "scaled_from": list(given.scaled_from) if given and given.scaled_from else None}
        if given is not None:
            names = _param_names(pycolmap, given.model)
            row.update(model=given.model, given=dict(zip(names, given.params)), sigmas=dict(given.sigmas),
                       pixel_size_mm=given.pixel_size_mm)
        if cam is not None:
            names = [s.strip() for s in cam.params_info.split(",")]
            row["final_model"] = cam.model.name
            row["final"] = {n: float(v) for n, v in zip(names, cam.params)}
        rows.append(row)
    return rows


__all__ = ["FOCAL_SOURCE", "GivenCamera", "check_given_focal", "colmap_camera", "held_cameras", "intrinsics_record",
           "match_calibration", "plan_cameras", "read_calibrations", "restore_held", "scan_interior", "source_label"]
