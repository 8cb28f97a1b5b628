"""Does the ground control mean what it says?  The checks a surveyor makes by eye before trusting control
(issue 47 items 2 and 12), run by the georeference stage around ``read_control``, before the adjustment:

:func:`read_checked_control` is ``read_control`` with these checks around it, and the readers' warnings put in the
stage's log:

* :func:`check_crs_parameter` (before reading): a geographic CRS parameter (``CRS=EPSG:4326``) is refused at
  once, naming the UTM zone of the photos' EXIF GPS that fixes it (the adjustment needs metres; GCPs and camera
  positions in degrees are reprojected into it); files without a CRS line whose numbers are metres are named.
* :func:`check_target_crs` (after reading): a target CRS that came out geographic because a GCP or camera
  position file is in degrees and no CRS was given: the same advice, naming the file.
* :func:`check_control_location`: control that lands far from where the photos' own EXIF GPS puts them
  (``FAR_FACTOR`` x the GPS positions' spread plus their error: thousands of km for lat/lon in the wrong columns,
  hundreds for the wrong UTM zone), or, without GPS, outside the target CRS's area of use, is refused naming the
  likely cause: axes swapped, the coordinates of another CRS (tried: the UTM zone of the photos, EPSG:4326).  The
  comparison itself is ``core.io.control_place`` (Align images and Orthorectify image make it too).

:func:`check_control_files` makes the same checks before the alignment (Run pipeline), on the files and the photos'
EXIF GPS read from the image files, so that a swapped or wrong-zone file is refused before minutes of alignment.
"""
from __future__ import annotations

import copy
import warnings
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..common.progress import Progress
from ..geometry.crs import crs_is_geographic
from ..io import gcp as gcpmod
from ..io.control_place import Gps, points_off, positions_off, usable_gps
from ..io.control_place import photos_utm as gps_utm
from ..project.stages import StageError
from ..project.workspace import Workspace
from .control_input import read_control, target_crs
from .options import GeorefOptions


def _gps(ws: Workspace) -> Gps:
    """(image, lon, lat) of the workspace's photos with EXIF GPS."""
    return usable_gps((im["name"], im.get("gps")) for im in ws.data.get("images", []))


def photos_utm(ws: Workspace) -> Optional[str]:
    """The WGS 84 / UTM zone of the photos' EXIF GPS (their mean), e.g. 'EPSG:32617'; None without GPS."""
    return gps_utm(_gps(ws))


def _projected_advice(gps: Gps) -> str:
    utm = gps_utm(gps)
    if utm:
        return f"CRS={utm} (the UTM zone of the photos' EXIF GPS)"
    return "CRS=<a projected CRS in metres>, e.g. the block's UTM zone (EPSG:326zz north, EPSG:327zz south)"


def _degree_like(xy: np.ndarray) -> bool:
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    return len(xy) > 0 and bool(np.all(np.abs(xy[:, 0]) <= 180.0) and np.all(np.abs(xy[:, 1]) <= 90.0))


def _unlabelled_metres(opt: GeorefOptions, utm: Optional[str]) -> List[str]:
    """Sentences naming the control files that carry no CRS line and hold numbers that are not degrees (read in the
    CRS parameter's CRS they would be refused or misplaced)."""
    out = []
    if opt.camera_positions_path:
        crs, cams = gcpmod.read_camera_positions(opt.camera_positions_path, warnings=[])
        xy = np.array([[c.x, c.y] for c in cams], dtype=float).reshape(-1, 2)
        if crs is None and len(xy) and not _degree_like(xy):
            zone = f" ({utm} if they are UTM coordinates of the photos' zone)" if utm else ""
            out.append(f"the camera positions in {opt.camera_positions_path} have no CRS line and hold metres, not "
                       f"degrees (x={xy[0, 0]:.3f}, y={xy[0, 1]:.3f}): a file without a CRS line is read in the CRS "
                       f"parameter's CRS, so that projected CRS{zone} is theirs")
    if opt.gcp_path and gcpmod.detect_gcp_format(opt.gcp_path) == "csv":
        file_crs, pts = gcpmod.csv_points_preview(opt.gcp_path)
        xy = np.array(pts, dtype=float).reshape(-1, 2)
        if file_crs is None and len(xy) and not _degree_like(xy):
            out.append(f"the GCP file {opt.gcp_path} has no CRS line and holds metres, not degrees "
                       f"(x={xy[0, 0]:.3f}, y={xy[0, 1]:.3f})")
    return out


def check_crs_parameter(ws: Workspace, opt: GeorefOptions) -> None:
    """StageError when the CRS parameter is geographic (degrees): the adjustment needs metres; name the CRS that
    fixes it (the UTM zone of the photos' GPS) and the control files that hold metres without a CRS line."""
    _crs_parameter(_gps(ws), opt)


def _crs_parameter(gps: Gps, opt: GeorefOptions) -> None:
    if not opt.crs or not crs_is_geographic(opt.crs):
        return
    utm = gps_utm(gps)
    files = _unlabelled_metres(opt, utm)
    raise StageError(
        f"CRS={opt.crs} (the CRS parameter) is geographic (degrees); georeferencing needs a projected CRS in metres: "
        f"give {_projected_advice(gps)}. GCPs and camera positions whose files name their CRS (EPSG:4326 included) "
        "are reprojected into it" + (f"; {'; '.join(files)}" if files else ""))


def check_target_crs(ws: Workspace, opt: GeorefOptions, gcps: Optional[gcpmod.GCPSet], target: str) -> None:
    """StageError when the target CRS came out geographic: no CRS parameter, and the GCP or camera position file
    it was taken from is in degrees.  Names that file and the CRS parameter that fixes it."""
    _target_crs(_gps(ws), opt, gcps, target)


def _target_crs(gps: Gps, opt: GeorefOptions, gcps: Optional[gcpmod.GCPSet], target: str) -> None:
    if not crs_is_geographic(target):
        return
    if opt.crs:  # check_crs_parameter has said it
        _crs_parameter(gps, opt)
    if gcps is not None and gcps.crs == target:
        src = f"the GCP file {opt.gcp_path}" if opt.gcp_path else "the GCP layer"
        what = "ground control points"
    else:
        src, what = f"the camera positions file {opt.camera_positions_path}", "camera positions"
    raise StageError(
        f"{src} is in {target}, a geographic CRS (degrees), and no CRS was given to georeference in: the "
        f"adjustment needs a projected CRS in metres: give {_projected_advice(gps)}; the {what} are reprojected "
        "into it")


# ---------------------------------------------------------------------------------------------------------------
# where the control lands (core.io.control_place: the one check, also made before the alignment and by
# Orthorectify image)
# ---------------------------------------------------------------------------------------------------------------

def _location(gps: Gps, opt: GeorefOptions, gcps: Optional[gcpmod.GCPSet], target: str) -> None:
    """StageError when the camera positions file's positions or the control points land far from the photos'
    EXIF GPS ``gps`` (without GPS: outside the target CRS's area of use), naming the likely cause.  ``gcps`` in
    ``target`` (``read_control``'s), or as read from their file before the alignment; camera positions from the
    EXIF GPS are not checked (they are the reference)."""
    if opt.camera_positions_path:
        what = positions_off(gps, opt.camera_positions_path, target)
        if what:
            raise StageError(what)
    if gcps is None:
        return
    pts = [p for p in gcps.points if p.role == gcpmod.CONTROL] or list(gcps.points)
    src, raw, labelled = gcps.crs or target, pts, True
    if opt.gcp_path:
        again = gcpmod.read_gcps(opt.gcp_path, default_crs=opt.crs)
        src = again.crs or target
        names = {q.name for q in pts}
        raw = [p for p in again.points if p.name in names]
        labelled = not opt.crs or again.crs != opt.crs
    elif gcps.crs and gcps.crs != target:  # a GCP layer's points as given (before the alignment: not reprojected)
        src = gcps.crs
    name = f"the GCP file {opt.gcp_path}" if opt.gcp_path else "the GCP layer"
    what = points_off(gps, raw, src, target, name, labelled)
    if what:
        raise StageError(what)


def check_control_location(ws: Workspace, opt: GeorefOptions, gcps: Optional[gcpmod.GCPSet], target: str) -> None:
    """StageError when the camera positions file's positions, or the control points, land far from the
    workspace's photos' own EXIF GPS (without GPS: outside the target CRS's area of use), naming the likely cause.
    ``gcps`` in ``target`` (``read_control``'s output)."""
    _location(_gps(ws), opt, gcps, target)


def _read_control(ws: Workspace, opt: GeorefOptions, progress: Progress, required: bool):
    """``read_control``, with the warnings the control readers issue (a camera position file's duplicate rows) put
    in the stage's log, where the user reads them (a Python warning reaches a console at best); other warnings
    go on as they came."""
    caught: List[warnings.WarningMessage] = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            return read_control(ws, opt, progress, required)
    finally:
        said = set()
        for w in caught:
            text = str(w.message)
            if w.category is UserWarning:  # what the readers say (warnings.warn(text))
                if text not in said:  # read_control reads the positions file twice
                    said.add(text)
                    progress.warning(text)
            else:
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno, source=w.source)


def read_checked_control(ws: Workspace, opt: GeorefOptions, progress: Progress, required: bool = True):
    """``read_control``'s (GCPs, camera positions, target CRS), checked: a geographic CRS parameter refused
    before reading, control far from the photos' GPS and a geographic target after (StageError each); the
    readers' warnings in the stage's log.  The one reader of control files: the georeference stage and the
    automatic control (its check points and rough positions: ``required`` False, no minimum) read through it."""
    check_crs_parameter(ws, opt)  # CRS=EPSG:4326: refused before reading, naming the UTM zone
    gcps, cams, target = _read_control(ws, opt, progress, required)
    check_control_location(ws, opt, gcps, target)  # lands where the photos' GPS says?
    check_target_crs(ws, opt, gcps, target)
    return gcps, cams, target


def check_control_files(photos_gps: Dict[str, Tuple[float, float, float]], opt: GeorefOptions,
                        image_names: Optional[Sequence[str]] = None, workspace_crs: Optional[str] = None) -> List[str]:
    """The checks :func:`read_checked_control` makes, made before the alignment (Run pipeline), with the photos'
    EXIF GPS read from the image files (``photos_gps``: ``core.io.images.folder_gps``): a geographic CRS parameter,
    a GCP file or camera positions that land far from the photos (swapped axes, another zone), a target CRS that
    would come out geographic.  The files are read as the georeference stage reads them (the GCP file's rows and
    the photos they name: ``image_names``; the target CRS: the CRS parameter, the GCPs', ``workspace_crs`` (a
    re-run's), the positions', the photos' UTM zone).  StageError (GCPError for a file that cannot be read)
    naming the file and the problem; returns the readers' warnings (a photo's camera position given twice)."""
    gps = usable_gps(photos_gps.items())
    _crs_parameter(gps, opt)
    said: List[str] = []
    gcps = opt.gcps
    if opt.gcp_path:
        gcps = gcpmod.read_gcps(opt.gcp_path, image_names=image_names, default_crs=opt.crs)
    if gcps is not None and opt.check_points:
        gcps = copy.deepcopy(gcps)
        gcpmod.apply_check_points(gcps, list(opt.check_points))
    positions_crs = None
    if opt.camera_positions_path:
        positions_crs = gcpmod.read_camera_positions(opt.camera_positions_path, warnings=said)[0]
    target = target_crs(opt.crs, gcps, workspace_crs, positions_crs, gps_utm(gps))
    if target:
        _location(gps, opt, gcps, target)
        _target_crs(gps, opt, gcps, target)
    return said


__all__ = ["check_control_files", "check_control_location", "check_crs_parameter",
           "check_target_crs", "photos_utm", "read_checked_control"]
