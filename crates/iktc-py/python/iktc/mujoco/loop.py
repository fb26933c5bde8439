"""iktc's imitation commanding the MuJoCo G1 tick by tick, with a log and the run's figures."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Dict, Optional, Tuple

import numpy as np

import iktc

from .plant import CONTROL_PERIOD, KP, KV, PHYSICS_STEP, FloatArray, Plant, yaw_between


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
    servo_flips: list = field(default_factory=list)
    foot_yaw: list = field(default_factory=list)


def summarise(log: Log, fallen_height: float) -> Dict[str, Any]:
    """The run's figures: stayed up (the pelvis above `fallen_height` [m] throughout), pelvis
    height, base tilt, foot slip, ZMP margin, tracking."""
    if not log.t:
        raise iktc.IktcError("log: no tick logged, no figures")
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
        # The feet's largest turn about the vertical from where they stood [rad]: a foot turning
        # on the ground slips more at its toe and heel than at the ankle `foot_slip_max_m` follows.
        "foot_yaw_max_rad": float(np.max(np.abs(log.foot_yaw))) if log.foot_yaw else 0.0,
        "zmp_ticks_measured": int(margins.size),
        "zmp_margin_min_m": float(margins.min()) if margins.size else float("nan"),
        "zmp_inside": bool(margins.size == len(log.t) and margins.min() > 0.0),
        "joint_error_rms_rad": float(np.sqrt(np.mean(je ** 2))),
        "joint_error_max_rad": float(np.abs(je).max()),
        "upper_body_error_rms_rad": float(np.sqrt(np.mean(ue ** 2))),
        "upper_body_error_max_rad": float(np.abs(ue).max()),
        # Ticks on which a servo went from one force limit to the other between two physics
        # steps: the integration is not resolving it (see PHYSICS_STEP).
        "servo_limit_flip_ticks": int(np.count_nonzero(log.servo_flips)),
    }


class Loop:
    """iktc's imitation of a clip commanding the MuJoCo G1, tick by tick."""

    def __init__(self, clip: str = "humanoid3d_dance_b", duration: Optional[float] = None,
                 kp: float = KP, kv: float = KV, physics_step: float = PHYSICS_STEP,
                 rate_feedforward: bool = True, time_scale: float = 1.0,
                 robot: Optional[iktc.Robot] = None, offset_feedforward: bool = False,
                 mjcf: Optional[str] = None, **imitation: Any):
        """`clip`: a built-in clip or a motion file (``iktc.load_motion``); `robot`: default the
        built-in ``g1``; `mjcf`: the plant's MJCF file (default iktc's G1); `imitation`: further
        keywords of `iktc.Imitation` (map, root_scales, bounds, level_hold, rebase_release,
        narrow)."""
        self.rate_feedforward = rate_feedforward
        self.robot = iktc.Robot("g1") if robot is None else robot
        self.sim = iktc.Imitation(self.robot, iktc.load_motion(clip), dt=CONTROL_PERIOD,
                                  duration=duration, time_scale=time_scale, **imitation)
        self.plant = Plant(self.robot, kp=kp, kv=kv, physics_step=physics_step, mjcf=mjcf)
        self.plant.set_state(self.sim.q)
        self.upper = [self.robot.q_index(n) - 7 for n in self.sim.upper_body_joints]
        self.feet0 = [self.plant.foot_pose(i) for i in range(2)]
        self.log = Log()
        self.t = 0.0
        self.offset_feedforward = offset_feedforward
        self._offset_prev = np.zeros(2)
        self._offset_rate_prev = np.zeros(2)

    def settle(self, seconds: float) -> None:
        """Holds the initial command while the servos take the load (not logged)."""
        if not (math.isfinite(seconds) and seconds >= 0.0):
            raise iktc.IktcError(f"seconds = {seconds}: expected a time >= 0 [s]")
        q = self.sim.q
        for _ in range(int(round(seconds / CONTROL_PERIOD))):
            self.plant.command(q)
            self.plant.advance()
        self.feet0 = [self.plant.foot_pose(i) for i in range(2)]

    def offset_rates(self, com_offset: Optional[Tuple[float, float]]
                     ) -> Tuple[Tuple[float, float], Tuple[float, float]]:
        """(velocity [m/s], acceleration [m/s²]) of the COM offset by backward differences over
        CONTROL_PERIOD (an absent offset counts as 0), as iktc's walking controller feeds its
        damping offset forward: the COM task's CLIK then follows the offset within a tick instead
        of through its second-order lag (k_p = 100 s⁻², k_v = 20 s⁻¹: a double pole at 10 rad/s,
        about 0.2 s), which the identification would otherwise fit as part of the plant."""
        off = np.zeros(2) if com_offset is None else np.asarray(com_offset, dtype=float)
        if off.shape != (2,):
            raise iktc.IktcError(f"com_offset: expected (dx, dy) [m], got {com_offset!r}")
        rate = (off - self._offset_prev) / CONTROL_PERIOD
        acc = (rate - self._offset_rate_prev) / CONTROL_PERIOD
        self._offset_prev, self._offset_rate_prev = off, rate
        return (float(rate[0]), float(rate[1])), (float(acc[0]), float(acc[1]))

    def step(self, imitate: bool = True, com_offset: Optional[Tuple[float, float]] = None,
             push: Optional[FloatArray] = None) -> None:
        """One control tick: iktc (if `imitate`, else the last command is held), the servos'
        set points, CONTROL_PERIOD of physics, the measurements. `com_offset` (dx, dy) [m] is
        added to the COM reference, with its rates fed forward when `offset_feedforward`;
        `push` [N] acts at the pelvis over the tick."""
        if imitate:
            rate, acc = self.offset_rates(com_offset)
            if com_offset is not None and self.offset_feedforward:
                self.sim.set_com_offset(com_offset, rate, acc)
            else:
                self.sim.set_com_offset(com_offset)
            report = self.sim.tick()
            if report.violation > 1e-9:
                raise AssertionError(f"iktc left its acceleration box by {report.violation}")
        q = self.sim.q
        self.plant.command(q, self.sim.v if self.rate_feedforward else None)
        self.plant.advance(push)
        self.t += CONTROL_PERIOD
        self.record(q, com_offset)

    def record(self, q: FloatArray, com_offset: Optional[Tuple[float, float]],
               upper_reference: Optional[FloatArray] = None) -> None:
        """Logs the tick; `upper_reference` [rad] (default: the imitation's upper-body
        reference) is what the upper-body joints are measured against."""
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
        log.foot_yaw.append(max((abs(yaw_between(f0, f)) for f, f0 in zip(feet, self.feet0)),
                                key=abs))
        qj = p.joint_positions()
        err = qj - q[7:]
        log.joint_error.append(float(np.abs(err).max()))
        up = self.sim.upper_body_reference() if upper_reference is None else upper_reference
        log.upper_error.append(float(np.abs(qj[self.upper] - up).max()))
        log.com_offset.append(com_offset)
        log.qpos.append(p.data.qpos.copy())
        log.q_cmd.append(q.copy())
        log.servo_flips.append(int(p.flipped.sum()))

    def summary(self) -> Dict[str, Any]:
        """The run's figures (``summarise``); fallen: the pelvis 0.25 m below its standing
        height (0.76 m)."""
        return summarise(self.log, fallen_height=0.5)


def run_standing(duration: Optional[float] = None, settle: float = 0.5,
                 clip: str = "humanoid3d_dance_b", rate_feedforward: bool = True,
                 time_scale: float = 1.0, robot: Optional[iktc.Robot] = None,
                 **imitation: Any) -> Loop:
    """(a) Standing imitation of the clip's upper body with the feet held; returns the loop.
    `imitation`: further keywords of `Loop` and `iktc.Imitation`."""
    loop = Loop(clip=clip, duration=duration, rate_feedforward=rate_feedforward,
                time_scale=time_scale, robot=robot, **imitation)
    loop.settle(settle)
    for _ in range(loop.sim.ticks):
        loop.step()
    return loop


def run_standing_keypoints(clip: str = "humanoid3d_dance_b", settle: float = 0.5,
                           robot: Optional[iktc.Robot] = None, standing: bool = False,
                           physics_step: float = PHYSICS_STEP, **keypoints: Any) -> Loop:
    """(a′) Standing imitation by the keypoint route (``iktc.retarget_keypoints(...,
    hold_feet=True)``: the clip's body points scaled to G1, both feet held where they stand,
    the COM reference over the support polygon); its q and v per tick are the servos' set
    points, the plan computed beforehand (it does not see the plant). With `standing` the
    route's standing imitation instead (``standing=True``: feet and pelvis held at G1's start
    pose, the COM over the middle of the soles, the clip's upper body relative to its pelvis).
    `keypoints`: further keywords of ``iktc.retarget_keypoints`` (smoothing, approach_rate).
    The loop's imitation (one tick long) serves only for the support polygon; the upper body is
    measured against the plan's own upper-body angles. Returns the loop."""
    loop = Loop(clip=clip, duration=CONTROL_PERIOD, robot=robot, physics_step=physics_step)
    plan = iktc.retarget_keypoints(iktc.load_motion(clip), loop.robot, dt=CONTROL_PERIOD,
                                   hold_feet=True, standing=standing, **keypoints)
    qs, vs = plan.q, plan.v
    loop.plant.set_state(qs[0])
    for _ in range(int(round(settle / CONTROL_PERIOD))):
        loop.plant.command(qs[0])
        loop.plant.advance()
    loop.feet0 = [loop.plant.foot_pose(i) for i in range(2)]
    for q, v in zip(qs, vs):
        loop.plant.command(q, v)
        loop.plant.advance()
        loop.t += CONTROL_PERIOD
        loop.record(q, None, upper_reference=q[7:][loop.upper])
    return loop


def plan_chatter(qs: Any, dt: float = CONTROL_PERIOD) -> Dict[str, Any]:
    """How a plan's joint accelerations [rad/s²] behave: their rms over the joints and ticks,
    and the median over the joints of how often q̈ changes sign (second differences of the
    tick-by-tick joint angles `qs`, one row per tick: base 7, then joints)."""
    qs = np.asarray(qs, dtype=float)
    if qs.ndim != 2 or len(qs) < 4 or qs.shape[1] < 8:
        raise iktc.IktcError(f"qs: expected at least 4 rows of q (base 7, then joints), got "
                             f"shape {qs.shape}")
    a = np.diff(qs[:, 7:], 2, axis=0) / dt ** 2
    flips = np.sum(np.sign(a[1:]) != np.sign(a[:-1]), axis=0)
    return {"joint_acceleration_rms_rad_s2": float(np.sqrt(np.mean(a ** 2))),
            "joint_acceleration_sign_changes_median": f"{int(np.median(flips))} of {len(a) - 1}"}
