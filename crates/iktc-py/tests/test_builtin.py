"""What the iktc module itself provides in place of repository files: the built-in data files'
text (``iktc.builtin_text``), a profile robot with other acceleration and velocity limits
(``iktc.Robot(profile, accel=…)``), an imitation with the map's pelvis scales replaced
(``root_scales``); and ``iktc.mujoco`` without MuJoCo."""
import json
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import iktc
from test_controller import REPO

DATA = REPO / "crates" / "iktc" / "data"


def test_the_builtin_texts_are_the_crates_data_files():
    for kind, name, path in [
        ("mjcf", "g1", DATA / "robots" / "g1" / "g1_29dof_rev_1_0.xml"),
        ("urdf", "g1", DATA / "robots" / "g1" / "g1_29dof_rev_1_0.urdf"),
        ("urdf", "jvrc1", DATA / "robots" / "jvrc1" / "jvrc1.urdf"),
        ("profile", "g1", DATA / "profiles" / "g1.toml"),
        ("map", "deepmimic_g1", DATA / "maps" / "deepmimic_g1.toml"),
        ("clip", "humanoid3d_walk", DATA / "motions" / "deepmimic" / "humanoid3d_walk.txt"),
    ]:
        assert iktc.builtin_text(kind, name) == path.read_bytes().decode("utf-8"), (kind, name)
    assert ET.fromstring(iktc.builtin_text("mjcf", "g1")).tag == "mujoco"
    assert len(json.loads(iktc.builtin_text("clip", "humanoid3d_dance_b"))["Frames"]) > 100


def test_an_unknown_builtin_text_is_an_iktc_error_naming_the_argument():
    with pytest.raises(iktc.IktcError, match="kind = `robot`"):
        iktc.builtin_text("robot", "g1")
    with pytest.raises(iktc.IktcError, match="name = `jvrc1`.*\"mjcf\" \\(g1\\)"):
        iktc.builtin_text("mjcf", "jvrc1")
    with pytest.raises(iktc.IktcError, match="humanoid3d_walk"):
        iktc.builtin_text("clip", "no_such_clip")


def test_a_profile_robot_takes_acceleration_and_velocity_limits_from_the_keywords():
    g1 = iktc.Robot("g1")
    _, _, vel, acc = g1.limits()
    assert np.allclose(acc[6:], 10.0 * vel[6:])  # the profile's per_velocity
    knee = "left_knee_joint"
    k = g1.v_index(knee)
    # Every joint's acceleration limit 1 × its velocity limit, as the profile key
    # acceleration.limits would set it; the knee's velocity limit lowered.
    slow = iktc.Robot("g1", accel=[(n, float(vel[g1.v_index(n)])) for n in g1.joint_names],
                      velocity=[(knee, 5.0)])
    assert slow.has_profile
    _, _, vel1, acc1 = slow.limits()
    assert np.allclose(acc1[6:], vel[6:])
    assert vel1[k] == 5.0 and np.array_equal(np.delete(vel1, k), np.delete(vel, k))
    # The imitation runs on it (the profile's feet, pelvis and maps are kept).
    sim = iktc.Imitation(slow, iktc.load_motion("humanoid3d_dance_b"), duration=0.05)
    sim.tick()
    with pytest.raises(iktc.IktcError, match="accel, velocity or default_velocity.*no_such_joint"):
        iktc.Robot("g1", accel=[("no_such_joint", 10.0)])
    with pytest.raises(iktc.IktcError, match="acceleration.limits.left_knee_joint"):
        iktc.Robot("g1", accel=[(knee, -1.0)])
    with pytest.raises(iktc.IktcError, match="apply to URDF and MJCF files only"):
        iktc.Robot("g1", lock=[(knee, 0.0)])
    with pytest.raises(iktc.IktcError, match="without a profile"):
        iktc.Robot("planar3r", accel=[("q1", 1.0)])


def test_root_scales_replace_the_maps_pelvis_scales():
    robot = iktc.Robot("g1")
    motion = iktc.load_motion("humanoid3d_dance_b")
    free = iktc.Imitation(robot, motion)
    held = iktc.Imitation(robot, motion,
                          root_scales={"height_scale": 0.0, "pitch_scale": 0.0, "roll_scale": 0.0})
    base_free, base_held = [], []
    for _ in range(free.ticks):
        free.tick()
        held.tick()
        base_free.append(free.q[:7].copy())
        base_held.append(held.q[:7].copy())
    base_free, base_held = np.array(base_free), np.array(base_held)
    # The clip's pelvis rises and sinks by 3 cm and tilts; held, its height and its quaternion's
    # x and y (roll and pitch) stay where they start.
    assert np.ptp(base_free[:, 2]) > 0.02 and np.ptp(base_free[:, 3:5], axis=0).min() > 0.05
    assert np.ptp(base_held[:, 2]) < 1e-9 and np.ptp(base_held[:, 3:5], axis=0).max() < 1e-9
    with pytest.raises(iktc.IktcError, match="root_scales: unknown key `scale`"):
        iktc.Imitation(robot, motion, root_scales={"scale": 0.0})
    with pytest.raises(iktc.IktcError, match="root_scales\\[\"height_scale\"\\]"):
        iktc.Imitation(robot, motion, root_scales={"height_scale": float("nan")})


def test_iktc_imports_without_mujoco_and_its_mujoco_subpackage_says_how_to_install_it():
    code = ("import sys; sys.modules['mujoco'] = None\n"
            "import iktc\n"
            "assert 'iktc.mujoco' not in sys.modules\n"
            "try:\n"
            "    import iktc.mujoco\n"
            "except ImportError as e:\n"
            "    print(e)\n"
            "else:\n"
            "    raise SystemExit('imported without mujoco')\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "pip install mujoco" in out.stdout, out
