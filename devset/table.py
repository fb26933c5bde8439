"""Per-clip neutral fidelity figures of an `iktc retarget` output folder, and their means.

Usage: python3 devset/table.py OUT/ROBOT

Reads each clip's quality.json (`summary.keypoints.fidelity`, the figures of
`iktc::retarget::fidelity`): mean keypoint error [cm]; knee flexion and trunk lean medians,
robot/person [deg]; hip height gap [cm]; largest slip over the person's contacts [mm] and
where it was (foot, window, the person's own scaled ankle slip there); lowest sole [mm];
the share of ticks whose change of q̈ reverses. The means: keypoint error, |knee gap|
(robot − person medians, both knees), |lean gap|, |hip gap|, the largest slip, the lowest
sole (minimum), the reversal share.
"""
import glob
import json
import os
import statistics
import sys

folder = sys.argv[1]
rows = []
print("clip | keypoint cm | knee r/p ° | lean r/p ° | hip gap cm | slip mm (where) | lowest sole mm | reversal")
for q in sorted(glob.glob(f"{folder}/*/quality.json")):
    name = os.path.basename(os.path.dirname(q))
    f = json.load(open(q))["summary"].get("keypoints", {}).get("fidelity")
    if not f:
        print(f"{name} | no fidelity figures")
        continue
    p = {x["name"]: x for x in f["posture"]}
    knee_r = (p["left_knee"]["robot_median"] + p["right_knee"]["robot_median"]) / 2
    knee_p = (p["left_knee"]["person_median"] + p["right_knee"]["person_median"]) / 2
    lean = p["trunk_lean"]
    c, s = f["contacts"], f["smoothness"]
    w = c.get("worst_slip")
    where = f" ({w['foot']} {w['start_s']:.2f}-{w['end_s']:.2f} s, person {w['person_mm']:.0f})" if w else ""
    print(f"{name} | {f['keypoint_mean_cm']:.1f} | {knee_r:.0f}/{knee_p:.0f} | "
          f"{lean['robot_median']:.0f}/{lean['person_median']:.0f} | "
          f"{p['hip_height']['difference_median']:.1f} | {c['slip_max_mm']:.0f}{where} | "
          f"{c['lowest_sole_mm']:.1f} | {s['reversal_share']:.3f}")
    rows.append((f["keypoint_mean_cm"], abs(knee_r - knee_p),
                 abs(lean["robot_median"] - lean["person_median"]),
                 abs(p["hip_height"]["difference_median"]), c["slip_max_mm"],
                 c["lowest_sole_mm"], s["reversal_share"]))
if rows:
    m = lambda i: statistics.mean(r[i] for r in rows)
    print(f"MEAN of {len(rows)} clips: keypoint {m(0):.2f} cm | knee gap {m(1):.1f}° | "
          f"lean gap {m(2):.1f}° | hip gap {m(3):.1f} cm | slip {m(4):.0f} mm "
          f"(worst {max(r[4] for r in rows):.0f}) | lowest sole {min(r[5] for r in rows):.1f} mm | "
          f"reversal {m(6):.3f}")
