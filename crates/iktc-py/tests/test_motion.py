"""Robots from profiles, motion loading, retargeting and the imitation, from Python, against
independently computed values and the Rust command line."""
import csv
import os
import subprocess
import tempfile

import numpy as np
import pytest

import iktc
from test_controller import REPO, iktc_binary

DATA = REPO / "crates" / "iktc" / "data"
BVH = REPO / "crates" / "iktc" / "tests" / "data" / "motions" / "cmu" / "131_01.bvh"
DT = 0.005  # control period [s]


def test_a_robot_from_a_builtin_name_a_profile_file_and_a_urdf_agree():
    by_name = iktc.Robot("g1")
    by_profile = iktc.Robot(str(DATA / "profiles" / "g1.toml"))
    by_urdf = iktc.Robot(str(DATA / "robots" / "g1" / "g1_29dof_rev_1_0.urdf"), floating=True)
    assert by_name.has_profile and by_profile.has_profile and not by_urdf.has_profile
    for r in (by_profile, by_urdf):
        assert r.joint_names == by_name.joint_names
        assert (r.nq, r.nv) == (by_name.nq, by_name.nv) == (36, 35)
        assert r.total_mass == pytest.approx(by_name.total_mass, rel=1e-12)
    # The profile's acceleration limits (10 × the velocity limit) replace the URDF's none.
    _, _, vel, acc = by_profile.limits()
    assert np.allclose(acc[6:], 10.0 * vel[6:])
    with pytest.raises(iktc.IktcError, match="apply to URDF and MJCF files only"):
        iktc.Robot("g1", floating=True)
    with pytest.raises(iktc.IktcError, match="cannot read the profile"):
        iktc.Robot("no_such_profile.toml")


def test_a_builtin_clip_and_its_file_load_to_the_same_keypoints():
    builtin = iktc.load_motion("humanoid3d_dance_b")
    from_file = iktc.load_motion(str(DATA / "motions" / "deepmimic" / "humanoid3d_dance_b.txt"))
    assert builtin.format == from_file.format == "DeepMimic JSON"
    names, times, pos = builtin.keypoints()
    names_f, times_f, pos_f = from_file.keypoints()
    assert names == names_f and np.array_equal(times, times_f) and np.array_equal(pos, pos_f)
    assert pos.dtype == np.float64 and pos.shape == (len(times), len(names), 3)
    # Z up: the head is above the ankles in every frame.
    head, la, ra = (names.index(n) for n in ("head", "left_ankle", "right_ankle"))
    assert np.all(pos[:, head, 2] > pos[:, la, 2] + 1.0)
    assert np.all(pos[:, head, 2] > pos[:, ra, 2] + 1.0)
    with pytest.raises(iktc.IktcError):
        iktc.load_motion(str(REPO / "no_such_motion.bvh"))


def test_retargeting_returns_arrays_and_the_resampled_splines_pass_through_the_frames():
    robot = iktc.Robot("g1")
    rt = iktc.retarget_joint_angles(iktc.load_motion("humanoid3d_dance_b"), robot)
    f, j = rt.joint_angles.shape
    assert f == rt.times.shape[0] and j == len(rt.joint_names) and rt.pelvis_angles.shape == (f, 3)
    assert all(n in robot.joint_names for n in rt.joint_names)
    # Resampled at the clip's own (uniform) frame period, the ticks are the frames: the cubic
    # splines interpolate their knots.
    period = float(np.mean(np.diff(rt.times)))
    assert np.allclose(np.diff(rt.times), period, atol=1e-9)
    refs = rt.resample(period)
    n = min(len(refs), f)
    assert refs.position.shape == (len(refs), j)
    assert np.allclose(refs.position[:n], rt.joint_angles[:n], atol=1e-9)
    assert np.allclose(refs.pelvis_height[:n, 0], rt.pelvis_height[:n], atol=1e-9)
    # Rates: a central difference of the spline at the control rate.
    fine = rt.resample(DT)
    fd = (fine.position[2:] - fine.position[:-2]) / (2 * DT)
    assert np.allclose(fine.velocity[1:-1], fd, atol=0.05 * max(1.0, np.abs(fd).max()))


def test_a_bvh_file_loads_with_its_body_points_in_metres_z_up():
    motion = iktc.load_motion(str(BVH))
    assert motion.format == "BVH" and motion.has_skeleton
    names, times, pos = motion.keypoints()
    assert pos.shape == (len(times), len(names), 3) and np.all(np.isfinite(pos))
    # A standing adult: the head 1.2–2.1 m above the ankles (units decided from that height).
    head, ankle = names.index("head"), names.index("left_ankle")
    assert 1.2 < pos[0, head, 2] - pos[0, ankle, 2] < 2.1


def test_a_map_is_needed_without_a_profile_and_the_profile_map_is_the_builtin_one():
    motion = iktc.load_motion("humanoid3d_dance_b")
    bare = iktc.Robot(str(DATA / "robots" / "jvrc1" / "jvrc1.urdf"), floating=True)
    with pytest.raises(iktc.IktcError, match="has no profile: pass map="):
        iktc.retarget_joint_angles(motion, bare)
    by_profile = iktc.retarget_joint_angles(motion, iktc.Robot("jvrc1"))
    by_name = iktc.retarget_joint_angles(motion, bare, map="deepmimic_jvrc1")
    assert by_name.joint_names == by_profile.joint_names
    assert np.array_equal(by_name.joint_angles, by_profile.joint_angles)


@pytest.mark.parametrize("bounds", ["viable", "quiet"])
def test_the_imitation_from_python_equals_the_rust_command_line(bounds):
    out = tempfile.mkdtemp()
    # The joint route: the one the Python `Imitation` runs.
    subprocess.run([iktc_binary(), "imitate", "--retarget", "joints", "--robot", "g1",
                    "--bounds", bounds, "--out", out], check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(out, "joints.csv")) as f:
        rows = list(csv.DictReader(f))
    robot = iktc.Robot("g1")
    sim = iktc.Imitation(robot, iktc.load_motion("humanoid3d_dance_b"), bounds=bounds)
    assert sim.ticks == len(rows)
    names = robot.joint_names
    worst = 0.0
    for row in rows:
        q = sim.q
        worst = max(worst, max(abs(q[7 + i] - float(row[n])) for i, n in enumerate(names)))
        report = sim.tick()
        assert report.violation <= 1e-9
    # Same code, same inputs: equal up to the CSV's printed digits.
    assert worst < 1e-9, worst


def test_the_imitation_holds_the_feet_and_moves_the_com_by_the_offset():
    robot = iktc.Robot("g1")
    sim = iktc.Imitation(robot, iktc.load_motion("humanoid3d_dance_b"), duration=1.0)
    # The clip cut at its first frame at or past 1 s (60 Hz frames), resampled at 5 ms.
    assert 1.0 <= (sim.ticks - 1) * DT < 1.0 + 1 / 60 + DT
    feet = sim.feet()
    for _ in range(100):
        sim.tick()
    sim.set_com_offset((0.01, -0.005))
    for _ in range(100):
        sim.tick()
    q = sim.q
    for name, pose in feet:
        assert np.abs(robot.frame_pose(q, name)[:3, 3] - pose[:3, 3]).max() < 1e-3
    # COM xy: the standing reference plus the offset (k_p = 100 s⁻², 0.5 s: converged to ~mm).
    target = sim.com_reference()[:2] + [0.01, -0.005]
    assert np.abs(robot.com(q)[:2] - target).max() < 2e-3
    # The support margin of the polygon's own centre is half the narrower extent, here the
    # sole length (the feet stand side by side, 0.237 m apart, soles 0.17 m × 0.05 m).
    centre = np.mean([p[:2, 3] for _, p in feet], axis=0) + [sim.sole()["sole_offset_x"], 0.0]
    assert sim.support_margin(tuple(centre)) == pytest.approx(0.5 * sim.sole()["sole_length"])
    with pytest.raises(iktc.IktcError, match="no profile"):
        iktc.Imitation(iktc.Robot("planar3r"), iktc.load_motion("humanoid3d_dance_b"))


def test_the_imitation_refuses_unknown_bounds_and_solver_settings_out_of_range():
    robot, motion = iktc.Robot("g1"), iktc.load_motion("humanoid3d_dance_b")
    with pytest.raises(iktc.IktcError, match="expected one of viable, paper, quiet"):
        iktc.Imitation(robot, motion, bounds="soft")
    with pytest.raises(iktc.IktcError, match="rebase_release"):
        iktc.Imitation(robot, motion, duration=0.1, rebase_release=0.0)
    with pytest.raises(iktc.IktcError, match="smoothing"):
        iktc.Imitation(robot, motion, duration=0.1, smoothing=0.0)


def test_the_imitation_low_passes_its_references_by_default():
    robot, motion = iktc.Robot("g1"), iktc.load_motion("humanoid3d_dance_b")

    def figures(**kw):
        sim = iktc.Imitation(robot, motion, duration=1.0, **kw)
        refs = []
        for _ in range(sim.ticks):
            refs.append(sim.upper_body_reference())
            sim.tick()
        a = np.diff(np.array(refs), 2, axis=0) / DT ** 2
        d = np.diff(a, axis=0)
        reversals = np.mean(np.sign(d[1:]) * np.sign(d[:-1]) < 0, axis=0)
        jerk = np.sqrt(np.mean((d / DT) ** 2, axis=0))
        return np.median(jerk), np.median(reversals)

    # Per upper-body joint, the median over the joints: RMS jerk of the references 2 470 →
    # 1 060 rad/s³ at 6 Hz (the default), the change of their acceleration reversing on
    # 17.5 % → 4.5 % of the ticks. (A few joints' decomposition swings past the shoulder's
    # gimbal lock dominate the RMS over all joints, which falls only 3 %.)
    (j0, r0), (j6, r6) = figures(smoothing=None), figures()
    assert (j6, r6) == figures(smoothing=6.0)
    assert j6 < 0.5 * j0 and r0 > 0.1 and r6 < 0.1, (j0, r0, j6, r6)


def test_a_com_offset_ramp_lags_by_kv_over_kp_unless_its_rates_are_fed_forward():
    robot = iktc.Robot("g1")
    rate = 0.05  # [m/s]
    errors = {}
    for feedforward in (False, True):
        sim = iktc.Imitation(robot, iktc.load_motion("humanoid3d_dance_b"), duration=1.0)
        for _ in range(100):
            sim.tick()
        for k in range(100):
            off = (rate * k * DT, 0.0)
            if feedforward:
                sim.set_com_offset(off, (rate, 0.0), (0.0, 0.0))
            else:
                sim.set_com_offset(off)
            sim.tick()
        # The COM after the last tick against the offset reference of that tick.
        target = sim.com_reference()[0] + rate * 99 * DT
        errors[feedforward] = target - robot.com(sim.q)[0]
    # CLIK c̈ = k_v (ċ_ref − ċ) + k_p (c_ref − c) follows a ramp with the steady error
    # rate · k_v / k_p (k_p = 100 s⁻², k_v = 20 s⁻¹: 1 cm; 0.5 s = 5 time constants in).
    assert errors[False] == pytest.approx(rate * 20.0 / 100.0, rel=0.1), errors
    assert abs(errors[True]) < 1e-3, errors
    with pytest.raises(iktc.IktcError, match="velocity"):
        sim.set_com_offset((0.0, 0.0), (float("nan"), 0.0))


def test_a_narrowed_knee_keeps_the_g1_leg_from_straightening():
    # The clip's pelvis rises up to 0.13 m above its first frame; G1 at its posture (knee
    # 0.6 rad) reaches only ≈ 0.03 m higher with straight legs, so the right knee is driven to
    # straight (its lower limit is −0.087 rad). Narrowed, it stays in its range.
    robot, motion = iktc.Robot("g1"), iktc.load_motion("humanoid3d_dance_b")
    i = robot.q_index("right_knee_joint")
    lowest = {}
    for narrow in (None, [("right_knee_joint", 0.3, 2.8), ("left_knee_joint", 0.3, 2.8)]):
        sim = iktc.Imitation(robot, motion, narrow=narrow)
        low = np.inf
        for _ in range(sim.ticks):
            sim.tick()
            low = min(low, sim.q[i])
        lowest[narrow is not None] = low
    assert lowest[False] < 0.05 and lowest[True] >= 0.3 - 1e-9, lowest
    with pytest.raises(iktc.IktcError, match="no_such_joint"):
        iktc.Imitation(robot, motion, narrow=[("no_such_joint", 0.0, 1.0)])
    with pytest.raises(iktc.IktcError, match="no_such_joint"):
        iktc.Walking(robot, motion, narrow=[("no_such_joint", 0.0, 1.0)])
