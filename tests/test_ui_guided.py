"""core.guided: predicted GCP positions in the photos (plain pytest, no QGIS).

The acceptance figure of issue 6: for a georeferenced synthetic block the predicted positions land
within 2 px of the true (noise-free) projections.
"""
import numpy as np
import pytest

from core.georef import guided
from core.georef.adjust import georeference
from core.io.gcp import GCPSet
from tests import synthetic as syn

TOL_PX = 2.0


@pytest.fixture(scope="module")
def block():
    return syn.vertical_block(seed=1)


@pytest.fixture(scope="module")
def georeferenced(block):
    rec = block.truth_reconstruction(n_points=800, noise_px=0.3)
    control = block.spread_control(5)
    result = georeference(rec, block.gcp_set(control, noise_px=0.4))
    return result, control


def _errors(block, predictions, names=None):
    errs, missed, extra = [], [], []
    for p in block.gcps:
        if names is not None and p.name not in names:
            continue
        pred = predictions.get(p.name, {})
        for img, px in p.observations.items():
            if img not in pred:
                missed.append((p.name, img))
                continue
            errs.append(float(np.hypot(*(np.array(pred[img].xy) - px))))
        extra += [(p.name, img) for img in pred if img not in p.observations]
    return np.array(errs), missed, extra


def test_georeferenced_block_predictions_within_2_px_of_the_truth(block, georeferenced):
    """World coordinates only (no observations at all): projected through the adjusted block."""
    result, control = georeferenced
    gcps = block.gcp_set(control)
    for p in gcps.points:
        p.observations = []
    pred = guided.Predictor(result.reconstruction, result.offset)
    assert pred.georeferenced
    out = pred.predict(gcps)
    assert {p.source for v in out.values() for p in v.values()} == {guided.GEOREF}
    errs, missed, extra = _errors(block, out)
    print(f"\n[guided, georeferenced] {len(errs)} predictions, max {errs.max():.3f} px, "
          f"mean {errs.mean():.3f} px; missed {len(missed)}, extra {len(extra)}")
    assert len(errs) >= 50
    assert errs.max() < TOL_PX
    assert not missed  # every photo that sees a point is offered
    assert len(extra) <= 0.1 * len(errs)  # few photos offered where the point is hidden or at the border


def test_rays_from_two_observations_predict_the_other_photos(block, georeferenced):
    """A point placed in two photos is triangulated in the block and projected into the others."""
    result, _ = georeferenced
    pred = guided.Predictor(result.reconstruction, result.offset)
    errs_all = []
    for p in block.gcps:
        gs = block.gcp_set([p.name], noise_px=0.3, only=[p.name])
        pt = gs.points[0]
        pt.x = pt.y = pt.z = float("nan")  # no world coordinates: only the rays
        pt.observations = pt.observations[:2]
        out = pred.predict_point(pt)
        assert all(v.source == guided.RAYS for v in out.values())
        for img, px in p.observations.items():
            if img in out:
                errs_all.append(float(np.hypot(*(np.array(out[img].xy) - px))))
    errs_all = np.array(errs_all)
    print(f"\n[guided, rays] max {errs_all.max():.3f} px, mean {errs_all.mean():.3f} px over {len(errs_all)}")
    assert errs_all.max() < 3.0
    assert np.median(errs_all) < 1.0


def test_aligned_block_three_placed_points_predict_the_rest(block):
    """Aligned only (arbitrary model frame): a similarity fitted to 3 placed points predicts the others."""
    rec = block.truth_reconstruction(n_points=800, noise_px=0.3)
    control = block.spread_control(5)[:3]
    gcps = block.gcp_set(control, noise_px=0.4)
    for p in gcps.points:
        if p.name not in control:
            p.observations = []
    pred = guided.Predictor(rec)
    out = pred.predict(gcps)
    assert sorted(pred.helmert_points) == sorted(control)
    assert pred.helmert_rms < 0.05
    others = [p.name for p in block.gcps if p.name not in control]
    assert {v.source for n in others for v in out[n].values()} == {guided.HELMERT}
    errs, missed, _ = _errors(block, out, others)
    print(f"\n[guided, Helmert from 3 points] max {errs.max():.3f} px, mean {errs.mean():.3f} px")
    assert errs.max() < 2.5 * TOL_PX
    assert len(missed) <= 2


def test_fewer_than_three_points_give_no_world_predictions(block):
    rec = block.truth_reconstruction(n_points=300, noise_px=0.3)
    control = block.spread_control(5)[:2]
    gcps = block.gcp_set(control)
    for p in gcps.points:
        if p.name not in control:
            p.observations = []
    lone = [p for p in gcps.points if p.name not in control][0]
    pred = guided.Predictor(rec)
    out = pred.predict(gcps)
    assert out[lone.name] == {}
    assert pred.helmert_points == []


def test_projection_rejects_the_wrap_around_of_the_lens_model(block):
    """A point far outside the field of view can come back inside the frame through the distortion
    polynomial; the round-trip check must refuse it."""
    rec = block.truth_reconstruction(n_points=50, noise_px=0.0, model_from_local=None)
    im = next(iter(rec.images.values()))
    cam = rec.cameras[im.camera_id]
    m = np.asarray(im.cam_from_world().matrix())
    # a direction at 80 degrees off the axis: k1 < 0 folds it back towards the image
    xc = np.array([np.tan(np.radians(80.0)), 0.2, 1.0]) * 30.0
    world = m[:, :3].T @ (xc - m[:, 3])
    px = np.asarray(cam.img_from_cam(xc.reshape(1, 3), check_cheirality=False)).reshape(2)
    out = guided.project_point(rec, world, images=[im.name])
    inside = 0 <= px[0] <= cam.width and 0 <= px[1] <= cam.height
    if inside:
        assert im.name not in out
    # and a point right below the camera is accepted, near the principal point
    below = m[:, :3].T @ (np.array([0.0, 0.0, 40.0]) - m[:, 3])
    ok = guided.project_point(rec, below, images=[im.name])
    assert im.name in ok and ok[im.name][2] < 0.1


def test_images_seeing_orders_observed_first_then_central(block, georeferenced):
    result, control = georeferenced
    gs = block.gcp_set(control)
    pred = guided.Predictor(result.reconstruction, result.offset)
    p = gs.points[0]
    out = pred.predict_point(p)
    order = guided.images_seeing(out, ["zzz.jpg"])
    assert order[0] == "zzz.jpg"
    cent = [out[n].centrality for n in order[1:]]
    assert cent == sorted(cent)


def test_ground_sample_distance_and_footprints(block, georeferenced, tmp_path):
    result, _ = georeferenced
    gsd = guided.ground_sample_distance(result.reconstruction)
    assert gsd == pytest.approx(block.gsd, rel=0.15)
    z = float(np.median([p.xyz[2] for p in block.gcps]))
    prints = guided.image_footprints(result.reconstruction, z)
    assert len(prints) == len(block.shots)
    # each footprint contains its camera's nadir point and spans about the image's ground size
    for s in block.shots:
        poly = np.array(prints[s.name])
        w = np.ptp(poly[:, 0])
        h = np.ptp(poly[:, 1])
        ground = block.altitude * np.array([block.camera.width / block.camera.fx, block.camera.height / block.camera.fy])
        assert max(w, h) == pytest.approx(max(ground), rel=0.35)
    path = guided.write_footprints_gpkg(str(tmp_path / "f.gpkg"), prints, result.offset, syn.CRS)
    from osgeo import ogr

    ds = ogr.Open(path)
    assert ds.GetLayer(0).GetFeatureCount() == len(prints)


def test_empty_block_and_set():
    import pycolmap

    pred = guided.Predictor(pycolmap.Reconstruction())
    assert pred.predict(GCPSet("EPSG:32633")) == {}
    assert guided.ground_sample_distance(pycolmap.Reconstruction()) is None


def test_matching_refines_a_prediction_that_is_tens_of_pixels_off(block, georeferenced, tmp_path):
    """A point placed in one photo is found in another by correlation around a prediction 47 px off."""
    from tests.test_ui_dock import quick_photos

    result, _ = georeferenced
    photos = quick_photos(block, str(tmp_path / "photos"))
    gray = {n: guided.read_gray(p) for n, p in photos.items()}
    rec = result.reconstruction
    pred = guided.Predictor(rec, result.offset)
    errs, found, tried = [], 0, 0
    for p in block.gcps:
        names = sorted(p.observations)
        if len(names) < 2:
            continue
        ref, tgt = names[0], names[1]
        xyz = p.xyz - (result.offset - syn.ORIGIN)  # the point in the adjusted local frame
        truth = p.observations[tgt]
        off = truth + np.array([40.0, -25.0])
        tried += 1
        m = guided.refine_by_matching(rec, guided.PhotoPoint(ref, p.observations[ref], gray[ref]),
                                      guided.PhotoPoint(tgt, off, gray[tgt]), xyz, guided.MatchSearch(radius=120))
        if m is None:
            continue
        found += 1
        errs.append(float(np.hypot(m.x - truth[0], m.y - truth[1])))
    errs = np.array(errs)
    print(f"\n[matching] {found}/{tried} found, max {errs.max():.3f} px, mean {errs.mean():.3f} px")
    assert found >= 0.8 * tried
    assert errs.max() < 1.0
    # nothing to find in a blank photo
    blank = np.full_like(gray[ref], 128)
    assert guided.refine_by_matching(rec, guided.PhotoPoint(ref, p.observations[ref], gray[ref]),
                                     guided.PhotoPoint(tgt, truth, blank), xyz) is None
    del pred


def test_leave_one_out_names_a_wrong_click(block, georeferenced):
    result, _ = georeferenced
    pred = guided.Predictor(result.reconstruction, result.offset)
    p = max(block.gcps, key=lambda q: len(q.observations))
    gs = block.gcp_set([p.name], noise_px=0.2, only=[p.name])
    pt = gs.points[0]
    assert len(pt.observations) >= 4
    good = pred.leave_one_out(pt)
    assert len(good) == len(pt.observations) and max(good.values()) < 2.0
    pt.observations[1].x += 25.0  # a click on the wrong spot
    bad = pred.leave_one_out(pt)
    worst = max(bad, key=bad.get)
    assert worst == pt.observations[1].image and bad[worst] > 15.0
