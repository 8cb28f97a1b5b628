"""The whole chain in one call: (prepare: sky masks ->) align -> georeference -> DSM -> orthomosaic -> DTM (+ relief)
-> (3-D model ->) report.

``run_pipeline`` calls each room's stage entry point in order on one workspace (``core.align.stage.align``,
``core.georef.stage.georeference_workspace``, ``core.dense.stage.build_dsm_workspace``,
``core.ortho.stage.build_orthophoto_workspace``, ``core.report.stage.build_report``).  Its options are a
:class:`PipelineOptions` (each stage's option object and the few chain settings) and a :class:`Control`
(the ground control and camera positions).
"""
from __future__ import annotations

import dataclasses
import glob
import os
import shutil
import time
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

from .align.options import AlignOptions
from .align.stage import align, check_options
from .common.progress import NullProgress, Progress, SubProgress
from .dense.options import DenseOptions
from .dense.stage import build_dsm_workspace
from .geometry.crs import validate_crs
from .georef.control_checks import check_control_files
from .georef.options import GeorefOptions
from .georef.stage import GeorefStageResult, georeference_workspace
from .georef.targets.options import FindTargetsOptions
from .georef.targets.stage import find_targets
from .io.gcp import GCPSet, read_target_coordinates
from .io.images import folder_gps, list_images, require_images
from .io.multispectral import band_files, read_block
from .io.raster import RasterFile
from .model.options import ModelOptions
from .model.stage import stage as build_model
from .ortho.options import OrthoOptions
from .ortho.stage import build_orthophoto_workspace
from .prepare.band_radiometry import PANEL_WINDOW
from .prepare.captures import CaptureStackOptions, is_band_folder, panel_files, stack_capture_folder
from .prepare.options import PrepareOptions
from .prepare.stage import prepare_images_workspace
from .project.stages import (
    ALIGN,
    DSM,
    GEOREFERENCE,
    MODEL,
    ORTHOPHOTO,
    PREPARE,
    RELIEF,
    REPORT,
    TERRAIN,
    StageError,
)
from .project.workspace import MANIFEST, Workspace
from .report.options import ReportOptions
from .report.stage import build_report
from .terrain.options import ReliefStageOptions, TerrainOptions
from .terrain.stage import build_dtm_workspace, relief_workspace


@dataclass
class Control:
    """What georeferences the block: ground control (a file or a GCPSet, with check points) and/or camera
    positions (a file or the images' EXIF GPS), and the target CRS (None: from the control)."""

    gcp_path: Optional[str] = None
    gcps: Optional[GCPSet] = None
    check_points: Sequence[str] = ()
    camera_positions_path: Optional[str] = None
    use_exif_gps: bool = False
    crs: Optional[str] = None
    gcps_upright: bool = False  # the GCPs' pixel coordinates were measured on upright photos (EXIF orientation)
    # surveyed coordinates of targets laid on the ground (CSV or gcp_list.txt): Find targets finds them on the
    # photos after the alignment, and its observations are the ground control (instead of gcp_path / gcps)
    targets_path: Optional[str] = None

    def given(self) -> bool:
        return not (self.gcp_path is None and self.gcps is None and not self.camera_positions_path
                    and not self.use_exif_gps and not self.targets_path)


@dataclass
class PipelineOptions:
    """Each stage's options, once, and the chain settings.  The DSM's quality and resolution are
    ``dense.quality`` and ``dense.resolution``, the orthomosaic's resolution and blending ``ortho.resolution`` and
    ``ortho.blending`` (its images filter ``ortho.images_filter``), the report's ``report``: the stages take them from
    their options and nothing here overrides them."""

    align: AlignOptions = field(default_factory=AlignOptions)
    georef: GeorefOptions = field(default_factory=GeorefOptions)  # refine_intrinsics and the adjustment
    dense: DenseOptions = field(default_factory=DenseOptions)
    ortho: OrthoOptions = field(default_factory=OrthoOptions)
    report: ReportOptions = field(default_factory=ReportOptions)  # uncertainty, write_layers
    # with sky_masks: the prepare stage's (screening, sky masks) before the alignment
    prepare: PrepareOptions = field(default_factory=lambda: PrepareOptions(sky_masks=True))
    targets: FindTargetsOptions = field(default_factory=FindTargetsOptions)  # with Control.targets_path
    make_report: bool = True  # False: the chain stops after the orthomosaic (and the terrain products)
    make_dtm: bool = True  # the DTM (seconds for a DSM of a few million cells)
    terrain: TerrainOptions = field(default_factory=TerrainOptions)  # with make_dtm: the ground filter, contours
    # with make_dtm: relief visualisations of the DTM (its keys: core.terrain.options.VISUALISATION_KEYS; slow)
    relief: ReliefStageOptions = field(default_factory=lambda: ReliefStageOptions(()))
    make_model: bool = False  # the textured 3-D model (Build 3-D model) after the terrain, with ``model``'s options
    model: ModelOptions = field(default_factory=ModelOptions)
    sky_masks: bool = False  # obliques: a prepare stage first (screening + sky masks), the prepared photos aligned
    # a folder of a multispectral rig's band files (core.prepare.captures.is_band_folder): "auto" stacks every
    # capture into one multi-band photo in <workspace>/captures first (Stack multispectral captures, with this
    # radiometry) and the chain goes on with those; "off": the files are taken as photos
    captures: str = "auto"
    capture_radiometry: str = "normalised"
    # the calibration panel's band files (or folders of them) and its reflectance (one number, band=value items or
    # a CSV file), as CaptureStackOptions takes them: the stacked photos, and so the orthomosaic, are then float32
    # reflectance; ``capture_panel_window``: the central window the panel is measured in (a fraction of the frame)
    capture_panel: Sequence[str] = ()
    capture_panel_reflectance: str = ""
    capture_panel_window: float = PANEL_WINDOW

    def capture_stack(self, workspace_dir: str) -> CaptureStackOptions:
        """The options of a band folder's stacking into <workspace>/captures (checked when made: PrepareError)."""
        return CaptureStackOptions(os.path.join(workspace_dir, CAPTURES_DIR), radiometry=self.capture_radiometry,
                                   panel=self.capture_panel, panel_reflectance=self.capture_panel_reflectance,
                                   panel_window=self.capture_panel_window)


@dataclass
class PipelineResult:
    """What ``run_pipeline`` did: each stage's own result object (None where the stage did not run)."""
    workspace: str
    align: object
    georef: Optional[GeorefStageResult]
    prepare: object = None
    dsm: object = None
    ortho: object = None
    report: object = None
    dtm: object = None
    relief: object = None
    model: object = None  # the 3-D model's result (core.model.stage.ModelResult) when it ran
    targets: object = None  # Find targets' result (core.georef.targets.stage.FindTargetsResult) when it ran
    captures: object = None  # the band folder's stacked captures (core.prepare.captures.CaptureStackResult)
    rgb_frames: List[str] = field(default_factory=list)  # the rig's RGB frames aligned with the captures
    ortho_rgb: object = None  # their orthomosaic (the orthophoto stage's result), beside the captures' one
    seconds: Dict[str, float] = field(default_factory=dict)
    # CPU seconds per stage (this process and its pool workers, os.times(): load-independent, unlike ``seconds``)
    cpu_seconds: Dict[str, float] = field(default_factory=dict)
    warnings: List[str] = field(default_factory=list)


# the share of the progress bar of each stage
FIND_TARGETS = "find targets"  # not a recorded stage: its products (georef/targets/) feed the georeference
CAPTURES = "captures"  # not a recorded stage: a band folder's captures stacked into multi-band photos
CAPTURES_DIR = "captures"
SPANS = {CAPTURES: (0.0, 0.05), PREPARE: (0.0, 0.05), ALIGN: (0.0, 0.40), FIND_TARGETS: (0.40, 0.42), GEOREFERENCE: (0.42, 0.45), DSM: (0.45, 0.75), ORTHOPHOTO: (0.75, 0.9),
         TERRAIN: (0.9, 0.92), RELIEF: (0.92, 0.94), MODEL: (0.94, 0.97), REPORT: (0.97, 1.0)}


def rig_rgb_frames(folder: str, photos: Sequence[str]) -> Tuple[List[str], List[str]]:
    """(the rig's RGB frames of the captures stacked into ``photos``, the band folder's other RGB frames: of a
    calibration panel's capture, of a capture left out), each sorted (core.io.multispectral: a three-band Red,
    Green, Blue frame of a capture)."""
    stacked = set()
    for path in photos:
        with RasterFile(path, "captured photo") as r:
            stacked.add(r.metadata().get("CAPTURE"))
    frames, others = [], []
    for cap in read_block(band_files(folder)).captures:
        for b in cap.bands:
            if b.is_rgb:
                (frames if cap.capture_id in stacked else others).append(b.path)
    return sorted(frames), sorted(others)


def _place(src: str, dst: str) -> None:
    """``src`` at ``dst``: a hard link (no copy of the photo), else a copy; another file there is replaced."""
    if os.path.lexists(dst):
        try:
            if os.path.samefile(src, dst):
                return
        except OSError:  # a dangling link left there
            pass
        os.unlink(dst)
    try:
        os.link(src, dst)
    except OSError:  # another file system, or links not allowed
        shutil.copy2(src, dst)


def _frames_beside(images_dir: str, out: str, photos: Sequence[str], progress: Progress) -> List[str]:
    """The rig's RGB frames of the stacked captures placed beside their photos in ``out`` (their names)."""
    frames, others = rig_rgb_frames(images_dir, photos)
    for path in others:
        progress.warning(f"{path}: an RGB frame of a capture not stacked (a calibration panel's, or left out): "
                         "not aligned")
    taken = {os.path.basename(p).lower(): p for p in photos}
    for path in frames:
        name = os.path.basename(path)
        if name.lower() in taken:
            raise StageError(f"the RGB frame {path} has the name of the stacked photo {taken[name.lower()]}: "
                             "rename the frame so that both can be aligned")
        if any(c in name for c in ",;\n"):
            raise StageError(f"the RGB frame {path}: a comma or semicolon in its name cannot be told apart in the "
                             "orthophoto's image list; rename it")
        _place(path, os.path.join(out, name))
    return [os.path.basename(p) for p in frames]


def _stack(images_dir: str, options: CaptureStackOptions, res: "PipelineResult", progress: Progress) -> str:
    """The band folder's captures stacked into <workspace>/captures (core.prepare.captures, ``options``), the rig's
    RGB frames beside them (aligned in one block with the captures: ``res.rgb_frames``); returns that folder."""
    out, radiometry = options.output_dir, options.radiometry
    res.captures = stack_capture_folder(images_dir, options, progress)
    res.rgb_frames = _frames_beside(images_dir, out, res.captures.photos, progress)
    kept = {os.path.basename(p) for p in res.captures.photos} | set(res.rgb_frames)
    for name in list_images(out):  # an earlier run's photo no longer in the band folder: not aligned now
        if name not in kept:
            os.unlink(os.path.join(out, name))
    res.warnings += res.captures.warnings + [f"capture {c} left out: {why}" for c, why in res.captures.left_out.items()]
    rgb = f" and the rig's {len(res.rgb_frames)} RGB frame(s)" if res.rgb_frames else ""
    progress.info(f"captures: {len(res.captures.photos)} multi-band photo(s) of {', '.join(res.captures.bands)}{rgb} "
                  f"in {out} ({radiometry} radiometry)")
    return out


def _excluding(names: Sequence[str]) -> str:
    """An IMAGES_FILTER (core.ortho.cameras.select_cameras) of every photo but ``names`` (taken literally)."""
    return ", ".join("!" + glob.escape(n) for n in names)


def _orthophotos(run, workspace_dir: str, options: OrthoOptions, res: "PipelineResult") -> None:
    """The orthophoto stage; a band folder with the rig's RGB frames (aligned as one block, one DSM) gives two
    mosaics of one kind each, where some of its photos are registered: the RGB frames' (``orthomosaic_rgb.tif``
    beside the orthomosaic) first, then the captures' multi-band one, the stage's record and the workspace's
    orthomosaic (unless IMAGES_FILTER chose the photos)."""
    if res.captures is None or not res.rgb_frames or options.images_filter:
        res.ortho = run(ORTHOPHOTO, build_orthophoto_workspace, workspace_dir, options)
        res.warnings += res.ortho.warnings
        return
    lo, hi = SPANS[ORTHOPHOTO]
    mid = lo + (hi - lo) * 0.4
    stacks = [os.path.basename(p) for p in res.captures.photos]
    missing = set(res.align.unregistered) if res.align is not None else set()
    if any(n not in missing for n in res.rgb_frames):
        main = options.output or os.path.join(workspace_dir, "orthomosaic.tif")
        rgb = dataclasses.replace(options, images_filter=_excluding(stacks), per_image_folder=None, seamlines=None,
                                  output=os.path.splitext(main)[0] + "_rgb.tif")
        res.ortho_rgb = run(ORTHOPHOTO, build_orthophoto_workspace, workspace_dir, rgb, span=(lo, mid))
        res.warnings += res.ortho_rgb.warnings
    else:
        res.warnings.append("no RGB frame registered: no RGB orthomosaic")
    if any(n not in missing for n in stacks):
        bands = dataclasses.replace(options, images_filter=_excluding(res.rgb_frames))
        res.ortho = run(ORTHOPHOTO, build_orthophoto_workspace, workspace_dir, bands, span=(mid, hi))
        res.warnings += res.ortho.warnings
    else:
        res.warnings.append("no captured photo registered: no multi-band orthomosaic")


MIN_BLOCK = 2  # photos (or a band folder's captures) taken from different positions: fewer is no block


def check_block_size(images_dir: str, names: Sequence[str], captures: str = "auto") -> None:
    """A block needs photos from ``MIN_BLOCK`` positions: a band folder's captures (``captures`` auto: the bands
    and RGB frame of one capture are one position, however many files) or the folder's photos counted from the
    file names and the band files' metadata, no pixels read; StageError naming the folder and the count before
    the stacking and the alignment (one capture stacked and escalated for 20 s before 'no initial pair')."""
    if captures == "auto" and is_band_folder(images_dir):
        block = read_block(band_files(images_dir))
        n = len(block.captures)
        if n < MIN_BLOCK:
            what = "one capture" if n == 1 else f"{n} captures"
            raise StageError(f"{images_dir} holds {what} of a multispectral rig ({', '.join(block.band_names)}; "
                             f"{len(names)} files): a block needs at least {MIN_BLOCK} captures taken from "
                             "different positions; for a single capture, stack it with 'Stack multispectral "
                             "captures' and use 'Orthorectify image'")
        return
    if len(names) < MIN_BLOCK:
        raise StageError(f"{images_dir} holds one photo ({names[0]}): a block needs at least {MIN_BLOCK} photos "
                         "that overlap, taken from different positions; for a single photo use 'Orthorectify "
                         "image'")


def check_inputs(images_dir: str, control: Control, workspace_dir: Optional[str] = None,
                 captures: str = "auto") -> None:
    """Read and check what the later stages take before the alignment starts (minutes of work that an unknown
    EPSG code or a bad GCP file would throw away): the image folder, the CRS, the GCP file (its CRS line, its
    rows, the images it names, the check points) and the camera positions file, and what the georeference stage
    checks of their meaning (``core.georef.control_checks.check_control_files``: a geographic CRS, control that
    lands far from the photos' EXIF GPS, read from the image files: swapped axes, another zone).  ``workspace_dir``:
    a re-run's workspace, whose CRS is the target where no CRS is given; ``captures``: as PipelineOptions (a band
    folder's captures counted for :func:`check_block_size`).  Raises the readers' errors (ImageError, CRSError,
    GCPError, MultispectralError) and StageError, each naming the file or value and the problem."""
    names = require_images(images_dir, "IMAGES folder")  # missing, unreadable or empty: before a workspace is created
    check_block_size(images_dir, names, captures)
    if control.crs:
        validate_crs(control.crs)
    if control.targets_path:
        if control.gcp_path or control.gcps is not None:
            raise StageError("give either ground control points (GCPS) or the targets to find on the photos "
                             f"(TARGETS: {control.targets_path}), not both")
        read_target_coordinates(control.targets_path, control.crs)
    workspace_crs = None
    if workspace_dir and os.path.isfile(os.path.join(workspace_dir, MANIFEST)):
        workspace_crs = Workspace.open(workspace_dir).crs
    given = GeorefOptions(gcp_path=control.gcp_path, gcps=control.gcps, check_points=control.check_points,
                          camera_positions_path=control.camera_positions_path, crs=control.crs)
    # the readers' warnings (a photo's camera position twice) are said by the georeference stage, in its log
    check_control_files(folder_gps(images_dir), given, names, workspace_crs)


def _check_stacking(images_dir: str, workspace_dir: str, opt: PipelineOptions) -> Optional[CaptureStackOptions]:
    """The band folder's stacking options, checked before any work (a bad radiometry, panel reflectance or panel
    path: PrepareError naming it); None where the images are not stacked (not a band folder, or captures off):
    a calibration panel given there is refused (StageError), since it would be silently ignored."""
    if opt.captures not in ("auto", "off"):
        raise StageError(f"captures {opt.captures!r}: auto (a band folder's captures stacked first) or off")
    options = opt.capture_stack(workspace_dir)
    panel_files(options.panel)  # a panel file or folder that is not there: before the stacking's reading
    if opt.captures == "auto" and is_band_folder(images_dir):
        return options
    if options.panel:
        why = "captures is off" if opt.captures == "off" else f"{images_dir} is not a folder of a rig's band files"
        raise StageError(f"a calibration panel ({', '.join(options.panel)}) calibrates a band folder's captures, "
                         f"but {why}: the photos would not be calibrated")
    return None


def run_pipeline(images_dir: str, workspace_dir: str, options: Optional[PipelineOptions] = None,
                 control: Optional[Control] = None, progress: Optional[Progress] = None) -> PipelineResult:
    """The whole chain in one call: (prepare: sky masks ->) align -> georeference -> DSM -> orthomosaic -> report.

    The same stage functions the single Processing algorithms call, in order, on one workspace; every
    stage records itself in workspace.json as when run alone, so a re-run resumes (features, matches and
    dense pairs already computed are reused).  Without ground control or camera positions the chain stops
    after the alignment: a DSM and an orthophoto need a metric scale and a vertical direction, so that is a
    StageError naming what to give."""
    opt = options or PipelineOptions()
    ctl = control or Control()
    progress = progress or NullProgress()
    if not ctl.given():
        raise StageError("the pipeline needs ground control (GCPS) and/or camera positions (CAMERA_POSITIONS or "
                         "USE_EXIF_GPS) to georeference the block before the DSM and orthophoto; to align only, "
                         "run 'Align images'")
    check_inputs(images_dir, ctl, workspace_dir, opt.captures)
    stacking = _check_stacking(images_dir, workspace_dir, opt)
    align_options = opt.align  # the camera positions also choose the pairs where the photos have no EXIF GPS
    if ctl.camera_positions_path and not align_options.camera_positions:
        align_options = dataclasses.replace(align_options, camera_positions=ctl.camera_positions_path)
    check_options(align_options)  # a bad calibration file or choice: before the prepare and the alignment
    seconds: Dict[str, float] = {}
    cpu_seconds: Dict[str, float] = {}

    def cpu_now() -> float:
        t = os.times()  # pool workers count once they have ended (each stage's pool ends with the stage)
        return t.user + t.system + t.children_user + t.children_system

    def run(name, fn, *args, span=None):  # a stage entry point: its inputs, its options, then the progress
        lo, hi = span or SPANS[name]
        progress.info(f"--- stage {name} ---")
        t0, c0 = time.time(), cpu_now()
        out = fn(*args, SubProgress(progress, lo, hi))
        seconds[name] = round(seconds.get(name, 0.0) + time.time() - t0, 2)  # a stage run twice: both runs
        cpu_seconds[name] = round(cpu_seconds.get(name, 0.0) + cpu_now() - c0, 2)
        return out

    res = PipelineResult(workspace=os.path.abspath(workspace_dir), align=None, georef=None, seconds=seconds,
                         cpu_seconds=cpu_seconds)
    aligned_from = images_dir
    if stacking is not None:
        aligned_from = run(CAPTURES, _stack, images_dir, stacking, res)
    if opt.sky_masks:  # the photos with their sky masks, so that no tie or dense point comes from the sky
        res.prepare = run(PREPARE, prepare_images_workspace, aligned_from, workspace_dir, opt.prepare)
        res.warnings += res.prepare.warnings
        progress.info(f"prepare: {len(res.prepare.masks)} sky mask(s), {res.prepare.kept} of "
                      f"{len(res.prepare.images)} photos kept")
        aligned_from = res.prepare.prepared_dir
    res.align = run(ALIGN, align, aligned_from, workspace_dir, align_options,
                    span=(SPANS[PREPARE][1], SPANS[ALIGN][1]) if opt.sky_masks or res.captures else None)
    gcp_path = ctl.gcp_path
    if ctl.targets_path:  # the targets found on the photos are the ground control
        res.targets = run(FIND_TARGETS, find_targets, workspace_dir,
                          dataclasses.replace(opt.targets, targets=ctl.targets_path, crs=opt.targets.crs or ctl.crs))
        for note in res.targets.reports:
            progress.info(f"find targets: {note}")
        progress.info(f"find targets: {res.targets.n_targets} of {len(res.targets.targets)} targets found, "
                      f"{res.targets.n_observations} observations")
        gcp_path = res.targets.gcps_path
    georef = dataclasses.replace(opt.georef, gcp_path=gcp_path, gcps=ctl.gcps, check_points=ctl.check_points,
                                 camera_positions_path=ctl.camera_positions_path, use_exif_gps=ctl.use_exif_gps,
                                 crs=ctl.crs, gcps_upright=ctl.gcps_upright)
    res.georef = run(GEOREFERENCE, georeference_workspace, workspace_dir, georef)
    res.warnings += res.georef.warnings
    res.dsm = run(DSM, build_dsm_workspace, workspace_dir, opt.dense)
    res.warnings += res.dsm.warnings
    _orthophotos(run, workspace_dir, opt.ortho, res)
    if opt.make_dtm:
        res.dtm = run(TERRAIN, build_dtm_workspace, workspace_dir, opt.terrain)
        if opt.relief.keys:
            res.relief = run(RELIEF, relief_workspace, workspace_dir, opt.relief)
    if opt.make_model:  # before the report: a model run after it would mark it stale (STAGE_ORDER)
        res.model = run(MODEL, build_model, workspace_dir, opt.model)
        res.warnings += res.model.notes
    if opt.make_report:
        res.report = run(REPORT, build_report, workspace_dir, opt.report)
        res.warnings += res.report.warnings
    progress.report(1.0, "pipeline done")
    return res


__all__ = ["Control", "PipelineOptions", "PipelineResult", "check_block_size", "check_inputs", "run_pipeline"]
