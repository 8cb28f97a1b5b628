"""Parameter builders and readers shared by the algorithms: the single stages and Run pipeline.

A builder makes one parameter definition (type, default, range, options, file filter, flags) and a reader
turns a parameter's value into what the core call takes, so that a parameter common to several
algorithms is defined once.  The algorithm gives the name (its class constant) and the label, already
translated with its own ``self.tr("...")``: every algorithm's strings stay in its class, the translation
context that pylupdate5 and AlgorithmBase.tr() share.  This module holds no user-facing text; a choice's options
are the core's values ("auto", "half", "feather"), shown translated in the "Choices" context (option_label):
i18n/make_catalog.py lists the option lists below for pylupdate5.
"""
from qgis.core import (
    QgsProcessing,
    QgsProcessingException,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterCrs,
    QgsProcessingParameterDefinition,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFeatureSource,
    QgsProcessingParameterFile,
    QgsProcessingParameterFolderDestination,
    QgsProcessingParameterNumber,
    QgsProcessingParameterString,
)
from qgis.PyQt.QtCore import QCoreApplication

# enum options: the values the core takes, in the order of the parameter's options (shown translated:
# option_label; i18n/make_catalog.py CHOICE_LISTS names the lists whose values are translated)
PAIRINGS = ["auto", "exhaustive", "sequential", "spatial"]
CAMERA_MODELS = ["AUTO", "SIMPLE_RADIAL", "RADIAL", "OPENCV", "FULL_OPENCV"]
MAPPERS = ["incremental", "global"]
INTRINSICS = ["auto", "fixed", "refined", "estimated"]  # core.align.options.INTRINSICS
QUALITIES = ("full", "half", "quarter")
ENGINES = ("cpu", "cuda")
BLENDINGS = ("feather", "multiband", "none")
INTERPOLATIONS = ("bilinear", "cubic", "nearest")

GCP_FILE_FILTER = "GCP files (*.txt *.csv);;All files (*)"
CSV_FILE_FILTER = "CSV/text (*.csv *.txt);;All files (*)"
CALIBRATION_FILE_FILTER = "Camera calibrations (*.yaml *.yml *.json *.xml *.txt);;All files (*)"
GCP_LAYER_FIELDS = ("name", "image", "px", "py")


def add(alg, *params):
    """Add the parameters to ``alg`` in order."""
    for p in params:
        alg.addParameter(p)


def advanced(*params):
    """The parameters, flagged advanced (folded away in the dialog); returns them as a list."""
    for p in params:
        p.setFlags(p.flags() | QgsProcessingParameterDefinition.Flag.FlagAdvanced)
    return list(params)


# --- folders ---------------------------------------------------------------------------------------
def folder(name, label):
    """An existing folder (the images, a workspace made by an earlier stage)."""
    return QgsProcessingParameterFile(name, label, behavior=QgsProcessingParameterFile.Behavior.Folder)


def workspace_destination(name, label):
    """The workspace folder a first stage creates (or resumes)."""
    return QgsProcessingParameterFolderDestination(name, label)


# --- numbers and flags -------------------------------------------------------------------------------
def integer(name, label, default=0, minimum=0):
    return QgsProcessingParameterNumber(name, label, type=QgsProcessingParameterNumber.Type.Integer,
                                        defaultValue=default, minValue=minimum)


def number(name, label, default=0.0, minimum=0.0, **kwargs):
    return QgsProcessingParameterNumber(name, label, type=QgsProcessingParameterNumber.Type.Double,
                                        defaultValue=default, minValue=minimum, **kwargs)


def flag(name, label, default=False):
    return QgsProcessingParameterBoolean(name, label, defaultValue=default)


CHOICES_CONTEXT = "Choices"


def option_label(option):
    """What an enum option shows: its translation in the "Choices" context (German 'halb (half)'), the value
    itself in English.  The parameter's value stays the option's index, read by read_choice, in any language
    (German choice values were shown in English: issue 36 item 21)."""
    return QCoreApplication.translate(CHOICES_CONTEXT, option)


def choice(name, label, options, default=0):
    return QgsProcessingParameterEnum(name, label, options=[option_label(o) for o in options], defaultValue=default)


def read_choice(alg, parameters, name, context, options):
    """The option chosen in an enum parameter."""
    return options[alg.parameterAsEnum(parameters, name, context)]


# --- alignment -------------------------------------------------------------------------------------------
def pairing(name, label):
    return choice(name, label, PAIRINGS)


def camera_model(name, label):
    return choice(name, label, CAMERA_MODELS)


def max_image_size(name, label):
    return integer(name, label)


def calibration_file(name, label):
    """A camera calibration file (core.io.calibration reads it), optional."""
    return QgsProcessingParameterFile(name, label, optional=True, fileFilter=CALIBRATION_FILE_FILTER)


def intrinsics(name, label):
    """What the adjustments may change of the cameras' interior orientation (core.align.options.INTRINSICS)."""
    return choice(name, label, INTRINSICS)


# --- ground control --------------------------------------------------------------------------------------
def gcp_file(name, label):
    return QgsProcessingParameterFile(name, label, optional=True, fileFilter=GCP_FILE_FILTER)


def gcp_layer(name, label):
    return QgsProcessingParameterFeatureSource(name, label, [QgsProcessing.SourceType.TypeVectorPoint], optional=True)


def check_points(name, label):
    return QgsProcessingParameterString(name, label, defaultValue="", optional=True)


def camera_positions(name, label):
    return QgsProcessingParameterFile(name, label, optional=True, fileFilter=CSV_FILE_FILTER)


def target_crs(name, label):
    return QgsProcessingParameterCrs(name, label, optional=True)


def read_optional_file(alg, parameters, name, context):
    """A file parameter's path, None when not given."""
    return alg.parameterAsFile(parameters, name, context) or None


def read_names(alg, parameters, name, context):
    """A comma-separated list of names (check points)."""
    return [s.strip() for s in alg.parameterAsString(parameters, name, context).split(",") if s.strip()]


def read_crs(alg, parameters, name, context):
    """A CRS parameter as the core takes it (authority id, else WKT); None when not given."""
    crs = alg.parameterAsCrs(parameters, name, context)
    return (crs.authid() or crs.toWkt()) if crs.isValid() else None


def read_gcp_layer(alg, parameters, name, context, missing_field):
    """A point layer with one feature per observation (fields name, image, px, py; z, sx, sy, sz, role
    optional) as a core GCPSet; None when not given.  ``missing_field``: the algorithm's translated message
    for a missing field, with {} for the layer and {} for the field."""
    from ..core.io import gcp as gcpmod

    source = alg.parameterAsSource(parameters, name, context)
    if source is None:
        return None
    fields = [f.name().lower() for f in source.fields()]
    for need in GCP_LAYER_FIELDS:
        if need not in fields:
            raise QgsProcessingException(missing_field.format(source.sourceName(), need))
    rows = []
    for feat in source.getFeatures():
        attrs = {k.lower(): feat[k] for k in source.fields().names()}
        pt = feat.geometry().constGet()
        z = attrs.get("z")
        if z in (None, "") and pt is not None and pt.is3D():
            z = pt.z()
        rows.append(dict(attrs, x=pt.x(), y=pt.y(), z=z or 0.0))
    crs = source.sourceCrs().authid() or source.sourceCrs().toWkt()
    try:
        return gcpmod.gcps_from_rows(rows, crs, source_name=source.sourceName())
    except gcpmod.GCPError as e:
        raise QgsProcessingException(str(e)) from e


def has_control(gcp_path, gcps, positions, use_exif_gps):
    """Whether a georeferencing has anything to fix the block with (ground control or camera positions)."""
    return not (gcp_path is None and gcps is None and not positions and not use_exif_gps)


# --- dense matching and tiles ---------------------------------------------------------------------------
def dsm_resolution(name, label):
    return number(name, label)


def quality(name, label):
    return choice(name, label, QUALITIES, default=1)


def blending(name, label):
    return choice(name, label, BLENDINGS)


def workers(name, label, default=0):
    return integer(name, label, default=default)


def scheduler(name, label):
    return QgsProcessingParameterString(name, label, defaultValue="", optional=True)


def read_scheduler(alg, parameters, name, context):
    """A Dask scheduler address, None for this computer."""
    return alg.parameterAsString(parameters, name, context).strip() or None


# --- terrain -----------------------------------------------------------------------------------------
def relief_choice(name, label):
    """Relief visualisations to make (several may be chosen; none by default: they take minutes)."""
    from ..core.terrain.options import VISUALISATIONS

    return QgsProcessingParameterEnum(name, label, options=[option_label(lab) for _, lab in VISUALISATIONS],
                                      allowMultiple=True, optional=True, defaultValue=[])


def read_relief(alg, parameters, name, context):
    """The core keys of the chosen relief visualisations."""
    from ..core.terrain.options import VISUALISATION_KEYS

    return [VISUALISATION_KEYS[i] for i in alg.parameterAsEnums(parameters, name, context)]
