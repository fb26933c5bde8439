"""The Python package against independently computed values and the Rust command line."""
import csv
import math
import os
import pathlib
import subprocess
import tempfile
import threading
import time

import numpy as np
import pytest

import iktc

REPO = pathlib.Path(__file__).resolve().parents[3]
DT = 0.005  # control period [s]


def bent_knees(robot):
    q, v = robot.neutral()
    for side in "RL":
        q[robot.q_index(f"{side}_HIP_P")] = -0.4
        q[robot.q_index(f"{side}_KNEE")] = 0.8
        q[robot.q_index(f"{side}_ANKLE_P")] = -0.4
    return q, v


def feet_and_com(robot, q, **kw):
    b = iktc.ControllerBuilder(robot, q, kp=100.0, **kw)
    b.level("feet")
    feet = (b.frame("r_ankle"), b.frame("l_ankle"))
    b.level("com")
    com = b.com("xy")
    return b.build(), feet, com


def test_quick_start_moves_the_com_and_keeps_the_box():
    robot = iktc.Robot("jvrc1")
    q, v = bent_knees(robot)
    ctrl, _, com = feet_and_com(robot, q)
    c0 = robot.com(q)
    ctrl.set_com_reference(com, c0 + [0.02, 0.0, 0.0])
    for _ in range(200):
        report = ctrl.step(q, v, DT)
        assert report.violation <= 1e-9
    # Converged with k_p = 100 s⁻²: 1 s is ten time constants.
    assert np.linalg.norm(robot.com(q)[:2] - (c0[:2] + [0.02, 0.0])) < 1e-3


def test_arrays_in_and_out_have_the_right_shapes_and_dtypes():
    robot = iktc.Robot("jvrc1")
    q, v = bent_knees(robot)
    assert q.dtype == np.float64 and q.shape == (robot.nq,)
    assert v.dtype == np.float64 and v.shape == (robot.nv,)
    ctrl, _, _ = feet_and_com(robot, q)
    ctrl.prepare(q, v, DT)
    eqs = ctrl.equations()
    assert [j.shape for j, _ in eqs] == [(12, robot.nv), (2, robot.nv)]
    assert [h.shape for _, h in eqs] == [(12,), (2,)]
    lower, upper = ctrl.bounds()
    assert lower.shape == upper.shape == (robot.nv,)
    ctrl.solve()
    assert ctrl.qdd.shape == (robot.nv,) and ctrl.qdd.dtype == np.float64
    assert robot.frame_pose(q, "r_ankle").shape == (4, 4)
    assert robot.frame_jacobian(q, "r_ankle").shape == (6, robot.nv)
    assert ctrl.level_dims == [12, 2]


def test_step_solves_the_first_level_and_integrates_with_constant_acceleration():
    robot = iktc.Robot("jvrc1")
    q, v = bent_knees(robot)
    v[robot.v_index("WAIST_Y")] = 0.3
    ctrl, _, com = feet_and_com(robot, q)
    ctrl.set_com_reference(com, robot.com(q) + [0.01, -0.01, 0.0])
    ctrl.prepare(q, v, DT)
    (j_feet, h_feet), _ = ctrl.equations()
    q0, v0 = q.copy(), v.copy()
    ctrl.step(q, v, DT)
    qdd = ctrl.qdd
    # The feet level holds exactly (it is feasible and inside the box here).
    assert np.allclose(j_feet @ qdd, h_feet, atol=1e-9 * max(1.0, np.abs(h_feet).max()))
    # Joints: q⁺ = q + Δt q̇ + ½Δt² q̈, q̇⁺ = q̇ + Δt q̈ (the base lives on SE(3)).
    nb = 7
    assert np.allclose(q[nb:], q0[nb:] + DT * v0[6:] + 0.5 * DT**2 * qdd[6:], atol=1e-12)
    assert np.allclose(v, v0 + DT * qdd, atol=1e-12)


def test_errors_are_python_exceptions_with_the_library_message():
    robot = iktc.Robot("jvrc1")
    q, _ = robot.neutral()
    b = iktc.ControllerBuilder(robot, q)
    b.level("one")
    with pytest.raises(iktc.IktcError, match="unknown frame `no_such_frame`; valid names are"):
        b.frame("no_such_frame")
    with pytest.raises(ValueError):  # IktcError is a ValueError
        iktc.Robot("no_such_robot")
    with pytest.raises(iktc.IktcError, match="dimension mismatch in q"):
        iktc.ControllerBuilder(robot, q[:-1])
    ctrl, _, com = feet_and_com(robot, q)
    with pytest.raises(iktc.IktcError, match="not finite"):
        ctrl.set_com_reference(com, [0.0, float("nan"), 0.0])


def test_a_handle_of_another_controller_is_rejected():
    robot = iktc.Robot("jvrc1")
    q, _ = bent_knees(robot)
    a, _, com_a = feet_and_com(robot, q)
    b, _, _ = feet_and_com(robot, q)
    with pytest.raises(iktc.IktcError):
        b.set_com_reference(com_a, [0.0, 0.0, 0.8])


def step_many(ctrl, q, v, n):
    for _ in range(n):
        ctrl.step(q, v, DT)


def parallel_ratio(serial, parallel):
    """Wall time of the two calls `parallel` in two threads over that of the two calls
    `serial` one after the other."""
    t0 = time.perf_counter()
    for f in serial:
        f()
    alone = time.perf_counter() - t0
    threads = [threading.Thread(target=f) for f in parallel]
    t0 = time.perf_counter()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return (time.perf_counter() - t0) / alone


def gil_round(robot, n):
    runs = []
    for _ in range(4):
        q, v = bent_knees(robot)
        ctrl, _, com = feet_and_com(robot, q)
        ctrl.set_com_reference(com, robot.com(q) + [0.02, 0.0, 0.0])
        runs.append((ctrl, q, v))
    steps = [lambda r=r: step_many(*r, n) for r in runs]
    return parallel_ratio(steps[:2], steps[2:])


def keypoint_round(robot, motion):
    def run():
        iktc.retarget_keypoints(motion, robot)

    return parallel_ratio([run, run], [run, run])


def python_share_during(call):
    """How much a pure-Python thread runs while `call` runs in this thread [–]: its iterations
    during the call over those it makes in the same wall time while this thread sleeps (which
    releases the GIL). Holding the GIL for the call leaves it at most one switch interval
    (`sys.getswitchinterval()`, 5 ms) at each end; released, it runs throughout (on one core
    the OS still shares it out)."""
    count = 0
    stop = threading.Event()

    def spin():
        nonlocal count
        while not stop.is_set():
            count += 1

    t = threading.Thread(target=spin)
    t.start()
    try:
        time.sleep(0.02)
        c0, t0 = count, time.perf_counter()
        time.sleep(0.1)
        rate = (count - c0) / (time.perf_counter() - t0)
        c0, t0 = count, time.perf_counter()
        call()
        during = count - c0
        elapsed = time.perf_counter() - t0
    finally:
        stop.set()
        t.join()
    return during / (rate * elapsed)


def test_the_gil_is_released_while_rust_runs():
    robot = iktc.Robot("jvrc1")
    motion = iktc.load_motion("humanoid3d_walk")
    # A clip's retargeting is one call of ≈ 0.1 s in Rust (`py.detach`): a Python thread keeps
    # running through it. Held, the GIL would stop that thread for all but a switch interval
    # at each end (≤ 10 ms of the call, ≤ 0.1 of its share). Measured: 1.0–1.35 here, and
    # 0.10–0.20 for a builtin that holds the GIL (`sorted` of 3 M integers, a shorter call).
    # Best of three calls.
    shares = [python_share_during(lambda: iktc.retarget_keypoints(motion, robot))
              for _ in range(3)]
    assert max(shares) > 0.3, shares
    # Two threads each retargeting a clip against the same two calls one after the other
    # (≈ 0.55 on two free cores, ≈ 1 on one), and two threads stepping controllers (a step is
    # ≈ 11 µs, much of it the Python call and the array conversions, GIL held: 0.75–1.2 from
    # run to run): wall-time ratios on a shared machine, reported, not asserted.
    clips = [keypoint_round(robot, motion) for _ in range(3)]
    print("two threads retargeting, parallel/serial wall time:", clips)
    steps = [gil_round(robot, 400) for _ in range(3)]
    print("two threads stepping controllers, parallel/serial wall time:", steps)


def iktc_binary():
    override = os.environ.get("IKTC_BIN")
    if override:
        return override
    # The newest build: a stale debug binary beside a fresh release one (or the other way
    # round) would compare the Python module with older code.
    built = [REPO / "target" / profile / "iktc" for profile in ("debug", "release")]
    built = [p for p in built if p.exists()]
    if built:
        return str(max(built, key=lambda p: p.stat().st_mtime))
    raise AssertionError("the iktc binary is not built: run `cargo build -p iktc-cli` (or set IKTC_BIN)")


def test_the_3r_arm_from_python_equals_the_rust_scenario():
    out = tempfile.mkdtemp()
    subprocess.run([iktc_binary(), "run", "planar3r", "--out", out], check=True,
                   stdout=subprocess.DEVNULL)
    with open(os.path.join(out, "trajectory.csv")) as f:
        rows = list(csv.DictReader(f))
    robot = iktc.Robot("planar3r")
    deg = math.pi / 180.0
    q = np.array([90 * deg, -90 * deg, 90 * deg])
    v = np.zeros(3)
    b = iktc.ControllerBuilder(robot, q, kp=100.0, kv=20.0, method="iktc", bounds="quiet")
    handles = []
    for name, axes in (("Py", "y"), ("Px", "x"), ("theta3", "w")):
        b.level(name)
        handles.append(b.frame("tip", axes))
    ctrl = b.build()
    worst = 0.0
    for k, row in enumerate(rows):
        t = k * DT
        if t <= 1.0:
            x = (1.5 - 0.5 * math.cos(math.pi * t), 2.0, 0.5 * math.pi)
            xd = (0.5 * math.pi * math.sin(math.pi * t), 0.0, 0.0)
            xdd = (0.5 * math.pi**2 * math.cos(math.pi * t), 0.0, 0.0)
        else:
            x, xd, xdd = (2.0, 2.0, 0.5 * math.pi), (0.0,) * 3, (0.0,) * 3
        quat = (0.0, 0.0, math.sin(x[2] / 2), math.cos(x[2] / 2))
        for h in handles:
            ctrl.set_frame_reference(h, (x[0], x[1], 0.0), quat,
                                     (xd[0], xd[1], 0, 0, 0, xd[2]), (xdd[0], xdd[1], 0, 0, 0, xdd[2]))
        for j in range(3):
            worst = max(worst, abs(q[j] - float(row[f"q{j + 1}"])))
        ctrl.step(q, v, DT)
    # Same equations, same solver: equal up to rounding and the CSV's printed digits.
    assert worst < 1e-6, worst


def test_the_soft_approach_brakes_a_joint_gently_into_its_limit():
    # The neck's yaw driven 0.3 rad beyond its upper limit by a joint task (k_p = 100 s⁻²),
    # feet held. The quiet bound brakes as late as possible: as it takes over, the command
    # changes by 18.8 rad/s² in one tick. With the approach at 10 /s the largest change of the
    # run is 6.6 rad/s². Both keep every limit, and the neck ends on its limit either way.
    robot = iktc.Robot("jvrc1")
    lower, upper, vmax, amax = robot.limits()
    name = "NECK_Y"
    iv = robot.v_index(name)
    jumps, ends = {}, {}
    for rate in (0.0, 10.0):
        q, v = bent_knees(robot)
        b = iktc.ControllerBuilder(robot, q, kp=100.0, approach_rate=rate)
        b.level("feet")
        b.frame("r_ankle")
        b.frame("l_ankle")
        b.level("elbow")
        elbow = b.joints([name])
        ctrl = b.build()
        ctrl.set_joints_reference(elbow, [upper[iv] + 0.3])
        qdd = []
        for _ in range(600):
            report = ctrl.step(q, v, DT)
            assert report.violation <= 1e-9
            qdd.append(ctrl.qdd[iv])
            assert lower[iv] - 1e-9 <= q[robot.q_index(name)] <= upper[iv] + 1e-9
        jumps[rate] = np.abs(np.diff(qdd)).max()
        ends[rate] = upper[iv] - q[robot.q_index(name)]
    assert jumps[10.0] < 0.5 * jumps[0.0], jumps
    assert ends[0.0] < 1e-9 and ends[10.0] < 1e-6, ends
    with pytest.raises(iktc.IktcError, match="approach_rate"):
        iktc.ControllerBuilder(robot, bent_knees(robot)[0], approach_rate=-1.0)
    with pytest.raises(iktc.IktcError, match="approach_rate"):
        iktc.ControllerBuilder(robot, bent_knees(robot)[0], bounds="paper", approach_rate=5.0)
