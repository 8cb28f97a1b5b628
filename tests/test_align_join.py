"""Components of a split block joined by the photos' positions (issue 46 item 2, core/align/joining.py).

A nadir strip (photos 27 m apart at 67 m, frames tilted up to 10 deg: seneca_south's flight) split into three
components as COLMAP leaves it -- each in its own arbitrary frame (rotation, scale, shift), two sharing a photo --
is placed on the photos' GPS positions (3 m noise) and merged into one reconstruction with every photo once, its
camera centres within a few metres of the truth.  Before the join the block held 5 of 12 photos."""
import math

import numpy as np
import pytest

pycolmap = pytest.importorskip("pycolmap")

from core.align.joining import (  # noqa: E402
    merged,
    place,
    pose_priors,
    position_targets,
    prior_adjustment,
    similarity,
    spacing,
)
from core.align.mapping import final_bundle_adjustment  # noqa: E402
from core.align.options import AlignOptions  # noqa: E402
from core.common.progress import NullProgress  # noqa: E402


def _rotation(axis, deg):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    t = math.radians(deg)
    return np.eye(3) + math.sin(t) * k + (1 - math.cos(t)) * k @ k


def _strip(n=12, step=27.0, height=67.0, seed=3):
    """(centres, cam_from_world rotations) of a nadir strip heading 55 deg, frames tilted 0-10 deg."""
    rng = np.random.default_rng(seed)
    heading = np.array([math.cos(math.radians(55)), math.sin(math.radians(55)), 0.0])
    centres = [k * step * heading + np.array([0, 0, height]) for k in range(n)]
    down = np.diag([1.0, -1.0, -1.0])  # camera z (viewing) along world -z
    rots = [down @ _rotation(rng.normal(size=3), rng.uniform(0, 10)) for _ in range(n)]
    return np.array(centres), rots


def _component(names, centres, rots, sim):
    """A reconstruction of the photos ``names`` (indices into the strip) in the frame ``sim`` (s, R, t)
    maps the world into."""
    s, r, t = sim
    rec = pycolmap.Reconstruction()
    rec.add_camera_with_trivial_rig(pycolmap.Camera(camera_id=1, model="SIMPLE_RADIAL", width=1800, height=1350,
                                                    params=[1300.0, 900.0, 675.0, 0.0]))
    for k in names:
        rot = rots[k] @ r.T  # cam_from_model: model -> world is x / s after R^T, shift
        c_model = s * r @ centres[k] + t
        pose = pycolmap.Rigid3d(pycolmap.Rotation3d(rot), -rot @ c_model)
        rec.add_image_with_trivial_frame(pycolmap.Image(name=f"IMG_{446 + k:04d}.jpg", keypoints=np.zeros((0, 2)),
                                                        camera_id=1, image_id=k + 1), pose)
    return rec


def test_components_placed_on_positions_merge_into_one_block():
    centres, rots = _strip()
    rng = np.random.default_rng(7)
    truth = {f"IMG_{446 + k:04d}.jpg": c for k, c in enumerate(centres)}
    targets = {n: c + rng.normal(0, [3.0, 3.0, 5.0]) for n, c in truth.items()}  # consumer GPS
    parts = [[5, 6, 7, 8, 10], [2, 3, 4, 11], [0, 1, 2]]  # seneca_south's split: 0448 in two, 0455 in none
    frames = [(0.05, _rotation([1, 2, 3], 40), np.array([3.0, -1.0, 2.0])),
              (2.0, _rotation([0, 1, 0], 170), np.array([-10.0, 4.0, 0.0])),
              (0.3, _rotation([1, 0, 0], -60), np.array([0.0, 0.0, 5.0]))]
    comps = [_component(p, centres, rots, f) for p, f in zip(parts, frames)]
    placed = []
    for rec in comps:
        p = place(rec, targets)
        assert p is not None and p[3] < 0.35 * spacing(targets)  # each fits its positions (3 m GPS noise)
        placed.append((rec, p[:3]))
    joined = merged(pycolmap, placed)
    names = sorted(joined.images[i].name for i in joined.reg_image_ids())
    assert len(names) == 11 and len(set(names)) == 11  # 0448 once, 0455 in no component
    err = [np.linalg.norm(joined.find_image_with_name(n).projection_center() - truth[n]) for n in names]
    assert max(err) < 10.0 and math.sqrt(np.mean(np.square(err))) < 6.0, err
    # the frames look down after the placement (the roll about the strip comes from the viewing directions)
    tilt = [math.degrees(math.acos(-joined.find_image_with_name(n).viewing_direction()[2])) for n in names]
    assert max(tilt) < 20.0, tilt


def test_similarity_recovers_a_known_transform():
    a = np.random.default_rng(1).normal(size=(6, 3))
    r = _rotation([1, 1, 0], 33)
    s, rr, t = similarity(a, 2.5 * (r @ a.T).T + np.array([1.0, 2.0, 3.0]))
    assert s == pytest.approx(2.5) and np.allclose(rr, r) and np.allclose(t, [1, 2, 3])


def test_position_targets_take_the_exif_altitude_only_when_every_photo_has_one():
    class Info:
        def __init__(self, name, gps):
            self.name, self.gps = name, gps

    infos = [Info("a", (7.0, 45.0, 280.0)), Info("b", (7.0001, 45.0, 290.0))]
    t, alt = position_targets(infos, {"a": (0.0, 0.0), "b": (7.9, 0.0)}, False)
    assert alt and t["b"][2] == 290.0
    t, alt = position_targets(infos, {"a": (0.0, 0.0), "b": (7.9, 0.0)}, True)  # a positions file: no altitude
    assert not alt and t["a"][2] == 0.0


def _two_camera_block():
    """A synthetic block of two cameras (5 frames each, 200 points), its true camera centres, and the same block
    with both cameras' focal lengths 3 % off and the distortion set to 0.02."""
    opts = pycolmap.SyntheticDatasetOptions()
    opts.num_rigs, opts.num_cameras_per_rig, opts.num_frames_per_rig, opts.num_points3D = 2, 1, 5, 200
    opts.sensor_from_rig_translation_stddev = opts.sensor_from_rig_rotation_stddev = 0.0
    pycolmap.set_random_seed(5)
    truth = pycolmap.synthesize_dataset(opts)
    noise = pycolmap.SyntheticNoiseOptions()
    noise.point2D_stddev = 0.5
    pycolmap.synthesize_noise(noise, truth)
    centres = {truth.images[i].name: np.asarray(truth.images[i].projection_center(), float)
               for i in truth.reg_image_ids()}
    block = pycolmap.Reconstruction(truth)
    for cam in block.cameras.values():
        params = np.asarray(cam.params, float)
        params[0] *= 1.03
        params[3] = 0.02
        cam.params = params
    return block, centres


@pytest.mark.parametrize("hold", [({1}, False), ((), True)])
def test_the_joins_adjustment_keeps_what_the_stage_holds(hold):
    """The join's adjustment with position priors (issue 46 item 2) holds the cameras the user's calibration holds
    (issue 32) and, where the mapping held it, the focal length (the distortion still refined), as the final
    adjustment does; a free camera's focal length is refined."""
    block, centres = _two_camera_block()
    before = {cid: np.asarray(c.params, float).copy() for cid, c in block.cameras.items()}
    prior_adjustment(pycolmap, block, pose_priors(pycolmap, block, centres, altitude=True), hold)
    held, hold_focal = hold
    for cid, cam in block.cameras.items():
        after = np.asarray(cam.params, float)
        if cid in held:
            assert np.array_equal(after, before[cid]), (cid, before[cid], after)
        elif hold_focal:
            assert after[0] == before[cid][0] and after[3] != before[cid][3], (cid, before[cid], after)
        else:
            assert abs(after[0] / before[cid][0] - 1.0) > 0.01, (cid, before[cid], after)


def test_the_final_adjustment_of_a_joined_block_keeps_its_position_priors():
    """The stage's final adjustment of a joined block keeps the position priors (the block stays in the positions'
    frame) and the held camera's intrinsics."""
    block, centres = _two_camera_block()
    given = np.asarray(block.cameras[1].params, float).copy()
    final_bundle_adjustment(pycolmap, block, AlignOptions(), NullProgress(), held={1},
                            priors=lambda r: pose_priors(pycolmap, r, centres, altitude=True))
    assert np.array_equal(np.asarray(block.cameras[1].params, float), given)
    err = [np.linalg.norm(block.find_image_with_name(n).projection_center() - c) for n, c in centres.items()]
    assert max(err) < 1.0, err
