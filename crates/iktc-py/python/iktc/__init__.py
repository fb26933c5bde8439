"""iktc: inverse kinematic control of humanoids under joint constraints (Kim & Oh), in Rust.

Quick start::

    import iktc
    robot = iktc.Robot("jvrc1")
    q, v = robot.neutral()
    b = iktc.ControllerBuilder(robot, q, kp=100.0)
    b.level("feet"); b.frame("r_ankle"); b.frame("l_ankle")
    b.level("com"); com = b.com("xy")
    ctrl = b.build()
    ctrl.set_com_reference(com, robot.com(q) + [0.02, 0.0, 0.0])
    report = ctrl.step(q, v, 0.005)     # q and v advanced in place

Motions (``load_motion``: a built-in DeepMimic clip or a BVH, ASF/AMC, DeepMimic, C3D,
points-CSV file, or an AMASS ``.npz`` archive with ``body_model=`` the SMPL-H / SMPL-X model
file) retarget to a robot with ``retarget_joint_angles`` or ``retarget_keypoints`` (body points,
the robot's q, v, q̈ per tick), numpy arrays; ``Imitation`` steps the
imitation of Section 5.3 tick by tick.

Every error of the library is raised as ``iktc.IktcError`` (a ``ValueError``) with the
library's message.

``iktc.mujoco`` (needs ``pip install mujoco``) runs the Unitree G1 in MuJoCo under iktc: the
plant, the closed loop, the identification and push test of the damping controller, walking.
"""
from ._iktc import (
    __version__,
    IktcError,
    Robot,
    ControllerBuilder,
    Controller,
    FrameHandle,
    ComHandle,
    JointsHandle,
    SolveReport,
    PlaneModel,
    DampingController,
    measure_zmp,
    identify,
    dominant_mode,
    Motion,
    Retargeted,
    References,
    Imitation,
    Walking,
    load_motion,
    retarget_joint_angles,
    retarget_keypoints,
    KeypointTrajectory,
    profile_init,
    builtin_text,
)

__all__ = [
    "__version__",
    "IktcError",
    "Robot",
    "ControllerBuilder",
    "Controller",
    "FrameHandle",
    "ComHandle",
    "JointsHandle",
    "SolveReport",
    "PlaneModel",
    "DampingController",
    "measure_zmp",
    "identify",
    "dominant_mode",
    "Motion",
    "Retargeted",
    "References",
    "Imitation",
    "Walking",
    "load_motion",
    "retarget_joint_angles",
    "retarget_keypoints",
    "KeypointTrajectory",
    "profile_init",
    "builtin_text",
]
