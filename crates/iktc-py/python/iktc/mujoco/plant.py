"""The MuJoCo G1 plant: position servos, ankle force/torque sensors, the joint torques that make
it follow a kinematic plan (``Feedforward``) and the ZMP a plan asks for (``planned_zmp``)."""
from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from typing import Optional, Sequence, Tuple, Union

import mujoco  # type: ignore[import-untyped]
import numpy as np
import numpy.typing as npt

import iktc

FloatArray = npt.NDArray[np.float64]
PathLike = Union[str, "os.PathLike[str]"]

#: Servo stiffness [N·m/rad]: stiffer tracks better and stiffens the ankle of the IPCJ model.
KP = 500.0
#: Servo damping [N·m·s/rad].
KV = 20.0
#: Physics step [s]: 0.1 ms, where the figures have converged. ``implicitfast`` damps a servo's
#: rate term implicitly only while its torque is inside the joint's force range; at a limit the
#: torque is a constant and one step changes the joint's rate by h·τ_max/M. Where that is more
#: than the band of rates 2·τ_max/KV in which the servo is not saturated, h > 2M/KV, the servo
#: jumps across the band and flips between its two force limits every step, for good (one hinge
#: of 1.8 g·m² at 25 N·m, commanded 3 rad/s: 0 and 13.9 rad/s in turn at 1 ms; it settles at 0.1 ms).
#: On G1 the wrists (0.6–5 g·m² about their axes) and the shoulders' yaw (6–10 g·m²) are that
#: light. The upper-body standing imitation (``run_standing_keypoints(standing=True)``, 508
#: ticks; MuJoCo 4.0.1, 2026-12-06) at 1, 0.5, 0.2, 0.1 and 0.05 ms: a servo flips on 141, 103,
#: 52, 21 and 5 ticks, the servos trail the plan by 0.094, 0.026, 0.024, 0.024 and 0.024 rad rms,
#: the feet slip 9.0, 4.0, 2.6, 2.6 and 2.6 mm. (Explicit Euler at 1 ms falls.)
PHYSICS_STEP = 0.0001
#: Control period [s]: one iktc tick, then CONTROL_PERIOD / PHYSICS_STEP physics steps.
CONTROL_PERIOD = 0.005
#: A foot whose sensed normal force is at most this is unloaded [N] (sensor noise is none here;
#: the lifted foot's own weight is ≈ 6 N).
MIN_NORMAL_FORCE = 10.0
#: The feet's bodies, in iktc's order: right, then left.
FEET = ("right_ankle_roll_link", "left_ankle_roll_link")
#: The force/torque sensors' sites added at the ankle roll joints.
SENSOR_SITES = {"right": "right_ankle_ft", "left": "left_ankle_ft"}
#: Floor of a foot's share of the ground wrench in double support [–]: keeps the weighted
#: split's matrix invertible when the plan's ZMP sits on one sole.
MIN_SHARE = 1e-6


def _check_servo(kp: float, kv: float, physics_step: float) -> None:
    for name, value in (("kp [N·m/rad]", kp), ("kv [N·m·s/rad]", kv)):
        if not (math.isfinite(value) and value >= 0.0):
            raise iktc.IktcError(f"{name} = {value}: expected a finite gain >= 0")
    if not (math.isfinite(physics_step) and 0.0 < physics_step <= CONTROL_PERIOD):
        raise iktc.IktcError(f"physics_step = {physics_step}: expected a step [s] in "
                             f"(0, CONTROL_PERIOD = {CONTROL_PERIOD}]")


def plant_xml(mjcf: Optional[PathLike] = None, kp: float = KP, kv: float = KV,
              physics_step: float = PHYSICS_STEP) -> str:
    """The MJCF text of the plant (see the package docstring): `mjcf` a G1 MJCF file, by default
    iktc's built-in one."""
    _check_servo(kp, kv, physics_step)
    try:
        if mjcf is None:
            root = ET.fromstring(iktc.builtin_text("mjcf", "g1"))
        else:
            root = ET.parse(os.fspath(mjcf)).getroot()
    except (OSError, ET.ParseError) as e:
        raise iktc.IktcError(f"mjcf = {mjcf!r}: cannot read it as an MJCF model: {e}") from e
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
    if act is None:
        raise iktc.IktcError(f"mjcf = {mjcf!r}: no <actuator>: the plant drives its joints' "
                             "<motor> actuators")
    joints = []
    for m in list(act):
        joint = m.get("joint")
        if joint is None:
            raise iktc.IktcError(f"mjcf = {mjcf!r}: actuator `{m.get('name')}` drives no joint: "
                                 "the plant puts a servo on each actuated joint")
        joints.append(joint)
        act.remove(m)
        ET.SubElement(act, "general", name=joint, joint=joint, gaintype="fixed",
                      biastype="affine", gainprm=f"{kp}", biasprm=f"0 {-kp} 0")
    for joint in joints:
        ET.SubElement(act, "general", name=f"{joint}_rate", joint=joint, gaintype="fixed",
                      biastype="affine", gainprm=f"{kv}", biasprm=f"0 0 {-kv}")
        ET.SubElement(act, "motor", name=f"{joint}_torque", joint=joint, gear="1")
    sensor = root.find("sensor")
    if sensor is None:
        sensor = ET.SubElement(root, "sensor")
    for side, site in SENSOR_SITES.items():
        body = next((b for b in root.iter("body") if b.get("name") == f"{side}_ankle_roll_link"),
                    None)
        if body is None:
            raise iktc.IktcError(f"mjcf = {mjcf!r}: no body `{side}_ankle_roll_link`: the plant "
                                 "puts its ankle sensors on the G1's ankle roll links")
        ET.SubElement(body, "site", name=site, pos="0 0 0", size="0.01")
        ET.SubElement(sensor, "force", name=f"{side}_ankle_force", site=site)
        ET.SubElement(sensor, "torque", name=f"{side}_ankle_torque", site=site)
    return ET.tostring(root, encoding="unicode")


def yaw_between(h0: FloatArray, h1: FloatArray) -> float:
    """The turn about the world's vertical from pose h0 to pose h1 (4 × 4) [rad]."""
    r = h1[:3, :3] @ h0[:3, :3].T
    return math.atan2(float(r[1, 0]), float(r[0, 0]))


def tilt(xmat: FloatArray) -> float:
    """Angle between a body's z axis and the world's [rad]."""
    return math.acos(max(-1.0, min(1.0, float(xmat.reshape(3, 3)[2, 2]))))


def _sized(x: Union[Sequence[float], FloatArray], n: int, what: str) -> FloatArray:
    a = np.asarray(x, dtype=float)
    if a.shape != (n,):
        raise iktc.IktcError(f"{what}: expected {n} numbers, got shape {a.shape}")
    return a


class Plant:
    """The MuJoCo G1 with the joint order of an iktc robot: `mjcf` a G1 MJCF file (default: iktc's
    built-in one), its joints named as the robot's."""

    def __init__(self, robot: iktc.Robot, kp: float = KP, kv: float = KV,
                 physics_step: float = PHYSICS_STEP, mjcf: Optional[PathLike] = None):
        self.model = mujoco.MjModel.from_xml_string(plant_xml(mjcf, kp=kp, kv=kv,
                                                              physics_step=physics_step))
        self.data = mujoco.MjData(self.model)
        self.robot = robot
        m = self.model
        names = robot.joint_names
        missing = [n for n in names if mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n) < 0]
        if missing or not robot.floating:
            raise iktc.IktcError(
                f"robot `{robot.name}`: the plant's model has no joint {', '.join(missing)}"
                if missing else f"robot `{robot.name}` has a fixed base: the plant is a "
                "floating G1")
        self.qadr = np.array([m.jnt_qposadr[m.joint(n).id] for n in names])
        self.dadr = np.array([m.jnt_dofadr[m.joint(n).id] for n in names])
        self.act = np.array([m.actuator(n).id for n in names])
        self.act_rate = np.array([m.actuator(f"{n}_rate").id for n in names])
        self.act_torque = np.array([m.actuator(f"{n}_torque").id for n in names])
        self.feet = [m.body(f).id for f in FEET]
        self.pelvis = m.body("pelvis").id
        self.sensor = {}
        for side, site in SENSOR_SITES.items():
            self.sensor[side] = (m.site(site).id,
                                 m.sensor_adr[m.sensor(f"{side}_ankle_force").id],
                                 m.sensor_adr[m.sensor(f"{side}_ankle_torque").id])
        self.substeps = int(round(CONTROL_PERIOD / m.opt.timestep))
        # The joints' force ranges, for the servo flips counted by `advance`.
        jid = [m.joint(n).id for n in names]
        self.force_low = np.array([m.jnt_actfrcrange[j][0] if m.jnt_actfrclimited[j] else -np.inf
                                   for j in jid])
        self.force_high = np.array([m.jnt_actfrcrange[j][1] if m.jnt_actfrclimited[j] else np.inf
                                    for j in jid])
        self._at_low = np.zeros(len(names), dtype=bool)
        self._at_high = np.zeros(len(names), dtype=bool)
        #: Joints whose servo torque went from one force limit to the other between two
        #: consecutive physics steps during the last `advance` (see PHYSICS_STEP).
        self.flipped = np.zeros(len(names), dtype=bool)

    def set_state(self, q: FloatArray) -> None:
        """Places the robot at iktc's q (base position, quaternion x y z w, joints), at rest."""
        q = _sized(q, self.robot.nq, "q")
        d = self.data
        d.qpos[:] = to_mujoco_qpos(self, q)
        d.qvel[:] = 0.0
        d.ctrl[self.act] = q[7:]
        d.ctrl[self.act_rate] = 0.0
        d.ctrl[self.act_torque] = 0.0
        mujoco.mj_forward(self.model, d)

    def command(self, q: FloatArray, v: Optional[FloatArray] = None,
                torque: Optional[FloatArray] = None) -> None:
        """Servo set points from iktc's q [rad] and v [rad/s] (None: rate set point 0), and the
        feed-forward torque [N·m] per joint (None: 0; see ``Feedforward``)."""
        q = _sized(q, self.robot.nq, "q")
        self.data.ctrl[self.act] = q[7:]
        self.data.ctrl[self.act_rate] = 0.0 if v is None else _sized(v, self.robot.nv, "v")[6:]
        self.data.ctrl[self.act_torque] = (0.0 if torque is None else
                                           _sized(torque, len(self.act), "torque"))

    def advance(self, push: Optional[FloatArray] = None) -> None:
        """One control period of physics; `push` [N] is applied at the pelvis meanwhile."""
        d = self.data
        if push is not None:
            d.xfrc_applied[self.pelvis, :3] = _sized(push, 3, "push [N]")
        self.flipped[:] = False
        for _ in range(self.substeps):
            mujoco.mj_step(self.model, d)
            tau = d.qfrc_actuator[self.dadr]
            low = tau <= self.force_low + 1e-9
            high = tau >= self.force_high - 1e-9
            self.flipped |= (low & self._at_high) | (high & self._at_low)
            self._at_low, self._at_high = low, high
        if push is not None:
            d.xfrc_applied[self.pelvis, :3] = 0.0

    def joint_positions(self) -> FloatArray:
        """The joints' angles [rad], iktc's order."""
        return np.array(self.data.qpos[self.qadr])

    def foot_pose(self, i: int) -> FloatArray:
        """4 × 4 pose of foot i (0 right, 1 left) in the world [m]."""
        if i not in (0, 1):
            raise iktc.IktcError(f"foot i = {i!r}: expected 0 (right) or 1 (left)")
        h = np.eye(4)
        h[:3, :3] = self.data.xmat[self.feet[i]].reshape(3, 3)
        h[:3, 3] = self.data.xpos[self.feet[i]]
        return h

    def sensor_reading(self, side: str) -> Tuple[FloatArray, FloatArray, FloatArray]:
        """(position [m], force [N], torque [N·m]) of the ground on the foot, world axes.

        MuJoCo's force/torque sensors give the wrench the child (foot) exerts on its parent,
        in the site's axes, at the site; with the foot's own weight and inertia neglected
        (0.61 kg) the ground's wrench on the foot is the opposite: the negated reading,
        rotated into the world.
        """
        if side not in self.sensor:
            raise iktc.IktcError(f"side = {side!r}: expected \"left\" or \"right\"")
        site, fa, ta = self.sensor[side]
        r = self.data.site_xmat[site].reshape(3, 3)
        f = -(r @ self.data.sensordata[fa:fa + 3])
        t = -(r @ self.data.sensordata[ta:ta + 3])
        return np.array(self.data.site_xpos[site]), f, t

    def zmp(self) -> Tuple[Optional[Tuple[float, float]], str]:
        """ZMP from the two ankle sensors (eqs. 29–30): ((x, y) or None, status)."""
        return iktc.measure_zmp(self.sensor_reading("left"), self.sensor_reading("right"),
                                MIN_NORMAL_FORCE)

    def pelvis_height(self) -> float:
        """The pelvis's height above the ground [m]."""
        return float(self.data.xpos[self.pelvis][2])

    def base_tilt(self) -> float:
        """The pelvis's tilt from upright [rad]."""
        return tilt(self.data.xmat[self.pelvis])


def to_mujoco_qpos(plant: Plant, q: FloatArray) -> FloatArray:
    """MuJoCo's qpos of iktc's q (base position, quaternion x y z w, joints; MuJoCo's
    quaternion is w x y z). Every coordinate of the plant's qpos is one of these."""
    q = _sized(q, plant.robot.nq, "q")
    x = np.zeros(plant.model.nq)
    x[:3] = q[:3]
    x[3:7] = [q[6], q[3], q[4], q[5]]
    x[plant.qadr] = q[7:]
    return x


class Feedforward:
    """The joint torques [N·m] that make the robot follow the kinematic plan, for the servos'
    feed-forward input (``Plant.command(q, v, torque)``: τ = KP (q_cmd − q) + KV (v_cmd − q̇)
    + τ_ff, the low-level command of a position-controlled humanoid such as G1's).

    From the plan's last three configurations q_{k−1}, q_k, q_{k+1} (iktc's state after each
    tick): rates v = (q_{k+1} − q_k)/Δt and accelerations a = (q_{k+1} − 2q_k + q_{k−1})/Δt²
    (``mj_differentiatePos``; iktc integrates v_{k+1} = v_k + q̈_k Δt, q_{k+1} = q_k ⊕ v_{k+1} Δt,
    so these are its own v_{k+1} and q̈_k), at q_{k+1}:

    1. MuJoCo's inverse dynamics with the contacts disabled gives the generalized force
       f = M(q) a + c(q, v) [N, N·m]: its free-joint rows f_b are the wrench the ground must
       exert on the robot, its joint rows what the joints would exert if it exerted none.
    2. The ground wrench is shared by the feet on the ground: foot i exerts w_i (force and
       moment at its ankle frame's origin, world axes) with Σ_i J_{i,b}ᵀ w_i = f_b, J_i the
       6 × n_v Jacobian of that point (``mj_jac``; b the free joint's columns). One foot: a
       6 × 6 solve. Two feet: the least Σ_i |w_i|²/α_i, w = D Aᵀ (A D Aᵀ)⁻¹ f_b with
       A = [J_{L,b}ᵀ J_{R,b}ᵀ] and D = diag(α_L I₆, α_R I₆), the shares α_R = 1 − α_L of
       the plan's ZMP p (from f_b: p_x = o_x − (τ_y + o_z F_x)/F_z,
       p_y = o_y + (τ_x − o_z F_y)/F_z) projected on the segment between the ankles,
       clamped to [``MIN_SHARE``, 1 − ``MIN_SHARE``]: a foot the plan unloads gets no wrench.
    3. τ_ff = f_j − Σ_i J_{i,j}ᵀ w_i.

    Without it the servos trail the plan: a 2 mrad error about the ankles is a 6 cm error of
    the ZMP (see ``run_walking``).
    """

    def __init__(self, plant: Plant):
        self.plant = plant
        self.data = mujoco.MjData(plant.model)
        self.history: list = []
        m = plant.model
        self._jp = np.zeros((3, m.nv))
        self._jr = np.zeros((3, m.nv))
        self._dofs = plant.dadr

    def torques(self, q: FloatArray, on_ground: Sequence[bool]) -> FloatArray:
        """τ_ff [N·m] per joint (iktc's joint order) at the plan's newest configuration `q`,
        with `on_ground` (right, left) saying which feet the plan has on the ground; zeros
        until three configurations have been seen."""
        if len(on_ground) != 2:
            raise iktc.IktcError(f"on_ground: expected (right, left), got {on_ground!r}")
        p, m, d = self.plant, self.plant.model, self.data
        self.history = (self.history + [to_mujoco_qpos(p, q)])[-3:]
        if len(self.history) < 3:
            return np.zeros(len(self._dofs))
        q0, q1, q2 = self.history
        dt = CONTROL_PERIOD
        v1 = np.zeros(m.nv)
        v2 = np.zeros(m.nv)
        mujoco.mj_differentiatePos(m, v1, dt, q0, q1)
        mujoco.mj_differentiatePos(m, v2, dt, q1, q2)
        d.qpos[:] = q2
        d.qvel[:] = v2
        d.qacc[:] = (v2 - v1) / dt
        flags = m.opt.disableflags
        m.opt.disableflags = flags | mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
        try:
            mujoco.mj_inverse(m, d)
        finally:
            m.opt.disableflags = flags
        f = d.qfrc_inverse.copy()
        feet = [i for i in range(2) if on_ground[i]]
        if not feet:
            return f[self._dofs]
        jac, ankles = [], []
        for i in feet:
            b = p.feet[i]
            mujoco.mj_jac(m, d, self._jp, self._jr, d.xpos[b], b)
            jac.append(np.vstack([self._jp, self._jr]))
            ankles.append(d.xpos[b][:2].copy())
        a = np.hstack([j[:, :6].T for j in jac])
        if len(feet) == 1:
            w = np.linalg.solve(a, f[:6])
        else:
            r = d.xmat[p.pelvis].reshape(3, 3)
            force, moment, o = f[:3], r @ f[3:6], d.qpos[:3]
            zmp = np.array([o[0] - (moment[1] + o[2] * force[0]) / force[2],
                            o[1] + (moment[0] - o[2] * force[1]) / force[2]])
            seg = ankles[0] - ankles[1]
            share = float(np.clip(np.dot(zmp - ankles[1], seg) / np.dot(seg, seg),
                                  MIN_SHARE, 1.0 - MIN_SHARE))
            dw = np.repeat([share, 1.0 - share], 6)
            w = dw * (a.T @ np.linalg.solve((a * dw) @ a.T, f[:6]))
        tau = f.copy()
        for k, j in enumerate(jac):
            tau -= j.T @ w[6 * k:6 * k + 6]
        return np.asarray(tau[self._dofs])


def planned_zmp(plant: Plant, qs: Sequence[FloatArray], dt: float = CONTROL_PERIOD,
                per_tick: bool = False, min_support: float = 0.0) -> FloatArray:
    """The ZMP the kinematic plan asks for [m], one row per tick (NaN at the two ends, and where
    the plan asks the ground to pull: a vertical ground force F_z ≤ 0, the body falling at least
    as fast as gravity, has no ZMP — as ``iktc.Robot.zmp`` rules; with `min_support` > 0 [–],
    also where F_z is under that share of the robot's weight, where dividing by F_z turns
    centimetres of moment into metres of ZMP).

    The plan's configurations `qs` (iktc's q per tick) are put into MuJoCo's coordinates; rates
    and accelerations by central differences (``mj_differentiatePos``; with `per_tick` the
    acceleration of each tick, (v_{k+1} − v_k)/Δt with v_k = (q_k − q_{k−1})/Δt, which is
    iktc's own q̈_k, and the rate (v_k + v_{k+1})/2; NaN at the first and last tick); MuJoCo's inverse
    dynamics (``mj_inverse``) then gives the wrench the ground must exert on the free base, force
    F and torque τ at the base origin o (world axes), and the ZMP is the ground point where its
    horizontal moment vanishes: p_x = o_x − (τ_y + o_z F_x)/F_z, p_y = o_y + (τ_x − o_z F_y)/F_z.
    Constraints (the floor's contacts) are disabled for it: the free joint's force is then the
    whole external wrench.
    """
    if not (math.isfinite(dt) and dt > 0.0):
        raise iktc.IktcError(f"dt = {dt}: expected a control period > 0 [s]")
    if not (math.isfinite(min_support) and min_support >= 0.0):
        raise iktc.IktcError(f"min_support = {min_support}: expected a share >= 0 of the weight")
    m = plant.model
    d = mujoco.MjData(m)
    flags = m.opt.disableflags
    m.opt.disableflags = flags | mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    try:
        return _planned_zmp(plant, m, d, qs, dt, per_tick, min_support)
    finally:
        m.opt.disableflags = flags


def _planned_zmp(plant, m, d, qs, dt, per_tick=False, min_support=0.0):
    weight = float(np.sum(m.body_mass)) * -float(m.opt.gravity[2])
    qpos = [to_mujoco_qpos(plant, q) for q in qs]
    n = len(qpos)
    out = np.full((n, 2), np.nan)
    vel = np.zeros((n, m.nv))
    if per_tick:
        for k in range(1, n):
            mujoco.mj_differentiatePos(m, vel[k], dt, qpos[k - 1], qpos[k])
        ticks = range(1, n - 1)
    else:
        for k in range(1, n - 1):
            mujoco.mj_differentiatePos(m, vel[k], 2 * dt, qpos[k - 1], qpos[k + 1])
        ticks = range(2, n - 2)
    for k in ticks:
        d.qpos[:] = qpos[k]
        if per_tick:
            d.qvel[:] = 0.5 * (vel[k] + vel[k + 1])
            d.qacc[:] = (vel[k + 1] - vel[k]) / dt
        else:
            d.qvel[:] = vel[k]
            d.qacc[:] = (vel[k + 1] - vel[k - 1]) / (2 * dt)
        mujoco.mj_inverse(m, d)
        r = d.xmat[plant.pelvis].reshape(3, 3)
        f = d.qfrc_inverse[:3]  # free joint: linear part in world axes
        tau = r @ d.qfrc_inverse[3:6]  # angular part in the body's axes
        o = d.qpos[:3]
        if f[2] > 0.0 and f[2] >= min_support * weight:
            out[k] = [o[0] - (tau[1] + o[2] * f[0]) / f[2], o[1] + (tau[0] - o[2] * f[1]) / f[2]]
    return out
