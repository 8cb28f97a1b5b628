"""The bundle adjustment's solver (core.georef.bundle.BundleProblem) on a synthetic block with known truth.

Two strips of nadir photos over ground with relief, one OPENCV camera with real radial distortion; the solve
starts from a wrong calibration (focal length 2 % off, no distortion) and perturbed poses, with a few control
points fixing the datum.  It must recover the calibration and converge well inside its iteration budget (the
camera unknowns mix radians, metres, pixels and distortion coefficients: a damping floor relative to the largest
diagonal held focal length and k2 for hundreds of iterations); an observation of a point far outside the field
of view, which a polynomial distortion model folds back into the image, must not take part; and on flat ground,
where focal length and flying height trade freely, the focal length prior keeps the calibration in place.
"""
import numpy as np
import pycolmap
import pytest

from core.geometry.similarity import rodrigues
from core.georef.bundle import BundleProblem, CameraPriors, Frames, Intrinsics, Observations, Points, field_radius

W, H = 1200, 900
TRUE = [700.0, 700.0, 600.0, 450.0, -0.06, 0.02, 0.0, 0.0]


def camera(params):
    return pycolmap.Camera(model="OPENCV", width=W, height=H, params=list(params))


def block(relief=8.0, seed=0):
    """Frames (R, C) of two strips 100 m up and ground points seen by them, with their pixel observations."""
    rng = np.random.default_rng(seed)
    centres = [(x, y, 100.0) for y in (0.0, 45.0) for x in np.arange(0.0, 121.0, 30.0)]
    r_nadir = np.diag([1.0, -1.0, -1.0])  # camera z down, x east
    R = np.array([rodrigues(rng.normal(0, 0.01, 3)[None])[0] @ r_nadir for _ in centres])
    C = np.array(centres, dtype=float)
    xy = rng.uniform([-40, -40], [160, 85], size=(1500, 2))
    z = relief * np.sin(xy[:, 0] / 23.0) * np.cos(xy[:, 1] / 17.0)
    X = np.column_stack([xy, z])
    cam = camera(TRUE)
    img, pt, obs = [], [], []
    for i in range(len(C)):
        xc = (X - C[i]) @ R[i].T
        uv = np.asarray(cam.img_from_cam(xc, check_cheirality=False))
        r = np.hypot(xc[:, 0], xc[:, 1]) / xc[:, 2]
        ok = (xc[:, 2] > 0) & (r < 0.95) & (uv[:, 0] > 0) & (uv[:, 0] < W) & (uv[:, 1] > 0) & (uv[:, 1] < H)
        for k in np.flatnonzero(ok):
            img.append(i)
            pt.append(k)
            obs.append(uv[k] + rng.normal(0, 0.3, 2))
    img, pt = np.array(img), np.array(pt)
    seen = np.bincount(pt, minlength=len(X)) >= 2
    keep = seen[pt]
    return R, C, X, img[keep], pt[keep], np.array(obs)[keep], seen


def problem(start_params, relief=8.0, focal_prior=0.0, fold=False, seed=0):
    rng = np.random.default_rng(seed + 1)
    R, C, X, img, pt, xy, seen = block(relief, seed)
    used = np.flatnonzero(seen)
    remap = -np.ones(len(X), dtype=int)
    remap[used] = np.arange(len(used))
    X = X[used]
    pt = remap[pt]
    if fold:  # a point beside the camera's plane: 3 x the field's radius, folded back into the image
        cam = camera(TRUE)
        xc = np.array([[2.4, 1.8, 1.0]]) * 20.0
        X = np.vstack([X, (xc @ R[0]) + C[0]])
        img = np.append(img, 0)
        pt = np.append(pt, len(X) - 1)
        xy = np.vstack([xy, np.clip(np.asarray(cam.img_from_cam(xc, check_cheirality=False)), 10, [W - 10, H - 10])])
    n = len(img)
    obs = Observations(img, pt, xy, np.ones(n), np.ones(n, dtype=bool), np.ones(n, dtype=bool))
    prior = np.full((len(X), 3), np.nan)
    sigma = np.full((len(X), 3), np.nan)
    ctrl = rng.choice(len(used), 12, replace=False)
    prior[ctrl] = X[ctrl]
    sigma[ctrl] = 0.02
    x0 = X + rng.normal(0, 0.3, X.shape)
    r0 = np.array([rodrigues(rng.normal(0, 0.003, 3)[None])[0] @ r for r in R])
    c0 = C + rng.normal(0, 0.5, C.shape)
    nf = len(R)
    cam = camera(start_params)
    free = [0, 1, 4, 5, 6, 7]
    frames = Frames(r0, c0, np.arange(nf), np.zeros(nf, dtype=int), np.tile(np.eye(3), (nf, 1, 1)), np.zeros((nf, 3)))
    prob = BundleProblem(frames, Intrinsics([cam], [free], focal_prior), Points(x0, prior, sigma), obs,
                         CameraPriors([], np.zeros((0, 3)), np.zeros((0, 3))))
    return prob, C


def test_field_radius_is_the_corners_undistorted_radius_with_a_margin():
    cam = camera(TRUE)
    corner = np.asarray(cam.cam_from_img(np.array([[0.0, 0.0]])))[0]
    assert field_radius(cam, margin=1.0) == pytest.approx(float(np.hypot(*corner)), rel=1e-6)
    assert field_radius(cam) > field_radius(cam, margin=1.0)
    assert field_radius(pycolmap.Camera(model="PINHOLE", width=0, height=0, params=[1, 1, 0, 0])) == float("inf")


def test_calibration_recovered_and_converged_from_a_wrong_start():
    prob, C = problem([714.0, 714.0, 600.0, 450.0, 0.0, 0.0, 0.0, 0.0])
    info = prob.solve(max_iterations=50)
    p = np.asarray(prob.cameras[0].params)
    assert p[0] == pytest.approx(700.0, rel=2e-3) and p[1] == pytest.approx(700.0, rel=2e-3)
    assert p[4] == pytest.approx(TRUE[4], abs=4e-3) and p[5] == pytest.approx(TRUE[5], abs=4e-3)
    assert info["iterations"] < 40, info
    assert np.max(np.linalg.norm(prob.camera_centres() - C, axis=1)) < 0.2


def test_an_observation_folded_into_the_image_by_the_distortion_takes_no_part():
    prob, C = problem([714.0, 714.0, 600.0, 450.0, 0.0, 0.0, 0.0, 0.0], fold=True)
    last = np.array([len(prob.obs.img) - 1])
    _, inside = prob.reprojection(last)
    assert not inside[0]
    prob.solve(max_iterations=50)
    p = np.asarray(prob.cameras[0].params)
    assert p[0] == pytest.approx(700.0, rel=2e-3)
    assert p[5] == pytest.approx(TRUE[5], abs=4e-3)


def test_focal_prior_holds_the_calibration_on_flat_ground():
    start = [700.0] * 2 + TRUE[2:]
    held, _ = problem(start, relief=0.0, focal_prior=0.01)
    held.solve(max_iterations=50)
    assert held.cameras[0].params[0] == pytest.approx(700.0, rel=2e-3)
    assert len(held.focal_prior_residuals()) == 2
    free, _ = problem(start, relief=0.0, focal_prior=0.0)  # without it the focal length slides (641 px here)
    free.solve(max_iterations=50)
    assert len(free.focal_prior_residuals()) == 0
    assert abs(free.cameras[0].params[0] - 700.0) > 7.0
