"""The motion files of other pipelines saved from a Python run and read back as their consumers
read them: GMR's pickle with `pickle.load` (NumPy arrays inside), mjlab's NPZ with `numpy.load`,
the LAFAN1 CSV with `numpy.loadtxt`; and `iktc retarget --format` writing the same files."""
import os
import pickle
import subprocess
import tempfile

import numpy as np

import iktc
from test_controller import REPO, iktc_binary

CLIP = REPO / "crates" / "iktc" / "data" / "motions" / "deepmimic" / "humanoid3d_walk.txt"
# Round-off of values computed two ways (the same float64 arithmetic up to ordering) [m], [rad].
ROUND_OFF = 1e-9
# float32 rounding of a coordinate below 2 m [m]: 2^-24 relative, with room.
F32 = 1e-6
# A unit quaternion's norm, up to round-off [-].
UNIT = 1e-12


def rotation(q_xyzw):
    """The rotation matrices of quaternions x, y, z, w (N x 4) -> N x 3 x 3."""
    x, y, z, w = (q_xyzw / np.linalg.norm(q_xyzw, axis=1, keepdims=True)).T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def run_and_files(rate=None):
    run = iktc.retarget_keypoints(iktc.load_motion(str(CLIP)), iktc.Robot("g1"))
    out = tempfile.mkdtemp()
    paths = {k: os.path.join(out, name) for k, name in
             (("gmr", "m.pkl"), ("mjlab", "m.npz"), ("lafan", "m.csv"))}
    run.save_gmr(paths["gmr"], rate=rate)
    run.save_mjlab(paths["mjlab"], rate=rate)
    run.save_lafan_csv(paths["lafan"], rate=rate)
    return run, paths


def test_saved_gmr_mjlab_and_lafan_files_load_with_their_consumers_semantics():
    run, paths = run_and_files()
    n = len(run)
    with open(paths["gmr"], "rb") as f:
        g = pickle.load(f)
    assert list(g) == ["fps", "root_pos", "root_rot", "dof_pos", "local_body_pos",
                       "link_body_list"]
    assert g["fps"] == 200 and isinstance(g["fps"], int)
    bodies = g["link_body_list"]
    assert isinstance(bodies, list) and bodies[0] == "pelvis" and len(bodies) == 30
    assert g["root_pos"].shape == (n, 3) and g["root_pos"].dtype == np.float64
    assert g["root_rot"].shape == (n, 4) and g["dof_pos"].shape == (n, 29)
    assert g["local_body_pos"].shape == (n, 30, 3) and g["local_body_pos"].dtype == np.float32
    # At the control rate every tick is copied: root_pos is the base position of the run.
    assert np.array_equal(g["root_pos"], run.q[:, :3])
    assert np.array_equal(g["root_rot"], run.q[:, 3:7])  # x, y, z, w, as the run's q
    assert np.array_equal(g["dof_pos"], run.q[:, 7:])
    assert np.abs(np.linalg.norm(g["root_rot"], axis=1) - 1).max() < UNIT
    assert np.abs(g["local_body_pos"][:, 0]).max() == 0.0
    # Writable, as arrays GMR's scripts adjust in place.
    g["root_pos"][:, 2] -= 0.0

    m = np.load(paths["mjlab"])
    assert m["fps"].shape == (1,) and m["fps"][0] == 200.0
    assert m["joint_pos"].shape == (n, 29) and m["joint_vel"].shape == (n, 29)
    assert np.array_equal(m["joint_pos"], run.q[:, 7:])
    assert np.array_equal(m["joint_vel"], run.v[:, 6:])
    assert list(m["body_names"]) == bodies
    for key, width in (("body_pos_w", 3), ("body_quat_w", 4), ("body_lin_vel_w", 3),
                       ("body_ang_vel_w", 3)):
        assert m[key].shape == (n, 30, width), key
    assert np.abs(np.linalg.norm(m["body_quat_w"], axis=2) - 1).max() < 1e-9
    # The pelvis: the base position, its quaternion as w, x, y, z, and the base twist (which
    # the run records in the base's axes) turned into world axes.
    assert np.abs(m["body_pos_w"][:, 0] - run.q[:, :3]).max() < ROUND_OFF
    wxyz = run.q[:, [6, 3, 4, 5]] / np.linalg.norm(run.q[:, 3:7], axis=1, keepdims=True)
    sign = np.sign(np.sum(wxyz * m["body_quat_w"][:, 0], axis=1, keepdims=True))
    assert np.abs(sign * m["body_quat_w"][:, 0] - wxyz).max() < ROUND_OFF
    r = rotation(run.q[:, 3:7])
    assert np.abs(m["body_lin_vel_w"][:, 0] - np.einsum("nij,nj->ni", r, run.v[:, :3])).max() \
        < ROUND_OFF
    assert np.abs(m["body_ang_vel_w"][:, 0] - np.einsum("nij,nj->ni", r, run.v[:, 3:6])).max() \
        < ROUND_OFF
    # GMR's local positions are the world positions in the root frame: R^T (p - p_root).
    local = np.einsum("nji,nbj->nbi", r, m["body_pos_w"] - m["body_pos_w"][:, :1])
    assert np.abs(local - g["local_body_pos"]).max() < F32

    c = np.loadtxt(paths["lafan"], delimiter=",")
    assert c.shape == (n, 36)
    assert np.array_equal(c, run.q)


def test_saved_files_at_another_rate_and_from_the_command_line_agree():
    run, paths = run_and_files(rate=50.0)
    with open(paths["gmr"], "rb") as f:
        g = pickle.load(f)
    n = (len(run) - 1) // 4 + 1
    # 50 Hz divides 200 Hz: every fourth tick, copied.
    assert g["fps"] == 50 and g["root_pos"].shape == (n, 3)
    assert np.array_equal(g["root_pos"], run.q[::4, :3][:n])
    out = tempfile.mkdtemp()
    subprocess.run([iktc_binary(), "retarget", str(CLIP), "--robot", "g1", "--no-viewer",
                    "--rate", "50", "--format", "gmr,lafan-csv,mjlab", "--out", out],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    folder = os.path.join(out, "humanoid3d_walk")
    assert sorted(os.listdir(folder)) == [".record", "motion_gmr.pkl", "motion_lafan.csv",
                                          "motion_mjlab.npz", "quality.json"]
    with open(os.path.join(folder, "motion_gmr.pkl"), "rb") as f:
        cli = pickle.load(f)
    for key in ("root_pos", "root_rot", "dof_pos", "local_body_pos"):
        assert np.allclose(cli[key], g[key], rtol=0, atol=ROUND_OFF), key
    assert cli["link_body_list"] == g["link_body_list"] and cli["fps"] == g["fps"]
    a, b = np.load(os.path.join(folder, "motion_mjlab.npz")), np.load(paths["mjlab"])
    assert sorted(a.files) == sorted(b.files)
    for key in a.files:
        if a[key].dtype.kind == "f":
            assert np.allclose(a[key], b[key], rtol=0, atol=ROUND_OFF), key
    assert np.allclose(np.loadtxt(os.path.join(folder, "motion_lafan.csv"), delimiter=","),
                       np.loadtxt(paths["lafan"], delimiter=","), rtol=0, atol=ROUND_OFF)
