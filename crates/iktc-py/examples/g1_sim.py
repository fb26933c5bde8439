"""The Unitree G1 in MuJoCo, driven by iktc tick by tick (the closed loop of issue 16).

The plant: the G1 MJCF of Unitree (``crates/iktc/data/robots/g1/g1_29dof_rev_1_0.xml``) with
its meshes left out (they carry no mass: every body has its own inertial; only the feet's four
contact spheres and the thighs' cylinders collide), its ``<motor>`` actuators turned into
position servos ``τ = KP (q_cmd − q) − KV q̇`` [N·m] (clipped to each joint's
``actuatorfrcrange``), the ``implicitfast`` integrator at ``PHYSICS_STEP``, and a 6-axis
force/torque sensor at each ankle roll joint (a site at the joint, ``force`` and ``torque``).

The controller: ``iktc.Imitation`` on the built-in ``g1`` profile (Table 1 stack, IKTC, viable
bounds) integrates its own kinematic state at ``CONTROL_PERIOD``; every tick its joint angles
are the servos' set points (position control, as on the paper's Hubo). The ZMP is measured from
the two ankle sensors by eqs. 29–30 (``iktc.measure_zmp``); the damping controller (Section 4)
turns it into a COM offset added to the imitation's COM reference.
"""
from __future__ import annotations

import math
import pathlib
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

import mujoco
import numpy as np

import iktc

REPO = pathlib.Path(__file__).resolve().parents[3]
MJCF = REPO / "crates" / "iktc" / "data" / "robots" / "g1" / "g1_29dof_rev_1_0.xml"

#: Servo stiffness [N·m/rad]: stiffer tracks better and stiffens the ankle of the IPCJ model.
KP = 500.0
#: Servo damping [N·m·s/rad].
KV = 20.0
#: Physics step [s]: 1 ms with ``implicitfast`` stands; explicit Euler at 1 ms falls.
PHYSICS_STEP = 0.001
#: Control period [s]: one iktc tick, then CONTROL_PERIOD / PHYSICS_STEP physics steps.
CONTROL_PERIOD = 0.005
#: A foot whose sensed normal force is at most this is unloaded [N] (sensor noise is none here;
#: the lifted foot's own weight is ≈ 6 N).
MIN_NORMAL_FORCE = 10.0
FEET = ("right_ankle_roll_link", "left_ankle_roll_link")  # iktc's order: right, then left
SENSOR_SITES = {"right": "right_ankle_ft", "left": "left_ankle_ft"}


def plant_xml(mjcf: pathlib.Path = MJCF, kp: float = KP, kv: float = KV,
              physics_step: float = PHYSICS_STEP) -> str:
    """The MJCF text of the plant (see the module docstring)."""
    root = ET.parse(mjcf).getroot()
    compiler = root.find("compiler")
    if compiler is not None and "meshdir" in compiler.attrib:
        del compiler.attrib["meshdir"]
    for asset in root.findall("asset"):
        for mesh in asset.findall("mesh"):
            asset.remove(mesh)
    for parent in root.iter():
        for g in list(parent.findall("geom")):
            if g.get("type") == "mesh":
                parent.remove(g)
    opt = root.find("option")
    if opt is None:
        opt = ET.SubElement(root, "option")
    opt.set("timestep", repr(physics_step))
    opt.set("integrator", "implicitfast")
    act = root.find("actuator")
    for m in list(act):
        joint = m.get("joint")
        act.remove(m)
        ET.SubElement(act, "general", name=joint, joint=joint, gaintype="fixed",
                      biastype="affine", gainprm=f"{kp}", biasprm=f"0 {-kp} 0")
    for m in list(act):
        joint = m.get("joint")
        ET.SubElement(act, "general", name=f"{joint}_rate", joint=joint, gaintype="fixed",
                      biastype="affine", gainprm=f"{kv}", biasprm=f"0 0 {-kv}")
    sensor = root.find("sensor")
    for side, site in SENSOR_SITES.items():
        body = next(b for b in root.iter("body") if b.get("name") == f"{side}_ankle_roll_link")
        ET.SubElement(body, "site", name=site, pos="0 0 0", size="0.01")
        ET.SubElement(sensor, "force", name=f"{side}_ankle_force", site=site)
        ET.SubElement(sensor, "torque", name=f"{side}_ankle_torque", site=site)
    return ET.tostring(root, encoding="unicode")


def tilt(xmat: np.ndarray) -> float:
    """Angle between a body's z axis and the world's [rad]."""
    return math.acos(max(-1.0, min(1.0, float(xmat.reshape(3, 3)[2, 2]))))


class Plant:
    """The MuJoCo G1 with the joint order of an iktc robot."""

    def __init__(self, robot: iktc.Robot, kp: float = KP, kv: float = KV,
                 physics_step: float = PHYSICS_STEP):
        self.model = mujoco.MjModel.from_xml_string(plant_xml(kp=kp, kv=kv,
                                                              physics_step=physics_step))
        self.data = mujoco.MjData(self.model)
        self.robot = robot
        m = self.model
        names = robot.joint_names
        self.qadr = np.array([m.jnt_qposadr[m.joint(n).id] for n in names])
        self.dadr = np.array([m.jnt_dofadr[m.joint(n).id] for n in names])
        self.act = np.array([m.actuator(n).id for n in names])
        self.act_rate = np.array([m.actuator(f"{n}_rate").id for n in names])
        self.feet = [m.body(f).id for f in FEET]
        self.pelvis = m.body("pelvis").id
        self.sensor = {}
        for side, site in SENSOR_SITES.items():
            self.sensor[side] = (m.site(site).id,
                                 m.sensor_adr[m.sensor(f"{side}_ankle_force").id],
                                 m.sensor_adr[m.sensor(f"{side}_ankle_torque").id])
        self.substeps = int(round(CONTROL_PERIOD / m.opt.timestep))

    def set_state(self, q: np.ndarray) -> None:
        """Places the robot at iktc's q (base position, quaternion x y z w, joints), at rest."""
        d = self.data
        d.qpos[:3] = q[:3]
        d.qpos[3:7] = [q[6], q[3], q[4], q[5]]  # MuJoCo's quaternion is w x y z
        d.qpos[self.qadr] = q[7:]
        d.qvel[:] = 0.0
        d.ctrl[self.act] = q[7:]
        d.ctrl[self.act_rate] = 0.0
        mujoco.mj_forward(self.model, d)

    def command(self, q: np.ndarray, v: np.ndarray | None = None) -> None:
        """Servo set points from iktc's q [rad] and v [rad/s] (None: rate set point 0)."""
        self.data.ctrl[self.act] = q[7:]
        self.data.ctrl[self.act_rate] = 0.0 if v is None else v[6:]

    def advance(self, push: np.ndarray | None = None) -> None:
        """One control period of physics; `push` [N] is applied at the pelvis meanwhile."""
        d = self.data
        if push is not None:
            d.xfrc_applied[self.pelvis, :3] = push
        for _ in range(self.substeps):
            mujoco.mj_step(self.model, d)
        if push is not None:
            d.xfrc_applied[self.pelvis, :3] = 0.0

    def joint_positions(self) -> np.ndarray:
        return self.data.qpos[self.qadr].copy()

    def foot_pose(self, i: int) -> np.ndarray:
        """4 × 4 pose of foot i (right, left) in the world [m]."""
        h = np.eye(4)
        h[:3, :3] = self.data.xmat[self.feet[i]].reshape(3, 3)
        h[:3, 3] = self.data.xpos[self.feet[i]]
        return h

    def sensor_reading(self, side: str):
        """(position [m], force [N], torque [N·m]) of the ground on the foot, world axes.

        MuJoCo's force/torque sensors give the wrench the child (foot) exerts on its parent,
        in the site's axes, at the site; with the foot's own weight and inertia neglected
        (0.61 kg) the ground's wrench on the foot is the opposite: the negated reading,
        rotated into the world.
        """
        site, fa, ta = self.sensor[side]
        r = self.data.site_xmat[site].reshape(3, 3)
        f = -(r @ self.data.sensordata[fa:fa + 3])
        t = -(r @ self.data.sensordata[ta:ta + 3])
        return self.data.site_xpos[site].copy(), f, t

    def zmp(self):
        """ZMP from the two ankle sensors (eqs. 29–30): ((x, y) or None, status)."""
        return iktc.measure_zmp(self.sensor_reading("left"), self.sensor_reading("right"),
                                MIN_NORMAL_FORCE)

    def pelvis_height(self) -> float:
        return float(self.data.xpos[self.pelvis][2])

    def base_tilt(self) -> float:
        return tilt(self.data.xmat[self.pelvis])


@dataclass
class Log:
    """Per control tick of a run."""
    t: list = field(default_factory=list)
    pelvis_height: list = field(default_factory=list)
    tilt: list = field(default_factory=list)
    zmp: list = field(default_factory=list)
    zmp_margin: list = field(default_factory=list)
    slip: list = field(default_factory=list)
    joint_error: list = field(default_factory=list)
    upper_error: list = field(default_factory=list)
    com_offset: list = field(default_factory=list)
    qpos: list = field(default_factory=list)
    q_cmd: list = field(default_factory=list)


def summarise(log: Log, fallen_height: float) -> dict:
    """The run's figures: stayed up, pelvis height, base tilt, foot slip, ZMP margin, tracking."""
    h = np.array(log.pelvis_height)
    margins = np.array([m for m in log.zmp_margin if m is not None])
    je = np.array(log.joint_error)
    ue = np.array(log.upper_error)
    return {
        "ticks": len(log.t),
        "duration_s": len(log.t) * CONTROL_PERIOD,
        "stayed_up": bool(h.min() > fallen_height),
        "pelvis_height_min_m": float(h.min()),
        "pelvis_height_max_m": float(h.max()),
        "base_tilt_max_rad": float(np.max(log.tilt)),
        "foot_slip_max_m": float(np.max(log.slip)),
        "zmp_ticks_measured": int(margins.size),
        "zmp_margin_min_m": float(margins.min()) if margins.size else float("nan"),
        "zmp_inside": bool(margins.size == len(log.t) and margins.min() > 0.0),
        "joint_error_rms_rad": float(np.sqrt(np.mean(je ** 2))),
        "joint_error_max_rad": float(np.abs(je).max()),
        "upper_body_error_rms_rad": float(np.sqrt(np.mean(ue ** 2))),
        "upper_body_error_max_rad": float(np.abs(ue).max()),
    }


class Loop:
    """iktc's imitation of a clip commanding the MuJoCo G1, tick by tick."""

    def __init__(self, clip: str = "humanoid3d_dance_b", duration: float | None = None,
                 kp: float = KP, kv: float = KV, physics_step: float = PHYSICS_STEP,
                 rate_feedforward: bool = True, time_scale: float = 1.0,
                 robot: iktc.Robot | None = None):
        self.rate_feedforward = rate_feedforward
        self.robot = iktc.Robot("g1") if robot is None else robot
        self.sim = iktc.Imitation(self.robot, iktc.load_motion(clip), dt=CONTROL_PERIOD,
                                  duration=duration, time_scale=time_scale)
        self.plant = Plant(self.robot, kp=kp, kv=kv, physics_step=physics_step)
        self.plant.set_state(self.sim.q)
        self.upper = [self.robot.q_index(n) - 7 for n in self.sim.upper_body_joints]
        self.feet0 = [self.plant.foot_pose(i) for i in range(2)]
        self.log = Log()
        self.t = 0.0

    def settle(self, seconds: float) -> None:
        """Holds the initial command while the servos take the load (not logged)."""
        q = self.sim.q
        for _ in range(int(round(seconds / CONTROL_PERIOD))):
            self.plant.command(q)
            self.plant.advance()
        self.feet0 = [self.plant.foot_pose(i) for i in range(2)]

    def step(self, imitate: bool = True, com_offset=None, push=None) -> None:
        """One control tick: iktc (if `imitate`, else the last command is held), the servos'
        set points, CONTROL_PERIOD of physics, the measurements."""
        if imitate:
            self.sim.set_com_offset(com_offset)
            report = self.sim.tick()
            if report.violation > 1e-9:
                raise AssertionError(f"iktc left its acceleration box by {report.violation}")
        q = self.sim.q
        self.plant.command(q, self.sim.v if self.rate_feedforward else None)
        self.plant.advance(push)
        self.t += CONTROL_PERIOD
        self.record(q, com_offset)

    def record(self, q, com_offset) -> None:
        p, log = self.plant, self.log
        log.t.append(self.t)
        log.pelvis_height.append(p.pelvis_height())
        log.tilt.append(p.base_tilt())
        zmp, _ = p.zmp()
        log.zmp.append(zmp)
        feet = [p.foot_pose(i) for i in range(2)]
        log.zmp_margin.append(None if zmp is None else self.sim.support_margin(zmp, feet))
        log.slip.append(max(float(np.linalg.norm(f[:2, 3] - f0[:2, 3]))
                            for f, f0 in zip(feet, self.feet0)))
        qj = p.joint_positions()
        err = qj - q[7:]
        log.joint_error.append(float(np.abs(err).max()))
        up = self.sim.upper_body_reference()
        log.upper_error.append(float(np.abs(qj[self.upper] - up).max()))
        log.com_offset.append(com_offset)
        log.qpos.append(p.data.qpos.copy())
        log.q_cmd.append(q.copy())

    def summary(self) -> dict:
        # Fallen: the pelvis 0.25 m below its standing height (0.76 m).
        return summarise(self.log, fallen_height=0.5)


def run_standing(duration: float | None = None, settle: float = 0.5,
                 clip: str = "humanoid3d_dance_b", rate_feedforward: bool = True,
                 time_scale: float = 1.0):
    """(a) Standing imitation of the clip's upper body with the feet held; returns the loop."""
    loop = Loop(clip=clip, duration=duration, rate_feedforward=rate_feedforward,
                time_scale=time_scale)
    loop.settle(settle)
    for _ in range(loop.sim.ticks):
        loop.step()
    return loop


def planned_zmp(plant: Plant, qs: list, dt: float = CONTROL_PERIOD) -> np.ndarray:
    """The ZMP the kinematic plan asks for [m], one row per tick (NaN at the two ends).

    The plan's configurations `qs` (iktc's q per tick) are put into MuJoCo's coordinates; rates
    and accelerations by central differences (``mj_differentiatePos``); MuJoCo's inverse
    dynamics (``mj_inverse``) then gives the wrench the ground must exert on the free base, force
    F and torque τ at the base origin o (world axes), and the ZMP is the ground point where its
    horizontal moment vanishes: p_x = o_x − (τ_y + o_z F_x)/F_z, p_y = o_y + (τ_x − o_z F_y)/F_z.
    Constraints (the floor's contacts) are disabled for it: the free joint's force is then the
    whole external wrench.
    """
    m = plant.model
    d = mujoco.MjData(m)
    flags = m.opt.disableflags
    m.opt.disableflags = flags | mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    try:
        return _planned_zmp(plant, m, d, qs, dt)
    finally:
        m.opt.disableflags = flags


def _planned_zmp(plant, m, d, qs, dt):
    qpos = []
    for q in qs:
        x = np.zeros(m.nq)
        x[:3] = q[:3]
        x[3:7] = [q[6], q[3], q[4], q[5]]
        x[plant.qadr] = q[7:]
        qpos.append(x)
    n = len(qpos)
    out = np.full((n, 2), np.nan)
    vel = np.zeros((n, m.nv))
    for k in range(1, n - 1):
        mujoco.mj_differentiatePos(m, vel[k], 2 * dt, qpos[k - 1], qpos[k + 1])
    for k in range(2, n - 2):
        d.qpos[:] = qpos[k]
        d.qvel[:] = vel[k]
        d.qacc[:] = (vel[k + 1] - vel[k - 1]) / (2 * dt)
        mujoco.mj_inverse(m, d)
        r = d.xmat[plant.pelvis].reshape(3, 3)
        f = d.qfrc_inverse[:3]  # free joint: linear part in world axes
        tau = r @ d.qfrc_inverse[3:6]  # angular part in the body's axes
        o = d.qpos[:3]
        out[k] = [o[0] - (tau[1] + o[2] * f[0]) / f[2], o[1] + (tau[0] - o[2] * f[1]) / f[2]]
    return out
