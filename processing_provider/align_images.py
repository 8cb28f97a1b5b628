"""Align images: thin adapter over core.align.stage.align."""
from qgis.core import QgsProcessingOutputNumber, QgsProcessingOutputVectorLayer

from . import params
from .base import AlgorithmBase, FeedbackProgress
from .params import CAMERA_MODELS, MAPPERS, PAIRINGS


class AlignImagesAlgorithm(AlgorithmBase):
    NAME = "alignimages"
    DISPLAY = "Align images"
    IMAGES = "IMAGES"
    WORKSPACE = "WORKSPACE"
    PAIRING = "PAIRING"
    CAMERA_MODEL = "CAMERA_MODEL"
    MAX_IMAGE_SIZE = "MAX_IMAGE_SIZE"
    MAX_FEATURES = "MAX_FEATURES"
    AFFINE_FEATURES = "AFFINE_FEATURES"
    FOCAL_MM = "FOCAL_MM"
    SENSOR_WIDTH_MM = "SENSOR_WIDTH_MM"
    SINGLE_CAMERA = "SINGLE_CAMERA"
    MAPPER = "MAPPER"
    ESCALATE = "ESCALATE"
    CALIBRATION = "CALIBRATION"
    CAMERA_POSITIONS = "CAMERA_POSITIONS"
    INTRINSICS = "INTRINSICS"
    CAMERAS = "CAMERAS"
    REGISTERED_IMAGES = "REGISTERED_IMAGES"
    MEAN_REPROJECTION_ERROR = "MEAN_REPROJECTION_ERROR"
    HELP = (
        "Structure from motion: SIFT features, pair selection, robust matching (RANSAC), incremental mapping "
        "with self-calibration (focal length, principal point, lens distortion) and a final bundle adjustment. "
        "The result is stored in the workspace folder, which the following stages (Georeference, Build DSM, "
        "Build orthophoto) take as input. A re-run resumes: features and matches already computed are reused.\n\n"
        "Pair selection: 'auto' uses EXIF GPS neighbours when the images carry GPS, every pair for up to 100 images "
        "otherwise, and sequential pairs with loop pairs for larger sets without GPS. "
        "Camera positions (CSV), optional: the photos' positions in the file Georeference takes (a GNSS log, for "
        "photos without EXIF GPS) choose the pairs and the probed photos' neighbours instead of EXIF GPS; they do "
        "not georeference the block.\n"
        "Camera model: 'AUTO' estimates focal length, principal point, k1, k2, p1, p2 (OPENCV) for cameras with "
        "10 or more images, and a simpler radial model below.\n"
        "Matching image size: the longest side the images are scaled to for the features (0 = automatic: photos "
        "of up to 2 megapixels as they are, larger ones scaled to 2 megapixels; the DSM and the orthophotos use "
        "every pixel). Features per image: 0 = automatic (about 4000 per megapixel, 2048 to 4096). With both at "
        "0, a few photos are probed first: where faint, low-contrast texture (ploughed fields) starves them of "
        "features, the first pass takes 8192 fainter ones, at up to twice the size if needed (the log says so). "
        "Affine-invariant features help with oblique views and are slower.\n"
        "Focal length and Sensor width: interior orientation when EXIF is missing (scanned film): the focal "
        "length and the width of the long side of the frame, in millimetres (0 = from EXIF / unknown).\n"
        "Camera calibration file: a calibrated camera's interior orientation (ArchaeoOrtho's YAML/JSON, Orthority "
        "interior parameters, OpenCV, COLMAP cameras.txt or Metashape XML); several cameras are matched to the "
        "photos by their image patterns, camera model or image size; a photo of another resolution takes it "
        "scaled. A file that cannot be read stops the run before any work, naming the file, the line and the "
        "field.\n"
        "Interior orientation: what the adjustments may change of a camera: 'fixed' keeps the given values through "
        "the alignment and the georeference (also with automatic control), 'refined' lets the georeference refine "
        "them with the calibration's standard deviations as priors, 'estimated' self-calibrates from them. 'auto' "
        "is 'fixed' where a calibration is given (the file, or film scans restituted by Prepare images) and "
        "'estimated' elsewhere; a camera's own 'adjust' in the file overrides it. With 'fixed' or 'refined' and no "
        "file, the focal length and sensor width are the given values. The log, sfm/alignment.json and the "
        "accuracy report say per camera what was held.\n"
        "Mapper (advanced): 'incremental' (COLMAP, the default) or 'global' (GLOMAP: rotation averaging and "
        "global positioning, often faster on large blocks; a Cancel takes effect only when it has finished).\n"
        "Retry images left out (advanced, on): images the fast settings leave out, or a block split into parts, are "
        "retried with richer features (fainter ones for low-contrast frames, affine-shape ones for steep obliques) "
        "and more pairs; the log and sfm/alignment.json say what was retried and why."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        params.add(
            self,
            params.folder(self.IMAGES, self.tr("Folder of images")),
            params.workspace_destination(self.WORKSPACE, self.tr("Workspace folder")),
            params.pairing(self.PAIRING, self.tr("Pair selection")),
            params.camera_model(self.CAMERA_MODEL, self.tr("Camera model")),
            params.max_image_size(self.MAX_IMAGE_SIZE, self.tr("Matching image size (px)")),
            params.integer(self.MAX_FEATURES, self.tr("Features per image")),
            params.flag(self.AFFINE_FEATURES, self.tr("Affine-invariant features")),
            params.number(self.FOCAL_MM, self.tr("Focal length (mm)")),
            params.number(self.SENSOR_WIDTH_MM, self.tr("Sensor width (mm)")),
            params.camera_positions(self.CAMERA_POSITIONS, self.tr("Camera positions (CSV)")),
            params.calibration_file(self.CALIBRATION, self.tr("Camera calibration file")),
            params.intrinsics(self.INTRINSICS, self.tr("Interior orientation")),
            params.flag(self.SINGLE_CAMERA, self.tr("One camera for all images")),
            *params.advanced(params.choice(self.MAPPER, self.tr("Mapper"), MAPPERS),
                             params.flag(self.ESCALATE, self.tr("Retry images left out"), default=True)),
        )
        self.addOutput(QgsProcessingOutputVectorLayer(self.CAMERAS, self.tr("Camera centres")))
        self.addOutput(QgsProcessingOutputNumber(self.REGISTERED_IMAGES, self.tr("Registered images")))
        self.addOutput(QgsProcessingOutputNumber(
            self.MEAN_REPROJECTION_ERROR, self.tr("Mean reprojection error (px)")))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.align.options import AlignOptions
        from ..core.align.stage import align
        from ..core.io.images import GROUP_AUTO, GROUP_SINGLE

        images = self.parameterAsFile(parameters, self.IMAGES, context)
        workspace = self.parameterAsString(parameters, self.WORKSPACE, context)
        focal_mm = self.parameterAsDouble(parameters, self.FOCAL_MM, context)
        sensor_mm = self.parameterAsDouble(parameters, self.SENSOR_WIDTH_MM, context)
        options = AlignOptions(
            pairing=params.read_choice(self, parameters, self.PAIRING, context, PAIRINGS),
            camera_model=params.read_choice(self, parameters, self.CAMERA_MODEL, context, CAMERA_MODELS),
            max_image_size=self.parameterAsInt(parameters, self.MAX_IMAGE_SIZE, context),
            max_features=self.parameterAsInt(parameters, self.MAX_FEATURES, context),
            affine_features=self.parameterAsBoolean(parameters, self.AFFINE_FEATURES, context),
            grouping=GROUP_SINGLE if self.parameterAsBoolean(parameters, self.SINGLE_CAMERA, context) else GROUP_AUTO,
            focal_mm=focal_mm or None,
            sensor_width_mm=sensor_mm or None,
            mapper=params.read_choice(self, parameters, self.MAPPER, context, MAPPERS),
            escalate=self.parameterAsBoolean(parameters, self.ESCALATE, context),
            calibration=params.read_optional_file(self, parameters, self.CALIBRATION, context),
            camera_positions=params.read_optional_file(self, parameters, self.CAMERA_POSITIONS, context),
            intrinsics=params.read_choice(self, parameters, self.INTRINSICS, context, params.INTRINSICS),
        )
        result = self.run_core(align, images, workspace, options, FeedbackProgress(feedback))
        feedback.pushInfo(self.tr("Registered {} of {} images, mean reprojection error {:.3f} px, {} points").format(
            result.registered, result.images_given, result.mean_reprojection_error, result.num_points3d))
        for r in (result.escalation or {}).get("rounds", []):
            feedback.pushInfo(self.tr("Retry {} ({} features): {} image(s) left out; main block {} -> {} images{}").format(
                r["round"], r["kind"], len(r["left_out"]), r["registered_before"], r["registered_after"],
                "" if r["kept"] else self.tr(" (not better: the previous result kept)")))
        if result.unregistered:
            feedback.pushInfo(self.tr("Images not registered:"))
            for name, why in result.unregistered.items():
                feedback.pushInfo(f"  {name}: {why}")
        for cam in result.intrinsics or []:
            if cam.get("source"):
                feedback.pushInfo(self.tr("Camera {}: interior orientation {} ({})").format(
                    cam["camera_id"], cam["mode"], cam["source"]))
        feedback.pushInfo(self.tr("Seconds per step: {}").format(
            ", ".join(f"{k} {v:.1f}" for k, v in result.timings.items())))
        return {
            self.WORKSPACE: result.workspace,
            self.CAMERAS: result.cameras_path,
            self.REGISTERED_IMAGES: result.registered,
            self.MEAN_REPROJECTION_ERROR: result.mean_reprojection_error,
        }
