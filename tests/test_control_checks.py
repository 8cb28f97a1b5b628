"""Does the control mean what it says? (issue 47 items 2, 12 and 17; core.georef.control_checks): camera positions
and GCPs that land far from the photos' own EXIF GPS (latitude in the x column, the next UTM zone), or without GPS
outside the CRS's area of use, are refused naming the likely cause; a geographic CRS is refused naming the UTM
zone that fixes it; a positions file's duplicate rows are warned in the stage's log.  All on a synthetic block
(EPSG:32633, lon 15 E lat 41.5 N) whose photos carry their true positions as EXIF GPS; the refusals come before the
adjustment, so each test costs a second or two."""
import numpy as np
import pytest

from core.common.progress import NullProgress
from core.geometry.crs import transform_points
from core.georef import stage as georef_stage
from core.georef.options import GeorefOptions
from core.io.gcp import write_csv_gcps
from core.project.stages import StageError
from core.project.workspace import Workspace
from tests import synthetic as syn
from tests.workspaces import synthetic_workspace, write_flat_reference


class _Said(NullProgress):
    def __init__(self):
        self.warnings = []

    def warning(self, message):
        self.warnings.append(message)


@pytest.fixture(scope="module")
def block():
    return syn.vertical_block(seed=1)


def _workspace(tmp_path, block, gps=True):
    root = synthetic_workspace(tmp_path / "ws", block, block.truth_reconstruction())
    if gps:
        ws = Workspace.open(root)
        world = np.array([s.centre + syn.ORIGIN for s in block.shots])
        lonlat = transform_points(world, syn.CRS, "EPSG:4326")
        by = {s.name: ll for s, ll in zip(block.shots, lonlat)}
        for im in ws.data["images"]:
            im["gps"] = [float(v) for v in by[im["name"]]]
        ws.save()
    return root


def _positions(block, tmp_path, name, crs_line, order="xy", lonlat=False, extra=()):
    """The block's camera positions (world, 0.5 m noise) as an ``image,x,y,z`` file; ``lonlat``: in EPSG:4326;
    ``order`` "yx": the columns swapped."""
    cams, _ = block.camera_positions(sigma=0.5)
    xyz = np.array([[c.x, c.y, c.z] for c in cams])
    if lonlat:
        xyz = transform_points(xyz, syn.CRS, "EPSG:4326")
    rows = ([crs_line] if crs_line else []) + ["image,x,y,z"]
    for c, p in zip(cams, xyz):
        a, b = (p[0], p[1]) if order == "xy" else (p[1], p[0])
        rows.append(f"{c.image},{a:.8f},{b:.8f},{p[2]:.3f}")
    rows += list(extra)
    path = tmp_path / name
    path.write_text("\n".join(rows) + "\n")
    return str(path)


def _gcp_file(block, tmp_path, crs_line):
    path = str(tmp_path / "gcps.csv")
    write_csv_gcps(block.gcp_set(block.spread_control(5)), path)
    lines = [ln for ln in open(path).read().splitlines() if not ln.startswith("# crs")]
    with open(path, "w") as f:
        f.write("\n".join(([f"# crs: {crs_line}"] if crs_line else []) + lines) + "\n")
    return path


def _refused(root, pattern, **options):
    with pytest.raises(StageError, match=pattern) as e:
        georef_stage.georeference_workspace(root, GeorefOptions(**options))
    return str(e.value)


def test_positions_with_the_latitude_in_x_are_refused_as_swapped(tmp_path, block):
    root = _workspace(tmp_path, block)
    p = _positions(block, tmp_path, "latlon.csv", "EPSG:4326", order="yx", lonlat=True)
    msg = _refused(root, r"camera positions in \S*latlon\.csv \(EPSG:4326\) land [\d,]+ km from the same photos' "
                         r"EXIF GPS", camera_positions_path=p)
    assert "latitude and longitude look swapped" in msg


def test_positions_and_gcps_of_another_utm_zone_are_refused_naming_the_zone(tmp_path, block):
    root = _workspace(tmp_path, block)
    p = _positions(block, tmp_path, "zone34.csv", "EPSG:32634")
    msg = _refused(root, r"camera positions in \S*zone34\.csv \(EPSG:32634\) land", camera_positions_path=p,
                   crs="EPSG:32633")
    assert "EPSG:32633 coordinates" in msg and "wrong CRS" in msg
    g = _gcp_file(block, tmp_path, "EPSG:32634")
    msg = _refused(root, r"control points of the GCP file \S*gcps\.csv \(EPSG:32634\) land", gcp_path=g)
    assert "EPSG:32633 coordinates" in msg


def test_without_gps_positions_outside_the_crs_area_of_use_are_refused(tmp_path, block):
    root = _workspace(tmp_path, block, gps=False)
    p = _positions(block, tmp_path, "latlon.csv", "EPSG:4326", order="yx", lonlat=True)
    msg = _refused(root, r"outside the area where EPSG:32633 is used", camera_positions_path=p, crs="EPSG:32633")
    assert "swapped" in msg


def test_a_geographic_crs_names_the_utm_zone_of_the_photos(tmp_path, block):
    root = _workspace(tmp_path, block)
    p = _positions(block, tmp_path, "lonlat.csv", "EPSG:4326", lonlat=True)
    _refused(root, r"CRS=EPSG:4326 \(the CRS parameter\) is geographic.*give CRS=EPSG:32633 \(the UTM zone of the "
                   r"photos' EXIF GPS\)", camera_positions_path=p, crs="EPSG:4326")
    # no CRS parameter: the positions' own CRS would be the target
    _refused(root, r"camera positions file \S*lonlat\.csv is in EPSG:4326, a geographic CRS.*CRS=EPSG:32633.*"
                   r"camera positions are reprojected", camera_positions_path=p)
    # metres without a CRS line, CRS=EPSG:4326: camera positions named as such, and the GCP file
    q = _positions(block, tmp_path, "nocrs.csv", None)
    msg = _refused(root, r"CRS=EPSG:32633", camera_positions_path=q, crs="EPSG:4326")
    assert "camera positions in" in msg and "no CRS line" in msg and "ground control" not in msg
    g = _gcp_file(block, tmp_path, None)
    msg = _refused(root, r"CRS=EPSG:32633", gcp_path=g, crs="EPSG:4326")
    assert "GCP file" in msg and "no CRS line" in msg


def test_a_duplicate_row_is_warned_in_the_stage_log_and_good_positions_pass(tmp_path, block):
    root = _workspace(tmp_path, block)
    cams, _ = block.camera_positions(sigma=0.5)
    c = cams[0]
    p = _positions(block, tmp_path, "dup.csv", syn.CRS, extra=[f"{c.image},{c.x:.8f},{c.y:.8f},{c.z:.3f}"])
    said = _Said()
    result = georef_stage.georeference_workspace(root, GeorefOptions(camera_positions_path=p), said)
    assert result.crs == syn.CRS
    dup = [w for w in said.warnings if c.image in w and "lines 3 and" in w]
    assert len(dup) == 1 and "is used" in dup[0], said.warnings


def test_automatic_control_reads_camera_positions_through_the_same_checks(tmp_path, block):
    """The automatic control (a reference orthophoto and DSM) reads the camera positions and GCPs given beside it
    through read_checked_control (issue 49: one place reads and checks control): latitude in the x column is
    refused before the matching with the message Georeference gives without a reference, a duplicate row is
    warned in the log, and GCPs of another UTM zone are refused as there."""
    from core.georef.autocontrol.options import AutoControlOptions
    from core.georef.autocontrol.stage import autocontrol_workspace

    root = _workspace(tmp_path, block)
    ortho, dsm = write_flat_reference(tmp_path / "ref", block.camera_positions(sigma=0.0)[0], syn.CRS)
    cams, _ = block.camera_positions(sigma=0.5)
    lat, lon = transform_points(np.array([[cams[0].x, cams[0].y, 0.0]]), syn.CRS, "EPSG:4326")[0, 1::-1]
    p = _positions(block, tmp_path, "latlon.csv", "EPSG:4326", order="yx", lonlat=True,
                   extra=[f"{cams[0].image},{lat:.8f},{lon:.8f},{cams[0].z:.3f}"])
    plain = _refused(root, r"latitude and longitude look swapped", camera_positions_path=p)

    def automatic(**control):
        said = _Said()
        with pytest.raises(StageError) as e:
            autocontrol_workspace(root, AutoControlOptions(reference_ortho=ortho, reference_dsm=dsm,
                                                           control=GeorefOptions(**control)), said)
        return str(e.value), said.warnings

    msg, said = automatic(camera_positions_path=p)
    assert msg == plain
    assert any(cams[0].image in w and "lines 3 and" in w for w in said), said
    g = _gcp_file(block, tmp_path, "EPSG:32634")
    plain = _refused(root, r"control points of the GCP file \S*gcps\.csv \(EPSG:32634\) land", gcp_path=g,
                     crs=syn.CRS)
    assert automatic(gcp_path=g)[0] == plain
    assert not (tmp_path / "ws" / "georef" / "autocontrol-failed.json").exists()  # refused before the matching


# ---------------------------------------------------------------------------------------------------------------
# before the alignment: Run pipeline and Align images read the photos' EXIF GPS from the files (issue 47 items 2,
# 12 and 17 "before any long work"); one photo: Orthorectify image
# ---------------------------------------------------------------------------------------------------------------

def _toledo(tmp_path, n=3):
    """``n`` Toledo photos (EXIF GPS, UTM zone 17N) in a folder of their own, and their EXIF GPS {name: lon, lat,
    alt}."""
    import os

    from core.io.images import read_image_info
    from tests.conftest import SAMPLE, TOLEDO_STRIP, copy_images

    folder = copy_images(os.path.join(SAMPLE, "images"), TOLEDO_STRIP[:n], str(tmp_path / "photos"))
    return folder, {n_: read_image_info(os.path.join(folder, n_)).gps for n_ in sorted(os.listdir(folder))}


def _toledo_positions(tmp_path, gps, name, crs_line, swap=False, extra=()):
    """The photos' EXIF GPS as an ``image,x,y,z`` file: in EPSG:4326 (``crs_line`` "EPSG:4326", ``swap``: the
    latitude in x), else in UTM 17N under ``crs_line`` (None: no CRS line)."""
    rows = ([crs_line] if crs_line else []) + ["image,x,y,z"]
    for n, (lon, lat, alt) in gps.items():
        if crs_line == "EPSG:4326":
            a, b = (lat, lon) if swap else (lon, lat)
        else:
            a, b = transform_points(np.array([[lon, lat, 0.0]]), "EPSG:4326", "EPSG:32617")[0, :2]
        rows.append(f"{n},{a:.8f},{b:.8f},{alt:.2f}")
    path = tmp_path / name
    path.write_text("\n".join(rows + list(extra)) + "\n")
    return str(path)


def test_run_pipeline_refuses_swapped_positions_before_the_alignment(tmp_path, monkeypatch):
    """Run pipeline with camera positions whose latitude is in the x column: refused by the up-front check (the
    photos' EXIF GPS read from the files), with the Georeference stage's message, before anything is aligned (was:
    refused only after the alignment's minutes)."""
    import time

    from core import pipeline

    images, gps = _toledo(tmp_path)
    p = _toledo_positions(tmp_path, gps, "latlon.csv", "EPSG:4326", swap=True)

    def aligned(*_a, **_k):
        raise AssertionError("the alignment ran")

    monkeypatch.setattr(pipeline, "align", aligned)
    t0 = time.time()
    with pytest.raises(StageError, match=r"camera positions in \S*latlon\.csv \(EPSG:4326\) land [\d,]+ km from "
                                         r"the same photos' EXIF GPS.*latitude and longitude look swapped"):
        pipeline.run_pipeline(images, str(tmp_path / "ws"), control=pipeline.Control(camera_positions_path=p))
    assert time.time() - t0 < 10.0
    assert not (tmp_path / "ws" / "sfm").exists()


def test_run_pipeline_checks_the_zone_the_gcps_and_a_geographic_crs_before_the_alignment(tmp_path):
    """check_inputs: positions of UTM 17N labelled 18N, GCPs labelled 18N, and CRS=EPSG:4326 are refused naming
    EPSG:32617 (the photos' zone); the right files pass."""
    from core.pipeline import Control, check_inputs

    images, gps = _toledo(tmp_path)
    good = _toledo_positions(tmp_path, gps, "utm.csv", "EPSG:32617")
    check_inputs(images, Control(camera_positions_path=good))
    zone = _toledo_positions(tmp_path, gps, "zone18.csv", "EPSG:32618")
    with pytest.raises(StageError, match=r"camera positions in \S*zone18\.csv \(EPSG:32618\) land .*EPSG:32617"):
        check_inputs(images, Control(camera_positions_path=zone))
    with pytest.raises(StageError, match=r"CRS=EPSG:4326 \(the CRS parameter\) is geographic.*CRS=EPSG:32617"):
        check_inputs(images, Control(camera_positions_path=good, crs="EPSG:4326"))
    lon, lat, alt = next(iter(gps.values()))
    x, y = transform_points(np.array([[lon, lat, 0.0]]), "EPSG:4326", "EPSG:32617")[0, :2]
    names = list(gps)
    (tmp_path / "gcps.csv").write_text("# crs: EPSG:32618\nname,x,y,z\n" + "".join(
        f"G{k},{x + dx:.3f},{y + dy:.3f},{alt - 100:.2f}\n" for k, (dx, dy) in enumerate([(-30, -30), (30, -30),
                                                                                         (30, 30), (-30, 30)])))
    (tmp_path / "gcps_observations.csv").write_text("name,image,px,py\n" + "".join(
        f"G{k},{n},{100 + 50 * k},{200 + 40 * k}\n" for k in range(4) for n in names))
    with pytest.raises(StageError, match=r"control points of the GCP file \S*gcps\.csv \(EPSG:32618\) land .*"
                                         r"EPSG:32617 coordinates"):
        check_inputs(images, Control(gcp_path=str(tmp_path / "gcps.csv")))


def test_align_images_refuses_swapped_positions_before_the_features_and_warns_duplicates(tmp_path, monkeypatch):
    """Align images with camera positions (they choose the pairs): latitude in the x column is refused before the
    features (was: aligned with the pairs of a South Pole block); a photo's row twice is warned in the log (was
    read silently); a file without a CRS line is not placed (Align images has no CRS to read it in)."""
    from core.align import stage as align_stage
    from core.align.options import AlignError, AlignOptions

    images, gps = _toledo(tmp_path)
    first = next(iter(gps))

    class Stop(Exception):
        pass

    def features(*_a, **_k):
        raise Stop()

    monkeypatch.setattr(align_stage, "extract_features", features)
    p = _toledo_positions(tmp_path, gps, "latlon.csv", "EPSG:4326", swap=True)
    with pytest.raises(AlignError, match=r"camera positions in \S*latlon\.csv \(EPSG:4326\) land .*latitude and "
                                         r"longitude look swapped"):
        align_stage.align(images, str(tmp_path / "ws"), AlignOptions(camera_positions=p))
    assert not (tmp_path / "ws" / "sfm").exists()
    lon, lat, alt = gps[first]
    dup = _toledo_positions(tmp_path, gps, "dup.csv", "EPSG:4326", extra=[f"{first},{lon:.8f},{lat:.8f},{alt:.2f}"])
    said = _Said()
    with pytest.raises(Stop):
        align_stage.align(images, str(tmp_path / "ws2"), AlignOptions(camera_positions=dup), said)
    assert any(first in w and "line" in w for w in said.warnings), said.warnings
    local = _toledo_positions(tmp_path, gps, "local.csv", None)  # UTM numbers, no CRS line: distances only
    with pytest.raises(Stop):
        align_stage.align(images, str(tmp_path / "ws3"), AlignOptions(camera_positions=local))


def test_orthorectify_image_refuses_gcps_far_from_the_photos_gps(tmp_path):
    """Orthorectify image with a GCP file of UTM 17N labelled 18N: refused naming the photo's EXIF GPS and the
    zone, before the resection (was: the resection's own complaint about the points' spread, nothing about where
    they are)."""
    import os

    from core.ortho.options import OrthoError, SingleImageOptions
    from core.ortho.single import orthorectify_image

    images, gps = _toledo(tmp_path, 1)
    name, (lon, lat, alt) = next(iter(gps.items()))
    x, y = transform_points(np.array([[lon, lat, 0.0]]), "EPSG:4326", "EPSG:32617")[0, :2]
    (tmp_path / "gcps.csv").write_text("# crs: EPSG:32618\nname,x,y,z\n" + "".join(
        f"G{k},{x + dx:.3f},{y + dy:.3f},{alt - 100:.2f}\n" for k, (dx, dy) in enumerate([(-30, -30), (30, -30),
                                                                                         (30, 30), (-30, 30)])))
    (tmp_path / "gcps_observations.csv").write_text("name,image,px,py\n" + "".join(
        f"G{k},{name},{px},{py}\n" for k, (px, py) in enumerate([(200, 700), (1000, 700), (1000, 200), (200, 200)])))
    out = tmp_path / "o.tif"
    with pytest.raises(OrthoError, match=r"control points of the GCP file \S*gcps\.csv \(EPSG:32618\) land [\d,]+ km "
                                         r"from the photo's EXIF GPS.*EPSG:32617 coordinates"):
        orthorectify_image(SingleImageOptions(os.path.join(images, name), str(out), None, gcps=str(tmp_path / "gcps.csv"),
                                              mode="planar", focal_px=700.0))
    assert not out.exists()
