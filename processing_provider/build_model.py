"""Build 3-D model: thin adapter over core.model.stage.stage (parameters -> ModelOptions -> the stage)."""
import os

from qgis.core import (
    Qgis,
    QgsProcessingOutputFile,
    QgsProcessingOutputFolder,
    QgsProcessingOutputNumber,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFolderDestination,
)

from . import params
from .base import AlgorithmBase, FeedbackProgress, styling_enabled

VIEWERS = {
    ".glb": "any glTF viewer (Blender, the Windows 3D Viewer, a web viewer)",
    ".obj": "Blender, MeshLab, CloudCompare",
    ".ply": "CloudCompare, MeshLab (geometry only)",
    ".json": "QGIS 3.34 or newer (Layer > Add Layer > Cesium 3D Tiles) or CesiumJS",
}


class BuildModelAlgorithm(AlgorithmBase):
    NAME = "buildmodel"
    DISPLAY = "Build 3-D model"
    WORKSPACE = "WORKSPACE"
    GEOMETRY = "GEOMETRY"
    FACE_BUDGET = "FACE_BUDGET"
    FORMATS = "FORMATS"
    TEXTURE = "TEXTURE"
    ATLAS_SIZE = "ATLAS_SIZE"
    MAX_ATLASES = "MAX_ATLASES"
    OUTPUT_FOLDER = "OUTPUT_FOLDER"
    OUT_WORKSPACE = "WORKSPACE"  # the same name as the input: models chain stages through it
    OUTPUT_GLB = "OUTPUT_GLB"
    OUTPUT_OBJ = "OUTPUT_OBJ"
    OUTPUT_TILESET = "OUTPUT_TILESET"
    FACES = "FACES"
    TEXTURED_FRACTION = "TEXTURED_FRACTION"
    HELP = (
        "A textured 3-D model of the site. The DSM's surface becomes a triangle mesh within a face budget, each face "
        "textured from the photo that sees it best; it is written as a textured OBJ (+ MTL + JPEG atlases), a binary "
        "glTF (GLB, texture embedded), a PLY of the geometry and OGC 3D Tiles (tileset.json with levels of "
        "detail), all in the workspace CRS about a local origin that the files name.\n\n"
        "On QGIS 3.34 or newer the 3D Tiles open as a tiled scene layer in the workspace's group (View > 3D Map "
        "View shows them over the orthomosaic); on older QGIS the log names the files and the programs that open "
        "them. A block without control (a model frame) is written as OBJ / GLB / PLY in that frame; 3D Tiles need "
        "a georeferenced block.\n\n"
        "Workspace folder: a georeferenced workspace with a DSM (run 'Build DSM' first).\n"
        "Geometry: auto (the DSM's 2.5-D surface), dsm, or points (the fused dense points' 3-D surface: not available yet).\n"
        "Face budget: the most triangles the model may have.\n"
        "Files: the formats to write.\n"
        "Texture from the photos: off for a grey model (faster).\n"
        "Atlas size and number of atlases (advanced): the texture images' side in pixels and how many at most.\n"
        "Model folder: where to write the files (default: <workspace>/model3d; the folder is replaced whole)."
    )

    def initAlgorithm(self, config=None):  # noqa: N802 (QGIS API name)
        from ..core.model.options import FORMATS, GEOMETRIES, ModelOptions

        defaults = ModelOptions()
        params.add(
            self,
            params.folder(self.WORKSPACE, self.tr("Workspace folder (with a DSM)")),
            params.choice(self.GEOMETRY, self.tr("Geometry"), GEOMETRIES, GEOMETRIES.index(defaults.geometry)),
            params.integer(self.FACE_BUDGET, self.tr("Face budget (triangles at most)"), defaults.face_budget, 2),
            QgsProcessingParameterEnum(self.FORMATS, self.tr("Files"), options=list(FORMATS), allowMultiple=True,
                                       defaultValue=[FORMATS.index(f) for f in defaults.formats]),
            params.flag(self.TEXTURE, self.tr("Texture from the photos"), defaults.texture),
            *params.advanced(
                params.integer(self.ATLAS_SIZE, self.tr("Atlas size in pixels (a power of two)"),
                               defaults.atlas_size, 256),
                params.integer(self.MAX_ATLASES, self.tr("Number of atlases at most"), defaults.max_atlases, 1)),
        )
        self.addParameter(QgsProcessingParameterFolderDestination(
            self.OUTPUT_FOLDER, self.tr("Model folder"), optional=True, createByDefault=False))
        self.addOutput(QgsProcessingOutputFolder(self.OUT_WORKSPACE, self.tr("Workspace")))
        self.addOutput(QgsProcessingOutputFile(self.OUTPUT_GLB, self.tr("Model (GLB)")))
        self.addOutput(QgsProcessingOutputFile(self.OUTPUT_OBJ, self.tr("Model (OBJ)")))
        self.addOutput(QgsProcessingOutputFile(self.OUTPUT_TILESET, self.tr("3D Tiles (tileset.json)")))
        self.addOutput(QgsProcessingOutputNumber(self.FACES, self.tr("Faces")))
        self.addOutput(QgsProcessingOutputNumber(self.TEXTURED_FRACTION, self.tr("Share of faces textured")))

    def register_styled_outputs(self, results, context, feedback=None):
        """The styled layers, and the 3-D model's 3D Tiles as a tiled scene layer (QGIS 3.34+)."""
        count = super().register_styled_outputs(results, context, feedback)
        if not styling_enabled():
            return count
        from ..qgisio.scene_layers import register_tiled_scene

        return count + register_tiled_scene(results, self.OUTPUT_TILESET, context, feedback)

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 (QGIS API name)
        from ..core.model import stage as model
        from ..core.model.options import FORMATS, GEOMETRIES, ModelOptions
        from ..qgisio.scene_layers import tiled_scenes_supported

        workspace = self.parameterAsFile(parameters, self.WORKSPACE, context)
        chosen = self.parameterAsEnums(parameters, self.FORMATS, context)
        options = self.run_core(
            ModelOptions, geometry=params.read_choice(self, parameters, self.GEOMETRY, context, GEOMETRIES),
            face_budget=self.parameterAsInt(parameters, self.FACE_BUDGET, context),
            formats=tuple(FORMATS[i] for i in chosen),
            texture=self.parameterAsBool(parameters, self.TEXTURE, context),
            atlas_size=self.parameterAsInt(parameters, self.ATLAS_SIZE, context),
            max_atlases=self.parameterAsInt(parameters, self.MAX_ATLASES, context),
            output_dir=self.parameterAsString(parameters, self.OUTPUT_FOLDER, context) or None)
        result = self.run_core(model.stage, workspace, options, FeedbackProgress(feedback))
        files = {os.path.splitext(f)[1].lower(): f for f in result.files if os.path.basename(f) != "model.json"}
        tileset = next((f for f in result.files if os.path.basename(f) == "tileset.json"), None)
        if tileset is not None:
            files[".json"] = tileset
        feedback.pushInfo(self.tr("3-D model in {}: {} faces, {:.0%} textured").format(
            result.folder, result.faces, result.textured_faces / max(result.faces, 1)))
        for ext, path in sorted(files.items()):
            if ext in VIEWERS:
                feedback.pushInfo(self.tr("{} opens in {}").format(path, VIEWERS[ext]))
        if tileset is not None and not tiled_scenes_supported():
            feedback.pushInfo(self.tr("QGIS {} has no 3D Tiles layers (QGIS 3.34 or newer has): open {} there or in "
                                      "CesiumJS, or model.glb in a glTF viewer").format(Qgis.QGIS_VERSION, tileset))
        return {self.OUT_WORKSPACE: result.workspace, self.OUTPUT_FOLDER: result.folder,
                self.OUTPUT_GLB: files.get(".glb"), self.OUTPUT_OBJ: files.get(".obj"), self.OUTPUT_TILESET: tileset,
                self.FACES: result.faces, self.TEXTURED_FRACTION: result.textured_faces / max(result.faces, 1)}
