"""No algorithm writes over its own input (issue 36, item 1): the output path equal to an input is refused before
any work, with a message naming the file, and the input stays byte for byte as it was; contours are refused under
an extension that is not the GeoPackage they are written as (item 8)."""
from __future__ import annotations

import hashlib
import json
import os
import subprocess

import pytest

from core.common.files import refuse_overwriting_inputs, same_path
from core.io import raster
from core.project.layout import Layout
from core.project.stages import TERRAIN
from core.project.workspace import Workspace
from core.terrain.contours import write_contours
from core.terrain.options import TerrainError, TerrainOptions
from core.terrain.products import DtmOutputs, build_dtm, relief
from core.terrain.stage import build_dtm_workspace
from tests import synthetic as syn
from tests.test_terrain import _workspace_with_dsm, synthetic_dsm


def _digest(path) -> str:
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


@pytest.fixture(scope="module")
def dsm(tmp_path_factory):
    """(scene, DSM path) of the terrain tests' synthetic DSM."""
    root = tmp_path_factory.mktemp("overwrite")
    scene, _x, _y, z, gt, _b, _t = synthetic_dsm()
    path = str(root / "dsm.tif")
    raster.write_cog(path, z, gt, syn.CRS)
    return scene, path


def test_same_path_sees_links_and_files_not_yet_written(tmp_path):
    a = tmp_path / "a.tif"
    a.write_bytes(b"x")
    link = tmp_path / "link.tif"
    os.symlink(a, link)
    assert same_path(str(a), str(link))
    assert same_path(str(tmp_path / "sub" / ".." / "new.tif"), str(tmp_path / "new.tif"))
    assert not same_path(str(a), str(tmp_path / "b.tif"))
    with pytest.raises(TerrainError, match="the DTM and the contours would be written to one file"):
        refuse_overwriting_inputs({"DTM": str(a), "contours": str(link)}, {}, TerrainError)


def test_build_dtm_refuses_to_write_over_its_dsm(dsm):
    _scene, path = dsm
    before = _digest(path)
    with pytest.raises(TerrainError, match=r"DTM would overwrite its input, the DSM .*dsm\.tif"):
        build_dtm(path, path)
    with pytest.raises(TerrainError, match="contours would overwrite its input"):
        build_dtm(path, DtmOutputs(path + ".dtm.tif", contours=path), contour_interval=1.0)
    assert _digest(path) == before


def test_relief_and_contours_refuse_to_write_over_their_input(dsm, tmp_path):
    pytest.importorskip("rvt.vis")
    _scene, path = dsm
    before = _digest(path)
    with pytest.raises(TerrainError, match="slrm visualisation would overwrite its input"):
        relief(path, ["slrm"], str(tmp_path), outputs={"slrm": path}, what="DSM")
    with pytest.raises(TerrainError, match="contours would overwrite its input"):
        write_contours(path, path, 1.0)
    assert _digest(path) == before


def test_contours_are_refused_under_an_extension_they_are_not(dsm, tmp_path):
    _scene, path = dsm
    for name in ("c.shp", "c.tif", "c"):
        with pytest.raises(TerrainError, match=r"GeoPackage: give an output file ending in \.gpkg"):
            write_contours(path, str(tmp_path / name), 1.0)
        assert not os.path.exists(tmp_path / name)
    assert write_contours(path, str(tmp_path / "c.GPKG"), 2.0) > 0


def test_workspace_dtm_over_the_workspace_dsm_is_refused_and_recorded_nowhere(dsm, tmp_path):
    scene, path = dsm
    root, _ = _workspace_with_dsm(tmp_path / "ws", path, scene)
    lay = Layout(Workspace.open(root))
    before = _digest(lay.default_dsm)
    with pytest.raises(TerrainError, match="DTM would overwrite its input"):
        build_dtm_workspace(root, TerrainOptions(dsm=lay.default_dsm, output_dtm=lay.default_dsm))
    with pytest.raises(TerrainError, match="contours would overwrite its input"):
        build_dtm_workspace(root, TerrainOptions(contour_interval=1.0, contours_copy=lay.default_dsm))
    ws = Workspace.open(root)
    assert _digest(lay.default_dsm) == before
    assert not ws.stage_done(TERRAIN) and ws.stage(TERRAIN).get("status") != "failed"


def test_qgis_process_refuses_output_equal_to_input(dsm, tmp_path):
    """The cases as a user ran them: builddtm WORKSPACE=ws DSM=ws/dsm.tif OUTPUT_DTM=ws/dsm.tif, contours
    INPUT=x.tif OUTPUT=x.tif: a message naming the file, exit non-zero, no traceback, the DSM unchanged."""
    from tests.conftest import qgis_process

    exe, env = qgis_process()
    scene, path = dsm
    root, _ = _workspace_with_dsm(tmp_path / "ws", path, scene)
    ws_dsm = os.path.join(root, "dsm.tif")
    before = _digest(ws_dsm)
    for alg, args in (("builddtm", [f"WORKSPACE={root}", f"DSM={ws_dsm}", f"OUTPUT_DTM={ws_dsm}"]),
                      ("contours", [f"INPUT={ws_dsm}", "INTERVAL=1", f"OUTPUT={ws_dsm}"])):
        out = subprocess.run([exe, "--json", "run", f"archaeoortho:{alg}", "--", *args], env=env,
                             capture_output=True, text=True, timeout=600)
        text = out.stdout + out.stderr
        assert out.returncode != 0, text[-2000:]
        assert "would overwrite its input" in text and ws_dsm in text and "Traceback" not in text, text[-2000:]
        assert _digest(ws_dsm) == before
    record = json.load(open(os.path.join(root, "workspace.json")))
    assert (record.get("stages") or {}).get(TERRAIN, {}).get("status") != "done"


def test_relief_copy_over_the_workspace_dtm_is_refused(dsm, tmp_path):
    pytest.importorskip("rvt.vis")
    scene, path = dsm
    root, _ = _workspace_with_dsm(tmp_path / "ws", path, scene)
    from core.terrain.options import ReliefStageOptions
    from core.terrain.stage import relief_workspace

    lay = Layout(Workspace.open(root))
    before = _digest(lay.default_dsm)
    with pytest.raises(TerrainError, match="slrm visualisation would overwrite its input, the DSM"):
        relief_workspace(root, ReliefStageOptions(["slrm"], source="dsm", copy_to=lay.default_dsm))
    assert _digest(lay.default_dsm) == before
    r = relief_workspace(root, ReliefStageOptions(["slrm"], source="dsm", copy_to=str(tmp_path / "slrm.tif")))
    assert os.path.samefile(r.paths["slrm"], tmp_path / "slrm.tif")


def test_an_image_given_as_a_dsm_is_refused_naming_what_it_is(dsm, tmp_path):
    """The RGBA orthomosaic given as the DSM to builddtm, reliefvisualisation and dsmdifference (issue 36 item 5:
    a median 'change' of 142 m), and a relief visualisation given as a DSM."""
    from osgeo import gdal

    from core.terrain.difference import dsm_difference

    _scene, path = dsm
    src = gdal.Open(path)
    rgba = str(tmp_path / "orthomosaic.tif")
    out = gdal.GetDriverByName("GTiff").Create(rgba, src.RasterXSize, src.RasterYSize, 4, gdal.GDT_Byte,
                                               ["PHOTOMETRIC=RGB", "ALPHA=YES"])
    out.SetGeoTransform(src.GetGeoTransform())
    out.SetProjection(src.GetProjection())
    for i in range(4):
        out.GetRasterBand(i + 1).Fill(120 + i)
    out = None
    with pytest.raises(TerrainError, match=r"orthomosaic\.tif is an image, not heights: 4 band\(s\) of Byte"):
        build_dtm(rgba, str(tmp_path / "dtm.tif"))
    with pytest.raises(TerrainError, match="is an image, not heights"):
        relief(rgba, ["slrm"], str(tmp_path), what="DSM")
    with pytest.raises(TerrainError, match="DSM B .*is an image, not heights"):
        dsm_difference(path, rgba, str(tmp_path / "diff.tif"))
    tagged = str(tmp_path / "slrm.tif")
    gdal.Translate(tagged, path, metadataOptions=["ARCHAEOORTHO_PRODUCT=relief-slrm"])
    with pytest.raises(TerrainError, match="ArchaeoOrtho relief-slrm raster, not heights"):
        build_dtm(tagged, str(tmp_path / "dtm2.tif"))
    assert not os.path.exists(tmp_path / "dtm.tif") and not os.path.exists(tmp_path / "diff.tif")


def test_a_stale_dsm_or_dtm_is_refused(dsm, tmp_path):
    """After a re-georeference (into another CRS) the DSM on disk describes the old block: builddtm and the relief
    refuse it (issue 36 item 6) instead of building from it and recording done."""
    from core.project.stages import DSM, GEOREFERENCE, STALE, run_stage
    from core.terrain.options import ReliefStageOptions
    from core.terrain.stage import relief_workspace

    scene, path = dsm
    root, _ = _workspace_with_dsm(tmp_path / "ws", path, scene)
    build_dtm_workspace(root)  # done on the current DSM
    ws = Workspace.open(root)
    with run_stage(ws, GEOREFERENCE, {"crs": "EPSG:32633"}) as run:  # georeferenced again: DSM, DTM stale
        run.finish(outputs={})
    assert Workspace.open(root).stage(DSM)["status"] == STALE
    with pytest.raises(TerrainError, match="DSM of workspace .* is stale: .*run 'Build DSM' again"):
        build_dtm_workspace(root)
    with pytest.raises(TerrainError, match="DTM of workspace .* is stale: .*run 'Build DTM' again"):
        relief_workspace(root, ReliefStageOptions(["slrm"], source="dtm"))
    assert Workspace.open(root).stage(TERRAIN)["status"] == STALE
    # a DSM file given explicitly (outside the workspace's records) is the user's choice
    r = build_dtm_workspace(root, TerrainOptions(dsm=path, output_dtm=str(tmp_path / "other-dtm.tif")))
    assert os.path.isfile(r.dtm_path)
