"""Weak links matched again, guided by the block's poses (issue 46, core/align/links.py).

seneca_south's halves met through a pair with 64 verified matches: SIFT's global ratio test loses a faint field's
features among the other photo's similar ones.  Predicted by the block (each feature's ray at the depth of its
nearest tie points, into the other photo), a feature is compared only with the few features near its predicted
place, and the repeats elsewhere in the frame no longer hide it."""
import math

import numpy as np
import pytest

pycolmap = pytest.importorskip("pycolmap")
cv2 = pytest.importorskip("cv2")

from core.align.links import LINK_RADIUS_SHARE, feature_ground, guided_matches, predicted, verified  # noqa: E402

W, H, F = 1800, 1350, 1300.0


def _pose(centre, tilt_deg=0.0):
    """cam_from_world of a nadir camera at ``centre`` (x right = east, y down = south), tilted about x."""
    t = math.radians(tilt_deg)
    rx = np.array([[1, 0, 0], [0, math.cos(t), -math.sin(t)], [0, math.sin(t), math.cos(t)]])
    r = rx @ np.diag([1.0, -1.0, -1.0])
    return r, -r @ np.asarray(centre, float)


def _block(rng, n_ground=4000, n_ties=60):
    """Two cameras 30 m apart at 70 m over flat ground (z 0 with 0.2 m of relief), a reconstruction holding them
    and ``n_ties`` tie points; returns (rec, ground points, their pixels in A and B, seen by both)."""
    cam = pycolmap.Camera(camera_id=1, model="SIMPLE_RADIAL", width=W, height=H, params=[F, W / 2, H / 2, 0.0])
    poses = [_pose((0, 0, 70), 3.0), _pose((0, 30, 70), -4.0)]
    ground = np.column_stack([rng.uniform(-40, 40, n_ground), rng.uniform(-30, 60, n_ground),
                              rng.normal(0, 0.2, n_ground)])
    pix = []
    for r, t in poses:
        xc = ground @ r.T + t
        pix.append(np.column_stack([F * xc[:, 0] / xc[:, 2] + W / 2, F * xc[:, 1] / xc[:, 2] + H / 2]))
    inside = [(p[:, 0] >= 0) & (p[:, 0] < W) & (p[:, 1] >= 0) & (p[:, 1] < H) for p in pix]
    both = inside[0] & inside[1]
    rec = pycolmap.Reconstruction()
    rec.add_camera_with_trivial_rig(cam)
    ties = np.nonzero(both)[0][:n_ties]
    for k, (r, t) in enumerate(poses):
        kp = pix[k][inside[k]]
        rec.add_image_with_trivial_frame(pycolmap.Image(name=f"{k}.jpg", keypoints=kp, camera_id=1, image_id=k + 1),
                                         pycolmap.Rigid3d(pycolmap.Rotation3d(r), t))
    index = [np.cumsum(inside[k]) - 1 for k in range(2)]
    for g in ties:
        track = pycolmap.Track()
        track.add_element(1, int(index[0][g]))
        track.add_element(2, int(index[1][g]))
        rec.add_point3D(ground[g], track, np.zeros(3, np.uint8))
    return rec, ground, pix, inside


def test_the_block_predicts_where_a_feature_of_one_photo_lies_in_the_other():
    rng = np.random.default_rng(4)
    rec, ground, pix, inside = _block(rng)
    kp_a = pix[0][inside[0]]
    g = feature_ground(rec, 1, kp_a)
    assert g is not None
    pred, seen = predicted(rec, 2, g)
    truth = pix[1][inside[0]]
    truly = inside[1][inside[0]]
    assert (seen == truly).mean() > 0.97
    err = np.hypot(*(pred[seen & truly] - truth[seen & truly]).T)
    # 0.2 m of relief at 70 m between tie points: a few pixels, well inside the search radius
    assert np.median(err) < 3.0 and np.percentile(err, 95) < LINK_RADIUS_SHARE * math.hypot(W, H)


def test_guided_matching_finds_the_matches_a_global_ratio_test_loses():
    """Each feature's descriptor has a near twin elsewhere in the other photo (a field's repeated texture): the
    global ratio test keeps almost none; the guided one, comparing only within the radius of the prediction,
    keeps most, and RANSAC verifies them."""
    rng = np.random.default_rng(5)
    rec, ground, pix, inside = _block(rng, n_ground=1500)
    both = inside[0] & inside[1]
    kp_a, kp_b_true = pix[0][both], pix[1][both]
    n = len(kp_a)
    base = rng.integers(0, 256, (n, 128)).astype(np.float32)
    desc_a = base + rng.normal(0, 6, base.shape)
    desc_b_true = base + rng.normal(0, 6, base.shape)
    # the twins: the same descriptors (their own noise) at places far from the true ones
    twins = np.column_stack([(kp_b_true[:, 0] + W / 2) % W, (kp_b_true[:, 1] + H / 2) % H])
    desc_twin = base + rng.normal(0, 6, base.shape)
    kp_b = np.vstack([kp_b_true + rng.normal(0, 0.5, kp_b_true.shape), twins])
    desc_b = np.clip(np.vstack([desc_b_true, desc_twin]), 0, 255).astype(np.uint8)
    desc_a = np.clip(desc_a, 0, 255).astype(np.uint8)

    knn = cv2.BFMatcher(cv2.NORM_L2).knnMatch(desc_a.astype(np.float32), desc_b.astype(np.float32), k=2)
    global_ok = sum(1 for m in knn if m[0].distance < 0.8 * m[1].distance and m[0].trainIdx == m[0].queryIdx)
    assert global_ok < 0.2 * n

    g = feature_ground(rec, 1, kp_a)
    pred, seen = predicted(rec, 2, g)
    m = guided_matches(desc_a, np.where(seen[:, None], pred, np.nan), kp_b, desc_b,
                       LINK_RADIUS_SHARE * math.hypot(W, H))
    right = m[:, 0] == m[:, 1]
    assert right.sum() > 0.8 * n and right.mean() > 0.95
    inl, f = verified(kp_a, kp_b, m, 1.9)
    assert len(inl) > 0.8 * n and (inl[:, 0] == inl[:, 1]).mean() > 0.99


def test_oblique_views_are_not_matched_again():
    """A steep view sees the ground foreshortened and turned: its links are left as the mapping made them (the
    synthetic orbits' poses got 2-3 x worse when they were matched again)."""
    from core.align.links import steep_views

    rec = pycolmap.Reconstruction()
    rec.add_camera_with_trivial_rig(pycolmap.Camera(camera_id=1, model="SIMPLE_RADIAL", width=W, height=H,
                                                    params=[F, W / 2, H / 2, 0.0]))
    tilts = [2.0, -5.0, 8.0, 0.0, 50.0, -55.0]
    for k, tilt in enumerate(tilts):
        r, t = _pose((k * 20.0, 0, 70), tilt)
        rec.add_image_with_trivial_frame(pycolmap.Image(name=f"{k}.jpg", keypoints=np.zeros((0, 2)), camera_id=1,
                                                        image_id=k + 1), pycolmap.Rigid3d(pycolmap.Rotation3d(r), t))
    assert steep_views(rec) == {5, 6}
