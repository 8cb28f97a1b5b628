"""Translations: the plugin loads i18n/archaeoortho_<lang>.qm for the QGIS locale; the dock and the toolbox
speak German (and Italian); the .ts files are complete and the algorithms' class-attribute strings are
in the catalog pylupdate5 reads."""
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
