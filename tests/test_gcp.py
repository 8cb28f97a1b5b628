"""Ground-control readers/writers, validation, CRS helpers (core/gcp.py).  No QGIS needed."""
import math
import os
import warnings

import numpy as np
import pytest

from core.geometry import crs as crsmod
from core.geometry.crs import check_coordinates_match_crs, crs_is_geographic, transform_points, utm_epsg_for_lonlat
from core.io.gcp import (
    CHECK,
    CONTROL,
    GCPError,
    GCPSet,
    GroundPoint,
    Observation,
    apply_check_points,
    check_units,
    gcps_from_rows,
    read_camera_positions,
    read_csv_gcps,
    read_gcps,
    write_csv_gcps,
    write_gcps,
    write_odm_gcp_list,
)

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "data", "gcp")
TOLEDO = os.path.join(DATA, "toledo_gcp_list.txt")
COPR = os.path.join(DATA, "copr_gcp_list.txt")
TOLEDO_IMAGES = ([f"1JI_{i:04d}.JPG" for i in list(range(64, 69)) + list(range(76, 81))]
                 + [f"DJI_{i:04d}.JPG" for i in range(61, 108)])
COPR_IMAGES = [f"IMG_{i:04d}.jpg" for i in (22, 25, 28, 31, 34, 37, 43, 46, 49, 52, 55, 58, 61, 64, 67, 70,
                                             73, 76, 79, 82, 85, 88, 91, 94, 97, 100, 103, 106, 109, 112, 115,
                                             118, 121, 127, 130, 133, 136, 139, 142, 145, 148)]

try:
    from osgeo import osr  # noqa: F401
    HAVE_OSR = True
except ImportError:
    HAVE_OSR = False
try:
    import pyproj
except ImportError:
    pyproj = None
needs_crs_lib = pytest.mark.skipif(not HAVE_OSR and pyproj is None, reason="needs GDAL (osgeo) or pyproj")


def write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return str(p)


def warns(gs):
    """The warnings, less the one saying the CRS could not be validated (when no CRS library is installed)."""
    return [w for w in gs.warnings if "not validated" not in w]


def obs_key(gs):
    return sorted((p.name, o.image, o.x, o.y) for p in gs.points for o in p.observations)


# ------------------------------------------------------------------ real files

def test_toledo_gcp_list():
    gs = read_gcps(TOLEDO)
    assert gs.crs == "+proj=utm +zone=17 +north +ellps=WGS84 +datum=WGS84 +units=m +no_defs"
    assert len(gs.points) == 5
    assert gs.n_observations() == 18
    # the name-less (old format) group is the 2nd point in file order
    assert [p.name for p in gs.points] == ["HV01", "gcp_2", "HV03", "HV04", "HV05"]
    assert [len(p.observations) for p in gs.points] == [3, 4, 3, 5, 3]
    hv01 = gs.by_name("HV01")
    # the commented-out bad observation (1350.499 -1506.619 in 1JI_0076.JPG) is skipped
    assert [(o.image, o.x, o.y) for o in hv01.observations] == [
        ("DJI_0068.JPG", 614.838, 257.108), ("DJI_0104.JPG", 634.011, 15.655),
        ("1JI_0076.JPG", 675.25, 753.309)]
    g2 = gs.by_name("gcp_2")
    assert (g2.x, g2.y, g2.z) == (274915.887, 4603307.715, 400.0)
    assert g2.images() == ["DJI_0068.JPG", "DJI_0104.JPG", "DJI_0083.JPG", "1JI_0076.JPG"]
    assert all(p.role == CONTROL for p in gs.points)
    # the only warning tells where the generated name came from
    ws = warns(gs)
    assert len(ws) == 1 and "gcp_2" in ws[0] and "toledo_gcp_list.txt:14" in ws[0]


def test_toledo_with_block_images_and_sizes():
    sizes = {n: (1200, 900) for n in TOLEDO_IMAGES}
    gs = read_gcps(TOLEDO, image_names=TOLEDO_IMAGES, image_sizes=sizes)
    assert gs.n_observations() == 18
    assert not any("lies outside" in w for w in gs.warnings)


def test_copr_gcp_list():
    gs = read_gcps(COPR, image_names=COPR_IMAGES, image_sizes={n: (1200, 800) for n in COPR_IMAGES})
    assert gs.crs == "+proj=utm +zone=11 +ellps=WGS84 +datum=WGS84 +units=m +no_defs"  # trailing tab gone
    assert sorted(p.name for p in gs.points) == [f"gcp{i:02d}" for i in range(10)]
    assert gs.n_observations() == 27
    g0 = gs.by_name("gcp00")
    assert len(g0.observations) == 1 and g0.observations[0].image == "IMG_0031.jpg"
    assert (g0.x, g0.y, g0.z) == (235277.61, 3811190.36, 0.0)
    # gcp00 is kept, with a warning naming file, line and point
    assert len(warns(gs)) == 1
    w = warns(gs)[0]
    assert "copr_gcp_list.txt:25" in w and "gcp00" in w and "only 1 image" in w


def test_shared_copies_are_identical():
    from tests.conftest import shared

    for name, local in (("toledo", TOLEDO), ("copr", COPR)):
        with open(shared(name, "gcp_list.txt"), "rb") as a, open(local, "rb") as b:
            assert a.read() == b.read()


# ------------------------------------------------------------------ ODM format details

@needs_crs_lib
@pytest.mark.parametrize("header,expected", [
    ("EPSG:32617", "EPSG:32617"),
    ("EPSG:32617 \t ", "EPSG:32617"),
    ("32617", "EPSG:32617"),
    ("epsg : 32617", "EPSG:32617"),
    ("WGS84 UTM 17N", "EPSG:32617"),
    ("WGS84 UTM 11S", "EPSG:32711"),
])
def test_crs_header_forms(tmp_path, header, expected):
    p = write(tmp_path, "g.txt", f"{header}\n274914.7 4603349.0 400 10 20 a.jpg P1\n"
                                 "274914.7 4603349.0 400 11 21 b.jpg P1\n")
    assert read_gcps(p).crs == expected


@needs_crs_lib
def test_multiline_wkt_header(tmp_path):
    wkt = ('GEOGCS["WGS 84",\n  DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563]],\n'
           '  PRIMEM["Greenwich",0],\n  UNIT["degree",0.0174532925199433]]')
    p = write(tmp_path, "g.txt", f"{wkt}\n-83.5 41.6 200 10 20 a.jpg P1\n-83.5 41.6 200 11 21 b.jpg P1\n")
    gs = read_gcps(p)
    assert gs.crs.startswith('GEOGCS["WGS 84", DATUM[') and "\n" not in gs.crs
    assert gs.n_observations() == 2


@needs_crs_lib
@pytest.mark.parametrize("header", ["EPSG:999999", "+proj=utm +zone=99", "not a crs at all"])
def test_unknown_crs_is_an_error(tmp_path, header):
    p = write(tmp_path, "g.txt", f"# comment first\n\n{header}\n1 2 3 10 20 a.jpg P1\n")
    with pytest.raises(GCPError) as e:
        read_gcps(p)
    assert f"{p}:3:" in str(e.value) and "CRS" in str(e.value)


def test_crs_not_validated_without_a_crs_library(tmp_path, monkeypatch):
    monkeypatch.setattr(crsmod, "_osr", lambda: None)
    monkeypatch.setattr(crsmod, "_pyproj", lambda: None)
    p = write(tmp_path, "g.txt", "EPSG:999999\n1 2 3 10 20 a.jpg P1\n1 2 3 11 21 b.jpg P1\n")
    gs = read_gcps(p)
    assert gs.crs == "EPSG:999999"
    assert any("not validated" in w and f"{p}:1" in w for w in gs.warnings)


def test_observation_before_crs_line(tmp_path):
    p = write(tmp_path, "g.txt", "274914.738 4603349.014 400 614.838 257.108 DJI_0068.JPG HV01\n")
    with pytest.raises(GCPError, match=r"g\.txt:1: expected the CRS line"):
        read_gcps(p)


@pytest.mark.parametrize("line,what", [
    ("274914.738 4603349.0x14 400 614.838 257.108 a.jpg P1", "y is not a number: '4603349.0x14'"),
    ("274914.738 4603349.014 4OO 614.838 257.108 a.jpg P1", "z is not a number"),
    ("274914.738 4603349.014 400 614,838 257.108 a.jpg P1", "pixel x is not a number"),
    ("274914.738 4603349.014 400 614.838 nan a.jpg P1", "pixel y is not a finite number"),
    ("274914.738 4603349.014 400 614.838 257.108", "expected 'x y z px py image [name]', found 5 field(s)"),
])
def test_bad_lines_name_file_and_line(tmp_path, line, what):
    p = write(tmp_path, "g.txt", f"EPSG:32617\n# c\n274914.738 4603349.014 400 1 2 b.jpg P1\n\n{line}\n")
    with pytest.raises(GCPError) as e:
        read_gcps(p)
    assert str(e.value).startswith(f"{p}:5: ") and what in str(e.value)


def test_unknown_image(tmp_path):
    p = write(tmp_path, "g.txt", "EPSG:32617\n1000 2000 3 10 20 a.jpg P1\n1000 2000 3 11 21 zz.jpg P1\n")
    with pytest.raises(GCPError) as e:
        read_gcps(p, image_names=["a.jpg", "b.jpg"], unknown_images="error")
    assert "line 3: zz.jpg" in str(e.value) and str(p) in str(e.value)
    # the lenient mode drops it with a warning instead
    gs = read_gcps(p, image_names=["a.jpg", "b.jpg"], unknown_images="warn")
    assert gs.n_observations() == 1
    assert any(f"{p}:3" in w and "zz.jpg" in w for w in gs.warnings)


def test_image_names_match_by_basename_and_case(tmp_path):
    p = write(tmp_path, "g.txt", "EPSG:32617\n1000 2000 3 10 20 images/dji_0068.jpg P1\n"
                                 "1000 2000 3 11 21 DJI_0069.JPG P1\n")
    gs = read_gcps(p, image_names=["DJI_0068.JPG", "DJI_0069.JPG"])
    assert gs.by_name("P1").images() == ["DJI_0068.JPG", "DJI_0069.JPG"]


def test_duplicate_observation_keeps_first(tmp_path):
    p = write(tmp_path, "g.txt", "EPSG:32617\n1000 2000 3 10 20 a.jpg P1\n1000 2000 3 11 21 b.jpg P1\n"
                                 "1000 2000 3 99 99 a.jpg P1\n")
    gs = read_gcps(p)
    assert [(o.image, o.x) for o in gs.by_name("P1").observations] == [("a.jpg", 10.0), ("b.jpg", 11.0)]
    w = [w for w in gs.warnings if "duplicate observation" in w]
    assert len(w) == 1 and f"{p}:4" in w[0] and "line 2" in w[0] and "a.jpg" in w[0]


def test_observation_outside_image_is_dropped(tmp_path):
    # the Toledo file's commented-out bad observation, uncommented
    p = write(tmp_path, "g.txt", "EPSG:32617\n274914.738 4603349.014 400 614.838 257.108 DJI_0068.JPG HV01\n"
                                 "274914.738 4603349.014 400 1350.499 -1506.619 1JI_0076.JPG HV01\n"
                                 "274914.738 4603349.014 400 634.011 15.655 DJI_0104.JPG HV01\n"
                                 "274914.738 4603349.014 400 1200.0 900.0 DJI_0105.JPG HV01\n")
    sizes = {n: (1200, 900) for n in ("DJI_0068.JPG", "1JI_0076.JPG", "DJI_0104.JPG", "DJI_0105.JPG")}
    gs = read_gcps(p, image_sizes=sizes)
    assert gs.by_name("HV01").images() == ["DJI_0068.JPG", "DJI_0104.JPG", "DJI_0105.JPG"]  # edge is inside
    w = [w for w in gs.warnings if "lies outside" in w]
    assert len(w) == 1 and f"{p}:3" in w[0] and "1JI_0076.JPG" in w[0] and "HV01" in w[0]


def test_point_losing_observations_warns(tmp_path):
    p = write(tmp_path, "g.txt", "EPSG:32617\n1000 2000 3 10 20 a.jpg P1\n1000 2000 3 5000 21 b.jpg P1\n")
    gs = read_gcps(p, image_sizes={"a.jpg": (100, 100), "b.jpg": (100, 100)})
    assert len(gs.by_name("P1").observations) == 1
    assert any("P1" in w and "only 1 image" in w and f"{p}:2" in w for w in gs.warnings)


def test_same_name_different_coordinates(tmp_path):
    p = write(tmp_path, "g.txt", "EPSG:32617\n1000 2000 3 10 20 a.jpg P1\n1000 2000.5 3 11 21 b.jpg P1\n")
    with pytest.raises(GCPError, match=r"g\.txt:3: point P1 has coordinates .* on line 2"):
        read_gcps(p)


def test_nameless_lines_join_named_point_and_names_avoid_collisions(tmp_path):
    p = write(tmp_path, "g.txt", "EPSG:32617\n"
                                 "1000 2000 3 10 20 a.jpg P1\n"
                                 "1000 2000 3 11 21 b.jpg\n"         # same coordinates as P1: joins it
                                 "1500 2500 3 12 22 a.jpg\n"         # 2nd point, no name -> gcp_2 ...
                                 "1500 2500 3 13 23 b.jpg\n"
                                 "1700 2700 3 14 24 a.jpg gcp_2\n"   # ... but that name is taken
                                 "1700 2700 3 15 25 b.jpg gcp_2  # inline comment\n")
    gs = read_gcps(p)
    assert [(q.name, len(q.observations)) for q in gs.points] == [("P1", 2), ("gcp_2_2", 2), ("gcp_2", 2)]


def test_check_role_field_and_inline_comment(tmp_path):
    p = write(tmp_path, "g.txt", "EPSG:32617\n1000 2000 3 10 20 a.jpg P1 check\n"
                                 "1000 2000 3 11 21 b.jpg P1 #x y\n"
                                 "1100 2000 3 10 20 a.jpg P2 extra stuff\n1100 2000 3 10 20 b.jpg P2\n")
    gs = read_gcps(p)
    assert gs.by_name("P1").role == CHECK and gs.by_name("P2").role == CONTROL
    assert len(gs.by_name("P1").observations) == 2


def test_odm_round_trip(tmp_path):
    gs = read_gcps(TOLEDO)
    apply_check_points(gs, "HV03")
    out = str(tmp_path / "out.txt")
    write_odm_gcp_list(gs, out)
    back = read_gcps(out)
    assert back.crs == gs.crs
    assert [(p.name, p.x, p.y, p.z, p.role) for p in back.points] == [(p.name, p.x, p.y, p.z, p.role)
                                                                     for p in gs.points]
    assert obs_key(back) == obs_key(gs)
    assert warns(back) == []  # names are explicit now
    with open(out) as f:
        lines = f.read().splitlines()
    assert lines[0] == gs.crs
    assert lines[1].split("\t")[:7] == ["274914.738", "4603349.014", "400.0", "614.838", "257.108",
                                        "DJI_0068.JPG", "HV01"]
    # written twice: identical files
    out2 = str(tmp_path / "out2.txt")
    write_gcps(back, out2)
    with open(out2) as f:
        assert f.read().splitlines() == lines


def test_odm_writer_rejects_names_with_blanks(tmp_path):
    gs = GCPSet("EPSG:32617", [GroundPoint("P 1", 1000, 2000, 3, observations=[Observation("a.jpg", 1, 2)])])
    with pytest.raises(GCPError, match="P 1"):
        write_odm_gcp_list(gs, str(tmp_path / "x.txt"))


# ------------------------------------------------------------------ CSV

def test_csv_read_sigmas_roles_and_crs_comment(tmp_path):
    pts = write(tmp_path, "pts.csv", "# crs: EPSG:32617\n"
                                     "Name,X,Y,Z,sx,sy,sz,role\n"
                                     "A,274914.738,4603349.014,400,0.02,0.05,0.08,control\n"
                                     "B,274915.887,4603307.715,401.5,,,,check\n"
                                     "C,274985.284,4603319.756,402,0.03,,,\n")
    write(tmp_path, "pts_observations.csv", "name,image,px,py\nA,a.jpg,10.5,20\nA,b.jpg,11,21\nB,a.jpg,1,2\n"
                                            "B,b.jpg,3,4\nC,a.jpg,5,6\nC,b.jpg,7,8\n")
    gs = read_gcps(pts)
    assert gs.crs == "EPSG:32617"
    a, b, c = gs.points
    assert (a.sigma_xy, a.sigma_z, a.role) == (0.05, 0.08, CONTROL)  # max(sx, sy)
    assert (b.sigma_xy, b.sigma_z, b.role, b.z) == (0.02, 0.05, CHECK, 401.5)  # defaults
    assert (c.sigma_xy, c.role) == (0.03, CONTROL)
    assert [(o.image, o.x, o.y) for o in a.observations] == [("a.jpg", 10.5, 20.0), ("b.jpg", 11.0, 21.0)]
    assert warns(gs) == []


@needs_crs_lib
def test_csv_semicolon_crs_argument_and_round_trip(tmp_path):
    pts = write(tmp_path, "p.csv", "name;x;y;z;role\nA;274914.738;4603349.014;400;check\n"
                                   "B;274915.887;4603307.715;400;control\n")
    obs = write(tmp_path, "o.csv", "image;name;px;py\na.jpg;A;1.25;2\nb.jpg;A;3;4\na.jpg;B;5;6\n")
    gs = read_csv_gcps(pts, obs, crs="32617")
    assert gs.crs == "EPSG:32617"
    assert any("B" in w and "only 1 image" in w and f"{pts}:3" in w for w in gs.warnings)
    gs.points[0].sigma_xy, gs.points[0].sigma_z = 0.015, 0.03
    p2, o2 = write_csv_gcps(gs, str(tmp_path / "r.csv"))
    assert o2 == str(tmp_path / "r_observations.csv")
    back = read_gcps(p2)
    assert back.crs == gs.crs
    assert [(p.name, p.x, p.y, p.z, p.sigma_xy, p.sigma_z, p.role) for p in back.points] == \
           [(p.name, p.x, p.y, p.z, p.sigma_xy, p.sigma_z, p.role) for p in gs.points]
    assert obs_key(back) == obs_key(gs)
    # CSV -> ODM -> same observations
    write_gcps(back, str(tmp_path / "g.txt"))
    assert obs_key(read_gcps(str(tmp_path / "g.txt"))) == obs_key(gs)


@pytest.mark.parametrize("points,obs,msg", [
    ("name,x,y,z\nA,1000,2000,3\nA,1000,2000,3\n", None, ":4: point A already defined on line 3"),
    ("name,x,y,z,role\nA,1000,2000,3,maybe\n", None, ":3: unknown role 'maybe'"),
    ("name,x,y,z,sx\nA,1000,2000,3,-1\n", None, ":3: sigma sx must be positive"),
    ("name,x,y,z\nA,1000,2000,three\n", None, ":3: z is not a number: 'three'"),
    ("name,x,y\nA,1000,2000\n", None, ":2: expected a header row naming the columns name, x, y, z"),
    ("name,x,y,z\nA,1000,2000,3\n", "name,image,px,py\nB,a.jpg,1,2\n",
     "o.csv:2: observation of unknown point 'B'"),
    ("name,x,y,z\nA,1000,2000,3\n", "name,image,px,py\nA,a.jpg,1,2x\n", "o.csv:2: py is not a number"),
])
def test_csv_errors(tmp_path, points, obs, msg):
    # line 1 of the points file is the CRS comment
    p = write(tmp_path, "p.csv", "# crs: EPSG:32617\n" + points)
    o = write(tmp_path, "o.csv", obs or "name,image,px,py\n")
    with pytest.raises(GCPError) as e:
        read_csv_gcps(p, o)
    assert msg in str(e.value)


def test_csv_without_crs_or_observations(tmp_path):
    p = write(tmp_path, "p.csv", "name,x,y,z\nA,1000,2000,3\n")
    with pytest.raises(GCPError, match="no CRS"):
        read_gcps(p)
    gs = read_gcps(p, crs="EPSG:32617")
    assert any("no observations file" in w for w in gs.warnings)


# ------------------------------------------------------------------ rows (e.g. a QGIS point layer)

def test_gcps_from_rows():
    rows = [
        {"Name": "A", "x": 274914.738, "y": 4603349.014, "z": 400, "image": "a.jpg", "px": 10, "py": "20.5",
         "sx": 0.01, "sy": 0.03, "sz": None, "role": "check"},
        {"Name": "A", "x": 274914.738, "y": 4603349.014, "z": 400, "image": "b.jpg", "px": 11, "py": 21},
        {"Name": "B", "x": 274915.887, "y": 4603307.715, "z": 401, "image": "a.jpg", "px": 12, "py": 22},
        {"Name": "B", "x": 274915.887, "y": 4603307.715, "z": 401, "image": "a.jpg", "px": 13, "py": 23},
    ]
    gs = gcps_from_rows(rows, "EPSG:32617", source_name="gcps layer", image_sizes={"a.jpg": (100, 100)})
    a, b = gs.points
    assert (a.name, a.role, a.sigma_xy, a.sigma_z) == ("A", CHECK, 0.03, 0.05)
    assert [(o.image, o.x, o.y) for o in a.observations] == [("a.jpg", 10.0, 20.5), ("b.jpg", 11.0, 21.0)]
    assert (b.role, len(b.observations)) == (CONTROL, 1)
    dup = [w for w in gs.warnings if "duplicate observation" in w]
    assert len(dup) == 1 and "gcps layer: row 4" in dup[0] and "row 3" in dup[0]
    assert any("gcps layer: row 3" in w and "only 1 image" in w for w in gs.warnings)
    bad = [dict(rows[0]), dict(rows[1], y=4603349.5)]
    with pytest.raises(GCPError, match="gcps layer: row 2: point A has coordinates .* in row 1"):
        gcps_from_rows(bad, "EPSG:32617", source_name="gcps layer")
    with pytest.raises(GCPError, match="gcps layer: row 1: px is not a number"):
        gcps_from_rows([dict(rows[0], px="ten")], "EPSG:32617", source_name="gcps layer")
    with pytest.raises(GCPError, match=r"gcps layer: .*row 2: zz\.jpg"):
        gcps_from_rows([rows[0], dict(rows[1], image="zz.jpg")], "EPSG:32617", source_name="gcps layer",
                       image_names=["a.jpg", "b.jpg"], unknown_images="error")


@needs_crs_lib
def test_check_units():
    gs = GCPSet("EPSG:32617", [GroundPoint("A", -83.6989, 41.5494, 190.0)], source="mem")
    with pytest.raises(GCPError, match="mem: GCP coordinates look like degrees"):
        check_units(gs, "EPSG:32617")
    gs.crs = "EPSG:4326"
    check_units(gs, "EPSG:32617")  # checked against the CRS the points are in, not the target


# ------------------------------------------------------------------ check points, CRS and units

def test_apply_check_points():
    gs = read_gcps(COPR)
    apply_check_points(gs, " gcp03, gcp07 ,,")
    assert sorted(p.name for p in gs.check_points()) == ["gcp03", "gcp07"]
    assert len(gs.control_points()) == 8
    with pytest.raises(GCPError) as e:
        apply_check_points(gs, "gcp03,GCP99")
    assert "GCP99" in str(e.value) and "gcp00" in str(e.value) and "gcp09" in str(e.value)


def test_to_dict_round_trip():
    gs = read_gcps(TOLEDO)
    back = GCPSet.from_dict(gs.to_dict())
    assert back == gs


@needs_crs_lib
def test_crs_is_geographic():
    assert crs_is_geographic("EPSG:4326")
    assert crs_is_geographic("EPSG:4979")
    assert crs_is_geographic("+proj=longlat +datum=WGS84 +no_defs")
    assert not crs_is_geographic("EPSG:32617")
    assert not crs_is_geographic("+proj=utm +zone=11 +ellps=WGS84 +datum=WGS84 +units=m +no_defs")
    assert not crs_is_geographic("EPSG:4978")  # geocentric
    with pytest.raises(GCPError):
        crs_is_geographic("EPSG:999999")


@needs_crs_lib
def test_degrees_given_as_metres(tmp_path):
    p = write(tmp_path, "g.txt", "EPSG:32617\n-83.6989 41.5494 190 10 20 a.jpg P1\n"
                                 "-83.6989 41.5494 190 1 2 b.jpg P1\n"
                                 "-83.6980 41.5490 190 10 20 a.jpg P2\n")
    with pytest.raises(GCPError, match=r"g\.txt: GCP coordinates look like degrees .*EPSG:32617"):
        read_gcps(p)


@needs_crs_lib
def test_metres_given_as_degrees_and_swapped_axes(tmp_path):
    p = write(tmp_path, "g.txt", "EPSG:4326\n274914.738 4603349.014 400 10 20 a.jpg P1\n")
    with pytest.raises(GCPError, match="projected coordinates"):
        read_gcps(p)
    p = write(tmp_path, "h.txt", "EPSG:4326\n-33.86 151.21 40 10 20 a.jpg P1\n")  # Sydney, latitude first
    with pytest.raises(GCPError, match="swapped"):
        read_gcps(p)
    # correct degrees in a geographic CRS, and small local metric grids, pass
    check_coordinates_match_crs("EPSG:4326", [(-83.6989, 41.5494)])
    check_coordinates_match_crs("EPSG:32617", [(10.0, 20.0), (60.0, 80.0)])


# ------------------------------------------------------------------ camera positions

def test_toledo_camera_positions():
    crs, cams = read_camera_positions(os.path.join(HERE, "..", "sample", "toledo", "cameras_32617.txt"))
    assert crs == "EPSG:32617"
    c = {p.image: p for p in cams}
    assert (c["1JI_0064.JPG"].x, c["1JI_0064.JPG"].y) == (274901.848, 4603267.294)
    assert all(math.isnan(p.z) for p in cams)  # 'x y image' rows: height unknown
    assert all((p.sigma_xy, p.sigma_z) == (5.0, 10.0) for p in cams)


def test_shared_toledo_camera_positions():
    from tests.conftest import shared

    path = shared("toledo", "cameras_32617.txt")
    crs, cams = read_camera_positions(path, default_sigma_xy=3, default_sigma_z=6)
    assert crs == "EPSG:32617" and len(cams) == 57
    assert (cams[0].sigma_xy, cams[0].sigma_z) == (3, 6)


def test_camera_positions_csv_forms(tmp_path):
    p = write(tmp_path, "c.csv", "image,x,y,z,sigma\na.jpg,274901.8,4603267.3,122.5,2.5\n"
                                 "b.jpg,274902.8,4603268.3,123.5,\n")
    crs, cams = read_camera_positions(p)
    assert crs is None
    assert [(c.image, c.z, c.sigma_xy, c.sigma_z) for c in cams] == [("a.jpg", 122.5, 2.5, 2.5),
                                                                     ("b.jpg", 123.5, 5.0, 10.0)]
    p = write(tmp_path, "d.txt", "EPSG:32617\n# image x y z sigma_xy sigma_z\n"
                                 "a.jpg 274901.8 4603267.3 122.5 1 3\nb.jpg\t274902.8\t4603268.3\n"
                                 "274903.8 4603269.3 124 c.jpg\n")
    crs, cams = read_camera_positions(p, crs="EPSG:4326")  # the file's own CRS wins
    assert crs == "EPSG:32617"
    assert [(c.image, c.sigma_xy, c.sigma_z) for c in cams] == [("a.jpg", 1.0, 3.0), ("b.jpg", 5.0, 10.0),
                                                                ("c.jpg", 5.0, 10.0)]
    assert math.isnan(cams[1].z) and cams[2].z == 124.0


def test_camera_positions_errors_and_duplicates(tmp_path):
    p = write(tmp_path, "c.txt", "a.jpg 1000 2000 100\na.jpg 1001 2001 101\n")
    ws = []
    _, cams = read_camera_positions(p, warnings=ws)
    assert len(cams) == 1 and cams[0].x == 1000 and any("lines 1 and 2" in w and "a.jpg" in w for w in ws)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        read_camera_positions(p)
    assert any("a.jpg" in str(r.message) for r in rec)
    p = write(tmp_path, "e.txt", "a.jpg 1000 20o0 100\n")
    with pytest.raises(GCPError, match=r"e\.txt:1: not a number: '20o0'"):
        read_camera_positions(p)
    p = write(tmp_path, "f.txt", "image,x,y,z\na.jpg,1000,2000,-\n")
    with pytest.raises(GCPError, match=r"f\.txt:2: z is not a number"):
        read_camera_positions(p)


def test_camera_positions_duplicate_rows_name_the_image_and_lines(tmp_path):
    """Issue 47 item 17: an image on two rows that agree within their sigmas is warned naming the image, both
    lines and the one used; rows farther apart than their sigmas are refused, naming the same."""
    p = write(tmp_path, "same.csv", "EPSG:32617\nimage,x,y,z,sigma\na.jpg,274901.8,4603267.3,122,5\n"
                                    "b.jpg,274911.8,4603267.3,122,5\na.jpg,274902.8,4603267.3,122,5\n")
    said = []
    _, cams = read_camera_positions(p, warnings=said)
    assert [c.image for c in cams] == ["a.jpg", "b.jpg"] and cams[0].x == 274901.8
    assert len(said) == 1 and "a.jpg" in said[0] and "lines 3 and 5" in said[0] and "line 3) is used" in said[0]
    p = write(tmp_path, "apart.csv", "EPSG:32617\nimage,x,y,z,sigma\na.jpg,274901.8,4603267.3,122,5\n"
                                     "b.jpg,274911.8,4603267.3,122,5\na.jpg,275101.8,4603267.3,122,5\n")
    with pytest.raises(GCPError, match=r"apart\.csv: image a\.jpg is on lines 3 and 5 .*200\.00 m apart.*sigmas"):
        read_camera_positions(p)


def test_camera_positions_with_semicolons_and_decimal_commas(tmp_path):
    """Issue 47 item 11: a spreadsheet's export (';' separators, decimal commas) is read; a file that mixes the
    separators names them."""
    p = write(tmp_path, "excel.csv", "EPSG:32617\nimage;x;y;z;sigma\n1JI_0064.JPG;274901,848;4603267,294;122,3;2,5\n"
                                     "1JI_0065.JPG;274901,230;4603277,193;122;2\n")
    crs, cams = read_camera_positions(p)
    assert crs == "EPSG:32617"
    assert [(c.image, c.x, c.y, c.z, c.sigma_xy) for c in cams] == [
        ("1JI_0064.JPG", 274901.848, 4603267.294, 122.3, 2.5), ("1JI_0065.JPG", 274901.23, 4603277.193, 122.0, 2.0)]
    p = write(tmp_path, "tabs.txt", "1JI_0064.JPG\t274901,848\t4603267,294\n1JI_0065.JPG\t274901,230\t4603277,193\n")
    _, cams = read_camera_positions(p, crs="EPSG:32617")
    assert [(c.x, c.y) for c in cams] == [(274901.848, 4603267.294), (274901.23, 4603277.193)]
    p = write(tmp_path, "mixed.csv", "image,x,y,z\n1JI_0064.JPG;274901,848;4603267,294;122,3\n"
                                     "1JI_0065.JPG,274901.2,4603277.1,122\n")
    with pytest.raises(GCPError, match=r"mixed\.csv:2: .*'848;4603267'.*';'.*separat"):
        read_camera_positions(p)


def test_gcp_csv_with_semicolons_and_decimal_commas(tmp_path):
    """The same spreadsheet export for a GCP CSV pair: decimal commas read where ';' separates."""
    pts = write(tmp_path, "pts.csv", "# crs: EPSG:32617\nname;x;y;z;sigma_xy;sigma_z\nA;274901,848;4603267,294;180,5;0,02;0,05\n")
    write(tmp_path, "pts_observations.csv", "name;image;px;py\nA;a.jpg;100,5;200,25\n")
    gs = read_gcps(pts)
    a = gs.by_name("A")
    assert (a.x, a.y, a.z, a.sigma_xy, a.sigma_z) == (274901.848, 4603267.294, 180.5, 0.02, 0.05)
    assert (a.observations[0].x, a.observations[0].y) == (100.5, 200.25)


# ------------------------------------------------------------------ transformations

def _utm_kruger(lon, lat, zone):
    """Independent reference: Kruger's n-series for the Transverse Mercator (Karney 2011, to n^4, ~0.1 mm),
    WGS 84, UTM scale 0.9996, false easting 500 km, northern hemisphere."""
    a, f, k0 = 6378137.0, 1 / 298.257223563, 0.9996
    n = f / (2 - f)
    big_a = a / (1 + n) * (1 + n ** 2 / 4 + n ** 4 / 64)
    alpha = [n / 2 - 2 * n ** 2 / 3 + 5 * n ** 3 / 16 + 41 * n ** 4 / 180,
             13 * n ** 2 / 48 - 3 * n ** 3 / 5 + 557 * n ** 4 / 1440,
             61 * n ** 3 / 240 - 103 * n ** 4 / 140, 49561 * n ** 4 / 161280]
    e = math.sqrt(f * (2 - f))
    phi, lam = math.radians(lat), math.radians(lon - (6 * zone - 183))
    t = math.sinh(math.atanh(math.sin(phi)) - e * math.atanh(e * math.sin(phi)))
    xi, eta = math.atan2(t, math.cos(lam)), math.atanh(math.sin(lam) / math.sqrt(1 + t * t))
    east = eta + sum(al * math.cos(2 * j * xi) * math.sinh(2 * j * eta) for j, al in enumerate(alpha, 1))
    north = xi + sum(al * math.sin(2 * j * xi) * math.cosh(2 * j * eta) for j, al in enumerate(alpha, 1))
    return 500000 + k0 * big_a * east, k0 * big_a * north


@needs_crs_lib
def test_transform_lonlat_to_utm_17n():
    out = transform_points([[-83.5, 41.6, 100.0]], "EPSG:4979", "EPSG:32617")
    # hard-coded from the Kruger series above (which agrees with pyproj to 0.1 mm)
    assert out.shape == (1, 3)
    assert out[0, 0] == pytest.approx(291656.4256, abs=0.002)
    assert out[0, 1] == pytest.approx(4608385.0349, abs=0.002)
    assert out[0, 2] == pytest.approx(100.0, abs=1e-6)  # ellipsoidal height passes through to a 2-D target
    ex, ny = _utm_kruger(-83.5, 41.6, 17)
    assert (out[0, 0], out[0, 1]) == pytest.approx((ex, ny), abs=0.002)


@needs_crs_lib
def test_transform_toledo_exif_gps_lands_on_camera_file():
    # EXIF of 1JI_0064.JPG: 41 deg 32' 57.8681" N, 83 deg 41' 56.1111" W, 122.3 m
    lat = 41 + 32 / 60 + 57.8681 / 3600
    lon = -(83 + 41 / 60 + 56.1111 / 3600)
    out = transform_points(np.array([[lon, lat, 122.3]]), "EPSG:4979", "EPSG:32617")
    # cameras_32617.txt: 274901.848 4603267.294 (rounded EXIF seconds account for a few cm)
    assert out[0, 0] == pytest.approx(274901.848, abs=0.1)
    assert out[0, 1] == pytest.approx(4603267.294, abs=0.1)
    assert (out[0, 0], out[0, 1]) == pytest.approx(_utm_kruger(lon, lat, 17), abs=0.002)


@needs_crs_lib
def test_transform_shapes_nan_height_and_round_trip():
    pts = np.array([[274901.848, 4603267.294, np.nan], [274914.738, 4603349.014, 400.0]])
    ll = transform_points(pts, "EPSG:32617", "EPSG:4326")
    assert math.isnan(ll[0, 2]) and ll[1, 2] == pytest.approx(400.0)
    assert ll[0, 0] == pytest.approx(-83.69892, abs=1e-5) and ll[0, 1] == pytest.approx(41.54941, abs=1e-5)
    back = transform_points(ll[:, :2], "EPSG:4326", "EPSG:32617")
    assert back.shape == (2, 2)
    assert back == pytest.approx(pts[:, :2], abs=1e-6)
    assert transform_points([-83.5, 41.6], "EPSG:4326", "EPSG:32617").shape == (2,)
    with pytest.raises(GCPError):
        transform_points([[0.0, 95.0]], "EPSG:4326", "EPSG:32617")
    with pytest.raises(GCPError):
        transform_points([[0.0, 0.0]], "EPSG:999999", "EPSG:32617")


@pytest.mark.skipif(pyproj is None or not HAVE_OSR, reason="needs pyproj and GDAL to compare")
def test_transform_agrees_with_pyproj():
    rng = np.random.default_rng(0)
    ll = np.column_stack([rng.uniform(-84, -78, 50), rng.uniform(0, 80, 50), rng.uniform(-50, 3000, 50)])
    ours = transform_points(ll, "EPSG:4979", "EPSG:32617")
    t = pyproj.Transformer.from_crs("EPSG:4979", "EPSG:32617", always_xy=True)
    ref = np.column_stack(t.transform(ll[:, 0], ll[:, 1], ll[:, 2]))
    assert np.max(np.abs(ours - ref)) < 1e-4


@pytest.mark.parametrize("lon,lat,epsg", [
    (-83.5, 41.6, 32617),      # Toledo
    (-119.88, 34.41, 32611),   # Coal Oil Point
    (151.2, -33.9, 32756),     # Sydney
    (0.0, 0.0, 32631),
    (-180.0, 10.0, 32601),
    (180.0, 10.0, 32601),      # 180 E is 180 W
    (179.99, -10.0, 32760),
    (5.0, 60.0, 32632),        # south-west Norway exception (32V)
    (2.0, 60.0, 32631),
    (10.0, 78.0, 32633),       # Svalbard exceptions
    (20.0, 78.0, 32633),
    (22.0, 78.0, 32635),
    (40.0, 78.0, 32637),
    (10.0, 86.0, 32661),       # UPS north
    (10.0, -85.0, 32761),      # UPS south
])
def test_utm_epsg_for_lonlat(lon, lat, epsg):
    assert utm_epsg_for_lonlat(lon, lat) == epsg


def test_utm_epsg_rejects_non_degrees():
    with pytest.raises(ValueError):
        utm_epsg_for_lonlat(274914.738, 4603349.014)
