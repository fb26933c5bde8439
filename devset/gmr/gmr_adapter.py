"""Run GMR (General Motion Retargeting) on BVH rigs other than LAFAN1, onto Unitree G1.

A GMR user's adapter: GMR's BVH path (`load_lafan1_file`) expects LAFAN1 bone names, LAFAN1's
bone axes, centimetres and Y up. This script reads any BVH itself and hands GMR the per-frame
dictionary `{lafan1_bone_name: (position [m, Z up], orientation wxyz)}` that
`load_lafan1_file` would return, then calls GMR's own `GeneralMotionRetargeting.retarget`
per frame with its own `bvh_to_g1.json` IK configuration, unchanged.

Adapting a rig:
* names: the rig's bones mapped onto LAFAN1's (BANDAI, MIXAMO, MOCAPBANK, PYMO, CMU below);
* axes: the first frame's up (ankles → head, the largest coordinate axis) taken onto Z as
  GMR's own loader does for Y up;
* units from the body's largest extent along up over the clip's frames (all joints and end
  sites): the one of m, cm, mm, inch, CMU's 1/0.45 inch that makes it 1.2-2.1 m (iktc's rule);
* GMR_HEIGHT=1.75 in the environment passes GMR's own loader's fixed height instead;
* orientations: GMR's IK drives each robot link to `bone_orientation * offset` (offset from
  its IK config), with LAFAN1's bone axes. Rigs' bone axes (and rest poses) differ, so every
  bone's orientation is rebuilt from joint positions: a frame C(t) per segment (pelvis: left
  hip - right hip and hips -> shoulders' middle; chest: left - right shoulder and hips ->
  shoulders' middle; thigh/shin: the segment's axis and the pelvis' left axis; upper arm and
  forearm: the segment's axis and the elbow's hinge axis, blended into the chest's left axis
  as the elbow straightens; foot: ankle -> toe and the shin's left axis), the same construction
  applied to the robot's links at q = 0 gives C_ref, and the bone is handed to GMR as
  C(t) C_ref^-1 E with E = R_link(q=0) offset^-1, so that GMR's target for the link is
  C(t) C_ref^-1 R_link(q=0): the link's zero orientation turned as the person's segment is
  turned away from the robot's zero posture. The hand takes the forearm's frame.
* heading: the clip turned about Z so that its first pelvis faces +x over the origin, where
  GMR's IK starts;
* height: `actual_human_height` (GMR scales by it / 1.8) = the head joint's largest height
  above the lower ankle over the clip + 0.2 m (ankle above the sole, crown above the head
  joint): an estimate of the stature, as a GMR user without the actor's height would make.
Outputs per clip: OUT/<clip>.npy (qpos per frame, MuJoCo order: xyz, wxyz, joints),
OUT/<clip>.csv (the plain CSV `iktc evaluate` reads) and OUT/<clip>.json (timing).
"""
import json
import os
import pathlib
import sys
import time

import mujoco as mj
import numpy as np
from scipy.spatial.transform import Rotation as R

# GMR's package __init__ imports its viewer and an SMPL-X body model (torch, imageio, cv2),
# which the BVH retargeting does not use: register the package without running __init__ and
# import only the retargeting module and its parameters (GMR's code itself is unchanged).
import importlib
import types

GMR_ROOT = pathlib.Path(os.environ.get("GMR_SRC", "/tmp/gmr")) / "general_motion_retargeting"
_pkg = types.ModuleType("general_motion_retargeting")
_pkg.__path__ = [str(GMR_ROOT)]
sys.modules["general_motion_retargeting"] = _pkg
GMR = importlib.import_module("general_motion_retargeting.motion_retarget").GeneralMotionRetargeting
_params = importlib.import_module("general_motion_retargeting.params")
IK_CONFIG_DICT, ROBOT_XML_DICT = _params.IK_CONFIG_DICT, _params.ROBOT_XML_DICT

# LAFAN1 name -> the rig's bone, per rig (matched by the rig's hip bone name).
BANDAI = dict(Hips="Hips", Spine2="Chest", Head="Head",
              LeftUpLeg="UpperLeg_L", LeftLeg="LowerLeg_L", LeftFoot="Foot_L", LeftToe="Toes_L",
              RightUpLeg="UpperLeg_R", RightLeg="LowerLeg_R", RightFoot="Foot_R", RightToe="Toes_R",
              LeftArm="UpperArm_L", LeftForeArm="LowerArm_L", LeftHand="Hand_L",
              RightArm="UpperArm_R", RightForeArm="LowerArm_R", RightHand="Hand_R")
MIXAMO = {k: "mixamorig:" + v for k, v in dict(
    Hips="Hips", Spine2="Spine2", Head="Head",
    LeftUpLeg="LeftUpLeg", LeftLeg="LeftLeg", LeftFoot="LeftFoot", LeftToe="LeftToeBase",
    RightUpLeg="RightUpLeg", RightLeg="RightLeg", RightFoot="RightFoot", RightToe="RightToeBase",
    LeftArm="LeftArm", LeftForeArm="LeftForeArm", LeftHand="LeftHand",
    RightArm="RightArm", RightForeArm="RightForeArm", RightHand="RightHand").items()}
MOCAPBANK = dict(Hips="Hips", Spine2="Chest2", Head="Head",
                 LeftUpLeg="LeftHip", LeftLeg="LeftKnee", LeftFoot="LeftAnkle", LeftToe=None,
                 RightUpLeg="RightHip", RightLeg="RightKnee", RightFoot="RightAnkle", RightToe=None,
                 LeftArm="LeftShoulder", LeftForeArm="LeftElbow", LeftHand="LeftWrist",
                 RightArm="RightShoulder", RightForeArm="RightElbow", RightHand="RightWrist")
PYMO = dict(Hips="Hips", Spine2="Spine", Head="Head",
            LeftUpLeg="LeftUpLeg", LeftLeg="LeftLeg", LeftFoot="LeftFoot", LeftToe="LeftToeBase",
            RightUpLeg="RightUpLeg", RightLeg="RightLeg", RightFoot="RightFoot", RightToe="RightToeBase",
            LeftArm="LeftArm", LeftForeArm="LeftForeArm", LeftHand="LeftHand",
            RightArm="RightArm", RightForeArm="RightForeArm", RightHand="RightHand")
CMU = dict(Hips="Hips", Spine2="Chest2", Head="Head",
           LeftUpLeg="LeftHip", LeftLeg="LeftKnee", LeftFoot="LeftAnkle", LeftToe="LeftToe",
           RightUpLeg="RightHip", RightLeg="RightKnee", RightFoot="RightAnkle", RightToe="RightToe",
           LeftArm="LeftShoulder", LeftForeArm="LeftElbow", LeftHand="LeftWrist",
           RightArm="RightShoulder", RightForeArm="RightElbow", RightHand="RightWrist")


def pick_rig(names):
    if "UpperLeg_L" in names:
        return "bandai", BANDAI
    if "mixamorig:Hips" in names:
        return "mixamo", MIXAMO
    if "LHipJoint" in names:
        return "cmu", CMU
    if "LeftKnee" in names:
        return "mocapbank", MOCAPBANK
    if "LeftUpLeg" in names:
        return "pymo", PYMO
    raise SystemExit(f"unknown rig: {names[:8]}")


def read_bvh(path):
    """Joints (name, parent, offset, channels) incl. end sites, frame time, motion rows."""
    toks = pathlib.Path(path).read_text().split()
    i, joints, stack = 0, [], []
    while toks[i] != "MOTION":
        t = toks[i]
        if t in ("ROOT", "JOINT"):
            joints.append(dict(name=toks[i + 1], parent=stack[-1] if stack else -1,
                               offset=None, channels=[], end=False))
            i += 2
        elif t == "End":
            joints.append(dict(name=joints[stack[-1]]["name"] + "_End", parent=stack[-1],
                               offset=None, channels=[], end=True))
            i += 2
        elif t == "{":
            stack.append(len(joints) - 1)
            i += 1
        elif t == "}":
            stack.pop()
            i += 1
        elif t == "OFFSET":
            joints[stack[-1]]["offset"] = np.array([float(x) for x in toks[i + 1:i + 4]])
            i += 4
        elif t == "CHANNELS":
            n = int(toks[i + 1])
            joints[stack[-1]]["channels"] = toks[i + 2:i + 2 + n]
            i += 2 + n
        else:
            i += 1
    nframes = int(toks[i + 2])
    ftime = float(toks[i + 5])
    data = np.array([float(x) for x in toks[i + 6:]]).reshape(nframes, -1)
    return joints, ftime, data


def fk(joints, data):
    """World rotations (F, J, 3, 3) and positions (F, J, 3), file units and axes."""
    nf = data.shape[0]
    rot = np.zeros((nf, len(joints), 3, 3))
    pos = np.zeros((nf, len(joints), 3))
    col = 0
    for j, jt in enumerate(joints):
        local_t = np.tile(jt["offset"], (nf, 1))
        local_r = np.tile(np.eye(3), (nf, 1, 1))
        ptr = {}
        for c in jt["channels"]:
            ptr[c] = data[:, col]
            col += 1
        if "Xposition" in ptr:
            local_t = np.stack([ptr["Xposition"], ptr["Yposition"], ptr["Zposition"]], axis=1)
        order = [c[0].lower() for c in jt["channels"] if c.endswith("rotation")]
        if order:
            angles = np.stack([ptr[c.upper() + "rotation"] for c in order], axis=1)
            local_r = R.from_euler("".join(order).upper(), angles, degrees=True).as_matrix()
        p = jt["parent"]
        if p < 0:
            rot[:, j], pos[:, j] = local_r, local_t
        else:
            rot[:, j] = rot[:, p] @ local_r
            pos[:, j] = pos[:, p] + np.einsum("fij,fj->fi", rot[:, p], local_t)
    return rot, pos


UNITS = [1.0, 0.01, 0.001, 0.0254, 0.0254 / 0.45]


def unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def frame(z, y):
    """Rotation matrices (..., 3, 3) with columns x, y, z: z along `z`, y = `y` made orthogonal."""
    z = unit(z)
    y = unit(y - z * np.sum(y * z, axis=-1, keepdims=True))
    x = np.cross(y, z)
    return np.stack([x, y, z], axis=-1)


def segment_frames(p, has_toe=True):
    """Per segment, its frame from the points p (name -> (..., 3) positions, Z up)."""
    lat = p["LeftUpLeg"] - p["RightUpLeg"]
    shoulders = 0.5 * (p["LeftArm"] + p["RightArm"])
    trunk = shoulders - p["Hips"]
    pelvis = frame(trunk, lat)
    chest = frame(trunk, p["LeftArm"] - p["RightArm"])
    out = {"Hips": pelvis, "Spine2": chest}
    for s in ("Left", "Right"):
        thigh = frame(p[s + "UpLeg"] - p[s + "Leg"], pelvis[..., 1])
        shin = frame(p[s + "Leg"] - p[s + "Foot"], thigh[..., 1])
        out[s + "UpLeg"], out[s + "Leg"] = thigh, shin
        if has_toe:
            toe = p[s + "Toe"] - p[s + "Foot"]
            fx = unit(toe)
            fy = unit(shin[..., 1] - fx * np.sum(shin[..., 1] * fx, axis=-1, keepdims=True))
            out[s + "FootMod"] = np.stack([fx, fy, np.cross(fx, fy)], axis=-1)
        else:
            out[s + "FootMod"] = shin
        # The elbow's hinge axis (upper arm x forearm; the left axis for a bent elbow), blended
        # into the chest's left axis (plus a little of its forward one) as the elbow
        # straightens, where the hinge is not defined.
        upper = p[s + "Arm"] - p[s + "ForeArm"]
        lower = p[s + "Hand"] - p[s + "ForeArm"]
        hinge = np.cross(upper, lower)
        sin_flex = np.linalg.norm(hinge, axis=-1, keepdims=True) / (
            np.linalg.norm(upper, axis=-1, keepdims=True) * np.linalg.norm(lower, axis=-1, keepdims=True))
        w = np.clip(sin_flex / np.sin(np.radians(20.0)), 0.0, 1.0)
        fallback = unit(chest[..., 1] + 0.1 * chest[..., 0])
        side = w * unit(hinge + 1e-12 * fallback) + (1.0 - w) * fallback
        arm = frame(upper, side)
        fore = frame(-lower, side)
        out[s + "Arm"], out[s + "ForeArm"], out[s + "Hand"] = arm, fore, fore
    return out


# The robot's bodies standing for the person's points in its zero posture.
ROBOT_POINTS = dict(
    Hips="pelvis", LeftUpLeg="left_hip_roll_link", RightUpLeg="right_hip_roll_link",
    LeftLeg="left_knee_link", RightLeg="right_knee_link",
    LeftFoot="left_ankle_roll_link", RightFoot="right_ankle_roll_link",
    LeftToe="left_toe_link", RightToe="right_toe_link",
    LeftArm="left_shoulder_roll_link", RightArm="right_shoulder_roll_link",
    LeftForeArm="left_elbow_link", RightForeArm="right_elbow_link",
    LeftHand="left_wrist_yaw_link", RightHand="right_wrist_yaw_link")


def main(bvh, out_dir, robot="unitree_g1"):
    joints, ftime, data = read_bvh(bvh)
    names = [j["name"] for j in joints]
    rig, m = pick_rig(names)
    idx = {k: (names.index(v) if v else None) for k, v in m.items()}
    rot, pos = fk(joints, data)
    # Up: ankles -> head on the first frame, the largest coordinate axis.
    ank = 0.5 * (pos[0, idx["LeftFoot"]] + pos[0, idx["RightFoot"]])
    upv = pos[0, idx["Head"]] - ank
    ax = int(np.argmax(np.abs(upv)))
    if ax == 1 and upv[1] > 0:
        F = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])  # GMR's own Y-up -> Z-up
    elif ax == 2 and upv[2] > 0:
        F = np.eye(3)
    else:
        raise SystemExit(f"{bvh}: up axis {upv} is not +Y or +Z")
    P = np.einsum("ij,fkj->fki", F, pos)
    stature_units = float(np.max(np.ptp(P[:, :, 2], axis=1)))
    units = [u for u in UNITS if 1.2 <= stature_units * u <= 2.1]
    if len(units) != 1:
        raise SystemExit(f"{bvh}: stature {stature_units} units fits {units}")
    P = P * units[0]
    # Stature for GMR: the head joint's largest height above the lower ankle over the clip,
    # plus 0.2 m for the ankle's height above the sole and the crown above the head joint.
    feet = np.minimum(P[:, idx["LeftFoot"], 2], P[:, idx["RightFoot"], 2])
    height = float(np.max(P[:, idx["Head"], 2] - feet)) + 0.2
    if os.environ.get("GMR_HEIGHT"):
        # GMR's own BVH loader passes 1.75 m for every clip: GMR_HEIGHT=1.75 reproduces that.
        height = float(os.environ["GMR_HEIGHT"])
    has_toe = idx["LeftToe"] is not None
    pts = {k: P[:, i] for k, i in idx.items() if i is not None}
    C = segment_frames(pts, has_toe)
    # The clip turned about Z so that the first frame's pelvis faces +x, its first pelvis over
    # the origin: GMR starts its IK from the robot's zero posture facing +x at the origin, and
    # from a start turned far from it the IK can stay in a wrong minimum (mocapbank, turned
    # 98 degrees, kept a 130-degree torso error). The figures iktc evaluate gives do not
    # depend on the clip's heading or place.
    yaw0 = np.arctan2(C["Hips"][0][1, 0], C["Hips"][0][0, 0])
    Rz = R.from_euler("z", -yaw0).as_matrix()
    origin = Rz @ pts["Hips"][0] * np.array([1.0, 1.0, 0.0])
    pts = {k: v @ Rz.T - origin for k, v in pts.items()}
    C = {k: np.einsum("ij,fjk->fik", Rz, v) for k, v in C.items()}
    # Robot zero posture.
    model = mj.MjModel.from_xml_path(str(ROBOT_XML_DICT[robot]))
    d = mj.MjData(model)
    mj.mj_kinematics(model, d)
    xpos = {model.body(b).name: d.xpos[b].copy() for b in range(model.nbody)}
    xmat = {model.body(b).name: d.xmat[b].reshape(3, 3).copy() for b in range(model.nbody)}
    Cref = segment_frames({k: xpos[v] for k, v in ROBOT_POINTS.items()}, has_toe)
    cfg = json.load(open(IK_CONFIG_DICT["bvh"][robot]))["ik_match_table1"]
    link_of = {v[0]: k for k, v in cfg.items()}
    frames = []
    for f in range(data.shape[0]):
        fr = {}
        for bone, link in link_of.items():
            off = R.from_quat(cfg[link][4], scalar_first=True).as_matrix()
            o = C[bone][f] @ Cref[bone].T @ xmat[link] @ off.T
            p = pts[bone.replace("Mod", "")]
            fr[bone] = (p[f], R.from_matrix(o).as_quat(scalar_first=True))
        frames.append(fr)
    retargeter = GMR(src_human="bvh", tgt_robot=robot, actual_human_height=height)
    qpos, times = [], []
    for fr in frames:
        t0 = time.perf_counter()
        q = retargeter.retarget(fr)
        times.append(time.perf_counter() - t0)
        qpos.append(q)
    qpos = np.array(qpos)
    out = pathlib.Path(out_dir); out.mkdir(parents=True, exist_ok=True)
    stem = pathlib.Path(bvh).stem
    np.save(out / f"{stem}.npy", qpos)
    jnames = [model.joint(j).name for j in range(1, model.njnt)]
    header = ["time", "x", "y", "z", "qw", "qx", "qy", "qz"] + jnames
    t = np.arange(len(qpos)) * ftime
    rows = np.column_stack([t, qpos])  # qpos: xyz, wxyz (MuJoCo), joints in model order
    with open(out / f"{stem}.csv", "w") as fh:
        fh.write(",".join(header) + "\n")
        for r in rows:
            fh.write(",".join(repr(float(x)) for x in r) + "\n")
    info = dict(clip=str(bvh), rig=rig, frames=len(qpos), frame_time_s=ftime, unit_m=units[0],
                stature_m=height, ms_per_frame_median=1e3 * float(np.median(times)),
                ms_per_frame_mean=1e3 * float(np.mean(times)))
    (out / f"{stem}.json").write_text(json.dumps(info, indent=1))
    print(json.dumps(info))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
