"""An MJCF model read by iktc (`iktc.Robot("model.xml")`) against MuJoCo reading the same file:
body poses, total centre of mass and body Jacobians at seeded random configurations.

Layouts: iktc's q is (base position, base quaternion (x, y, z, w), joints), MuJoCo's qpos
(position, quaternion (w, x, y, z), joints), the joints in the same order. iktc's base velocity
is (linear, angular), both in the base's axes; MuJoCo's free joint qvel is the linear velocity
in world axes, then the angular velocity in the body's axes. So with R the base's rotation,
J_iktc[:, 0:3] = J_mujoco[:, 0:3] @ R and every other column is the same."""
import pathlib
import xml.etree.ElementTree as ET

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")
import iktc  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parents[3]
HUMANOID = REPO / "crates" / "iktc" / "tests" / "data" / "mjcf" / "humanoid.xml"
T1 = REPO / "crates" / "iktc" / "tests" / "data" / "mjcf" / "booster_t1" / "t1_mocap.xml"
G1_MJCF = REPO / "crates" / "iktc" / "data" / "robots" / "g1" / "g1_29dof_rev_1_0.xml"

# Largest difference of a body position [m], of a rotation matrix entry [-], of the total
# centre of mass [m] and of a Jacobian entry [m/rad or 1]: both compute in double precision
# from the same numbers, so they agree to round-off (~1e-15 per operation, ~30 bodies deep).
POSITION_TOL = 1e-9
ROTATION_TOL = 1e-9
COM_TOL = 1e-9
JACOBIAN_TOL = 1e-9
# Joint range used for unlimited hinges [rad].
UNLIMITED_RANGE = np.pi


def without_meshes(path, out):
    """A copy of the MJCF `path` without mesh assets and mesh geoms (the crate ships the G1's
    and the T1's MJCF without their meshes; their bodies have explicit inertials, so their
    masses are unchanged)."""
    tree = ET.parse(path)
    root = tree.getroot()
    for asset in root.iter("asset"):
        for m in list(asset.findall("mesh")):
            asset.remove(m)
    for parent in root.iter():
        for g in list(parent.findall("geom")):
            if g.get("type") == "mesh":
                parent.remove(g)
    tree.write(out)
    return out


def random_qpos(m, rng):
    """A MuJoCo qpos: free joint at a random pose, hinges and slides uniform in their range."""
    qpos = np.zeros(m.nq)
    for j in range(m.njnt):
        a = m.jnt_qposadr[j]
        if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            qpos[a:a + 3] = rng.uniform(-1, 1, 3)
            quat = rng.normal(size=4)
            qpos[a + 3:a + 7] = quat / np.linalg.norm(quat)
        elif m.jnt_limited[j]:
            qpos[a] = rng.uniform(*m.jnt_range[j])
        else:
            qpos[a] = rng.uniform(-UNLIMITED_RANGE, UNLIMITED_RANGE)
    return qpos


def to_iktc(qpos):
    """iktc's q of a MuJoCo qpos with a free joint first: the quaternion's w moved last."""
    w, x, y, z = qpos[3:7]
    return np.concatenate([qpos[0:3], [x, y, z, w], qpos[7:]])


@pytest.mark.parametrize("model, mujoco_file", [
    ("humanoid", None),
    ("g1", "strip"),
    ("t1", "strip"),
])
def test_iktc_and_mujoco_agree_on_bodies_com_and_jacobians(model, mujoco_file, tmp_path):
    path = {"humanoid": HUMANOID, "g1": G1_MJCF, "t1": T1}[model]
    robot = iktc.Robot(str(path))
    mj_path = path if mujoco_file is None else without_meshes(path, tmp_path / "m.xml")
    m = mujoco.MjModel.from_xml_path(str(mj_path))
    d = mujoco.MjData(m)
    assert robot.floating and robot.nq == m.nq and robot.nv == m.nv
    names = [m.joint(j).name for j in range(1, m.njnt)]
    assert robot.joint_names == names
    assert robot.total_mass == pytest.approx(m.body_mass.sum(), rel=1e-12)
    root = m.jnt_bodyid[0]
    rng = np.random.default_rng(11)
    for _ in range(10):
        qpos = random_qpos(m, rng)
        d.qpos[:] = qpos
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        q = to_iktc(qpos)
        assert np.abs(robot.com(q) - d.subtree_com[0]).max() < COM_TOL
        r_base = d.xmat[root].reshape(3, 3)
        for b in range(1, m.nbody):
            name = m.body(b).name
            pose = robot.frame_pose(q, name)
            assert np.abs(pose[:3, 3] - d.xpos[b]).max() < POSITION_TOL, name
            assert np.abs(pose[:3, :3] - d.xmat[b].reshape(3, 3)).max() < ROTATION_TOL, name
            jacp, jacr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
            mujoco.mj_jacBody(m, d, jacp, jacr, b)
            j_mj = np.vstack([jacp, jacr])
            j_mj[:, 0:3] = j_mj[:, 0:3] @ r_base
            j = robot.frame_jacobian(q, name)
            assert np.abs(j - j_mj).max() < JACOBIAN_TOL, name


def test_a_jacobian_column_moves_the_body_as_mujoco_integrates_the_velocity():
    """The velocity mapping itself, through MuJoCo's own integration: a small base velocity in
    iktc's convention, turned into qvel, moves the body as the Jacobian says."""
    robot = iktc.Robot(str(HUMANOID))
    m = mujoco.MjModel.from_xml_path(str(HUMANOID))
    d = mujoco.MjData(m)
    rng = np.random.default_rng(5)
    qpos = random_qpos(m, rng)
    d.qpos[:] = qpos
    mujoco.mj_kinematics(m, d)
    r_base = d.xmat[m.jnt_bodyid[0]].reshape(3, 3)
    v = rng.normal(size=m.nv)  # iktc's velocity
    qvel = v.copy()
    qvel[0:3] = r_base @ v[0:3]
    h = 1e-7  # step [s]: first-order error ~h·|v|² ≈ 1e-6 relative
    q2 = qpos.copy()
    mujoco.mj_integratePos(m, q2, qvel, h)
    d.qpos[:] = q2
    mujoco.mj_kinematics(m, d)
    b = m.body("hand_left").id
    moved = d.xpos[b].copy()
    d.qpos[:] = qpos
    mujoco.mj_kinematics(m, d)
    predicted = robot.frame_jacobian(to_iktc(qpos), "hand_left")[:3] @ v
    assert np.abs((moved - d.xpos[b]) / h - predicted).max() < 1e-4 * (1 + np.abs(predicted).max())


def test_profile_init_reads_an_mjcf_model_and_the_robot_loads_its_profile(tmp_path):
    out = tmp_path / "t1.toml"
    text = iktc.profile_init(str(T1), out=str(out))
    assert 'frame = "left_foot_link"' in text and 'frame = "right_foot_link"' in text
    robot = iktc.Robot(str(out))
    assert robot.has_profile and robot.floating
    assert robot.nv == mujoco.MjModel.from_xml_path(
        str(without_meshes(T1, tmp_path / "m.xml"))).nv


# A model written for this test: every orientation form, an Euler sequence mixing moving and
# fixed axes, degrees, a <frame>, classes with childclass, hinge and slide joints with `ref`
# and off-origin `pos`, a body with two joints, fullinertia, and masses from primitive geoms.
FEATURES = """<mujoco model="features">
  <compiler angle="degree" eulerseq="zXy"/>
  <default>
    <joint range="-90 90"/>
    <default class="arm"><joint axis="0 1 0" damping="1"/><geom type="capsule" size="0.03"/></default>
  </default>
  <worldbody>
    <body name="base" pos="0.1 0.2 1" euler="10 20 30">
      <freejoint name="root"/>
      <geom type="box" size="0.1 0.15 0.05" pos="0 0 0.02" euler="5 0 -15"/>
      <geom type="ellipsoid" size="0.05 0.08 0.03" pos="0.1 0 0"/>
      <body name="upper" pos="0 0.2 0" axisangle="1 1 0 35" childclass="arm">
        <joint name="shoulder_y" pos="0 0.01 0.02" ref="12"/>
        <joint name="shoulder_x" axis="1 0 0.3" pos="0 0 0.05"/>
        <geom fromto="0 0 0 0.25 0 -0.05"/>
        <frame pos="0.3 0 0" xyaxes="0 1 0 -1 0 0.2">
          <body name="lower" pos="0 0 -0.02">
            <joint name="elbow" class="arm" ref="-20"/>
            <inertial pos="0.1 0 0" mass="0.7" fullinertia="0.003 0.004 0.002 0.0004 -0.0002 0.0001"/>
            <body name="slider" zaxis="1 0.5 -0.2">
              <joint name="slide" type="slide" axis="0 0 1" range="-0.1 0.2" ref="0.05"/>
              <geom type="cylinder" size="0.02 0.04"/>
              <geom type="sphere" size="0.03" pos="0 0 0.05"/>
            </body>
          </body>
        </frame>
      </body>
      <body name="leg" pos="0 -0.1 -0.2" quat="0.9 0.1 -0.2 0.3">
        <joint name="hip" axis="1 0 0" limited="false"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.04"/>
      </body>
    </body>
  </worldbody>
</mujoco>"""


def test_every_orientation_form_and_joint_option_agrees_with_mujoco(tmp_path):
    path = tmp_path / "features.xml"
    path.write_text(FEATURES)
    robot = iktc.Robot(str(path))
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    assert robot.joint_names == [m.joint(j).name for j in range(1, m.njnt)]
    assert robot.total_mass == pytest.approx(m.body_mass.sum(), rel=1e-12)
    rng = np.random.default_rng(2)
    for _ in range(10):
        qpos = random_qpos(m, rng)
        d.qpos[:] = qpos
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        q = to_iktc(qpos)
        assert np.abs(robot.com(q) - d.subtree_com[0]).max() < COM_TOL
        r_base = d.xmat[1].reshape(3, 3)
        for b in range(1, m.nbody):
            name = m.body(b).name
            pose = robot.frame_pose(q, name)
            assert np.abs(pose[:3, 3] - d.xpos[b]).max() < POSITION_TOL, name
            assert np.abs(pose[:3, :3] - d.xmat[b].reshape(3, 3)).max() < ROTATION_TOL, name
            jacp, jacr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
            mujoco.mj_jacBody(m, d, jacp, jacr, b)
            j_mj = np.vstack([jacp, jacr])
            j_mj[:, 0:3] = j_mj[:, 0:3] @ r_base
            assert np.abs(robot.frame_jacobian(q, name) - j_mj).max() < JACOBIAN_TOL, name
