"""The one way tests build a workspace from a synthetic block's truth, as if the earlier stages had run.

Every product goes where ``core.project.layout.Layout`` says and every stage record through
``core.project.stages.run_stage`` (the same epilogue the real stages use), so a test workspace cannot drift from
the real format.
"""
import os

from core.io.vector import write_cameras_gpkg
from core.project.layout import Layout, write_json
from core.project.stages import ALIGN, GEOREFERENCE, run_stage
from core.project.workspace import Workspace


def synthetic_workspace(root, block, rec, *, names=None, images_dir=None, photos=None, camera_groups=None,
                        georeferenced=False, crs=None, offset=None, align_parameters=None, alignment=None,
                        align_timings=None, align_results=None, cameras_gpkg=False):
    """A workspace at ``root`` holding ``rec`` (a pycolmap.Reconstruction, usually
    ``block.truth_reconstruction(...)``) and returning its path.

    - aligned only (default): ``rec`` is the aligned model in ``sfm/model``;
    - ``georeferenced=True``: ``rec`` is the georeferenced model (local frame) in ``georef/model`` with a
      transform of ``crs`` and ``offset`` (the local frame's origin), and both stages are done;
    - ``photos``: {name: path} of rendered photos (the image list then records their paths, as the aligner does),
      else the image list is ``names`` (default: all of the block's) at the block camera's size;
    - ``alignment``: the figures written to ``sfm/alignment.json``; ``align_timings`` {step: seconds} and
      ``align_results`` go into the align stage's record; ``cameras_gpkg`` writes ``cameras.gpkg``.
    """
    ws = Workspace.create_or_open(str(root))
    lay = Layout(ws)
    if photos is not None:
        ws.data["images_dir"] = os.path.dirname(next(iter(photos.values())))
        ws.data["images"] = [{"name": n, "path": p, "width": block.camera.width, "height": block.camera.height,
                              "gps": None} for n, p in photos.items()]
    else:
        ws.data["images_dir"] = images_dir
        ws.data["images"] = [{"name": n, "width": block.camera.width, "height": block.camera.height}
                             for n in (names or block.names)]
    if camera_groups is not None:
        ws.data["camera_groups"] = camera_groups
    outputs = {"model": "sfm/model"}
    with run_stage(ws, ALIGN, align_parameters or {"synthetic": True}) as run:
        folder = lay.georef_model_dir if georeferenced else lay.aligned_model_dir
        os.makedirs(folder, exist_ok=True)
        rec.write_binary(folder)
        if alignment is not None:
            write_json(lay.alignment_json, alignment)
        for step, seconds in (align_timings or {}).items():
            ws.record_timing(ALIGN, step, seconds)
        if cameras_gpkg:
            from core.align.mapping import camera_rows

            outputs["cameras"] = lay.rel(write_cameras_gpkg(ws.root, camera_rows(rec), crs=None))
        run.finish(outputs=outputs, results=align_results)
    if georeferenced:
        ws.crs = crs
        with run_stage(ws, GEOREFERENCE, {"synthetic": True}) as run:
            write_json(lay.transform_json, {"crs": crs, "offset": [float(v) for v in offset]})
            run.finish(outputs={"model": lay.rel(lay.georef_model_dir), "transform": lay.rel(lay.transform_json)})
    return ws.root


def set_exif_gps(root, positions, crs):
    """Record ``positions`` (core.io.gcp.CameraPosition in ``crs``) as the photos' EXIF GPS (lon, lat, height) in
    the workspace's image list, as the aligner records a photo's GPS; photos without a position keep theirs."""
    import numpy as np

    from core.geometry.crs import transform_points

    ws = Workspace.open(str(root))
    by_name = {c.image: c for c in positions}
    rows = [im for im in ws.data.get("images", []) if im["name"] in by_name]
    xyz = transform_points(np.array([[by_name[im["name"]].x, by_name[im["name"]].y, by_name[im["name"]].z]
                                     for im in rows], dtype=float), crs, "EPSG:4326")
    for im, p in zip(rows, xyz):
        im["gps"] = [float(p[0]), float(p[1]), float(p[2])]
    ws.save()
    return ws.root


def rendered_once(block, cache_dir):
    """``cache_dir``/images: the block's photos, rendered the first time and kept (a ``done`` file marks a complete
    rendering; an interrupted one is rendered again)."""
    import shutil

    images = os.path.join(cache_dir, "images")
    done = os.path.join(cache_dir, "done")
    if not os.path.exists(done):
        shutil.rmtree(images, ignore_errors=True)
        block.render(images)
        open(done, "w").close()
    return images


def write_flat_reference(folder, positions, crs, margin=100.0, gsd=1.0):
    """(orthophoto, DSM): a random-texture RGB orthophoto and a gently sloping DSM in ``crs`` over the box of
    ``positions`` (core.io.gcp.CameraPosition in ``crs``) plus ``margin``: a reference pair the automatic control
    opens and accepts, for the checks made before its matching (nothing in it matches the photos)."""
    import numpy as np
    from osgeo import gdal, osr

    xy = np.array([[c.x, c.y] for c in positions], dtype=float)
    x0, y0 = xy.min(axis=0) - margin
    x1, y1 = xy.max(axis=0) + margin
    w, h = int(np.ceil((x1 - x0) / gsd)), int(np.ceil((y1 - y0) / gsd))
    srs = osr.SpatialReference()
    srs.SetFromUserInput(crs)
    os.makedirs(str(folder), exist_ok=True)
    rng = np.random.default_rng(3)
    paths = []
    for name, bands, dtype in (("ref_ortho.tif", 3, gdal.GDT_Byte), ("ref_dsm.tif", 1, gdal.GDT_Float32)):
        path = os.path.join(str(folder), name)
        ds = gdal.GetDriverByName("GTiff").Create(path, w, h, bands, dtype)
        ds.SetGeoTransform((float(x0), gsd, 0.0, float(y1), 0.0, -gsd))
        ds.SetProjection(srs.ExportToWkt())
        if bands == 3:
            for b, ci in zip(range(3), (gdal.GCI_RedBand, gdal.GCI_GreenBand, gdal.GCI_BlueBand)):
                band = ds.GetRasterBand(b + 1)
                band.WriteArray(rng.integers(0, 256, (h, w), dtype=np.uint8))
                band.SetColorInterpretation(ci)
        else:
            yy, xx = np.mgrid[0:h, 0:w]
            ds.GetRasterBand(1).WriteArray((100.0 + 0.02 * xx + 0.01 * yy).astype(np.float32))
        ds = None
        paths.append(path)
    return paths[0], paths[1]
