"""Translations: the plugin loads i18n/archaeoortho_<lang>.qm for the QGIS locale; the dock and the toolbox
speak German (and Italian); the .ts files are complete and the algorithms' class-attribute strings are
in the catalog pylupdate5 reads."""
import ast
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest

from tests.conftest import ROOT

pytestmark = pytest.mark.usefixtures("qgis_processing")

I18N = os.path.join(ROOT, "i18n")


def _qm(lang, tmp_path):
    """The compiled translation (make transcompile); compiled here when missing."""
    qm = os.path.join(I18N, f"archaeoortho_{lang}.qm")
    ts = os.path.join(I18N, f"archaeoortho_{lang}.ts")
    if os.path.exists(qm) and os.path.getmtime(qm) >= os.path.getmtime(ts):
        return qm
    if not shutil.which("lrelease"):
        pytest.skip("no compiled translation and no lrelease (run make transcompile)")
    subprocess.run(["lrelease", "-silent", ts, "-qm", qm], check=True)
    return qm


@pytest.fixture
def locale_setting():
    """Set QGIS's locale override for a test, restore it after."""
    from qgis.core import QgsSettings

    s = QgsSettings()
    saved = {k: s.value(k) for k in ("locale/overrideFlag", "locale/userLocale")}

    def set_locale(lang):
        s.setValue("locale/overrideFlag", True)
        s.setValue("locale/userLocale", lang)

    yield set_locale
    for k, v in saved.items():
        if v is None:
            s.remove(k)
        else:
            s.setValue(k, v)


def test_german_dock_and_toolbox(qgis_iface, qgis_canvas, locale_setting, tmp_path):
    import archaeoortho
    from archaeoortho import plugin as plugin_module
    from qgis.core import QgsApplication

    _qm("de", tmp_path)
    locale_setting("de_AT")
    assert plugin_module._locale() == "de"
    p = archaeoortho.classFactory(qgis_iface)
    try:
        assert p.translator is not None
        p.initProcessing()
        from archaeoortho.ui.gcp_dock import GcpDock

        dock = GcpDock(None, qgis_canvas)
        try:
            assert dock.windowTitle() == "ArchaeoOrtho Passpunkte"
            assert dock.btn_georef.text() == "Georeferenzieren"
            assert dock.act_pick.text() == "Auf der Karte messen"
            assert dock.model.headerData(6, 1) == "Rolle"
            assert dock.photo_panel.filter_box.text() == "Nur Fotos, die den Punkt voraussichtlich zeigen"
            assert dock.photo_dock.windowTitle() == "ArchaeoOrtho Fotos"
            assert dock.summary.text() == "" and dock.ws_label.text() == "keiner geöffnet"
        finally:
            dock.close()
        reg = QgsApplication.processingRegistry()
        align = reg.algorithmById("archaeoortho:alignimages")
        georef = reg.algorithmById("archaeoortho:georeference")
        assert align.displayName() == "Bilder ausrichten"
        assert align.group() == "Photogrammetrie"
        assert align.parameterDefinition("IMAGES").description() == "Bilderordner"
        assert align.shortHelpString().startswith("Structure from Motion: SIFT-Merkmale")
        assert georef.displayName() == "Georeferenzieren"
        assert georef.parameterDefinition("CHECK_POINTS").description() == "Kontrollpunkte"
        assert reg.providerById("archaeoortho").longName() == "ArchaeoOrtho Photogrammetrie"
    finally:
        p.unload()
    # unloading removes the translator
    assert QgsApplication.processingRegistry().algorithmById("archaeoortho:alignimages") is None
    from archaeoortho.ui.gcp_dock import GcpDock

    dock = GcpDock(None, qgis_canvas)
    assert dock.btn_georef.text() == "Georeference"
    dock.close()


def test_italian_translation_loads(qgis_iface, locale_setting, tmp_path):
    import archaeoortho
    from qgis.core import QgsApplication

    _qm("it", tmp_path)
    locale_setting("it")
    p = archaeoortho.classFactory(qgis_iface)
    try:
        p.initProcessing()
        alg = QgsApplication.processingRegistry().algorithmById("archaeoortho:georeference")
        assert alg.displayName() == "Georeferenzia"
        assert alg.parameterDefinition("GCPS").description() == "File dei punti d'appoggio"
    finally:
        p.unload()


@pytest.mark.parametrize("lang, expected", [
    ("de", {("runpipeline", "QUALITY"): ["voll (full)", "halb (half)", "Viertel (quarter)"],
            ("buildorthophoto", "BLENDING"): ["weiche Naht (feather)", "Mehrband (multiband)", "keine (none)"],
            ("alignimages", "PAIRING"): ["automatisch (auto)", "alle Paare (exhaustive)",
                                         "aufeinanderfolgend (sequential)", "räumlich (spatial)"],
            ("reliefvisualisation", "VISUALISATION"): "Sky-View-Faktor",
            ("runpipeline", "ORTHO_RESOLUTION"): "Orthomosaik-Auflösung (KBS-Einh., 0 = GSD)"}),
    ("it", {("runpipeline", "QUALITY"): ["piena (full)", "metà (half)", "un quarto (quarter)"],
            ("alignimages", "INTRINSICS"): ["automatica (auto)", "fisso (fixed)", "affinato (refined)",
                                            "stimato (estimated)"],
            ("buildorthophoto", "RESOLUTION"): "Risoluzione (unità del SR, 0 = GSD)"}),
])
def test_choice_values_and_units_translated(qgis_iface, locale_setting, tmp_path, lang, expected):
    """The options of the choices ('auto', 'half', 'feather' ...) were English in a German or Italian QGIS (issue
    36 item 21): they show translated, the core's value beside it, and a run still takes the option by its index;
    the orthomosaic's resolution gives its unit."""
    import archaeoortho
    from archaeoortho.processing_provider import params
    from qgis.core import QgsApplication, QgsProcessingContext

    _qm(lang, tmp_path)
    locale_setting(lang)
    p = archaeoortho.classFactory(qgis_iface)
    try:
        p.initProcessing()
        reg = QgsApplication.processingRegistry()
        for (alg_id, name), want in expected.items():
            definition = reg.algorithmById("archaeoortho:" + alg_id).parameterDefinition(name)
            if isinstance(want, list):
                assert definition.options() == want, (alg_id, name)
            elif hasattr(definition, "options"):
                assert want in definition.options(), (alg_id, name, definition.options())
            else:
                assert definition.description() == want, (alg_id, name)
        alg = reg.algorithmById("archaeoortho:runpipeline").create()
        assert params.read_choice(alg, {"QUALITY": 1}, "QUALITY", QgsProcessingContext(), params.QUALITIES) == "half"
        from archaeoortho.qgisio.layers import relief_name  # a relief layer is named as the option was

        assert relief_name(str(tmp_path / "dtm-svf.tif")) == {"de": "Sky-View-Faktor (DTM)",
                                                              "it": "Fattore di vista del cielo (sky-view factor) (DTM)"}[lang]
    finally:
        p.unload()
    locale_setting("en")
    english = archaeoortho.classFactory(qgis_iface)  # no translator: the core's values, the units in English
    try:
        assert english.translator is None
        english.initProcessing()
        pipeline = QgsApplication.processingRegistry().algorithmById("archaeoortho:runpipeline")
        assert pipeline.parameterDefinition("QUALITY").options() == ["full", "half", "quarter"]
        assert pipeline.parameterDefinition("ORTHO_RESOLUTION").description() == (
            "Orthomosaic resolution (CRS units, 0 = GSD)")
    finally:
        english.unload()


def test_english_without_a_translation(qgis_iface, locale_setting):
    import archaeoortho

    locale_setting("fr")
    p = archaeoortho.classFactory(qgis_iface)
    assert p.translator is None
    p.unload()


@pytest.mark.parametrize("lang", ["de", "it"])
def test_ts_files_are_complete_and_keep_placeholders(lang):
    import string

    tree = ET.parse(os.path.join(I18N, f"archaeoortho_{lang}.ts"))
    fmt = string.Formatter()
    n = 0
    for msg in tree.getroot().iter("message"):
        src = msg.find("source").text
        tr = msg.find("translation")
        assert tr.get("type") != "unfinished" and tr.text, f"untranslated ({lang}): {src!r}"
        fields = [f[1:] for f in fmt.parse(src) if f[1] is not None]
        assert fields == [f[1:] for f in fmt.parse(tr.text) if f[1] is not None], (lang, src, tr.text)
        n += 1
    assert n > 200


def test_algorithm_strings_are_in_the_catalog():
    """ui/catalog.py carries DISPLAY / HELP / GROUP of every algorithm for pylupdate5; when an algorithm's
    text changes, run `python3 i18n/make_catalog.py && make transup` and translate the new strings."""
    out = subprocess.run([sys.executable, os.path.join(I18N, "make_catalog.py"), "--check"],
                         capture_output=True, text=True)
    assert out.returncode == 0, ("ui/catalog.py is out of date (an algorithm's name or help changed): "
                                 "run python3 i18n/make_catalog.py && make transup, then translate\n"
                                 + out.stdout + out.stderr)


# --------------------------------------------------------------------------------------------------
# issue 48 item 6: nothing the user reads stays English in a German QGIS
# --------------------------------------------------------------------------------------------------

# methods and widgets whose text argument a user reads
USER_FACING = {"setText", "setWindowTitle", "setToolTip", "setPlaceholderText", "setSpecialValueText", "addItem",
               "addAction", "setStatusTip", "pushInfo", "pushWarning", "reportError", "pushMessage", "pushSuccess",
               "pushCritical", "setProgressText", "setLabelText", "setTitle", "message", "setName", "addMenu",
               "setWhatsThis", "setHeaderLabels", "addTab", "setDescription", "showMessage", "info", "warning",
               "critical", "information", "question", "QLabel", "QPushButton", "QCheckBox", "QGroupBox", "QAction",
               "QToolButton", "QgsProcessingException"}
NOT_WORDS = {"ArchaeoOrtho"}  # a name, the same in every language


def _face_sources():
    for folder in ("", "ui", "processing_provider", "qgisio"):
        for name in sorted(os.listdir(os.path.join(ROOT, folder))):
            if name.endswith(".py") and name not in ("catalog.py", "core_messages.py"):
                yield os.path.join(folder, name)


def _literal_text(node):
    """What a user would read of ``node`` when it is a literal (an f-string, "...".format(), a sum or a choice of
    literals), its fields as {}; None when it is anything else (a tr() call, a variable)."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.JoinedStr):
        return "".join(v.value if isinstance(v, ast.Constant) else "{}" for v in node.values)
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "format":
        return _literal_text(node.func.value)
    if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Mod)):
        parts = [_literal_text(node.left), _literal_text(node.right)]
        return "".join(p for p in parts if p) if any(parts) else None
    if isinstance(node, ast.IfExp):
        parts = [_literal_text(node.body), _literal_text(node.orelse)]
        return " | ".join(p for p in parts if p) if any(parts) else None
    return None


def _words(text):
    """The words of ``text`` outside HTML tags and replacement fields."""
    import re

    text = re.sub(r"<[^>]*>|\{[^}]*\}", " ", text)
    return [w for w in re.findall(r"[A-Za-z]{3,}", text) if w not in NOT_WORDS]


def untranslated_literals(sources, catalogued=()):
    """[(file:line, text)] of the literal texts given to a user-facing call (USER_FACING) without tr() or
    translate(); a message whose template is ``catalogued`` (qgisio/core_messages.py: translated where shown)
    is not counted."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("make_catalog", os.path.join(I18N, "make_catalog.py"))
    catalog = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(catalog)
    out = []
    for rel, text in sources:
        for node in ast.walk(ast.parse(text)):
            if not isinstance(node, ast.Call):
                continue
            name = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")
            if name not in USER_FACING:
                continue
            for arg in node.args:
                literal = _literal_text(arg)
                if literal and _words(literal) and catalog.message_template(arg) not in catalogued:
                    out.append((f"{rel}:{node.lineno}", literal))
    return out


def test_no_user_facing_string_is_left_untranslated():
    """Issue 48 item 6: the faces give no literal text to a label, a button, a log line or a message bar without
    tr() (or the core messages' catalogue), and the check finds one (the Find targets dialog's target kinds
    were such literals: 'checkerboard', 'circle')."""
    from archaeoortho.qgisio.core_messages import TEMPLATES

    sources = [(rel, open(os.path.join(ROOT, rel), encoding="utf-8").read()) for rel in _face_sources()]
    assert untranslated_literals(sources, TEMPLATES) == []
    planted = [("ui/planted.py", 'box.addItem("checkerboard")\nlabel.setText(f"{n} targets found")\n'
                                 'bar.pushMessage(tr("Done"))\nw.setText("<b>{}</b>".format(x))\n')]
    assert [t for _w, t in untranslated_literals(planted)] == ["checkerboard", "{} targets found"]


def _ts_translations(lang):
    tree = ET.parse(os.path.join(I18N, f"archaeoortho_{lang}.ts"))
    return {(ctx.findtext("name"), m.findtext("source")): m.find("translation")
            for ctx in tree.getroot().iter("context") for m in ctx.iter("message")}


@pytest.mark.parametrize("lang", ["de", "it"])
def test_core_messages_report_labels_and_target_kinds_are_translated(lang):
    """The core's message templates (qgisio/core_messages.py), the report's headings and labels (context
    "Report") and the target kinds are in the .ts file, translated (not 'unfinished')."""
    from archaeoortho.qgisio.core_messages import TEMPLATES

    have = _ts_translations(lang)
    wanted = [("CoreMessages", t) for t in TEMPLATES] + [("Choices", "checkerboard"), ("Choices", "circle")]
    wanted += [("Report", t) for t in ("At a glance", "Summary", "Control and check points", "reprojection error (px)",
                                       "image")]
    missing = [k for k in wanted if k not in have or not have[k].text or have[k].get("type") == "unfinished"]
    assert missing == []
    assert len(TEMPLATES) > 100


def test_core_messages_and_diagnosis_read_in_german(qgis_iface, locale_setting, tmp_path):
    """A German QGIS: the core's progress lines, log lines and the adjustment's diagnosis (English f-strings from
    core/) are shown in German with their own names and numbers; a message from no known template stays as it is;
    the target kinds are German in Processing's Find targets and in the dock's dialog."""
    import archaeoortho
    from archaeoortho.qgisio.messages import translate_message
    from qgis.core import QgsApplication

    _qm("de", tmp_path)
    locale_setting("de")
    p = archaeoortho.classFactory(qgis_iface)
    try:
        p.initProcessing()
        assert translate_message("mapping: registered image IMG_0042.JPG") == "Bildzuordnung: Bild IMG_0042.JPG registriert"
        assert translate_message("DSM tile 3/12") == "DOM-Kachel 3/12"
        assert translate_message("control point G07 is 0.412 m off the Helmert fit of the others (threshold 0.150 m): "
                                 "left out of the first adjustment, then re-tested against the adjusted block") == (
            "Passpunkt G07 liegt 0.412 m neben der Helmert-Passung der anderen (Schwelle 0.150 m): aus der ersten "
            "Ausgleichung ausgelassen, dann gegen den ausgeglichenen Block erneut geprüft")
        assert translate_message("pipeline done\nDSM done") == "Verarbeitung fertig\nDOM fertig"
        assert translate_message("something the core never says") == "something the core never says"
        kinds = QgsApplication.processingRegistry().algorithmById("archaeoortho:findtargets") \
            .parameterDefinition("TARGET_KIND").options()
        assert "Schachbrett (checkerboard)" in kinds and "Kreis (circle)" in kinds
        from archaeoortho.ui.gcp_targets import FindTargetsDialog

        dialog = FindTargetsDialog()
        shown = [dialog.kind.itemText(i) for i in range(dialog.kind.count())]
        assert "Schachbrett (checkerboard)" in shown and "Kreis (circle)" in shown
        assert dialog.kind.itemData(shown.index("Kreis (circle)")) == "circle"  # the core's value
        dialog.close()
    finally:
        p.unload()
    assert translate_message("DSM tile 3/12") == "DSM tile 3/12"  # no translator: the core's English


def test_report_headings_in_the_report_language(tmp_path):
    """The accuracy report of a German QGIS has German headings, table headings and labels (the Processing
    algorithms pass QGIS's language as ReportOptions.language); English without one."""
    from archaeoortho.core.project.workspace import Workspace
    from archaeoortho.core.report import stage as report
    from archaeoortho.core.report.labels import language, t
    from archaeoortho.core.report.options import ReportOptions

    ws = Workspace.create_or_open(str(tmp_path / "ws")).root
    text = open(report.build_report(ws, ReportOptions(language="de_AT")).path, encoding="utf-8").read()
    for german in ('<html lang="de">', "<h2>Auf einen Blick</h2>", "<h2>Übersicht</h2>", "<h2>Produkte</h2>",
                   "kein ausgerichtetes Modell: 'Bilder ausrichten' ausführen", "Übersprungen:"):
        assert german in text, german
    assert "At a glance" not in text and "<h2>Summary</h2>" not in text
    english = open(report.build_report(ws, ReportOptions()).path, encoding="utf-8").read()
    assert "<h2>At a glance</h2>" in english and '<html lang="en">' in english
    with language("it"):
        assert t("reprojection error (px)") == "errore di riproiezione (px)"  # a figure's axis label
    assert t("reprojection error (px)") == "reprojection error (px)"
    with pytest.raises(Exception, match="language"):
        ReportOptions(language="../../etc")


def test_dtm_band_legend_in_german(qgis_iface, locale_setting, tmp_path):
    """The DTM's legend named its band by the file's English description, "Band 1: DTM (bare earth)", in a
    German QGIS (issue 48 item 6): the layer the plugin loads shows it translated; the file keeps its own."""
    import archaeoortho
    import numpy as np
    from archaeoortho.qgisio import layers
    from osgeo import gdal
    from qgis.core import QgsMapLayerLegendUtils, QgsProject

    path = str(tmp_path / "dtm.tif")
    ds = gdal.GetDriverByName("GTiff").Create(path, 16, 16, 1, gdal.GDT_Float32)
    ds.SetGeoTransform((500000.0, 1.0, 0.0, 4600000.0, 0.0, -1.0))
    ds.GetRasterBand(1).WriteArray(np.arange(256, dtype="float32").reshape(16, 16))
    ds.GetRasterBand(1).SetDescription("DTM (bare earth)")  # as core/terrain/products.py writes it
    ds = None
    _qm("de", tmp_path)
    locale_setting("de")
    p = archaeoortho.classFactory(qgis_iface)
    project = QgsProject()
    try:
        dtm = layers.load_dtm(path, project)[0]
        node = project.layerTreeRoot().findLayer(dtm.id())
        labels = [QgsMapLayerLegendUtils.legendNodeUserLabel(node, i) for i in range(3)]
        assert any("DGM (Gelände)" in label for label in labels), labels
        assert not any("bare earth" in label for label in labels)
        assert gdal.Open(path).GetRasterBand(1).GetDescription() == "DTM (bare earth)"
    finally:
        project.clear()
        p.unload()
