//! Bad input to the model: each gives a clear error, never a panic.

use iktc::model::RobotFiles;
use iktc::model::*;
use iktc::Error;
use nalgebra::DVector;

const GOOD: &str = r#"<robot name="r">
  <link name="a"/><link name="b"/>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="2" effort="1"/></joint>
</robot>"#;

fn load(s: &str) -> Result<Robot, Error> {
    Robot::from_urdf_str(s, &ModelOptions::default())
}

#[test]
fn good_urdf_loads() {
    let r = load(GOOD).unwrap();
    assert_eq!(r.nv(), 1);
    let j = r.active_joints().next().unwrap();
    assert_eq!(j.limit.acceleration, 20.0, "default a_max = 10 s⁻¹ × v_max");
}

#[test]
fn malformed_urdf() {
    let e = load("<robot name=\"r\"><link name=\"a\"></robot>").unwrap_err();
    assert!(matches!(e, Error::Urdf { .. }), "{e}");
    assert!(e.to_string().contains("cannot parse"), "{e}");
}

#[test]
fn lower_above_upper() {
    let e = load(&GOOD.replace("lower=\"-1\"", "lower=\"2\"")).unwrap_err();
    assert!(
        matches!(e, Error::InvalidLimit { ref what, lower, upper } if what.contains('j') && lower == 2.0 && upper == 1.0),
        "{e}"
    );
}

#[test]
fn nan_in_urdf() {
    let e = load(&GOOD.replace("lower=\"-1\"", "lower=\"nan\"")).unwrap_err();
    assert!(
        matches!(e, Error::NonFinite { .. } | Error::Urdf { .. }),
        "{e}"
    );
}

#[test]
fn unknown_link_and_two_roots() {
    let e = load(&GOOD.replace("<child link=\"b\"/>", "<child link=\"c\"/>")).unwrap_err();
    assert!(
        e.to_string().contains("c") && e.to_string().contains("a, b"),
        "{e}"
    );
    let e = load(&GOOD.replace("<link name=\"b\"/>", "<link name=\"b\"/><link name=\"z\"/>"))
        .unwrap_err();
    assert!(e.to_string().contains("exactly one root"), "{e}");
}

#[test]
fn unsupported_joint_type() {
    let e = load(&GOOD.replace("revolute", "planar")).unwrap_err();
    assert!(
        e.to_string().contains("Planar") || e.to_string().contains("planar"),
        "{e}"
    );
}

#[test]
fn zero_axis() {
    let e = load(&GOOD.replace("0 0 1", "0 0 0")).unwrap_err();
    assert!(e.to_string().contains("zero axis"), "{e}");
}

#[test]
fn unknown_locked_joint_lists_valid_names() {
    let o = ModelOptions {
        locked: vec![("nope".into(), 0.0)],
        ..Default::default()
    };
    let e = Robot::from_urdf_str(GOOD, &o).unwrap_err();
    assert!(
        matches!(e, Error::UnknownName { ref valid, .. } if valid == &vec!["j".to_string()]),
        "{e}"
    );
}

#[test]
fn mimic_reject_policy() {
    let o = ModelOptions {
        mimic: MimicPolicy::Reject,
        base: BaseKind::Fixed,
        ..Default::default()
    };
    let e = Robot::from_urdf_str(JVRC1_URDF, &o).unwrap_err();
    assert!(e.to_string().contains("mimics"), "{e}");
}

#[test]
fn unknown_frame_lists_valid_names() {
    let r = planar3r();
    let e = r.frame_id("hand").unwrap_err();
    let m = e.to_string();
    assert!(
        m.contains("hand") && m.contains("tip") && m.contains("link1"),
        "{m}"
    );
}

#[test]
fn bad_states() {
    let r = jvrc1(&ModelOptions::default()).unwrap();
    let mut s = State::neutral(&r);
    s.q[10] = f64::NAN;
    assert!(matches!(
        Kinematics::new(&r, &s),
        Err(Error::NonFinite { .. })
    ));
    let s = State {
        q: DVector::zeros(5),
        qd: DVector::zeros(38),
    };
    assert!(matches!(
        Kinematics::new(&r, &s),
        Err(Error::DimensionMismatch {
            expected: 39,
            got: 5,
            ..
        })
    ));
    let mut s = State::neutral(&r);
    s.q[6] = 0.0; // zero quaternion
    assert!(Kinematics::new(&r, &s).is_err());
    let mut s = State::neutral(&r);
    assert!(s.integrate(&r, &DVector::zeros(3), 0.01).is_err());
    assert!(s.integrate(&r, &DVector::zeros(38), 0.0).is_err());
    assert!(s.set_joint(&r, "R_KNEE", f64::INFINITY).is_err());
    let e = s.set_joint(&r, "R_KNE", 0.1).unwrap_err();
    assert!(e.to_string().contains("R_KNEE"), "{e}");
}

#[test]
fn builtin_names() {
    assert!(builtin_robot("jvrc1").is_ok());
    let e = builtin_robot("hubo").unwrap_err();
    assert!(e.to_string().contains("planar3r") && e.to_string().contains("jvrc1"));
}

#[test]
fn bad_acceleration_option() {
    let o = ModelOptions {
        acceleration_limits: vec![("j".into(), -1.0)],
        ..Default::default()
    };
    assert!(matches!(
        Robot::from_urdf_str(GOOD, &o),
        Err(Error::InvalidSetting { .. })
    ));
    let o = ModelOptions {
        acceleration_limits: vec![("j".into(), 7.0)],
        ..Default::default()
    };
    let r = Robot::from_urdf_str(GOOD, &o).unwrap();
    assert_eq!(r.active_joints().next().unwrap().limit.acceleration, 7.0);
}

/// A per-joint acceleration or jerk limit that is not positive names its joint, its kind and
/// its unit.
#[test]
fn bad_per_joint_acceleration_and_jerk_limits_are_named() {
    for (options, says) in [
        (
            ModelOptions {
                acceleration_limits: vec![("L_KNEE".into(), 0.0)],
                ..ModelOptions::default()
            },
            ["acceleration limit of joint `L_KNEE`", "rad/s²"],
        ),
        (
            ModelOptions {
                jerk_limits: vec![("L_KNEE".into(), f64::NAN)],
                ..ModelOptions::default()
            },
            ["jerk limit of joint `L_KNEE`", "rad/s³"],
        ),
    ] {
        let e = jvrc1(&options).unwrap_err().to_string();
        for s in says {
            assert!(e.contains(s), "`{s}` not in {e}");
        }
    }
}

/// URDF requires a `name` on `<material>`; exporters leave it out (Unitree's H1-2 description
/// has 55 such). The reader takes them as unnamed, with a warning that counts them, and reads
/// the same robot as with the names written; a material with a name gives no warning.
#[test]
fn materials_without_a_name_are_read_as_unnamed() {
    let visual = |material: &str| {
        format!(
            r#"<robot name="r">
  <link name="a"><visual><geometry><box size="0.1 0.1 0.1"/></geometry>{material}</visual></link>
  <link name="b"><visual><geometry><sphere radius="0.1"/></geometry>{material}</visual></link>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    <origin xyz="0 0 0.3"/><limit lower="-1" upper="1" velocity="2" effort="1"/></joint>
</robot>"#
        )
    };
    let unnamed = load(&visual(
        r#"<material><color rgba="0.1 0.1 0.1 1"/></material>"#,
    ))
    .unwrap();
    let empty = load(&visual("<material/>")).unwrap();
    let named = load(&visual(
        r#"<material name="grey"><color rgba="0.1 0.1 0.1 1"/></material>"#,
    ))
    .unwrap();
    assert!(named.warnings().is_empty(), "{:?}", named.warnings());
    for r in [&unnamed, &empty] {
        assert_eq!(r.nv(), named.nv());
        assert_eq!(r.joints()[0].origin, named.joints()[0].origin);
        let w = r.warnings().join("\n");
        assert!(
            w.contains("2 <material> element(s) without the `name`"),
            "{w}"
        );
    }
    // The profile guesses and the viewer's meshes read the same document.
    let text = visual("<material><color rgba=\"0.1 0.1 0.1 1\"/></material>");
    assert!(iktc::profile::init_profile_toml(&text, "r.urdf").is_ok());
    assert!(iktc::mesh::urdf::meshes_from_urdf(&text, std::path::Path::new("."), 0.01).is_ok());
}
