"""The Unitree G1 in MuJoCo, driven by iktc tick by tick: a closed loop for the imitation, the
identification and damping controller of Section 4, and walking.

MuJoCo is optional for the rest of iktc: this subpackage needs it (``pip install mujoco``, or
``pip install 'iktc[sim]'``) and raises ImportError saying so without it.

The plant (``Plant``, ``plant_xml``): the G1 MJCF of Unitree, by default the one built into
iktc (``iktc.builtin_text("mjcf", "g1")``), with its meshes left out (they carry no mass: every
body has its own inertial; only the feet's four contact spheres and the thighs' cylinders
collide), its ``<motor>`` actuators turned into position servos
``τ = KP (q_cmd − q) + KV (v_cmd − q̇) + τ_ff`` [N·m] (clipped to each joint's
``actuatorfrcrange``; v_cmd and τ_ff are 0 unless given, τ_ff from ``Feedforward`` in
walking), the ``implicitfast`` integrator at ``PHYSICS_STEP``, and a 6-axis force/torque
sensor at each ankle roll joint (a site at the joint, ``force`` and ``torque``).

The controller (``Loop``, ``run_standing``, ``run_standing_keypoints``): ``iktc.Imitation`` on
the built-in ``g1`` profile (Table 1 stack, IKTC, quiet bounds) integrates its own kinematic
state at ``CONTROL_PERIOD``; every tick its joint angles are the servos' set points (position
control, as on the paper's Hubo). The ZMP is measured from the two ankle sensors by eqs.
29–30 (``iktc.measure_zmp``); the damping controller (Section 4; ``identify_on_plant``,
``push_test``) turns it into a COM offset added to the imitation's COM reference. Walking
(``run_walking``) runs ``iktc.Walking`` on the plant with the plan's joint torques fed forward
(``Feedforward``). ``planned_zmp`` is the ZMP a kinematic plan asks for (MuJoCo's inverse
dynamics), ``write_replay`` an HTML replay of a run next to its plan.

The damping ratio of a measured response is the library's: ``iktc.dominant_mode(t, y)``.
"""
try:
    import mujoco as _mujoco  # type: ignore[import-untyped] # noqa: F401
except ImportError as _e:  # pragma: no cover - exercised in a subprocess by the tests
    raise ImportError(
        "iktc.mujoco needs MuJoCo's Python bindings, which iktc does not install: "
        "pip install mujoco (or pip install 'iktc[sim]')") from _e

from .plant import (
    CONTROL_PERIOD,
    FEET,
    KP,
    KV,
    MIN_NORMAL_FORCE,
    MIN_SHARE,
    PHYSICS_STEP,
    SENSOR_SITES,
    Feedforward,
    Plant,
    planned_zmp,
    plant_xml,
    tilt,
    to_mujoco_qpos,
    yaw_between,
)
from .loop import Log, Loop, plan_chatter, run_standing, run_standing_keypoints, summarise
from .balance import (
    SWEEP_AMPLITUDE,
    SWEEP_BAND,
    frequency_response,
    identify_on_plant,
    pendulum_length,
    push_test,
    sine_response,
    standing_loop,
)
from .walking import ON_GROUND, held_clip, run_walking
from .diagnostics import (
    G1_KNEES,
    PELVIS_HELD,
    plan_outside,
    robot_with_acceleration,
    standing_figures,
    walking_plan_figures,
)
from .replay import write_replay

__all__ = [
    "CONTROL_PERIOD",
    "FEET",
    "KP",
    "KV",
    "MIN_NORMAL_FORCE",
    "MIN_SHARE",
    "PHYSICS_STEP",
    "SENSOR_SITES",
    "Feedforward",
    "Plant",
    "planned_zmp",
    "plant_xml",
    "tilt",
    "to_mujoco_qpos",
    "yaw_between",
    "Log",
    "Loop",
    "plan_chatter",
    "run_standing",
    "run_standing_keypoints",
    "summarise",
    "SWEEP_AMPLITUDE",
    "SWEEP_BAND",
    "frequency_response",
    "identify_on_plant",
    "pendulum_length",
    "push_test",
    "sine_response",
    "standing_loop",
    "ON_GROUND",
    "held_clip",
    "run_walking",
    "G1_KNEES",
    "PELVIS_HELD",
    "plan_outside",
    "robot_with_acceleration",
    "standing_figures",
    "walking_plan_figures",
    "write_replay",
]
