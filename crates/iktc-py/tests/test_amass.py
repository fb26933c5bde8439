"""AMASS archives from Python: a synthetic SMPL-X body model and archive written with numpy
(``np.savez_compressed`` and ``np.savez``, the way the real files are written), loaded with
``body_model=``; the body points against joints computed by hand; without a model, the error
naming the model file and the keyword."""
import numpy as np
import pytest

import iktc

J = 55  # SMPL-X joints
# SMPL's parents of the first 22 joints, then the jaw and eyes on the head, then the fingers.
BODY_PARENTS = [-1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19]
# Template joints [m]: Y up, facing +Z, left along +X (pelvis, hips, spine1, knees, spine2,
# ankles, spine3, feet, neck, collars, head, shoulders, elbows, wrists).
BODY = [
    (0, 0.93, 0), (0.08, 0.85, 0), (-0.08, 0.85, 0), (0, 1.03, 0), (0.09, 0.48, 0.01),
    (-0.09, 0.48, 0.01), (0, 1.16, 0), (0.09, 0.08, -0.03), (-0.09, 0.08, -0.03), (0, 1.22, 0),
    (0.1, 0.02, 0.11), (-0.1, 0.02, 0.11), (0, 1.44, 0), (0.07, 1.36, 0), (-0.07, 1.36, 0),
    (0, 1.53, 0.02), (0.17, 1.38, 0), (-0.17, 1.38, 0), (0.43, 1.38, 0), (-0.43, 1.38, 0),
    (0.68, 1.38, 0), (-0.68, 1.38, 0),
]
HEIGHT_SCALE = 0.1  # shape component 0: m of height per m per unit beta
TOL = 1e-12  # f64 sums of a few products of values below 2 m [m]


def skeleton():
    p = [np.array(b, dtype=float) for b in BODY]
    parents = list(BODY_PARENTS)
    for x in (0.0, 0.03, -0.03):
        p.append(p[15] + [x, 0.05, 0.06])
        parents.append(15)
    for wrist, sign in ((20, 1.0), (21, -1.0)):
        for finger in range(5):
            for k in range(3):
                p.append(p[wrist] + [sign * (0.06 + 0.025 * k), 0.0, 0.02 * (finger - 2)])
                parents.append(wrist if k == 0 else len(p) - 2)
    return np.array(p), parents


def write_model(path):
    """V = 2J vertices at P_j ± d; the regressor averages each pair; component 0 scales
    heights, so J_j(beta) = (x, y (1 + 0.1 beta_0), z)."""
    p, parents = skeleton()
    d = np.array([0.01, 0.02, -0.015])
    v_template = np.empty((2 * J, 3))
    v_template[0::2] = p + d
    v_template[1::2] = p - d
    regressor = np.zeros((J, 2 * J))
    for j in range(J):
        regressor[j, 2 * j:2 * j + 2] = 0.5
    shapedirs = np.zeros((2 * J, 3, 16))
    shapedirs[0::2, 1, 0] = HEIGHT_SCALE * p[:, 1]
    shapedirs[1::2, 1, 0] = HEIGHT_SCALE * p[:, 1]
    kintree = np.array([np.array(parents).astype(np.uint32), np.arange(J, dtype=np.uint32)])
    np.savez_compressed(path, v_template=v_template, shapedirs=shapedirs, J_regressor=regressor,
                        kintree_table=kintree, posedirs=np.zeros((2 * J, 3, 9)),
                        weights=np.full((2 * J, J), 1.0 / J), f=np.zeros((4, 3), np.int32))
    return p


def standing_rotation():
    """Axis-angle of Rz(90°) Rx(90°): the template stood up in a Z-up world, facing +X."""
    # Rz(90) Rx(90) maps x -> y, y -> z, z -> x: a 120° turn about (1, 1, 1).
    return np.full(3, 2 * np.pi / 3 / np.sqrt(3))


def write_archive(path, frames=31):
    p, _ = skeleton()
    poses = np.zeros((frames, 3 * J))
    poses[:, 0:3] = standing_rotation()
    t = np.arange(frames) / 30.0
    trans = np.stack([t, np.full(frames, -p[0, 1]), np.full(frames, p[0, 1])], axis=1)
    betas = np.zeros(16)
    betas[0] = 0.5
    np.savez(path, poses=poses, trans=trans, betas=betas, gender=np.array("neutral"),
             mocap_frame_rate=np.array(30.0), root_orient=poses[:, :3])
    return trans, betas


def test_an_amass_archive_loads_with_its_body_model(tmp_path):
    model, archive = tmp_path / "SMPLX_NEUTRAL.npz", tmp_path / "walk_stageii.npz"
    p = write_model(model)
    trans, betas = write_archive(archive)
    m = iktc.load_motion(str(archive), body_model=str(model))
    assert m.format == "AMASS (SMPL-H/SMPL-X)" and m.has_skeleton
    names, times, positions = m.keypoints()
    assert times[1] == pytest.approx(1 / 30.0, abs=TOL)
    shaped = p * [1.0, 1.0 + HEIGHT_SCALE * betas[0], 1.0]

    def rotate(v):  # Rz(90°) Rx(90°): (x, y, z) -> (z, x, y)
        return np.array([v[2], v[0], v[1]])

    pelvis = shaped[0] + trans[5]
    expected = {
        "pelvis": pelvis,
        "left_knee": pelvis + rotate(shaped[4] - shaped[0]),
        "right_ankle": pelvis + rotate(shaped[8] - shaped[0]),
        "head": pelvis + rotate(shaped[15] - shaped[0]),
        "left_wrist": pelvis + rotate(shaped[20] - shaped[0]),
    }
    for name, at in expected.items():
        assert np.allclose(positions[5, names.index(name)], at, atol=TOL, rtol=0), name


def test_without_a_body_model_the_error_names_the_model_and_the_keyword(tmp_path):
    archive = tmp_path / "walk_stageii.npz"
    write_archive(archive)
    with pytest.raises(iktc.IktcError, match="body_model=") as e:
        iktc.load_motion(str(archive))
    assert "SMPLX_NEUTRAL.npz" in str(e.value) and "SMPL-X" in str(e.value)
