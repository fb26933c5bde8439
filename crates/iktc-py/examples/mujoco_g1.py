"""Standing imitation of a clip by the Unitree G1 in MuJoCo, driven by iktc tick by tick.

    python crates/iktc-py/examples/mujoco_g1.py [--clip humanoid3d_dance_b] [--time-scale 1]
                                                [--robot g1|profile.toml] [--json out.json]

Prints the run's figures (stayed up, pelvis height, base tilt, foot slip, ZMP margin from the
ankle force/torque sensors, tracking errors) and the ZMP that iktc's kinematic plan asks for
(MuJoCo's inverse dynamics of the plan), which says whether any plant could follow it without
tipping. See ``g1_sim.py`` for the plant and the loop.
"""
import argparse
import json

import numpy as np

import g1_sim
import iktc


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clip", default="humanoid3d_dance_b")
    ap.add_argument("--time-scale", type=float, default=1.0, help="play the clip this many times slower")
    ap.add_argument("--robot", default="g1", help="the built-in g1 or a G1 profile file (.toml)")
    ap.add_argument("--settle", type=float, default=0.5, help="time holding the start posture [s]")
    ap.add_argument("--json", help="write the figures to this file")
    a = ap.parse_args()
    loop = g1_sim.Loop(clip=a.clip, time_scale=a.time_scale, robot=iktc.Robot(a.robot))
    loop.settle(a.settle)
    for _ in range(loop.sim.ticks):
        loop.step()
    s = loop.summary()
    plan = g1_sim.planned_zmp(loop.plant, loop.log.q_cmd)
    margins = [loop.sim.support_margin(tuple(p)) for p in plan if np.all(np.isfinite(p))]
    s["planned_zmp_margin_min_m"] = float(min(margins))
    s["planned_zmp_ticks_outside"] = int(sum(m < 0 for m in margins))
    s["plant"] = {"kp_Nm_per_rad": g1_sim.KP, "kv_Nms_per_rad": g1_sim.KV,
                  "physics_step_s": g1_sim.PHYSICS_STEP, "control_period_s": g1_sim.CONTROL_PERIOD,
                  "integrator": "implicitfast"}
    print(json.dumps(s, indent=1))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(s, f, indent=1)


if __name__ == "__main__":
    main()
