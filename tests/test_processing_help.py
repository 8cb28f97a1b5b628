"""Processing dialogs as a new user meets them: every '…' browse button and label is visible at the dialog's
default size (English and German), the help names parameters by the labels the form shows, and the help
link opens the README section of the algorithm."""
import os
import re
import subprocess

import pytest

from tests.conftest import ROOT

pytestmark = pytest.mark.usefixtures("qgis_processing")

_KEEP = []
DIALOG_ALGORITHMS = ("alignimages", "georeference", "runpipeline", "buildorthophoto")
# every algorithm of the provider: the help of each names its parameters by the form's labels
ALL_ALGORITHMS = ("prepareimages", "alignimages", "georeference", "builddsm", "buildorthophoto", "accuracyreport",
                  "orthorectifyimage", "builddtm", "reliefvisualisation", "contours", "runpipeline", "autocontrol",
                  "dsmdifference", "findtargets", "spectralindex", "stackcaptures", "buildmodel")


def _dialog(alg_id):
    from processing.gui import ParametersPanel
    from processing.gui.AlgorithmDialog import AlgorithmDialog
    from qgis.core import QgsApplication
    from qgis.gui import QgsBrowserGuiModel

    if ParametersPanel.iface is not None:  # pytest-qgis's interface has no browser model: a real one
        model = QgsBrowserGuiModel()
        model.initialize()
        _KEEP.append(model)
        ParametersPanel.iface.browserModel = lambda: model

    alg = QgsApplication.processingRegistry().algorithmById(alg_id)
    assert alg is not None, alg_id
    return AlgorithmDialog(alg.create(), False, None)


def _process(ms=100):
    import time

    from qgis.PyQt.QtCore import QCoreApplication

    end = time.time() + ms / 1000.0
    while time.time() < end:
        QCoreApplication.processEvents()


def hidden_in_dialog(alg_id):
    """[(what, how far past the right edge in px)] for the browse buttons and labels of the dialog's
    parameters panel at its default size (the Advanced parameters folded, as the dialog opens)."""
    from qgis.gui import QgsFileWidget
    from qgis.PyQt.QtWidgets import QLabel, QScrollArea, QToolButton

    dlg = _dialog(alg_id)
    try:
        dlg.show()
        _process(200)
        area = max(dlg.findChildren(QScrollArea), key=lambda a: a.width() * a.height())
        viewport = area.viewport()
        right = viewport.width()
        out = []
        for fw in dlg.findChildren(QgsFileWidget):
            for b in fw.findChildren(QToolButton):
                if not b.isVisibleTo(dlg):
                    continue
                x = b.mapTo(viewport, b.rect().topRight()).x()
                if x > right:
                    out.append((f"browse button of {fw.parent().objectName() or fw.objectName()}", x - right))
        for label in area.widget().findChildren(QLabel):
            if not label.isVisibleTo(dlg) or not label.text():
                continue
            x = label.mapTo(viewport, label.rect().topRight()).x()
            if x > right + 1 and not label.wordWrap():
                out.append((f"label {label.text()!r}", x - right))
        return out, (dlg.width(), dlg.height(), right)
    finally:
        dlg.close()
        dlg.deleteLater()


@pytest.mark.parametrize("alg", ALL_ALGORITHMS)
def test_browse_buttons_and_labels_visible_at_default_size(plugin, alg):
    hidden, size = hidden_in_dialog("archaeoortho:" + alg)
    print(f"\n[{alg}] dialog {size[0]} x {size[1]}, panel {size[2]} px wide; hidden: {hidden}")
    assert hidden == []


@pytest.fixture
def german():
    """The German translation installed (as the plugin does for a German QGIS); the algorithms' labels are
    made when an instance is created, so a dialog opened now is German."""
    from qgis.PyQt.QtCore import QCoreApplication, QTranslator

    qm = os.path.join(ROOT, "i18n", "archaeoortho_de.qm")
    ts = os.path.join(ROOT, "i18n", "archaeoortho_de.ts")
    if not os.path.exists(qm) or os.path.getmtime(qm) < os.path.getmtime(ts):  # compiled here (as test_ui_i18n)
        subprocess.run(["lrelease", "-silent", ts, "-qm", qm], check=True)
    t = QTranslator()
    assert t.load(qm)
    QCoreApplication.installTranslator(t)
    yield t
    QCoreApplication.removeTranslator(t)


@pytest.mark.parametrize("alg", ALL_ALGORITHMS)
def test_browse_buttons_and_labels_visible_in_german(plugin, german, alg):
    from qgis.core import QgsApplication

    a = QgsApplication.processingRegistry().algorithmById("archaeoortho:" + alg).create()
    assert a.shortHelpString() != a.HELP  # German
    hidden, size = hidden_in_dialog("archaeoortho:" + alg)
    print(f"\n[{alg}, de] dialog {size[0]} x {size[1]}, panel {size[2]} px wide; hidden: {hidden}")
    assert hidden == []


def _ids_in(text, alg):
    """Parameter and output ids (PAIRING, CAMERA_MODEL) written in ``text``; DSM, DTM, CRS and GSD are words
    too."""
    names = {p.name() for p in alg.parameterDefinitions()} | {o.name() for o in alg.outputDefinitions()}
    names -= {"DSM", "DTM", "CRS", "GSD"}
    return sorted(n for n in names if re.search(rf"\b{re.escape(n)}\b", text))


@pytest.mark.parametrize("alg", ALL_ALGORITHMS)
def test_help_names_parameters_by_their_labels(plugin, alg):
    """The form shows labels, never ids: the help text must not speak of PAIRING or CAMERA_MODEL, and the
    labels it names are the form's."""
    from qgis.core import QgsApplication

    a = QgsApplication.processingRegistry().algorithmById("archaeoortho:" + alg).create()
    text = a.shortHelpString()
    assert _ids_in(text, a) == []
    labels = {p.description() for p in a.parameterDefinitions()}
    named = [line.split(":")[0].replace(" (advanced)", "") for line in text.split("\n")
             if ":" in line and len(line.split(":")[0]) < 40 and line[:1].isupper()]
    unknown = [n for n in named if not any(n in lab or lab in n for lab in labels)
               and n not in ("Structure from motion", "Outputs")]
    assert not [u for u in unknown if " and " not in u], (alg, unknown)


@pytest.mark.parametrize("alg", ALL_ALGORITHMS)
def test_help_in_german_uses_the_german_labels(plugin, german, alg):
    from qgis.core import QgsApplication

    a = QgsApplication.processingRegistry().algorithmById("archaeoortho:" + alg).create()
    assert a.shortHelpString() != a.HELP  # translated
    assert _ids_in(a.shortHelpString(), a) == []


def test_help_url_opens_the_readme_section(plugin):
    from archaeoortho.processing_provider.base import heading_anchor, readme_headings
    from qgis.core import QgsApplication

    headings = {heading_anchor(h): h for h in readme_headings()}
    assert heading_anchor("Align images (`archaeoortho:alignimages`)") == "align-images-archaeoorthoalignimages"
    provider = QgsApplication.processingRegistry().providerById("archaeoortho")
    for a in provider.algorithms():
        url = a.helpUrl()
        assert url.startswith("https://github.com/archaeoortho/archaeoortho#"), (a.id(), url)
        anchor = url.split("#", 1)[1]
        if a.name() in DIALOG_ALGORITHMS or f"`archaeoortho:{a.name()}`" in "".join(headings.values()):
            assert anchor in headings, (a.id(), url)
    by_id = {a.name(): a.helpUrl().split("#", 1)[1] for a in provider.algorithms()}
    assert headings[by_id["runpipeline"]].startswith("The whole chain")
    assert "archaeoortho:buildorthophoto" in headings[by_id["buildorthophoto"]]


def test_build_orthophoto_output_is_named_orthomosaic_in_the_workspace_group(plugin, tmp_path, qgis_new_project):
    """As the toolbox dialog loads a ticked destination: the layer is 'Orthomosaic' (not the parameter's label
    'Orthomosaic (default: <workspace>/orthomosaic.tif)') and sits in the workspace's group with its other
    layers; a re-run replaces it."""
    from archaeoortho.qgisio import layers
    from processing.gui.Postprocessing import handleAlgorithmResults
    from qgis.core import (
        QgsApplication,
        QgsProcessingContext,
        QgsProcessingFeedback,
        QgsProject,
        QgsRasterLayer,
    )

    from tests.test_ui_layers import _raster

    ws = tmp_path / "Site 7"
    ws.mkdir()
    path = _raster(str(ws / "orthomosaic.tif"), 4, alpha=True)
    project = QgsProject.instance()
    # the workspace's group exists already (the dock's Load results made it) with an older orthomosaic
    older = layers.load_orthomosaic(path, project, layers.workspace_group_name(str(ws)))
    assert len(older) == 1
    alg = QgsApplication.processingRegistry().algorithmById("archaeoortho:buildorthophoto")

    class Feedback(QgsProcessingFeedback):
        def __init__(self):
            super().__init__()
            self.infos = []

        def pushInfo(self, info):  # noqa: N802 (QGIS API name)
            self.infos.append(info)

    def run_dialog_loading():
        ctx = QgsProcessingContext()
        ctx.setProject(project)
        out = alg.outputDefinition("OUTPUT")
        details = QgsProcessingContext.LayerDetails(out.description(), project, "OUTPUT")
        ctx.addLayerToLoadOnCompletion(path, details)  # the dialog's "Open output file after running"
        results = {"WORKSPACE": str(ws), "OUTPUT": path, "VALID_FRACTION": 1.0}
        feedback = Feedback()
        assert alg.register_styled_outputs(results, ctx, feedback) == 1, feedback.infos
        assert handleAlgorithmResults(alg, ctx, QgsProcessingFeedback(), parameters={"OUTPUT": path})

    run_dialog_loading()
    run_dialog_loading()  # a re-run
    loaded = [lyr for lyr in project.mapLayers().values() if isinstance(lyr, QgsRasterLayer)]
    assert [lyr.name() for lyr in loaded] == ["Orthomosaic \u2014 Site 7"]  # named after its workspace
    root = project.layerTreeRoot()
    group = root.findGroup("ArchaeoOrtho: Site 7")
    assert group is not None
    node = root.findLayer(loaded[0].id())
    assert node.parent() is group
    assert loaded[0].renderer().type() == "multibandcolor"
    assert [n.name() for n in root.children()] == ["ArchaeoOrtho: Site 7"]


def test_run_pipeline_passes_gcps_upright_on_to_the_georeferencing(plugin, tmp_path, monkeypatch):
    """'GCP pixels measured on upright photos' of Run pipeline reaches the pipeline's Control, and the pipeline
    hands it to the georeferencing stage (no stage runs: they are replaced by recorders)."""
    from archaeoortho.core import pipeline
    from qgis.core import QgsApplication, QgsProcessingContext, QgsProcessingException, QgsProcessingFeedback

    alg = QgsApplication.processingRegistry().algorithmById("archaeoortho:runpipeline").create()
    flag = alg.parameterDefinition("GCPS_UPRIGHT")
    assert flag is not None and flag.description() == "GCP pixels measured on upright photos"
    assert flag.defaultValue() in (False, None)

    class Stop(Exception):
        pass

    seen = {}

    def fake_run_pipeline(images, workspace, options=None, control=None, progress=None):
        seen["control"] = control
        raise Stop()

    gcp = tmp_path / "gcp_list.txt"
    gcp.write_text("EPSG:32633\n500000 5000000 100 10 20 a.jpg p1\n")
    images = tmp_path / "images"
    images.mkdir()
    monkeypatch.setattr(pipeline, "run_pipeline", fake_run_pipeline)
    for value in (True, False):
        seen.clear()
        parameters = {"IMAGES": str(images), "WORKSPACE": str(tmp_path / "ws"), "GCPS": str(gcp),
                      "GCPS_UPRIGHT": value}
        with pytest.raises(QgsProcessingException, match="Stop"):  # run_core turns it into this
            alg.processAlgorithm(parameters, QgsProcessingContext(), QgsProcessingFeedback())
        assert seen["control"].gcps_upright is value
        assert seen["control"].gcp_path == str(gcp)
    monkeypatch.undo()

    # the pipeline itself: Control.gcps_upright -> georeference_workspace(GeorefOptions(gcps_upright=...))
    got = {}

    def fake_georeference(workspace_dir, options, progress=None):
        got["options"] = options
        raise Stop()

    monkeypatch.setattr(pipeline, "check_inputs", lambda *a: None)
    monkeypatch.setattr(pipeline, "align", lambda *a, progress=None, **k: None)
    monkeypatch.setattr(pipeline, "georeference_workspace", fake_georeference)
    for value in (True, False):
        got.clear()
        with pytest.raises(Stop):
            pipeline.run_pipeline(str(images), str(tmp_path / "ws"),
                                  control=pipeline.Control(gcp_path=str(gcp), gcps_upright=value))
        assert got["options"].gcps_upright is value


def test_run_pipeline_capture_radiometry_as_in_stack_captures(plugin, tmp_path, monkeypatch):
    """Run pipeline's 'Capture radiometry' (advanced) is Stack multispectral captures' Radiometry: same options,
    normalised by default, an unknown choice refused; each choice reaches PipelineOptions.capture_radiometry (no
    stage runs: run_pipeline is replaced by a recorder)."""
    from archaeoortho.core import pipeline
    from archaeoortho.core.prepare.band_radiometry import MODES
    from qgis.core import (
        QgsApplication,
        QgsProcessingContext,
        QgsProcessingException,
        QgsProcessingFeedback,
        QgsProcessingParameterDefinition,
    )

    registry = QgsApplication.processingRegistry()
    alg = registry.algorithmById("archaeoortho:runpipeline").create()
    stack_alg = registry.algorithmById("archaeoortho:stackcaptures").create()  # kept: it owns its parameters
    stack = stack_alg.parameterDefinition("RADIOMETRY")
    p = alg.parameterDefinition("CAPTURE_RADIOMETRY")
    assert p is not None and p.description() == "Capture radiometry"
    assert p.flags() & QgsProcessingParameterDefinition.Flag.FlagAdvanced
    assert p.options() == stack.options() and p.defaultValue() == stack.defaultValue() == MODES.index("normalised")
    assert not p.checkValueIsAcceptable(len(MODES)) and not p.checkValueIsAcceptable("sunny")
    assert pipeline.PipelineOptions().capture_radiometry == "normalised"  # the same default as without the form

    class Stop(Exception):
        pass

    seen = {}

    def fake_run_pipeline(images, workspace, options=None, control=None, progress=None):
        seen["options"] = options
        raise Stop()

    images = tmp_path / "images"
    images.mkdir()
    monkeypatch.setattr(pipeline, "run_pipeline", fake_run_pipeline)
    base = {"IMAGES": str(images), "WORKSPACE": str(tmp_path / "ws"), "USE_EXIF_GPS": True}
    for value, mode in [(None, "normalised")] + list(enumerate(MODES)):
        parameters = dict(base) if value is None else dict(base, CAPTURE_RADIOMETRY=value)
        with pytest.raises(QgsProcessingException, match="Stop"):
            alg.processAlgorithm(parameters, QgsProcessingContext(), QgsProcessingFeedback())
        assert seen.pop("options").capture_radiometry == mode, value


def test_run_pipeline_returns_the_rgb_frames_orthomosaic(plugin, tmp_path, monkeypatch):
    """Run pipeline declares the RGB frames' orthomosaic (a raster layer output, so that QGIS loads it) and returns
    PipelineResult.ortho_rgb's path when there is one, None when not; a run whose captures registered none leaves
    ORTHOMOSAIC None rather than failing after the stages (run_pipeline replaced by a stub: no stage runs)."""
    from types import SimpleNamespace

    from archaeoortho.core import pipeline
    from qgis.core import (
        QgsApplication,
        QgsProcessingContext,
        QgsProcessingFeedback,
        QgsProcessingOutputRasterLayer,
    )

    alg = QgsApplication.processingRegistry().algorithmById("archaeoortho:runpipeline").create()
    out = alg.outputDefinition("ORTHOMOSAIC_RGB")
    assert isinstance(out, QgsProcessingOutputRasterLayer)
    assert out.description() == "RGB orthomosaic (a rig's RGB frames)"
    assert out.description() in alg.shortHelpString()  # the help names it by its label

    images = tmp_path / "images"
    images.mkdir()
    ws = str(tmp_path / "ws")
    main, rgb = os.path.join(ws, "orthomosaic.tif"), os.path.join(ws, "orthomosaic_rgb.tif")
    results = []

    def fake_run_pipeline(images_dir, workspace, options=None, control=None, progress=None):
        return results.pop(0)

    def result(ortho, ortho_rgb):
        def stage(path):
            return path and SimpleNamespace(warnings=[], valid_fraction=0.9, orthomosaic=path)

        return pipeline.PipelineResult(
            workspace=ws, align=SimpleNamespace(registered=4, mean_reprojection_error=0.5),
            georef=SimpleNamespace(figures={}), dsm=SimpleNamespace(dsm_path=os.path.join(ws, "dsm.tif"),
                                                                    valid_fraction=0.8),
            ortho=stage(ortho), ortho_rgb=stage(ortho_rgb))

    monkeypatch.setattr(pipeline, "run_pipeline", fake_run_pipeline)
    parameters = {"IMAGES": str(images), "WORKSPACE": ws, "USE_EXIF_GPS": True}
    for ortho, ortho_rgb in [(main, rgb), (main, None), (None, rgb)]:
        results.append(result(ortho, ortho_rgb))
        got = alg.processAlgorithm(parameters, QgsProcessingContext(), QgsProcessingFeedback())
        assert got["ORTHOMOSAIC"] == ortho and got.get("ORTHOMOSAIC_RGB") == ortho_rgb
        assert got["ORTHO_VALID_FRACTION"] == (0.9 if ortho else None)


def test_orthorectify_mode_options_are_translated(plugin, german):
    """The Mode drop-down of Orthorectify image is German in a German QGIS (its options were plain strings)."""
    from qgis.core import QgsApplication

    a = QgsApplication.processingRegistry().algorithmById("archaeoortho:orthorectifyimage").create()
    options = a.parameterDefinition("MODE").options()
    assert options == ["Echtes Orthofoto auf dem DOM", "Ebene Entzerrung (flaches Gelände)"]


# features that are no one algorithm's name: each named in the plugin manager's "about" (issue 48 item 12)
FEATURES = ("terrain", "automatic control", "targets", "multispectral", "calibration file", "DEM", "GCPs dock",
            "qgis_process", "scanned")


def _metadata():
    import configparser

    meta = configparser.ConfigParser(interpolation=None)
    assert meta.read(os.path.join(ROOT, "metadata.txt"), encoding="utf-8")
    return meta["general"]


def test_the_plugin_manager_text_names_every_algorithm_and_each_release(plugin):
    """Issue 48 item 12: metadata.txt said 0.2.0, and its about and changelog named none of the features since.
    The about text (what the plugin manager shows) and the changelog name every algorithm the provider registers
    by its toolbox name, so that a newly registered algorithm fails here until both say so; the changelog has an
    entry per release, newest first, the newest being the version."""
    from qgis.core import QgsApplication

    general = _metadata()
    version = general["version"].strip()
    assert re.fullmatch(r"\d+\.\d+\.\d+", version), version
    about = " ".join(general["about"].split()).lower()
    changelog = general["changelog"]
    releases = re.findall(r"^\s*(\d+\.\d+\.\d+)\b", changelog, flags=re.M)
    assert releases and releases[0] == version, (version, releases)
    key = [tuple(int(p) for p in r.split(".")) for r in releases]
    assert key == sorted(key, reverse=True) and len(set(key)) == len(key), releases
    entries = re.split(r"^\s*\d+\.\d+\.\d+\b.*$", changelog, flags=re.M)[1:]
    assert all(re.search(r"^\s*- \S", e, flags=re.M) for e in entries), changelog  # each release says something
    flat = " ".join(changelog.split()).lower()
    provider = QgsApplication.processingRegistry().providerById("archaeoortho")
    names = [a.displayName() for a in provider.algorithms()]
    assert len(names) >= 16, names
    assert [n for n in names if n.lower() not in about] == [], "named nowhere in metadata.txt's about"
    assert [n for n in names if n.lower() not in flat] == [], "named in no release of metadata.txt's changelog"
    assert [f for f in FEATURES if f.lower() not in about] == []
