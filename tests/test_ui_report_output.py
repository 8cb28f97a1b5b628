"""The accuracy report in the QGIS GUI (issue 36 item 15): Run pipeline's and Accuracy report's report is an HTML
output, so the toolbox dialog lists it in the Results Viewer when the run ends, and a double click opens it."""
import pytest

pytestmark = pytest.mark.usefixtures("qgis_processing")
_KEEP = []


def _dialog(alg):
    """The toolbox's dialog of ``alg`` (pytest-qgis's interface has no browser model: a real one)."""
    from processing.gui import ParametersPanel
    from processing.gui.AlgorithmDialog import AlgorithmDialog
    from qgis.gui import QgsBrowserGuiModel

    if ParametersPanel.iface is not None:
        model = QgsBrowserGuiModel()
        model.initialize()
        _KEEP.append(model)
        ParametersPanel.iface.browserModel = lambda: model
    return AlgorithmDialog(alg, False, None)


@pytest.mark.parametrize("alg_id, output, extra", [
    ("runpipeline", "REPORT", {"DSM": None, "ORTHOMOSAIC": None, "DTM": None, "REGISTERED_IMAGES": 18}),
    ("accuracyreport", "OUTPUT_HTML", {"CAMERA_PRECISION": None, "POINT_PRECISION": None, "SECTIONS_SKIPPED": ""}),
])
def test_the_report_is_listed_in_the_results_viewer_and_opens(plugin, tmp_path, monkeypatch, alg_id, output, extra):
    """The dialog's end of a run (AlgorithmDialog.finish, as QGIS calls it) with the algorithm's results: the
    report is in the Results Viewer, named after the output; opening it opens the HTML file (Run pipeline's was a
    plain file output: the Results Viewer stayed empty)."""
    from processing.core.ProcessingResults import resultsList
    from processing.gui import ResultsDock as results_dock
    from qgis.core import QgsApplication, QgsProcessingContext, QgsProcessingFeedback, QgsProcessingOutputHtml

    alg = QgsApplication.processingRegistry().algorithmById("archaeoortho:" + alg_id).create()
    assert isinstance(alg.outputDefinition(output), QgsProcessingOutputHtml), type(alg.outputDefinition(output))
    ws = tmp_path / "site"
    ws.mkdir()
    report = str(ws / "report.html")
    with open(report, "w", encoding="utf-8") as fh:
        fh.writelines(["<html><body><h1>Accuracy report</h1></body></html>"])
    viewer = results_dock.ResultsDock()
    before = len(resultsList.getResults())
    dialog = _dialog(alg)
    dialog.iterateParam = None  # as AlgorithmDialog.runAlgorithm sets it for a single run
    try:
        dialog.finish(True, dict(extra, WORKSPACE=str(ws), **{output: report}), QgsProcessingContext(),
                      QgsProcessingFeedback())
        listed = resultsList.getResults()[before:]
        assert [r.filename for r in listed] == [report]
        item = viewer.treeResults.topLevelItem(0)
        assert item.filename == report and alg.outputDefinition(output).description() in item.text(0)
        opened = []
        monkeypatch.setattr(results_dock.QDesktopServices, "openUrl", lambda url: opened.append(url.toLocalFile()))
        viewer.openResult(item, 0)
        assert opened == [report]
    finally:
        dialog.close()
        viewer.close()
