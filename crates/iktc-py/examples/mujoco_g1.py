"""The Unitree G1 in MuJoCo driven by iktc tick by tick: standing imitation, identification, push.

    python crates/iktc-py/examples/mujoco_g1.py standing [--clip humanoid3d_dance_b]
        [--plan joints|keypoints|upper-body] [--time-scale 1] [--robot g1|profile.toml]
        [--json out.json] [--replay out.html]
    python crates/iktc-py/examples/mujoco_g1.py balance [--damping 0.72] [--designs 0.3,0.9]
        [--json out.json]
    python crates/iktc-py/examples/mujoco_g1.py walking [--steps 4] [--clip humanoid3d_walk]
        [--hold-upper-body] [--no-feedforward] [--zmp-passes 1] [--json out.json] [--replay out.html]
    python crates/iktc-py/examples/mujoco_g1.py causes [--json out.json]

`standing` prints the run's figures (stayed up, pelvis height, base tilt, foot slip, ZMP margin
from the ankle force/torque sensors, tracking errors) and the ZMP that iktc's kinematic plan asks
for (MuJoCo's inverse dynamics of the plan), which says whether any plant could follow it
without tipping. `balance` identifies the IPCJ model of the sagittal plane on MuJoCo by the sine
sweep of Section 4.2, places the poles, and pushes the standing robot at the pelvis with and
without the damping controller, printing the fit and the damping ratios. `walking` walks
while imitating the clip (damping controller off; the plan's joint torques fed forward to the
servos unless `--no-feedforward`; `--hold-upper-body` holds the clip's first frame) and prints
whether the robot stayed up, the standing feet's errors and the ZMP against the support polygon
of the feet carrying load and against the pattern's. `causes` prints the
figures behind the expected failures: the standing run with the knees narrowed, the viable
bounds and Algorithm 2's level as printed,
the pelvis held, the clip slower, the arms frozen in the plan; the walking plan's ZMP and knees
with and without narrowed knees; the walk in MuJoCo with stiffer servos. The plant, the loop
and the runs are ``iktc.mujoco``'s.
"""
import argparse
import json
import pathlib

import numpy as np

import iktc
import iktc.mujoco as g1


def balance(a) -> dict:
    model, fit, (omega, mag, phase) = g1.identify_on_plant()
    wn, zeta = model.modal()
    out = {
        "sweep_hz": [float(w / (2 * np.pi)) for w in omega],
        "sweep_magnitude_m_per_rad": [float(m) for m in mag],
        "sweep_phase_deg": [float(np.degrees(p)) for p in phase],
        "model": {"length_m": model.length, "stiffness_per_mass": model.stiffness_per_mass,
                  "damping_per_mass": model.damping_per_mass, "lag_s": model.lag,
                  "pade_s": model.pade, "natural_frequency_rad_s": wn, "damping_ratio": zeta},
        "fit": fit,
        "design_damping_ratio": a.damping,
    }
    for name, m in (("open_loop", None), ("damped", model)):
        loop, t, y = g1.push_test(model=m, damping=a.damping)
        z, w = iktc.dominant_mode(t, y)
        s = loop.summary()
        out[f"push_{name}"] = {"damping_ratio": z, "natural_frequency_rad_s": w,
                               "zmp_peak_m": float(np.abs(y).max()),
                               "stayed_up": s["stayed_up"], "foot_slip_max_m": s["foot_slip_max_m"],
                               "zmp_margin_min_m": s["zmp_margin_min_m"]}
    if a.designs:
        out["push_damped_by_design"] = {}
        for z in (float(x) for x in a.designs.split(",")):
            loop, t, y = g1.push_test(model=model, damping=z)
            out["push_damped_by_design"][str(z)] = iktc.dominant_mode(t, y)[0]
    return out


def causes(a) -> dict:
    """The figures behind the expected failures (diagnostic settings, not defaults)."""
    names = iktc.Robot("g1").joint_names
    slow = g1.robot_with_acceleration(1.0)
    upper = [n for n in names if any(x in n for x in ("shoulder", "elbow", "wrist"))]
    runs = {
        "default": {},
        "arms_frozen_in_the_plan": {"frozen": upper},
        "knees_narrowed": {"narrow": g1.G1_KNEES},
        "knees_narrowed_accel_1x_velocity_limit": {"narrow": g1.G1_KNEES, "robot": slow},
        "viable_bounds_algorithm2": {"bounds": "viable", "level_hold": 1},
        "pelvis_held": {"root_scales": g1.PELVIS_HELD},
        "clip_4x_slower": {"time_scale": 4.0},
    }
    out = {"standing": {k: g1.standing_figures(**kw) for k, kw in runs.items()}}
    out["walking_plan"] = {f"{clip} {'knees narrowed' if n else 'default'}":
                           g1.walking_plan_figures(clip, n)
                           for clip in ("humanoid3d_dance_b", "humanoid3d_walk")
                           for n in (None, g1.G1_KNEES)}
    out["walking_mujoco_walk_clip_knees_narrowed"] = {
        f"kp {kp}": g1.run_walking(clip="humanoid3d_walk", narrow=g1.G1_KNEES, kp=kp,
                                   kv=kv)["stayed_up"]
        for kp, kv in ((500.0, 20.0), (2000.0, 40.0), (5000.0, 100.0))}
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run", nargs="?", default="standing",
                    choices=["standing", "balance", "walking", "causes"])
    ap.add_argument("--steps", type=int, default=4, help="footsteps of the walking run")
    ap.add_argument("--hold-upper-body", action="store_true",
                    help="walking: every frame of the clip its first (upper body and pelvis held)")
    ap.add_argument("--no-feedforward", action="store_true",
                    help="walking: the servos without the plan's joint torques")
    ap.add_argument("--zmp-passes", type=int, default=1,
                    help="walking: passes of the ZMP correction of the pattern (0: the cart-table alone)")
    ap.add_argument("--damping", type=float, default=0.72, help="design damping ratio [–]")
    ap.add_argument("--designs", help="balance: also push with these design ratios, e.g. "
                    "0.3,0.5,0.72,0.9, and print the measured ones")
    ap.add_argument("--clip", default="humanoid3d_dance_b")
    ap.add_argument("--plan", default="joints", choices=["joints", "keypoints", "upper-body"],
                    help="standing: the imitation of Table 1 ticking in the loop (joint route), "
                    "the keypoint retargeting with the feet held, or the keypoint retargeting's "
                    "standing imitation (feet and pelvis held, the clip's upper body relative to "
                    "its pelvis), both computed beforehand")
    ap.add_argument("--time-scale", type=float, default=1.0, help="play the clip this many times slower")
    ap.add_argument("--robot", default="g1", help="the built-in g1 or a G1 profile file (.toml)")
    ap.add_argument("--settle", type=float, default=0.5, help="time holding the start posture [s]")
    ap.add_argument("--json", help="write the figures to this file")
    ap.add_argument("--replay", help="standing, walking: write an HTML replay of the physics run next to "
                    "iktc's plan to this file")
    a = ap.parse_args()
    if a.run == "balance":
        s = balance(a)
    elif a.run == "causes":
        s = causes(a)
    elif a.run == "walking":
        clip = a.clip
        if a.hold_upper_body:
            import tempfile
            clip = g1.held_clip(pathlib.Path(tempfile.mkdtemp()) / f"held_{a.clip}.txt", a.clip)
        s = g1.run_walking(steps=a.steps, clip=clip, feedforward=not a.no_feedforward,
                           replay=a.replay, zmp_passes=a.zmp_passes)
    else:
        s = standing(a)
    print(json.dumps(s, indent=1))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(s, f, indent=1)


#: The plan's ZMP is reported where the ground carries at least this share of the robot's
#: weight [–]: below it the ZMP divides a moment by a small force (the keypoint plan of
#: humanoid3d_dance_b asks for less on 41 of 504 ticks, for a pull on 34, and its ZMP then
#: reaches kilometres).
PLANNED_MIN_SUPPORT = 0.1


def standing(a) -> dict:
    if a.plan in ("keypoints", "upper-body"):
        if a.time_scale != 1.0:
            raise SystemExit("--time-scale applies to --plan joints only")
        loop = g1.run_standing_keypoints(clip=a.clip, settle=a.settle,
                                         robot=iktc.Robot(a.robot),
                                         standing=a.plan == "upper-body")
    else:
        loop = g1.Loop(clip=a.clip, time_scale=a.time_scale, robot=iktc.Robot(a.robot))
        loop.settle(a.settle)
        for _ in range(loop.sim.ticks):
            loop.step()
    s = loop.summary()
    s["plan"] = a.plan
    s.update(g1.plan_chatter(loop.log.q_cmd))
    # The plan's ZMP where the ground carries at least PLANNED_MIN_SUPPORT of the weight; the
    # ticks (the two at each end aside) where it carries less, or would have to pull, counted.
    plan = g1.planned_zmp(loop.plant, loop.log.q_cmd, min_support=PLANNED_MIN_SUPPORT)
    pulls = g1.planned_zmp(loop.plant, loop.log.q_cmd)
    feet = [loop.robot.frame_pose(loop.log.q_cmd[0], f) for f in g1.FEET]  # held
    margins = [loop.sim.support_margin(tuple(p), feet) for p in plan if np.all(np.isfinite(p))]
    s["planned_zmp_margin_min_m"] = float(min(margins))
    s["planned_zmp_ticks_outside"] = int(sum(m < 0 for m in margins))
    s["planned_light_support_ticks"] = int(np.isnan(plan[2:-2, 0]).sum())
    s["planned_ground_pulls_ticks"] = int(np.isnan(pulls[2:-2, 0]).sum())
    if a.replay:
        g1.write_replay(a.replay, loop.plant, loop.log.qpos, loop.log.q_cmd,
                        f"G1 in MuJoCo imitating {a.clip} (time scale {a.time_scale})")
    s["plant"] = {"kp_Nm_per_rad": g1.KP, "kv_Nms_per_rad": g1.KV,
                  "physics_step_s": g1.PHYSICS_STEP, "control_period_s": g1.CONTROL_PERIOD,
                  "integrator": "implicitfast"}
    return s


if __name__ == "__main__":
    main()
