"""`iktc retarget`'s NPZ and CSV read by numpy and the csv module, against the Python imitation
of the same clip (an independent path through the bindings)."""
import csv
import os
import subprocess
import tempfile

import numpy as np

import iktc
from test_controller import REPO, iktc_binary

CLIP = REPO / "crates" / "iktc" / "data" / "motions" / "deepmimic" / "humanoid3d_walk.txt"


def test_retarget_npz_and_csv_equal_the_python_imitation():
    out = tempfile.mkdtemp()
    subprocess.run([iktc_binary(), "retarget", str(CLIP), "--robot", "g1", "--no-viewer",
                    "--out", out], check=True, stdout=subprocess.DEVNULL,
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
    # The Python imitation of the same clip: q = (base position, quaternion x y z w, joints).
    sim = iktc.Imitation(robot, iktc.load_motion(str(CLIP)))
    assert sim.ticks == n
    worst = 0.0
    for k in range(n):
        q = sim.q
        worst = max(worst, np.abs(q[7:] - d["joint_pos"][k]).max(),
                    np.abs(q[:3] - d["base_pos"][k]).max(),
                    np.abs(q[3:7] / np.linalg.norm(q[3:7]) - d["base_quat_xyzw"][k]).max())
        sim.tick()
    assert worst < 1e-9, worst
