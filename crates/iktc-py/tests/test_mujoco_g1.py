"""The MuJoCo closed loop of the G1 (``iktc.mujoco``), run briefly, headless."""
import mujoco
import numpy as np
import pytest

import iktc
import iktc.mujoco as g1


def test_the_plant_stands_and_its_ankle_sensors_carry_the_weight():
    loop = g1.Loop(duration=0.1)
    p = loop.plant
    q = loop.sim.q
    for _ in range(200):  # 1 s holding the initial posture
        p.command(q)
        p.advance()
    m = p.model
    # Ground force on the feet = the weight of everything above the ankle sensors (the feet's own
    # weight is below them), from the model's masses.
    feet = sum(m.body_subtreemass[i] for i in p.feet)
    above = (m.body_subtreemass[p.pelvis] - feet) * -m.opt.gravity[2]
    fz = p.sensor_reading("left")[1][2] + p.sensor_reading("right")[1][2]
    assert fz == pytest.approx(above, rel=0.02)
    zmp, status = p.zmp()
    assert status == "both"
    assert loop.sim.support_margin(zmp, [p.foot_pose(i) for i in range(2)]) > 0.01
    assert p.pelvis_height() > 0.74 and p.base_tilt() < 0.05


def test_the_sensor_zmp_is_the_centre_of_pressure_of_the_contact_forces():
    loop = g1.Loop(duration=0.1)
    loop.settle(0.5)
    p, m, d = loop.plant, loop.plant.model, loop.plant.data
    # Centre of pressure from MuJoCo's contact forces (an independent route to the ZMP).
    total, moment = 0.0, np.zeros(2)
    f6 = np.zeros(6)
    for i in range(d.ncon):
        c = d.contact[i]
        mujoco.mj_contactForce(m, d, i, f6)
        fz = (c.frame.reshape(3, 3).T @ f6[:3])[2]
        total += fz
        moment += fz * c.pos[:2]
    cop = moment / total
    zmp, _ = p.zmp()
    # The sensors miss the feet's own weight and the spheres' 5 mm radius: within 5 mm.
    assert np.abs(np.array(zmp) - cop).max() < 5e-3, (zmp, cop)


def test_standing_imitation_of_the_default_clip_stays_up():
    loop = g1.run_standing()
    s = loop.summary()
    assert s["ticks"] == loop.sim.ticks == 507
    assert s["stayed_up"], s
    # 507 of 507 with MuJoCo 4.0.0 (478 at a 1 ms physics step).
    assert s["zmp_ticks_measured"] > 0.8 * s["ticks"]


# The plan is not dynamically feasible: MuJoCo's inverse dynamics of it puts the ZMP outside
# the polygon on 127 of 503 ticks (MuJoCo 4.0.1), the legs at their acceleration limit (200
# rad/s²); with the clip's pelvis held the slip is 17 mm (book/src/mujoco.md, `mujoco_g1.py causes`).
@pytest.mark.xfail(strict=True, reason="G1 on MuJoCo rocks and its feet slip 28 mm "
                   "while imitating humanoid3d_dance_b (see book/src/mujoco.md)")
def test_standing_imitation_of_the_default_clip_keeps_the_feet_within_5_mm():
    s = g1.run_standing().summary()
    assert s["foot_slip_max_m"] <= 5e-3, s


# The keypoint route (body points scaled to G1, feet held, COM over the polygon), its q and v
# the servos' set points, is no gentler: its joint accelerations (second differences) change
# sign every 4–5 ticks (rms 81 rad/s² against the joint route's 30), its ZMP is outside on 391
# of 504 ticks, and G1 falls (book/src/mujoco.md).
@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="G1 on MuJoCo falls following the keypoint route's plan "
                   "of humanoid3d_dance_b with its feet held (see book/src/mujoco.md)")
def test_standing_imitation_by_the_keypoint_route_keeps_the_feet_within_5_mm():
    s = g1.run_standing_keypoints().summary()
    assert s["foot_slip_max_m"] <= 5e-3, s


# The keypoint route's standing imitation (``standing=True``: feet and pelvis held at G1's start
# pose, the COM over the middle of the soles, the clip's upper body relative to its pelvis)
# keeps G1 up and level. MuJoCo 4.0.1: pelvis 0.761–0.762 m, tilt at most 0.014 rad; the plan's
# ZMP (inverse dynamics) outside the polygon on 3 of 504 ticks, by at most 18 mm (the joint
# route's: outside on 127).
def test_standing_imitation_of_the_upper_body_stays_up_and_level():
    loop = g1.run_standing_keypoints(standing=True)
    s = loop.summary()
    assert s["stayed_up"], s
    assert s["pelvis_height_min_m"] > 0.74 and s["base_tilt_max_rad"] < 0.1, s
    # The upper body does move (the arms' set points span more than a radian).
    q = np.array(loop.log.q_cmd)[:, 7:]
    assert np.ptp(q[:, loop.upper], axis=0).max() > 1.0


# Its feet slip 2.6 mm; the servos trail the plan by 0.024 rad rms (MuJoCo 4.0.1, 2026-12-06).
# At a 1 ms physics step: 9.0 mm and 0.094 rad rms, the light arm servos (the wrists and the
# shoulders' yaw most) flipping between their force limits on 141 of 508 ticks (see
# g1.PHYSICS_STEP). The feet turn by up to 28 mrad and back: MuJoCo's soft friction on its
# pyramidal cone.
def test_standing_imitation_of_the_upper_body_keeps_the_feet_within_5_mm():
    s = g1.run_standing_keypoints(standing=True).summary()
    assert s["foot_slip_max_m"] <= 5e-3, s
    assert s["upper_body_error_rms_rad"] < 0.05, s


def test_the_upper_body_standing_imitation_has_converged_in_the_physics_step():
    # Halving the physics step changes the figures little (0.1 → 0.05 ms: slip 2.6 → 2.6 mm,
    # servo error 0.0240 → 0.0238 rad rms, MuJoCo 4.0.1, 2026-12-06); at 1 ms they are 9.0 mm
    # and 0.094 rad.
    a = g1.run_standing_keypoints(standing=True).summary()
    b = g1.run_standing_keypoints(standing=True,
                                  physics_step=g1.PHYSICS_STEP / 2).summary()
    assert abs(a["foot_slip_max_m"] - b["foot_slip_max_m"]) < 0.5e-3, (a, b)
    assert abs(a["upper_body_error_rms_rad"] - b["upper_body_error_rms_rad"]) < 5e-3, (a, b)


def _hinge(physics_step: float, inertia: float, limit: float = 25.0) -> list:
    """Rates [rad/s] of one hinge (inertia [kg·m²] about its axis, no gravity) under the plant's
    rate servo KV (q̇_cmd − q̇), q̇_cmd = 3 rad/s from rest, its torque within ±limit [N·m], over
    8 ms of ``implicitfast``."""
    xml = f"""<mujoco><option timestep="{physics_step}" integrator="implicitfast" gravity="0 0 0"/>
      <worldbody><body><joint name="j" axis="0 0 1" actuatorfrcrange="{-limit} {limit}"/>
        <inertial pos="0 0 0" mass="1" diaginertia="{inertia} {inertia} {inertia}"/>
      </body></worldbody>
      <actuator><general joint="j" gainprm="{g1.KV}" biastype="affine"
        biasprm="0 0 {-g1.KV}"/></actuator></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    d.ctrl[0] = 3.0
    rates = []
    for _ in range(int(round(0.008 / physics_step))):
        mujoco.mj_step(m, d)
        rates.append(float(d.qvel[0]))
    return rates


def test_a_saturated_rate_servo_on_a_light_link_needs_a_short_physics_step():
    # The mechanism behind PHYSICS_STEP: at its force limit the servo's torque is a constant, and
    # a step of h changes the rate by h τ_max / M. A link of 1.8 g·m² (G1's right wrist roll)
    # at 1 ms: 13.9 rad/s per step, past the 2.5 rad/s band where the servo is not saturated, so
    # the rate flips between 0 and 13.9 rad/s for good; at PHYSICS_STEP it settles on 3 rad/s.
    coarse = _hinge(1e-3, 1.8e-3)
    assert sorted(coarse[-2:]) == pytest.approx([0.0, 13.889], abs=1e-3), coarse
    assert _hinge(g1.PHYSICS_STEP, 1.8e-3)[-1] == pytest.approx(3.0, abs=1e-3)


def test_the_planned_zmp_is_the_com_standing_and_shifts_by_z_a_over_g_when_accelerated():
    loop = g1.Loop(duration=0.1)
    q0 = loop.sim.q
    com = loop.robot.com(q0)
    # Standing still: the ZMP is under the COM (iktc's COM, an independent computation).
    z = g1.planned_zmp(loop.plant, [q0] * 7)
    assert np.allclose(z[2:5], com[:2], atol=1e-6)
    # The whole robot translated with a constant horizontal acceleration a [m/s²]: the
    # cart-table closed form x_zmp = x_com − z_com a / g holds exactly for a pure translation.
    a = 0.8
    qs = []
    for k in range(7):
        q = q0.copy()
        q[0] += 0.5 * a * (k * g1.CONTROL_PERIOD) ** 2
        qs.append(q)
    z = g1.planned_zmp(loop.plant, qs)
    g = -loop.plant.model.opt.gravity[2]
    for k in range(2, 5):
        expected = com[0] + 0.5 * a * (k * g1.CONTROL_PERIOD) ** 2 - com[2] * a / g
        assert z[k, 0] == pytest.approx(expected, abs=1e-6)
        assert z[k, 1] == pytest.approx(com[1], abs=1e-6)


@pytest.fixture(scope="module")
def identified():
    """The IPCJ model identified on MuJoCo by a short sweep (6 frequencies over the band)."""
    return g1.identify_on_plant(freqs=np.geomspace(*g1.SWEEP_BAND, 6), settle=2.5,
                                cycles=3, min_time=1.5)


def test_identification_on_mujoco_fits_the_measured_frequency_response(identified):
    model, fit, (omega, mag, phase) = identified
    # The model's own prediction at the measured frequencies (recomputed from the model, not
    # the fitter's figure): within 10 % rms, 10° of phase everywhere.
    assert fit["prediction_rms_relative_error"] < 0.10, fit
    assert fit["prediction_max_phase_error_deg"] < 10.0, fit
    # The pendulum length near the COM height (0.66 m) and a lightly damped mode.
    wn, zeta = model.modal()
    assert 0.5 < model.length < 0.8 and zeta < 0.3, (model, wn, zeta)


def test_a_push_in_double_support_is_damped_more_with_the_damping_controller(identified):
    model = identified[0]
    ratios = {}
    for name, m in (("open", None), ("damped", model)):
        loop, t, y = g1.push_test(model=m)
        s = loop.summary()
        assert s["stayed_up"] and s["foot_slip_max_m"] < 5e-3 and s["zmp_inside"], s
        ratios[name] = iktc.dominant_mode(t, y)[0]
    assert ratios["damped"] > ratios["open"] + 0.2, ratios


# The dominant closed-loop pair measured on MuJoCo (Prony) sits at ζ ≈ 0.62 for the design 0.72
# with this short sweep (0.73 with the full one of ``mujoco_g1.py balance``), where the same
# estimate on the identified model's own closed loop reads 0.72; designs 0.3, 0.5 and 0.9 read
# 0.32, 0.53 and 0.69 (MuJoCo 4.0.1, 2026-12-06).
def test_a_push_in_double_support_is_damped_to_the_design_ratio(identified):
    loop, t, y = g1.push_test(model=identified[0], damping=0.72)
    assert abs(iktc.dominant_mode(t, y)[0] - 0.72) <= 0.15


def test_the_walking_binding_moves_the_feet_as_the_pattern_says():
    robot = iktc.Robot("g1")
    walk = iktc.Walking(robot, iktc.load_motion("humanoid3d_dance_b"), steps=4, step_length=0.1)
    start = [f[:3, 3] for f in walk.feet0()]
    worst = 0.0
    for _ in range(walk.ticks):
        walk.tick()
        for name, ref in zip(g1.FEET, walk.feet_references()):
            worst = max(worst, float(np.abs(robot.frame_pose(walk.q, name)[:3, 3] - ref[:3, 3]).max()))
    end = [robot.frame_pose(walk.q, f)[:3, 3] for f in g1.FEET]
    # Four steps of 0.1 m, the last closing the feet side by side: both feet 0.3 m ahead.
    for s, e in zip(start, end):
        assert e[0] - s[0] == pytest.approx(0.3, abs=2e-3) and abs(e[1] - s[1]) < 2e-3
    assert worst < 0.01, worst


def test_the_walking_binding_feeds_the_measured_zmp_back_only_with_the_damping_controller():
    robot = iktc.Robot("g1")
    motion = iktc.load_motion("humanoid3d_dance_b")
    plain = iktc.Walking(robot, motion)
    ignored = iktc.Walking(robot, motion)
    damped = iktc.Walking(robot, motion, damping=True)
    for _ in range(60):
        plain.tick()
        # A measured ZMP 2 cm ahead of and 1 cm left of the initial feet's centre.
        at = (float(np.mean([f[0, 3] for f in plain.feet0()])) + 0.02 + 0.035,
              float(np.mean([f[1, 3] for f in plain.feet0()])) + 0.01)
        ignored.tick(at)
        damped.tick(at)
    # Off, the measurement is not read; on, it moves the plan (the COM reference), within cm.
    assert np.array_equal(plain.q, ignored.q)
    moved = float(np.abs(damped.q[:2] - plain.q[:2]).max())
    assert 1e-4 < moved < 0.05, moved
    # Without the offset's rates fed forward the COM follows the same offsets more slowly.
    slow = iktc.Walking(robot, motion, damping=True, offset_feedforward=False)
    for _ in range(60):
        slow.tick(at)
    assert not np.array_equal(slow.q, damped.q)
    with pytest.raises(ValueError, match="four PlaneModels"):
        iktc.Walking(robot, motion, damping=True, cases=[iktc.PlaneModel(0.6, 15.0, 0.5, 0.1, 0.01)])


def test_iktc_computes_the_plans_zmp_as_mujocos_inverse_dynamics_does():
    # Robot.zmp (the links' masses and inertias of G1's URDF, each tick's acceleration) against
    # MuJoCo's inverse dynamics of the MJCF at the same accelerations (``planned_zmp(…,
    # per_tick=True)``) on the walk with the arms of humanoid3d_walk: within 2 mm (MuJoCo 4.0.0:
    # at most 1.7 mm, median 0.5 µm; the angular momenta's rates are central differences over
    # two ticks). ``planned_zmp``'s default, central differences over two ticks for every
    # acceleration, differs from both by up to 2.7 cm where the arms' accelerations change.
    robot = iktc.Robot("g1")
    walk = iktc.Walking(robot, iktc.load_motion("humanoid3d_walk"))
    qs = [walk.q.copy()]
    for _ in range(walk.ticks):
        walk.tick()
        qs.append(walk.q.copy())
    qs = np.array(qs)
    ours = robot.zmp(qs, g1.CONTROL_PERIOD)
    theirs = g1.planned_zmp(g1.Plant(robot), list(qs), per_tick=True)
    both = np.all(np.isfinite(theirs), axis=1)
    assert both.sum() == len(qs) - 2
    d = np.abs(ours[both] - theirs[both])
    assert d.max() < 2e-3 and np.median(d) < 1e-5, (d.max(), np.median(d))
    # The arms matter: the same walk's cart-table ZMP is not what the links give.
    assert np.abs(ours[both] - ours[both].mean(axis=0)).max() > 0.05
    # A base snapped down faster than gravity (its height's second difference −800 m/s²):
    # the ground would have to pull, there is no ZMP.
    snap = qs[:3].copy()
    snap[1, 2] += 0.01
    assert np.isnan(robot.zmp(snap, g1.CONTROL_PERIOD)).all()
    # MuJoCo's inverse dynamics of the same snap: no ZMP either (not kilometres).
    plant = g1.Plant(robot)
    assert np.isnan(g1.planned_zmp(plant, list(snap), per_tick=True)).all()
    # Standing still the ground carries the whole weight: a ZMP with any share up to 1 asked,
    # none above it.
    still = [qs[0]] * 3
    assert np.all(np.isfinite(g1.planned_zmp(plant, still, per_tick=True, min_support=0.99)[1]))
    assert np.isnan(g1.planned_zmp(plant, still, per_tick=True, min_support=1.01)[1]).all()
    with pytest.raises(ValueError, match="columns"):
        robot.zmp(qs[:, :10], g1.CONTROL_PERIOD)
    with pytest.raises(iktc.IktcError, match="at least 3"):
        robot.zmp(qs[:2], g1.CONTROL_PERIOD)


def test_the_fed_forward_torques_hold_the_standing_robot_where_it_is_commanded():
    # MuJoCo's own contact forces against the wrench split of ``Feedforward``: with the plan's
    # torques fed forward the servos (K_P 500 N·m/rad) hold G1's start posture 140 times more
    # closely after 1 s (MuJoCo 4.0.0: largest joint error 0.17 against 23.5 mrad).
    robot = iktc.Robot("g1")
    q = iktc.Walking(robot, iktc.load_motion("humanoid3d_dance_b")).q
    errors = []
    for feed in (False, True):
        plant = g1.Plant(robot)
        plant.set_state(q)
        ff = g1.Feedforward(plant)
        for _ in range(200):
            plant.command(q, None, ff.torques(q, (True, True)) if feed else None)
            plant.advance()
        errors.append(float(np.abs(plant.joint_positions() - q[7:]).max()))
    assert errors[1] < errors[0] / 20, errors


@pytest.fixture(scope="module")
def walking_without_the_dance(tmp_path_factory):
    held = g1.held_clip(tmp_path_factory.mktemp("walk") / "held_dance_b.txt")
    return g1.run_walking(clip=held)


def test_walking_without_the_dance_plans_a_zmp_inside_the_support_polygon(walking_without_the_dance):
    # The upper body and pelvis held at the clip's first frame: the plan's ZMP is inside on
    # every tick (at least 4.3 mm; median 15.7 mm in single support, on soles 50 mm wide) and
    # the knees stay bent (>= 0.48 rad).
    s = walking_without_the_dance
    assert s["plan_zmp_outside_single"] == "0 of 480", s
    assert s["plan_zmp_outside_double"].startswith("0 of "), s
    assert s["knee_plan_min_rad"] > 0.4, s


def test_walking_four_steps_in_mujoco_stays_up_with_the_zmp_inside(walking_without_the_dance):
    # The servos get the plan's joint torques (``g1.Feedforward``). MuJoCo 4.0.0: G1 walks
    # the four steps (the pelvis 0.29 m ahead), tilts at most 0.04 rad, and the measured ZMP is
    # inside the polygon of the feet carrying load on all 861 ticks (at least 2.0 mm).
    s = walking_without_the_dance
    assert s["stayed_up"] and s["zmp_inside"], s
    assert s["zmp_ticks_measured"] == s["ticks"], s
    assert s["base_tilt_max_rad"] < 0.1, s
    # Four steps of 0.1 m, the last one closing the feet: the pelvis ends about 0.3 m ahead.
    assert 0.25 < s["forward_progress_m"] < 0.35, s


def test_walking_needs_the_plans_torques_fed_forward(tmp_path):
    # Without them the servos (K_P 500 N·m/rad) trail the plan's weight shift: at the first
    # lift-off the measured ZMP is 8 cm inside of the plan's, through the first single support
    # it sits on the stance sole's outer edge and G1 falls (at 2.84 s with MuJoCo 4.0.0).
    held = g1.held_clip(tmp_path / "held_dance_b.txt")
    s = g1.run_walking(clip=held, feedforward=False)
    assert not s["stayed_up"], s


def test_walking_while_imitating_the_walk_clip_keeps_the_zmp_inside():
    # The arms of humanoid3d_walk while walking. The pattern plans the COM on the cart-table,
    # not the arms: the plan's own ZMP leaves the pattern's polygon on 33 of 480 single-support
    # ticks and G1's soles reach their edges (MuJoCo 4.0.0: 53 ticks, at most 3.7 mm past the
    # rectangle of the contact spheres' centres). One pass of the ZMP correction (the default
    # of ``run_walking``) moves the COM there: the measured ZMP is inside on every tick.
    plain = g1.run_walking(clip="humanoid3d_walk", zmp_passes=0)
    assert plain["stayed_up"] and not plain["zmp_inside"], plain
    s = g1.run_walking(clip="humanoid3d_walk")
    assert s["stayed_up"] and s["zmp_inside"], s
    assert s["zmp_ticks_measured"] == s["ticks"], s
    assert 0.25 < s["forward_progress_m"] < 0.35, s


def test_a_forward_push_in_single_support_while_walking_is_absorbed(tmp_path):
    # Section 5.2's push in single support, while walking (upper body held): 80 N for 50 ms
    # (4 N·s) forward at the pelvis in the middle of the first single support (1.1 s, right
    # foot standing). Open loop (no damping controller) G1 walks on, the ZMP inside the loaded
    # feet's polygon on every tick (MuJoCo 4.0.0: tilt at most 0.065 rad). Backward or outward
    # pushes are not absorbed that well (book/src/mujoco.md).
    held = g1.held_clip(tmp_path / "held_dance_b.txt")
    s = g1.run_walking(clip=held, push=(1.1, (80.0, 0.0, 0.0), 0.05))
    assert s["stayed_up"] and s["zmp_inside"], s


def test_walking_while_dancing_stays_up_with_the_zmp_correction():
    # The dance's upper body: without the correction the plan's ZMP is outside on 264 of 480
    # single-support ticks and G1 falls (2.48 s); with one pass it is outside on 111 and G1
    # walks on (MuJoCo 4.0.0: tilt at most 0.37 rad, the pelvis 0.24 m ahead).
    assert not g1.run_walking(zmp_passes=0)["stayed_up"]
    s = g1.run_walking()
    assert s["stayed_up"], s


# With the correction G1 stays up while dancing, but its soles tip onto their edges on 347 ticks
# (by up to 6 cm): the plan's ZMP is still outside on 111 of 480 single-support ticks, where
# the correction's move of the COM is more than the cart-table's ZMP can follow in time.
@pytest.mark.xfail(strict=True, reason="walking while dancing, the plan's ZMP is still outside "
                   "on 111 of 480 single-support ticks after the correction (book/src/mujoco.md)")
def test_walking_while_dancing_keeps_the_zmp_inside():
    s = g1.run_walking()
    assert s["zmp_inside"], s


def test_the_walking_replay_holds_both_runs_tick_by_tick(tmp_path):
    import json
    path = tmp_path / "walk.html"
    s = g1.run_walking(steps=1, clip="humanoid3d_walk", replay=str(path))
    data = json.loads(path.read_text().split("const D = ", 1)[1].split(";\n", 1)[0])
    assert len(data["physics"]) == len(data["plan"]) == s["ticks"]
    # Both start where the plan starts: the physics run's first tick follows a settle at rest.
    assert np.allclose(data["physics"][0], data["plan"][0], atol=0.01)


def test_the_replay_holds_both_runs_tick_by_tick(tmp_path):
    import json
    loop = g1.Loop(duration=0.1)
    for _ in range(loop.sim.ticks):
        loop.step()
    path = tmp_path / "replay.html"
    g1.write_replay(path, loop.plant, loop.log.qpos, loop.log.q_cmd, "test")
    text = path.read_text()
    data = json.loads(text.split("const D = ", 1)[1].split(";\n", 1)[0])
    n = loop.sim.ticks
    assert len(data["physics"]) == len(data["plan"]) == n
    # The plan's feet are where iktc puts them (MuJoCo's kinematics of the plan = iktc's).
    m = loop.plant.model
    for i, name in enumerate(g1.FEET):
        b = m.body(name).id - 1
        assert np.allclose(data["plan"][-1][b], loop.robot.frame_pose(loop.log.q_cmd[-1], name)[:3, 3],
                           atol=1e-4)


def test_the_walking_plan_straightens_a_knee_unless_the_knees_are_narrowed_or_approached_softly():
    # The cause recorded for the walking failure: the pelvis height reference drives a knee to
    # its lower limit (the leg straight); narrowed, the knees stay off it. With the viable
    # bounds the straight knee chattered at ±200 rad/s² and the plan's ZMP (MuJoCo's inverse
    # dynamics) left the single-support polygon on 459 of 480 ticks (49 narrowed); with the
    # quiet bounds and the level hold, the clip as captured, the knee rests on its limit and the
    # plan's ZMP is outside on 50 single-support ticks (71 narrowed) and 64 of 377 in double
    # support. The imitation's defaults (the soft approach at 10 /s, the clip low-passed at
    # 6 Hz) keep both knees off their limits (right at least 0.11 rad) and the plan's ZMP is
    # outside on 33 and 2.
    hard = dict(smoothing=None, approach_rate=0.0)
    plain = g1.walking_plan_figures("humanoid3d_walk", **hard)
    narrowed = g1.walking_plan_figures("humanoid3d_walk", g1.G1_KNEES, **hard)
    soft = g1.walking_plan_figures("humanoid3d_walk")
    assert plain["right_knee_straight_from_s"] is not None, plain
    assert narrowed["right_knee_straight_from_s"] is None, narrowed
    assert min(narrowed["left_knee_min_rad"], narrowed["right_knee_min_rad"]) >= 0.3 - 1e-6
    assert soft["right_knee_straight_from_s"] is None and soft["left_knee_straight_from_s"] is None

    def outside(f, phase="single"):
        n_out, n = f[f"plan_zmp_outside_{phase}"].split(" of ")
        return int(n_out) / int(n)

    assert outside(plain) < 0.25, plain
    assert outside(soft) < outside(plain) and outside(soft, "double") < outside(plain, "double"), (soft, plain)


def test_the_plant_reads_a_given_mjcf_file_as_the_builtin_one(tmp_path):
    # The built-in model (``iktc.builtin_text("mjcf", "g1")``) and the same file given by path
    # make the same plant.
    path = tmp_path / "g1.xml"
    path.write_text(iktc.builtin_text("mjcf", "g1"))
    robot = iktc.Robot("g1")
    a, b = g1.Plant(robot), g1.Plant(robot, mjcf=path)
    assert g1.plant_xml() == g1.plant_xml(path)
    assert a.model.nq == b.model.nq == robot.nq and a.model.nu == b.model.nu == 3 * 29
    assert np.sum(a.model.body_mass) == pytest.approx(robot.total_mass, rel=1e-9)


def test_bad_input_to_the_subpackage_is_an_iktc_error_naming_it(tmp_path):
    robot = iktc.Robot("g1")
    with pytest.raises(iktc.IktcError, match="mjcf = .*no_such.xml"):
        g1.plant_xml(tmp_path / "no_such.xml")
    with pytest.raises(iktc.IktcError, match="physics_step"):
        g1.Plant(robot, physics_step=0.01)
    with pytest.raises(iktc.IktcError, match="kp"):
        g1.plant_xml(kp=float("nan"))
    with pytest.raises(iktc.IktcError, match="no joint"):
        g1.Plant(iktc.Robot("jvrc1"))
    p = g1.Plant(robot)
    q, v = robot.standing()
    with pytest.raises(iktc.IktcError, match="q: expected 36"):
        p.command(q[:10])
    with pytest.raises(iktc.IktcError, match="v: expected 35"):
        p.command(q, q)
    with pytest.raises(iktc.IktcError, match="side = 'middle'"):
        p.sensor_reading("middle")
    with pytest.raises(iktc.IktcError, match="foot i = 2"):
        p.foot_pose(2)
    with pytest.raises(iktc.IktcError, match="on_ground"):
        g1.Feedforward(p).torques(q, (True,))
    with pytest.raises(iktc.IktcError, match="min_support"):
        g1.planned_zmp(p, [q] * 3, min_support=-1.0)
    with pytest.raises(iktc.IktcError, match="push = "):
        g1.run_walking(push=(1.0, (80.0, 0.0), 0.05))
    with pytest.raises(iktc.IktcError, match="humanoid3d_walk"):
        g1.held_clip(tmp_path / "x.txt", "no_such_clip")
    with pytest.raises(iktc.IktcError, match="per_velocity"):
        g1.robot_with_acceleration(0.0)
    with pytest.raises(iktc.IktcError, match="axis"):
        g1.push_test(axis=2)
    with pytest.raises(iktc.IktcError, match="qs"):
        g1.plan_chatter(np.zeros((2, 36)))


def test_the_diagnostic_robot_has_its_acceleration_limits_at_the_velocity_limits():
    _, _, vel, acc = g1.robot_with_acceleration(1.0).limits()
    assert np.allclose(acc[6:], vel[6:])
