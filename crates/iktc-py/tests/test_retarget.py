"""`iktc retarget`'s NPZ and CSV read by numpy and the csv module, against the Python retargeting
of the same clip (an independent path through the bindings): the keypoint route (the default)
against `iktc.retarget_keypoints`, the joint route against `iktc.Imitation`."""
import csv
import json
import os
import subprocess
import tempfile

import numpy as np

import iktc
from test_controller import REPO, iktc_binary

CLIP = REPO / "crates" / "iktc" / "data" / "motions" / "deepmimic" / "humanoid3d_walk.txt"


def batch_outputs(*route):
    """Runs `iktc retarget` on the walk clip for G1 and returns its NPZ, after checking the NPZ's
    shapes and that the CSV holds the same numbers by its named columns."""
    out = tempfile.mkdtemp()
    subprocess.run([iktc_binary(), "retarget", str(CLIP), "--robot", "g1", "--no-viewer",
                    *route, "--out", out], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    d = np.load(os.path.join(out, "humanoid3d_walk", "motion.npz"))
    robot = iktc.Robot("g1")
    names = list(d["joint_names"])
    assert names == list(robot.joint_names)
    n, m = d["joint_pos"].shape
    assert m == len(names) and d["joint_vel"].shape == (n, m)
    assert d["base_pos"].shape == (n, 3) and d["base_quat_xyzw"].shape == (n, 4)
    assert d["body_pos_w"].shape == (n, len(d["body_names"]), 3)
    assert float(d["fps"]) == 200.0
    with open(os.path.join(out, "humanoid3d_walk", "motion.csv")) as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == n
    for k, row in enumerate(rows):
        assert float(row["t"]) == d["time"][k]
        assert [float(row[c]) for c in ("base_qx", "base_qy", "base_qz", "base_qw")] == \
            list(d["base_quat_xyzw"][k])
        assert [float(row[c]) for c in names] == list(d["joint_pos"][k])
    return d, robot


def worst_difference(d, qs, vs):
    """The largest difference between the NPZ's frames and configurations `qs` (base position,
    quaternion x y z w, joints) and velocities `vs` (base twist, joint rates)."""
    worst = 0.0
    for k, (q, v) in enumerate(zip(qs, vs)):
        worst = max(worst, np.abs(q[7:] - d["joint_pos"][k]).max(),
                    np.abs(q[:3] - d["base_pos"][k]).max(),
                    np.abs(q[3:7] / np.linalg.norm(q[3:7]) - d["base_quat_xyzw"][k]).max(),
                    np.abs(v[6:] - d["joint_vel"][k]).max(),
                    np.abs(v[:3] - d["base_lin_vel"][k]).max(),
                    np.abs(v[3:6] - d["base_ang_vel"][k]).max())
    return worst


def test_retarget_npz_and_csv_equal_the_python_keypoint_retargeting():
    d, robot = batch_outputs()
    run = iktc.retarget_keypoints(iktc.load_motion(str(CLIP)), robot)
    assert len(run) == d["joint_pos"].shape[0]
    assert np.allclose(run.times, d["time"], rtol=0, atol=1e-12)
    assert worst_difference(d, run.q, run.v) < 1e-9


def cli_npz(*args):
    """`iktc retarget` on the walk clip for G1 with `args`: its NPZ and the CSV's text."""
    out = tempfile.mkdtemp()
    subprocess.run([iktc_binary(), "retarget", str(CLIP), "--robot", "g1", "--no-viewer",
                    *args, "--out", out], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    with open(os.path.join(out, "humanoid3d_walk", "motion.csv")) as f:
        text = f.read()
    return np.load(os.path.join(out, "humanoid3d_walk", "motion.npz")), text


def saved(run, rate=None):
    """The run's `save_npz` and `save_csv` at `rate`, read back."""
    out = tempfile.mkdtemp()
    run.save_npz(os.path.join(out, "m.npz"), rate=rate)
    run.save_csv(os.path.join(out, "m.csv"), rate=rate)
    with open(os.path.join(out, "m.csv")) as f:
        return np.load(os.path.join(out, "m.npz")), f.read()


def assert_same_archive(a, b):
    assert sorted(a.files) == sorted(b.files)
    for name in ("joint_names", "body_names"):
        assert list(a[name]) == list(b[name])
    for name in a.files:
        if name not in ("joint_names", "body_names"):
            assert a[name].shape == b[name].shape, name
            assert np.allclose(a[name], b[name], rtol=0, atol=1e-9), name


def assert_same_csv(a, b):
    ra, rb = list(csv.reader(a.splitlines())), list(csv.reader(b.splitlines()))
    assert ra[0] == rb[0] and len(ra) == len(rb)
    assert np.allclose(np.array(ra[1:], float), np.array(rb[1:], float), rtol=0, atol=1e-9)


def test_a_python_run_saves_the_files_iktc_retarget_writes():
    """`KeypointTrajectory.save_npz` / `save_csv` write what `iktc retarget` writes for the same
    clip, at the control rate and at another output rate."""
    run = iktc.retarget_keypoints(iktc.load_motion(str(CLIP)), iktc.Robot("g1"))
    npz, text = saved(run)
    cli, cli_text = cli_npz()
    assert_same_archive(npz, cli)
    assert_same_csv(text, cli_text)
    assert list(npz["body_names"]) == run.body_names and float(npz["fps"]) == 200.0
    # At the control rate every tick is copied: the archive holds the run's own arrays.
    assert np.array_equal(npz["joint_pos"], run.q[:, 7:])
    assert np.array_equal(npz["base_pos"], run.q[:, :3])
    slow, slow_text = saved(run, rate=50.0)
    cli_slow, cli_slow_text = cli_npz("--rate", "50")
    assert_same_archive(slow, cli_slow)
    assert_same_csv(slow_text, cli_slow_text)
    # 50 Hz divides 200 Hz: its frames are every fourth tick, copied.
    n = slow["joint_pos"].shape[0]
    assert float(slow["fps"]) == 50.0 and n == (len(run) - 1) // 4 + 1
    assert np.array_equal(slow["joint_pos"], npz["joint_pos"][::4][:n])
    assert np.array_equal(slow["body_pos_w"], npz["body_pos_w"][::4][:n])


def test_saving_a_run_rejects_a_bad_rate_and_an_unwritable_path():
    run = iktc.retarget_keypoints(iktc.load_motion("humanoid3d_walk"), iktc.Robot("g1"))
    out = tempfile.mkdtemp()
    for rate in (0.0, -50.0, float("nan"), float("inf")):
        try:
            run.save_npz(os.path.join(out, "m.npz"), rate=rate)
        except iktc.IktcError as e:
            assert "rate" in str(e)
        else:
            raise AssertionError(f"rate {rate} accepted")
    assert not os.path.exists(os.path.join(out, "m.npz"))
    missing = os.path.join(out, "no such folder", "m.csv")
    try:
        run.save_csv(missing)
    except iktc.IktcError as e:
        assert "no such folder" in str(e)
    else:
        raise AssertionError("an unwritable path accepted")


def test_retarget_joints_npz_equals_the_python_imitation():
    d, robot = batch_outputs("--retarget", "joints")
    sim = iktc.Imitation(robot, iktc.load_motion(str(CLIP)))
    n = d["joint_pos"].shape[0]
    assert sim.ticks == n
    qs, vs = [], []
    for _ in range(n):
        qs.append(sim.q.copy())
        vs.append(sim.v.copy())
        sim.tick()
    assert worst_difference(d, qs, vs) < 1e-9


def test_the_python_quality_figures_equal_the_batch_ones():
    """`retarget_keypoints(...).quality` holds the figures `iktc retarget` writes in the clip's
    quality.json (in cm and mm there in m), the static reach included when asked for."""
    out = tempfile.mkdtemp()
    subprocess.run([iktc_binary(), "retarget", str(CLIP), "--robot", "g1", "--no-viewer",
                    "--reach", "--out", out], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    with open(os.path.join(out, "humanoid3d_walk", "quality.json")) as f:
        figures = json.load(f)["figures"]
    robot = iktc.Robot("g1")
    motion = iktc.load_motion(str(CLIP))
    q = iktc.retarget_keypoints(motion, robot, reach=True).quality
    assert q["route"] == "keypoints" and len(q["points"]) == 13
    assert abs(q["mean_cm"] / 100 - figures["mean_keypoint_error"]) < 1e-12
    assert abs(q["slip_mm"] / 1000 - figures["foot_slip"]) < 1e-12
    assert abs(q["reach_cm"] / 100 - figures["reach_keypoint_error"]) < 1e-12
    assert abs(q["reach_run_cm"] / 100 - figures["reach_run_keypoint_error"]) < 1e-12
    assert abs(q["balanced_reach_cm"] / 100 - figures["balanced_reach_keypoint_error"]) < 1e-12
    assert abs(q["float_mm"] / 1000 - figures["foot_float"]) < 1e-12
    assert q["float_share"] == figures["foot_float_share"] and 0 <= q["float_share"] <= 1
    # The joints on a position limit, most often first; the first is the report's.
    shares = [share for _, share in q["on_limit"]]
    assert shares == sorted(shares, reverse=True) and all(0 < s <= 1 for s in shares)
    first = q["on_limit"][0] if q["on_limit"] else ("", 0.0)
    assert first[0] == figures["most_on_limit"] and first[1] == figures["most_on_limit_share"]
    assert 0 < q["reach_cm"] <= q["reach_run_cm"]
    # The per-point means average to the mean; every margin says no limit was exceeded.
    assert abs(np.mean([p["mean_cm"] for p in q["points"]]) - q["mean_cm"]) < 1e-9
    assert max(q["position_margin"], q["velocity_margin"], q["acceleration_margin"]) < 1e-6
    plain = iktc.retarget_keypoints(motion, robot).quality
    assert plain["reach_cm"] is None and plain["reach_run_cm"] is None
    assert plain["mean_cm"] == q["mean_cm"]
