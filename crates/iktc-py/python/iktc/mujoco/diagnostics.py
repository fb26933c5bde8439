"""The causes of the failures: figures of runs with diagnostic settings (not defaults)."""
from __future__ import annotations

import math
from typing import Any, Callable, Dict, Iterable, Optional, Sequence, Tuple

import numpy as np

import iktc

from .loop import Loop
from .plant import CONTROL_PERIOD, FloatArray, Plant, planned_zmp

#: G1's knees narrowed [rad]: 0.3 rad (17°) short of straight, so that the pelvis height task is
#: corrected before a leg straightens (its lower limit is −0.087 rad); the upper end is the
#: joint's own 2.88 rad less a margin. A diagnostic setting: the clip's pelvis height rises up to
#: 0.13 m above its first frame, where G1 at its posture (knee 0.6 rad) has 0.03 m of leg left.
G1_KNEES = (("left_knee_joint", 0.3, 2.8), ("right_knee_joint", 0.3, 2.8))

#: ``iktc.Imitation(root_scales=PELVIS_HELD)``: the map's pelvis height, pitch and roll scales
#: 0, the pelvis held at its start.
PELVIS_HELD = {"height_scale": 0.0, "pitch_scale": 0.0, "roll_scale": 0.0}


def robot_with_acceleration(per_velocity: float, spec: str = "g1") -> iktc.Robot:
    """The robot `spec` (a built-in profile or a profile file) with every joint's acceleration
    limit `per_velocity` [1/s] times its velocity limit (G1's profile has 10: 200–370 rad/s²)."""
    if not (math.isfinite(per_velocity) and per_velocity > 0.0):
        raise iktc.IktcError(f"per_velocity = {per_velocity}: expected a ratio > 0 [1/s]")
    robot = iktc.Robot(spec)
    velocity = robot.limits()[2]
    accel = [(n, per_velocity * float(velocity[robot.v_index(n)])) for n in robot.joint_names]
    return iktc.Robot(spec, accel=accel)


def plan_outside(plant: Plant, qs: Sequence[FloatArray],
                 margin: Callable[[int, Tuple[float, float]], float]) -> int:
    """Ticks on which the plan's ZMP (``planned_zmp``) is outside the support polygon, with
    `margin(k, point)` the signed margin of tick k."""
    plan = planned_zmp(plant, qs)
    return int(sum(margin(k, (float(p[0]), float(p[1]))) < 0
                   for k, p in enumerate(plan) if np.all(np.isfinite(p))))


def standing_figures(frozen: Iterable[str] = (), **kw: Any) -> Dict[str, Any]:
    """Slip, the plan's ZMP ticks outside and the legs' largest |q̈| of one standing run
    (`kw`: keywords of ``Loop`` and ``settle`` [s], default 0.5); `frozen`: joint names held at
    their first angle in the plan before its ZMP is computed (what those joints' motion
    contributes)."""
    peak = 0.0
    loop = Loop(**{k: v for k, v in kw.items() if k not in ("settle",)})
    loop.settle(kw.get("settle", 0.5))
    names = loop.robot.joint_names
    legs = [6 + i for i, n in enumerate(names) if any(x in n for x in ("hip", "knee", "ankle"))]
    for _ in range(loop.sim.ticks):
        loop.step()
        peak = max(peak, float(np.abs(loop.sim.qdd[legs]).max()))
    s = loop.summary()
    qs = [q.copy() for q in loop.log.q_cmd]
    idx = [loop.robot.q_index(n) for n in frozen]
    for q in qs:
        q[idx] = loop.log.q_cmd[0][idx]
    return {"foot_slip_max_m": s["foot_slip_max_m"], "stayed_up": s["stayed_up"],
            "plan_zmp_ticks_outside": plan_outside(loop.plant, qs,
                                                   lambda k, p: loop.sim.support_margin(p)),
            "ticks": s["ticks"], "legs_qdd_max_rad_s2": peak}


def walking_plan_figures(clip: str = "humanoid3d_dance_b",
                         narrow: Optional[Sequence[Tuple[str, float, float]]] = None,
                         **walking: Any) -> Dict[str, Any]:
    """The walking plan alone (no physics): its ZMP against the pattern's support polygon per
    phase, and the lowest angle of each knee [rad] with the first time at its lower limit [s].
    `walking`: further keywords of `iktc.Walking` (smoothing, approach_rate)."""
    robot = iktc.Robot("g1")
    qs, phases = [], []
    walk = iktc.Walking(robot, iktc.load_motion(clip), narrow=narrow, **walking)
    for _ in range(walk.ticks):
        phases.append(walk.tick()[1])
        qs.append(walk.q.copy())
    plan = planned_zmp(Plant(robot), qs)
    replay = iktc.Walking(robot, iktc.load_motion(clip), narrow=narrow, **walking)
    out: Dict[str, Tuple[int, int]] = {}
    for k, p in enumerate(plan):
        replay.tick()
        if np.all(np.isfinite(p)):
            n_out, n = out.get(phases[k], (0, 0))
            inside = replay.support_margin((float(p[0]), float(p[1])))
            out[phases[k]] = (n_out + int(inside < 0), n + 1)
    fig: Dict[str, Any] = {f"plan_zmp_outside_{ph}": f"{o} of {n}" for ph, (o, n) in out.items()}
    lower = robot.limits()[0]
    for side in ("left", "right"):
        name = f"{side}_knee_joint"
        q = np.array([x[robot.q_index(name)] for x in qs])
        # At its lower limit: within 0.01 rad of it (the leg straight).
        at = np.nonzero(q < lower[robot.v_index(name)] + 0.01)[0]
        fig[f"{side}_knee_min_rad"] = float(q.min())
        fig[f"{side}_knee_straight_from_s"] = float(at[0] * CONTROL_PERIOD) if at.size else None
    return fig
