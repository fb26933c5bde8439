"""`iktc.profile_init`: a starting profile for a URDF, as `iktc profile init` writes it, that
`iktc.Robot` loads with its feet, pelvis and hands."""
import os
import subprocess
import tempfile

import numpy as np
import pytest

import iktc
from test_controller import REPO, iktc_binary

G1_URDF = REPO / "crates" / "iktc" / "data" / "robots" / "g1" / "g1_29dof_rev_1_0.urdf"


def test_profile_init_writes_the_cli_profile_and_the_robot_loads_it():
    out = tempfile.mkdtemp()
    path = os.path.join(out, "g1.toml")
    text = iktc.profile_init(str(G1_URDF), out=path)
    assert text.count("# guessed") >= 8
    with open(path) as f:
        assert f.read() == text
    # The command line writes the same profile for the same files.
    cli = os.path.join(out, "cli.toml")
    subprocess.run([iktc_binary(), "profile", "init", str(G1_URDF), "--out", cli], check=True,
                   stdout=subprocess.DEVNULL)
    with open(cli) as f:
        assert f.read() == text
    robot = iktc.Robot(path)
    assert robot.has_profile and robot.floating
    assert robot.nv == 6 + 29
    assert "left_rubber_hand" in robot.frame_names
    # Without `out`, the URDF key is the path as given.
    assert f'urdf = "{G1_URDF}"' in iktc.profile_init(str(G1_URDF))


def test_a_urdf_without_a_profile_points_to_profile_init():
    robot = iktc.Robot(str(G1_URDF))
    motion = iktc.load_motion("humanoid3d_walk")
    try:
        iktc.retarget_keypoints(motion, robot)
    except iktc.IktcError as e:
        assert "iktc.profile_init" in str(e), str(e)
    else:
        raise AssertionError("a robot without a profile retargeted")


T1_MJCF = REPO / "crates" / "iktc" / "tests" / "data" / "mjcf" / "booster_t1" / "t1_mocap.xml"


def test_an_mjcf_file_without_velocity_limits_gets_them_from_the_keywords_or_its_profile():
    # MJCF gives no velocity limits: every joint is unlimited unless told.
    bare = iktc.Robot(str(T1_MJCF))
    _, _, vel, acc = bare.limits()
    assert np.all(np.isinf(vel)) and np.all(np.isinf(acc))
    knee = bare.v_index("Left_Knee_Pitch")
    robot = iktc.Robot(str(T1_MJCF), default_velocity=20.0, velocity=[("Left_Knee_Pitch", 7.5)])
    _, _, vel, acc = robot.limits()
    joints = np.arange(6, robot.nv)
    others = joints[joints != knee]
    # The acceleration limits follow at 10 × the velocity limit (ModelOptions' default ratio).
    assert np.all(vel[others] == 20.0) and np.all(acc[others] == 200.0)
    assert vel[knee] == 7.5 and acc[knee] == 75.0
    with pytest.raises(iktc.IktcError, match="default_velocity"):
        iktc.Robot(str(T1_MJCF), default_velocity=-1.0)
    # profile_init writes a guessed default the profile's robot applies.
    out = tempfile.mkdtemp()
    path = os.path.join(out, "t1.toml")
    text = iktc.profile_init(str(T1_MJCF), out=path)
    assert "[velocity]\ndefault = 20.0 # guessed" in text
    _, _, vel, _ = iktc.Robot(path).limits()
    assert np.all(vel[6:] == 20.0)


def test_standing_puts_the_profile_posture_on_the_ground():
    robot = iktc.Robot("g1")
    q, v = robot.standing()
    assert q.shape == (robot.nq,) and np.all(v == 0.0)
    # The profile's bent knees (G1's built-in profile: 0.6 rad), the rest of its posture alike.
    assert q[robot.q_index("left_knee_joint")] == q[robot.q_index("right_knee_joint")] > 0.0
    # The base upright above the origin, raised so that the lower foot frame is at the
    # profile's ankle height (G1: 0.035 m): its sole on the ground.
    assert np.allclose(q[:2], 0.0) and np.allclose(q[3:7], [0.0, 0.0, 0.0, 1.0])
    feet = [robot.frame_pose(q, f)[2, 3] for f in ("left_ankle_roll_link", "right_ankle_roll_link")]
    assert min(feet) == pytest.approx(0.035, abs=1e-12)
    with pytest.raises(iktc.IktcError, match="no profile"):
        iktc.Robot(str(G1_URDF)).standing()
