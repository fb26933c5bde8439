"""`iktc.profile_init`: a starting profile for a URDF, as `iktc profile init` writes it, that
`iktc.Robot` loads with its feet, pelvis and hands."""
import os
import subprocess
import tempfile

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
