//! The controller: handles bound to their controller, tasks that hold still when created from
//! the state, the inspect-before-solve path equal to `step`, ticks out of order rejected.

use iktc::prelude::*;
use iktc::solver::Solver;

/// JVRC-1 standing with bent knees (away from the straight-leg singularity), the right elbow
/// bent.
fn standing() -> (Robot, State) {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let mut state = State::neutral(&robot);
    for (joint, q) in [("HIP_P", -0.4), ("KNEE", 0.8), ("ANKLE_P", -0.4)] {
        for side in ["R", "L"] {
            state
                .set_joint(&robot, &format!("{side}_{joint}"), q)
                .unwrap();
        }
    }
    state.set_joint(&robot, "R_ELBOW_P", -0.5).unwrap();
    (robot, state)
}

/// Table 1's shape: both feet, COM (x, y), pelvis attitude, pelvis height, two arm joints.
struct Table1 {
    ctl: Controller,
    feet: [FrameHandle; 2],
    com: ComHandle,
    pelvis: FrameHandle,
    arm: JointsHandle,
    /// The COM of the builder's state \[m\].
    com0: Vector3<f64>,
}

fn table1(robot: &Robot, state: &State, settings: ControllerSettings) -> Table1 {
    let mut b = Controller::builder(robot.clone(), state).unwrap();
    b.settings(settings);
    let feet = [
        b.level("feet").frame("r_ankle", Axes::ALL).unwrap(),
        b.frame("l_ankle", Axes::ALL).unwrap(),
    ];
    let com = b.level("com").com([true, true, false]).unwrap();
    let pelvis = b
        .level("pelvis attitude")
        .frame("PELVIS_S", Axes::ORIENTATION)
        .unwrap();
    b.level("pelvis height").frame("PELVIS_S", Axes::Z).unwrap();
    let arm = b.level("arm").joints(&["R_ELBOW_P", "WAIST_Y"]).unwrap();
    let com0 = b.kinematics().com();
    Table1 {
        ctl: b.build().unwrap(),
        com0,
        feet,
        com,
        pelvis,
        arm,
    }
}

#[test]
fn a_handle_of_another_controller_is_rejected() {
    let (robot, state) = standing();
    let mut a = table1(&robot, &state, ControllerSettings::default());
    let mut b = table1(&robot, &state, ControllerSettings::default());
    assert_ne!(a.ctl.id(), b.ctl.id());
    // Same kinds at the same places, but another controller: every use is an error.
    let r = FrameReference::hold(Isometry3::identity());
    let want = Error::ForeignHandle {
        kind: "frame",
        owner: a.ctl.id().get(),
        controller: b.ctl.id().get(),
    };
    assert_eq!(b.ctl.set_frame_reference(a.feet[0], r), Err(want.clone()));
    assert_eq!(b.ctl.frame(a.pelvis).err(), Some(want));
    assert!(matches!(
        b.ctl
            .set_com_reference(a.com, ComReference::hold(Vector3::zeros())),
        Err(Error::ForeignHandle { kind: "COM", .. })
    ));
    assert!(matches!(
        b.ctl
            .set_joints_reference(a.arm, &[0.0; 2], &[0.0; 2], &[0.0; 2]),
        Err(Error::ForeignHandle { kind: "joints", .. })
    ));
    // Nothing of b was touched: its feet still hold where they were built.
    assert_eq!(
        b.ctl.frame(b.feet[0]).unwrap().reference,
        a.ctl.frame(a.feet[0]).unwrap().reference
    );
    // A clone has the same tasks in the same places and accepts its original's handles.
    let mut c = a.ctl.clone();
    c.set_frame_reference(a.feet[0], r).unwrap();
    assert_eq!(c.frame(a.feet[0]).unwrap().reference, r);
    assert_ne!(a.ctl.frame(a.feet[0]).unwrap().reference, r);
    a.ctl.set_frame_reference(a.feet[1], r).unwrap();
}

#[test]
fn tasks_created_from_the_state_hold_still() {
    let (robot, state0) = standing();
    let mut t = table1(&robot, &state0, ControllerSettings::default());
    let mut state = state0.clone();
    let dt = 0.005;
    for tick in 0..200 {
        let report = t.ctl.step(&mut state, dt).unwrap();
        assert_eq!(report.corrected_from, None, "tick {tick}");
        // At rest every error, rate and drift is zero: so is every h_i and q̈.
        for eq in t.ctl.equations() {
            assert!(
                eq.rhs.amax() < 1e-12,
                "tick {tick} `{}`: {}",
                eq.name,
                eq.rhs
            );
        }
        assert!(t.ctl.qdd().amax() < 1e-12, "tick {tick}: {}", t.ctl.qdd());
    }
    // No drift after 1 s.
    assert!((&state.q - &state0.q).amax() < 1e-12);
    assert!(state.qd.amax() < 1e-12);
    // The references are where the builder's state put the tasks.
    let kin = Kinematics::new(&robot, &state0).unwrap();
    let foot = robot.frame_id("l_ankle").unwrap();
    assert_eq!(
        t.ctl.frame(t.feet[1]).unwrap().reference.pose,
        kin.frame_pose(&robot, foot).unwrap()
    );
    assert_eq!(t.ctl.com(t.com).unwrap().reference.position, kin.com());
    let arm = t.ctl.joints(t.arm).unwrap();
    assert_eq!(arm.position.as_slice(), [-0.5, 0.0]);
}

/// A tick with work for the solver: the COM moves, the elbow is sent past its upper limit
/// (0 rad) so that the box binds and IKTC corrects.
fn drive(t: &mut Table1, tick: usize) {
    let s = (tick as f64 * 0.02).sin();
    t.ctl
        .set_com_reference(
            t.com,
            ComReference::hold(t.com0 + Vector3::new(0.02 * s, 0.01 * s, 0.0)),
        )
        .unwrap();
    t.ctl
        .set_joints_reference(t.arm, &[0.3, 0.4 * s], &[0.0; 2], &[0.0; 2])
        .unwrap();
}

#[test]
fn the_problem_read_before_the_solve_is_the_one_step_solves() {
    let (robot, state0) = standing();
    for method in [Method::Iktc, Method::Cascade] {
        let settings = ControllerSettings {
            method,
            ..ControllerSettings::default()
        };
        let mut stepped = table1(&robot, &state0, settings);
        let mut inspected = table1(&robot, &state0, settings);
        let dims: Vec<usize> = inspected.ctl.level_dims().collect();
        let mut independent = Solver::new(robot.nv(), &dims, settings.solver).unwrap();
        let mut qdd = nalgebra::DVector::zeros(robot.nv());
        let (mut sa, mut sb) = (state0.clone(), state0.clone());
        let dt = 0.005;
        let mut corrected = 0;
        for tick in 0..300 {
            drive(&mut stepped, tick);
            drive(&mut inspected, tick);
            let a = stepped.ctl.step(&mut sa, dt).unwrap().clone();
            inspected.ctl.prepare(&sb, dt).unwrap();
            // The problem, read before it is solved, solved by a solver of our own.
            let (eqs, bounds) = (inspected.ctl.equations(), inspected.ctl.bounds());
            let c = independent
                .solve(method, eqs, bounds, &mut qdd)
                .unwrap()
                .clone();
            let b = inspected.ctl.solve().unwrap().clone();
            inspected.ctl.integrate(&mut sb).unwrap();
            assert_eq!(a, b, "{method:?} tick {tick}");
            assert_eq!(b, c, "{method:?} tick {tick}");
            assert_eq!(&qdd, inspected.ctl.qdd(), "{method:?} tick {tick}");
            assert_eq!(
                stepped.ctl.qdd(),
                inspected.ctl.qdd(),
                "{method:?} tick {tick}"
            );
            assert_eq!(sa.q, sb.q, "{method:?} tick {tick}");
            assert_eq!(sa.qd, sb.qd, "{method:?} tick {tick}");
            corrected += usize::from(b.qp_solves > 0);
        }
        assert!(
            corrected > 20,
            "{method:?}: the box must bind ({corrected} ticks)"
        );
    }
}

#[test]
fn a_tick_out_of_order_is_an_error() {
    let (robot, mut state) = standing();
    let mut t = table1(&robot, &state, ControllerSettings::default());
    assert!(matches!(t.ctl.solve(), Err(Error::InvalidSetting { .. })));
    assert!(t.ctl.integrate(&mut state).is_err());
    t.ctl.prepare(&state, 0.005).unwrap();
    assert!(
        t.ctl.integrate(&mut state).is_err(),
        "integrate before solve"
    );
    t.ctl.solve().unwrap();
    t.ctl.integrate(&mut state).unwrap();
    assert!(t.ctl.integrate(&mut state).is_err(), "integrated twice");
    // A bad period is the box's error, before anything is solved.
    assert!(t.ctl.step(&mut state, 0.0).is_err());
    assert!(t.ctl.solve().is_err());
}

#[test]
fn builder_errors_name_what_is_wrong() {
    let (robot, state) = standing();
    let mut b = Controller::builder(robot.clone(), &state).unwrap();
    let e = b.frame("r_ankle", Axes::ALL).unwrap_err();
    assert!(e.to_string().contains("ControllerBuilder::level"), "{e}");
    b.level("feet");
    assert!(matches!(
        b.frame("no_such_frame", Axes::ALL),
        Err(Error::UnknownName { kind: "frame", .. })
    ));
    b.level("empty");
    let e = b.build().unwrap_err();
    assert!(e.to_string().contains("`feet`"), "{e}");
    let e = Controller::builder(robot, &state)
        .unwrap()
        .build()
        .unwrap_err();
    assert!(e.to_string().contains("at least one level"), "{e}");
}
