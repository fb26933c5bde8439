"""Walking while imitating, on the MuJoCo G1 (``iktc.Walking`` ticking with the plant)."""
from __future__ import annotations

import json
import os
import pathlib
from typing import Any, Dict, Optional, Sequence, Tuple, Union

import numpy as np

import iktc

from .plant import (
    CONTROL_PERIOD,
    KP,
    KV,
    MIN_NORMAL_FORCE,
    Feedforward,
    Plant,
    planned_zmp,
)
from .replay import write_replay

#: A foot counts as standing when its ankle reference is within this of its initial height [m].
ON_GROUND = 1e-3

Push = Tuple[float, Sequence[float], float]


def run_walking(steps: int = 4, step_length: float = 0.1, clip: str = "humanoid3d_dance_b",
                settle: float = 0.5, rate_feedforward: bool = True,
                narrow: Optional[Sequence[Tuple[str, float, float]]] = None,
                kp: float = KP, kv: float = KV, damping: bool = False,
                cases: Optional[Sequence[iktc.PlaneModel]] = None,
                offset_feedforward: bool = True, feedforward: bool = True,
                replay: Optional[Union[str, "os.PathLike[str]"]] = None,
                push: Optional[Push] = None, zmp_passes: int = 1,
                robot: Optional[iktc.Robot] = None,
                mjcf: Optional[str] = None) -> Dict[str, Any]:
    """Walking `steps` footsteps while imitating the clip (a built-in clip or a motion file),
    on the MuJoCo G1 (`narrow`: narrowed joint ranges, as for `iktc.Walking`; `robot` default
    the built-in ``g1``, `mjcf` the plant's MJCF file, default iktc's G1). With `damping` the
    measured ZMP (ankle sensors) is fed back every tick through the damping controller
    (`iktc.Walking(damping=True, cases=cases, offset_feedforward=offset_feedforward)`), else
    the loop is open. With `feedforward` the servos also get the plan's joint torques
    (``Feedforward``; the feet on the ground are those whose reference is within ``ON_GROUND``
    of its start height). `zmp_passes` passes of the ZMP correction (``iktc.Walking(zmp_passes=
    …)``: where the plan's own ZMP comes within 5 mm of the polygon's edge, the COM reference is
    moved so that it does not). Returns the figures: stayed up (and when it fell), pelvis
    height, base tilt, the largest horizontal error of a standing foot against its reference
    (slip), the ZMP from the ankle sensors against the support polygon of the feet carrying
    load (normal force above ``MIN_NORMAL_FORCE``: its margin, ticks outside, ``zmp_inside``)
    and against the pattern's polygon per phase (stance sole in single support; a tick without
    a measured ZMP counts as outside), the plan's ZMP (``planned_zmp``) against the pattern's
    polygon, the knees' lowest planned angles, servo tracking and flips. With `replay` an HTML
    replay of the physics run next to the plan is written to that path (``write_replay``).
    `push` = (time [s], force (x, y, z) [N], duration [s]) applies that force at the pelvis
    over the control periods from `time` on."""
    if push is not None:
        try:
            at, force, duration = push
            force_n = np.asarray(force, dtype=float)
            ok = force_n.shape == (3,) and float(duration) >= 0.0
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise iktc.IktcError(f"push = {push!r}: expected (time [s], (x, y, z) [N], "
                                 "duration [s] >= 0)")
    robot = iktc.Robot("g1") if robot is None else robot
    kw: Dict[str, Any] = {} if cases is None else {"cases": cases}
    if not offset_feedforward:
        kw["offset_feedforward"] = False
    walk = iktc.Walking(robot, iktc.load_motion(clip), steps=steps, step_length=step_length,
                        narrow=narrow, damping=damping, zmp_passes=zmp_passes, **kw)
    plant = Plant(robot, kp=kp, kv=kv, mjcf=mjcf)
    plant.set_state(walk.q)
    z0 = [f[2, 3] for f in walk.feet0()]
    ff = Feedforward(plant) if feedforward else None
    for _ in range(int(round(settle / CONTROL_PERIOD))):
        plant.command(walk.q, None, None if ff is None else ff.torques(walk.q, (True, True)))
        plant.advance()
    heights, tilts, slips, margins, errs, phases, qs, flips = [], [], [], [], [], [], [], []
    physics = []
    plan_margins, contact_margins = [], []
    zmp = None
    for k in range(walk.ticks):
        report, phase = walk.tick(zmp if damping else None)
        if report.violation > 1e-9:
            raise AssertionError(f"iktc left its acceleration box by {report.violation}")
        q = walk.q
        qs.append(q.copy())
        on = [abs(r[2, 3] - z0[i]) < ON_GROUND for i, r in enumerate(walk.feet_references())]
        plant.command(q, walk.v if rate_feedforward else None,
                      None if ff is None else ff.torques(q, on))
        pushing = push is not None and push[0] <= k * CONTROL_PERIOD < push[0] + push[2] - 1e-9
        plant.advance(np.asarray(push[1], dtype=float) if pushing and push is not None else None)
        physics.append(plant.data.qpos.copy())
        heights.append(plant.pelvis_height())
        tilts.append(plant.base_tilt())
        refs = walk.feet_references()
        slip = 0.0
        for i, r in enumerate(refs):
            if abs(r[2, 3] - z0[i]) < ON_GROUND:
                slip = max(slip, float(np.linalg.norm(plant.foot_pose(i)[:2, 3] - r[:2, 3])))
        slips.append(slip)
        zmp, _ = plant.zmp()
        margins.append(None if zmp is None else walk.support_margin(zmp))
        loaded = [plant.foot_pose(i) for i, side in enumerate(("right", "left"))
                  if plant.sensor_reading(side)[1][2] > MIN_NORMAL_FORCE]
        contact_margins.append(None if zmp is None or not loaded
                               else walk.support_margin(zmp, loaded))
        errs.append(float(np.abs(plant.joint_positions() - q[7:]).max()))
        phases.append(phase)
        flips.append(int(plant.flipped.sum()))
    if replay is not None:
        write_replay(replay, plant, physics, qs,
                     f"G1 walking {steps} steps, {pathlib.Path(clip).stem}")
    # The plan's ZMP against the same polygons: replayed (the plan does not see the plant
    # without the damping controller; with it, the ZMP of the commanded motion).
    again = iktc.Walking(robot, iktc.load_motion(clip), steps=steps, step_length=step_length,
                         narrow=narrow, zmp_passes=zmp_passes)
    for p in planned_zmp(plant, qs):
        again.tick()
        plan_margins.append(again.support_margin((float(p[0]), float(p[1])))
                            if np.all(np.isfinite(p)) else None)
    h = np.array(heights)
    ph = np.array(phases)
    m = np.array([np.nan if x is None else x for x in margins])
    cm = np.array([np.nan if x is None else x for x in contact_margins])
    pm = np.array([np.nan if x is None else x for x in plan_margins])
    fallen = np.nonzero(h < 0.5)[0]
    names = robot.joint_names
    knees = [7 + names.index(f"{s}_knee_joint") for s in ("left", "right")]
    out: Dict[str, Any] = {
        "ticks": walk.ticks,
        "stayed_up": bool(h.min() > 0.5),
        "fell_at_s": float(fallen[0] * CONTROL_PERIOD) if fallen.size else None,
        "pelvis_height_min_m": float(h.min()),
        "base_tilt_max_rad": float(np.max(tilts)),
        "standing_foot_error_max_m": float(np.max(slips)),
        "zmp_ticks_measured": int(np.sum(np.isfinite(cm))),
        "zmp_margin_min_m": float(np.nanmin(cm)) if np.any(np.isfinite(cm)) else float("nan"),
        "zmp_ticks_outside": int(np.sum(cm < 0)),
        "zmp_inside": bool(np.all(np.isfinite(cm)) and cm.min() > 0.0),
        "joint_error_max_rad": float(np.max(errs)),
        "servo_limit_flip_ticks": int(np.count_nonzero(flips)),
        "knee_plan_min_rad": float(np.min(np.array(qs)[:, knees])),
        "forward_progress_m": float(plant.data.xpos[plant.pelvis][0] - walk.feet0()[0][0, 3]),
        "zmp_corrections_m": walk.zmp_corrections(),
    }
    for name in ("single", "double"):
        sel = ph == name
        out[f"zmp_outside_{name}"] = f"{int(np.sum(~(m[sel] >= 0)))} of {int(np.sum(sel))}"
        out[f"plan_zmp_outside_{name}"] = (f"{int(np.sum(pm[sel] < 0))} of "
                                           f"{int(np.sum(np.isfinite(pm[sel])))}")
    return out


def held_clip(path: Union[str, "os.PathLike[str]"], clip: str = "humanoid3d_dance_b") -> str:
    """Writes the DeepMimic `clip` (a built-in clip, ``iktc.builtin_text("clip", …)``, or a
    DeepMimic file) with every frame its first (the upper body and the pelvis held at the
    clip's start) to `path`; returns the path: walking without the dance."""
    if os.path.isfile(clip):
        text = pathlib.Path(clip).read_text()
    else:
        text = iktc.builtin_text("clip", clip)
    try:
        data = json.loads(text)
        frames = data["Frames"]
        data["Frames"] = [list(frames[0]) for _ in frames]
    except (ValueError, KeyError, IndexError, TypeError) as e:
        raise iktc.IktcError(f"clip = {clip!r}: not a DeepMimic clip with frames ({e})") from e
    pathlib.Path(path).write_text(json.dumps(data))
    return os.fspath(path)
