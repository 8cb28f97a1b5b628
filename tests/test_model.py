"""The textured 3-D model (issue 50, core.model): the DSM's mesh against the true surface, the texture against the
true texture, the files read back, bad input refused before work.  A tiny synthetic scene with known truth: a
height field with a mound, a texture painted on the ground, three pinhole photos rendered by ray casting."""
from __future__ import annotations

import json
import os
import struct

import cv2
import numpy as np
import pytest

from core.geometry.camera import Intrinsics, Pose
from core.model.geometry import dsm_mesh, vertex_normals
from core.model.inputs import check_memory, check_output, median_tilt_deg, resolve_geometry
from core.model.options import ModelError, ModelOptions
from core.model.stage import stage
from core.model.texture import texture_mesh
from core.model.types import MeshPart, TexturedMesh
from core.model.writers import GLB_MAGIC, encode_image, glb_bytes, write_obj, write_ply
from core.ortho.cameras import OrthoCamera
from core.project.layout import Layout
from core.project.workspace import Workspace

ORIGIN = np.array([500000.0, 4600000.0, 100.0])  # UTM-sized: float32 would lose the millimetres without it
CELL = 0.1  # m, the DSM's
W, H, F = 360, 270, 330.0  # photos: px and focal (GSD about 0.085 m at 28 m)
ALT = 28.0


def true_z(x, y):
    """Local heights: a gentle swell and a mound 2 m high."""
    return 0.4 * np.sin(x / 3.0) * np.cos(y / 4.0) + 2.0 * np.exp(-((x - 2.0) ** 2 + (y + 1.0) ** 2) / 8.0)


def true_texture(x, y):
    """Grey levels painted on the ground (features of 1 m and more: a dozen GSD)."""
    return 128 + 60 * np.sin(x * 1.3) * np.cos(y * 1.1) + 50 * np.sign(np.sin(x * 0.7 + y * 0.4))


def _camera(centre, tilt_deg: float) -> OrthoCamera:
    t = np.radians(tilt_deg)
    # camera x east, y south (image rows go down), z down and tilted towards +x by t
    rot = np.array([[np.cos(t), 0.0, np.sin(t)], [0.0, -1.0, 0.0], [np.sin(t), 0.0, -np.cos(t)]])
    return OrthoCamera("p.png", "", Intrinsics.simple(W, H, F), Pose.from_centre(rot, centre))


def _render(cam: OrthoCamera) -> np.ndarray:
    """The photo: each pixel's ray cast on the height field (fixed-point iterations from above)."""
    u, v = np.meshgrid(np.arange(W) + 0.5, np.arange(H) + 0.5)
    d_cam = np.stack([(u - W / 2) / F, (v - H / 2) / F, np.ones_like(u)], axis=-1).reshape(-1, 3)
    d = d_cam @ cam.pose.rotation  # to the local frame (R^T d)
    c = cam.centre
    z = np.zeros(len(d))
    for _ in range(30):
        s = (c[2] - z) / -d[:, 2]
        x, y = c[0] + s * d[:, 0], c[1] + s * d[:, 1]
        z = true_z(x, y)
    g = np.clip(true_texture(x, y), 0, 255).reshape(H, W).astype(np.uint8)
    return np.repeat(g[:, :, None], 3, axis=2)


@pytest.fixture(scope="module")
def scene():
    xs = np.arange(-10, 10, CELL) + CELL / 2
    ys = np.arange(8, -8, -CELL) - CELL / 2
    gx, gy = np.meshgrid(xs, ys)
    z = true_z(gx, gy) + ORIGIN[2]
    z[70:80, 20:35] = np.nan  # a hole in the DSM
    gt = (ORIGIN[0] - 10.0, CELL, 0.0, ORIGIN[1] + 8.0, 0.0, -CELL)
    verts, faces, _step = dsm_mesh(z, gt, ORIGIN, 6000)
    cams = [_camera((-3.0, 0.0, ALT), 0.0), _camera((4.0, 1.0, ALT), 0.0), _camera((-12.0, -1.0, ALT), 20.0)]
    photos = {id(c): _render(c) for c in cams}
    tex = texture_mesh(verts, faces, vertex_normals(verts, faces), cams, 1024, 2,
                       reader=lambda c: photos[id(c)])
    return verts, faces, tex


def test_mesh_matches_the_surface_within_the_budget(scene):
    verts, faces, _tex = scene
    assert 0 < len(faces) <= 6000
    # the mesh at its face centres and edge midpoints against the true surface: RMSE <= 1 GSD
    pts = np.concatenate([verts[faces].mean(axis=1), 0.5 * (verts[faces[:, 0]] + verts[faces[:, 1]])])
    rmse = float(np.sqrt(np.mean((pts[:, 2] - true_z(pts[:, 0], pts[:, 1])) ** 2)))
    assert rmse <= ALT / F, rmse
    # no face over the DSM's hole (cells 70..79 x 20..34: x -8.0 .. -6.5, y 1.0 .. 0.0)
    c = verts[faces].mean(axis=1)
    inside = (c[:, 0] > -7.8) & (c[:, 0] < -6.7) & (c[:, 1] < 0.8) & (c[:, 1] > 0.2)
    assert not inside.any()
    # counter-clockwise seen from above: normals up
    n = np.cross(verts[faces[:, 1]] - verts[faces[:, 0]], verts[faces[:, 2]] - verts[faces[:, 0]])
    assert (n[:, 2] > 0).all()


def test_without_the_decimation_library_a_coarser_grid_meets_the_budget():
    xs, ys = np.arange(0, 20, CELL) + CELL / 2, np.arange(0, -16, -CELL) - CELL / 2
    gx, gy = np.meshgrid(xs, ys)
    z = true_z(gx, gy)
    verts, faces, step = dsm_mesh(z, (0.0, CELL, 0.0, 0.0, 0.0, -CELL), np.zeros(3), 6000, cap=0)
    assert step > 1 and 3000 < len(faces) <= 6000
    c = verts[faces].mean(axis=1)
    assert np.sqrt(np.mean((c[:, 2] - true_z(c[:, 0], c[:, 1])) ** 2)) <= ALT / F


def _bilinear(img, u, v):
    return cv2.remap(img.astype(np.float32), (u * img.shape[1] - 0.5).astype(np.float32),
                     (v * img.shape[0] - 0.5).astype(np.float32), cv2.INTER_LINEAR)


def test_texture_matches_the_true_texture(scene):
    verts, faces, tex = scene
    assert tex.seen_faces / len(faces) > 0.9, tex.seen_faces
    got, want = [], []
    for p in tex.parts:
        if p.atlas is None:
            continue
        assert p.uv.min() >= 0 and p.uv.max() <= 1
        assert p.atlas.shape[0] <= 1024 and p.atlas.shape[1] <= 1024
        for w in ((1 / 3, 1 / 3, 1 / 3), (0.6, 0.2, 0.2), (0.2, 0.2, 0.6)):  # samples inside each face
            uv = np.einsum("k,fkc->fc", np.array(w), p.uv[p.faces])
            xyz = np.einsum("k,fkc->fc", np.array(w), p.vertices[p.faces].astype(np.float64))
            got.append(_bilinear(p.atlas[:, :, 0], uv[:, 0], uv[:, 1]).ravel())
            want.append(true_texture(xyz[:, 0], xyz[:, 1]))
    got, want = np.concatenate(got), np.concatenate(want)
    ncc = float(np.corrcoef(got, want)[0, 1])
    assert ncc >= 0.9, ncc
    assert tex.textured_faces >= tex.seen_faces


def _mesh(scene) -> TexturedMesh:
    _verts, _faces, tex = scene
    return TexturedMesh(ORIGIN.copy(), tex.parts, crs_wkt="PROJCS[...]", crs_name="EPSG:32633")


def test_obj_and_ply_read_back_in_world_coordinates(scene, tmp_path):
    mesh = _mesh(scene)
    images = [encode_image(p.atlas) if p.atlas is not None else None for p in mesh.parts]
    files = write_obj(mesh, str(tmp_path / "m.obj"), images)
    assert {os.path.basename(f) for f in files} >= {"m.obj", "m.mtl", "m_0.jpg"}
    text = (tmp_path / "m.obj").read_text()
    origin = next(np.array(line.split()[2:5], float) for line in text.splitlines() if line.startswith("# origin"))
    v = np.array([line.split()[1:4] for line in text.splitlines() if line.startswith("v ")], float)
    world = np.concatenate([mesh.world_vertices(p) for p in mesh.parts])
    assert np.abs(v + origin - world).max() < 1e-3
    assert sum(1 for line in text.splitlines() if line.startswith("f ")) == mesh.face_count
    write_ply(mesh, str(tmp_path / "m.ply"))
    raw = (tmp_path / "m.ply").read_bytes()
    head, body = raw.split(b"end_header\n", 1)
    nv = int(next(x for x in head.split(b"\n") if x.startswith(b"element vertex")).split()[2])
    pv = np.frombuffer(body[:nv * 24], "<f8").reshape(-1, 3)
    assert abs(pv[:, 0].mean() - world[:, 0].mean()) < 1.0 and pv[:, 1].min() == pytest.approx(world[:, 1].min())


def test_glb_parses_back(scene):
    mesh = _mesh(scene)
    b = glb_bytes(mesh.parts, extras={"origin": mesh.origin.tolist()})
    magic, version, total = struct.unpack_from("<III", b, 0)
    assert (magic, version, total) == (GLB_MAGIC, 2, len(b))
    jlen, jtype = struct.unpack_from("<II", b, 12)
    doc = json.loads(b[20:20 + jlen])
    blen, btype = struct.unpack_from("<II", b, 20 + jlen)
    assert jtype == 0x4E4F534A and btype == 0x004E4942 and doc["buffers"][0]["byteLength"] == blen
    prims = doc["meshes"][0]["primitives"]
    assert len(prims) == len(mesh.parts)
    for p, part in zip(prims, mesh.parts):
        pos = doc["accessors"][p["attributes"]["POSITION"]]
        assert pos["count"] == len(part.vertices)
        assert doc["accessors"][p["indices"]]["count"] == 3 * len(part.faces)
        v = part.vertices
        # glTF is y-up: (x, y, z) -> (x, z, -y)
        assert pos["min"] == pytest.approx([v[:, 0].min(), v[:, 2].min(), -v[:, 1].max()], abs=1e-5)
        assert pos["max"] == pytest.approx([v[:, 0].max(), v[:, 2].max(), -v[:, 1].min()], abs=1e-5)
        view = doc["bufferViews"][pos["bufferView"]]
        assert view["byteOffset"] % 4 == 0
    assert doc["asset"]["version"] == "2.0" and doc["asset"]["extras"]["origin"] == mesh.origin.tolist()


def test_bad_input_refused_before_work(tmp_path):
    with pytest.raises(ModelError, match="face budget"):
        ModelOptions(face_budget=0)
    with pytest.raises(ModelError, match="atlas size"):
        ModelOptions(atlas_size=3000)
    ws = Workspace.create_or_open(str(tmp_path / "ws"))
    with pytest.raises(ModelError, match="no DSM: run 'Build DSM' first"):
        stage(ws.root)
    lay = Layout(ws)
    dsm = os.path.join(ws.root, "dsm.tif")
    with pytest.raises(ModelError, match="would replace"):
        check_output(ws.root, lay, [dsm])
    with pytest.raises(ModelError, match="would replace"):
        check_output(str(tmp_path), lay, [dsm])
    other = tmp_path / "notes"
    other.mkdir()
    (other / "keep.txt").write_text("x")
    with pytest.raises(ModelError, match="not a model's folder"):
        check_output(str(other), lay, [dsm])
    check_output(str(tmp_path / "new"), lay, [dsm])  # a new folder is fine
    with pytest.raises(ModelError, match="smaller atlas size"):
        check_memory(ModelOptions(max_atlases=10 ** 6), 1000, 10 ** 6)


def test_geometry_from_the_cameras_tilt():
    vertical = [_camera((0.0, 0.0, 20.0), 0.0), _camera((5.0, 0.0, 20.0), 5.0)]
    oblique = [_camera((0.0, 0.0, 20.0), 40.0), _camera((5.0, 0.0, 20.0), 35.0)]
    assert median_tilt_deg(vertical) == pytest.approx(2.5)
    assert resolve_geometry(ModelOptions(), vertical) == ("dsm", [])
    geometry, notes = resolve_geometry(ModelOptions(), oblique)
    assert geometry == "dsm" and "oblique" in notes[0]
    with pytest.raises(ModelError, match="not available yet"):
        resolve_geometry(ModelOptions(geometry="points"), oblique)


def test_a_grey_part_holds_the_faces_no_photo_sees():
    verts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [50, 50, 0], [51, 50, 0], [50, 51, 0]], float)
    faces = np.array([[0, 1, 2], [3, 4, 5]])
    cam = _camera((0.3, 0.3, 10.0), 0.0)
    img = np.full((H, W, 3), 200, np.uint8)
    tex = texture_mesh(verts, faces, None, [cam], 256, 1, reader=lambda c: img)
    assert tex.seen_faces == 1 and tex.textured_faces == 1
    grey = [p for p in tex.parts if p.atlas is None]
    assert len(grey) == 1 and len(grey[0].faces) == 1 and grey[0].uv is None
    assert isinstance(tex.parts[0], MeshPart) and tex.parts[0].atlas[..., 0].max() == 200


def test_a_face_hidden_under_another_is_not_textured_from_that_photo():
    """The depth buffer: a square 5 m above another of the same footprint hides it from a photo overhead."""
    xs, ys = np.meshgrid(np.linspace(0, 2, 9), np.linspace(0, 2, 9))
    grid = np.column_stack([xs.ravel(), ys.ravel()])
    quads = [(r * 9 + c, r * 9 + c + 1, (r + 1) * 9 + c) for r in range(8) for c in range(8)]
    quads += [(r * 9 + c + 1, (r + 1) * 9 + c + 1, (r + 1) * 9 + c) for r in range(8) for c in range(8)]
    low = np.column_stack([grid, np.zeros(81)])
    high = np.column_stack([grid, np.full(81, 5.0)])
    verts = np.concatenate([low, high])
    faces = np.concatenate([np.array(quads), np.array(quads) + 81])
    img = np.full((H, W, 3), 90, np.uint8)
    tex = texture_mesh(verts, faces, None, [_camera((1.0, 1.0, 20.0), 0.0)], 256, 1, reader=lambda c: img)
    assert (tex.labels[:128] == -1).all() and (tex.labels[128:] == 0).all()


def test_the_orthophotos_radiometric_correction_applies_to_the_photos():
    """The vignetting the orthophoto removed (a fitted fall-off exp(-0.5 r^2)) is removed from the texture's photos
    too: x 1 at the principal point, x exp(0.5) in a corner; a photo the mosaic did not take stays as it is."""
    from core.model.texture import corrected_reader
    from core.ortho.radiometry import RadiometryModel
    from core.ortho.radiometry_record import photo_correction, radiometry_record

    model = RadiometryModel(groups=[0], falloff=[[-0.5, 0.0, 0.0]], hot=[0.0], antisolar=[0.0, 0.0, -1.0],
                            hot_width=0.1, exposure=[0.0], fields=[[0.0]])
    record = json.loads(json.dumps(radiometry_record(["p.png"], {"p.png": 1.0}, model)))
    cam = _camera((0.0, 0.0, 20.0), 0.0)
    f = photo_correction(record)(cam, np.array([[W / 2, H / 2], [0.0, 0.0]]))
    assert f == pytest.approx([1.0, np.exp(0.5)], rel=1e-4)
    img = np.full((H, W, 3), 100, np.uint8)
    out = corrected_reader(lambda c: img, photo_correction(record))(cam)
    assert out[H // 2, W // 2, 0] == 100 and out[1, 1, 0] == pytest.approx(100 * np.exp(0.5), abs=3)
    gains = photo_correction(radiometry_record(["q.png"], {"q.png": 2.0}, None))
    assert gains(cam, np.array([[1.0, 1.0]]))[0] == 1.0  # p.png: not in the mosaic


@pytest.fixture(scope="module")
def workspace(tmp_path_factory):
    """A georeferenced workspace of the scene made by hand: the model (three photos), its frame, the DSM."""
    import pycolmap

    from core.io.raster import write_cog
    from core.project.stages import DONE, GEOREFERENCE

    root = tmp_path_factory.mktemp("model ws")
    photos = root / "photos"
    photos.mkdir()
    ws = Workspace.create_or_open(str(root / "ws"))
    ws.data["images_dir"] = str(photos)
    ws.crs = "EPSG:32633"
    ws.begin_stage(GEOREFERENCE, {})
    ws.end_stage(GEOREFERENCE, DONE)
    lay = Layout(ws)
    rec = pycolmap.Reconstruction()
    rec.add_camera_with_trivial_rig(pycolmap.Camera.create_from_model_name(1, "PINHOLE", F, W, H))
    rec.cameras[1].params = np.array([F, F, W / 2, H / 2])
    for k, (centre, tilt) in enumerate((((-3.0, 0.0, ALT), 0.0), ((4.0, 1.0, ALT), 0.0)), start=1):
        cam = _camera(centre, tilt)
        cv2.imwrite(str(photos / f"P{k}.png"), _render(cam))
        im = pycolmap.Image(name=f"P{k}.png", keypoints=np.zeros((0, 2)), camera_id=1, image_id=k)
        rec.add_image_with_trivial_frame(im, pycolmap.Rigid3d(pycolmap.Rotation3d(cam.pose.rotation),
                                                              cam.pose.translation))
    os.makedirs(lay.georef_model_dir)
    rec.write_binary(lay.georef_model_dir)
    with open(lay.transform_json, "w") as f:
        json.dump({"crs": "EPSG:32633", "offset": ORIGIN.tolist()}, f)
    xs = np.arange(-10, 10, 0.2) + 0.1
    ys = np.arange(8, -8, -0.2) - 0.1
    gx, gy = np.meshgrid(xs, ys)
    write_cog(os.path.join(ws.root, "dsm.tif"), (true_z(gx, gy) + ORIGIN[2]).astype(np.float32),
              (ORIGIN[0] - 10.0, 0.2, 0.0, ORIGIN[1] + 8.0, 0.0, -0.2), "EPSG:32633")
    return ws.root


class _CancelAt:
    def __init__(self, after: int):
        self.left = after

    def report(self, fraction, message=""):
        pass

    def info(self, message):
        pass

    warning = info

    def is_cancelled(self):
        self.left -= 1
        return self.left < 0


def test_the_stage_writes_records_and_keeps_the_old_model_when_cancelled(workspace):
    from core.common.progress import Cancelled
    from core.project.stages import CANCELLED, DONE, MODEL

    r = stage(workspace, ModelOptions(face_budget=3000, atlas_size=1024))
    names = {os.path.basename(f) for f in r.files}
    assert names >= {"model.obj", "model.mtl", "model_0.jpg", "model.glb", "model.ply", "model.json", "model.prj"}
    assert 0 < r.faces <= 3000 and r.textured_faces == r.faces
    rec = Workspace.open(workspace).stage(MODEL)
    assert rec["status"] == DONE and rec["outputs"]["folder"] == "model3d" and rec["results"]["faces"] == r.faces
    side = json.load(open(os.path.join(r.folder, "model.json")))
    assert side["origin"] == ORIGIN.tolist() and side["crs"] == "EPSG:32633" and not side["model_frame"]
    before = open(os.path.join(r.folder, "model.glb"), "rb").read()
    with pytest.raises(Cancelled):
        stage(workspace, ModelOptions(face_budget=2000, atlas_size=1024), _CancelAt(2))
    assert Workspace.open(workspace).stage(MODEL)["status"] == CANCELLED
    assert open(os.path.join(r.folder, "model.glb"), "rb").read() == before  # the previous model, whole
    assert sorted(os.listdir(os.path.dirname(r.folder))).count("model3d") == 1
    assert not [n for n in os.listdir(os.path.dirname(r.folder)) if "model3d" in n and n != "model3d"]


def test_masked_pixels_texture_nothing(tmp_path):
    """A mask (the boom, the sky) hides the left half of the photo: the faces seen there are not textured from it."""
    xs, ys = np.meshgrid(np.linspace(-4, 4, 9), np.linspace(-3, 3, 7))
    verts = np.column_stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)])
    quads = [(r * 9 + c, r * 9 + c + 1, (r + 1) * 9 + c) for r in range(6) for c in range(8)]
    faces = np.array(quads)
    mask = np.full((H, W), 255, np.uint8)
    mask[:, : W // 2] = 0
    cv2.imwrite(str(tmp_path / "m.png"), mask)
    cam = _camera((0.0, 0.0, 20.0), 0.0)
    cam.mask_path = str(tmp_path / "m.png")
    tex = texture_mesh(verts, faces, None, [cam], 256, 1, reader=lambda c: np.full((H, W, 3), 50, np.uint8))
    centre_x = verts[faces].mean(axis=1)[:, 0]
    seen = tex.labels >= 0
    assert seen[centre_x > 0.5].all() and not seen[centre_x < -0.5].any()  # nor filled from the masked pixels
