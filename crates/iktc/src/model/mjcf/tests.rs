//! The MJCF reader on small hand-written models, against hand-computed poses and inertias.

use crate::model::RobotFiles;
use std::f64::consts::FRAC_PI_2;

use nalgebra::{Matrix3, UnitQuaternion, Vector3};

use crate::error::Error;
use crate::model::{BaseKind, JointRole, Kinematics, ModelOptions, Robot, State};

/// Largest difference accepted between poses, inertias or masses computed two ways from the
/// same numbers \[m, rad, kg, kg·m²\]: round-off only.
const EXACT: f64 = 1e-12;

fn fixed() -> ModelOptions {
    ModelOptions::default()
}

fn read(xml: &str) -> Robot {
    Robot::from_mjcf_str(xml, &fixed()).unwrap_or_else(|e| panic!("{e}\n{xml}"))
}

/// The world pose of link `name` at joint positions `q`.
fn pose(r: &Robot, q: &[f64], name: &str) -> nalgebra::Isometry3<f64> {
    let mut s = State::neutral(r);
    s.q.as_mut_slice().copy_from_slice(q);
    let k = Kinematics::new(r, &s).unwrap();
    k.frame_pose(r, r.frame_id(name).unwrap()).unwrap()
}

fn model(compiler: &str, bodies: &str) -> String {
    format!("<mujoco>{compiler}<worldbody><body name=\"base\">{bodies}</body></worldbody></mujoco>")
}

#[test]
fn angles_are_degrees_unless_the_compiler_says_radian() {
    let turned = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), FRAC_PI_2);
    let deg = read(&model(
        "",
        r#"<body name="a" euler="0 0 90"><joint name="j" range="-45 90"/></body>
           <body name="b" axisangle="0 0 1 90"/>"#,
    ));
    let rad = read(&model(
        r#"<compiler angle="radian"/>"#,
        r#"<body name="a" euler="0 0 1.5707963267948966"><joint name="j" range="-0.5 1"/></body>"#,
    ));
    for (r, body) in [(&deg, "a"), (&deg, "b"), (&rad, "a")] {
        let q = vec![0.0; r.nq()];
        assert!(
            pose(r, &q, body).rotation.angle_to(&turned) < EXACT,
            "{body}"
        );
    }
    let j = deg.active_joints().next().unwrap().limit;
    assert!((j.lower + 45f64.to_radians()).abs() < EXACT && (j.upper - FRAC_PI_2).abs() < EXACT);
    let j = rad.active_joints().next().unwrap().limit;
    assert_eq!((j.lower, j.upper), (-0.5, 1.0));
}

#[test]
fn euler_sequences_turn_about_moving_or_fixed_axes() {
    let (a, b, c) = (0.3, -0.7, 1.1);
    let rx = |t| UnitQuaternion::from_axis_angle(&Vector3::x_axis(), t);
    let ry = |t| UnitQuaternion::from_axis_angle(&Vector3::y_axis(), t);
    let rz = |t| UnitQuaternion::from_axis_angle(&Vector3::z_axis(), t);
    // Moving axes compose on the right, fixed axes on the left.
    for (seq, want) in [
        ("xyz", rx(a) * ry(b) * rz(c)),
        ("zyx", rz(a) * ry(b) * rx(c)),
        ("XYZ", rz(c) * ry(b) * rx(a)),
        ("ZXZ", rz(c) * rx(b) * rz(a)),
        ("xYz", ry(b) * rx(a) * rz(c)),
    ] {
        let r = read(&model(
            &format!(r#"<compiler angle="radian" eulerseq="{seq}"/>"#),
            &format!(r#"<body name="a" euler="{a} {b} {c}"/>"#),
        ));
        assert!(pose(&r, &[], "a").rotation.angle_to(&want) < EXACT, "{seq}");
    }
    let bad = Robot::from_mjcf_str(&model(r#"<compiler eulerseq="xyw"/>"#, ""), &fixed());
    assert!(bad.unwrap_err().to_string().contains("eulerseq"));
}

#[test]
fn classes_inherit_nest_and_follow_childclass() {
    let xml = r#"<mujoco><compiler angle="radian"/>
      <default>
        <joint axis="0 1 0" range="-1 1"/>
        <default class="leg"><joint range="-2 2"/>
          <default class="knee"><joint axis="1 0 0"/></default>
        </default>
      </default>
      <worldbody><body name="base">
        <body name="plain"><joint name="j0"/></body>
        <body name="thigh" childclass="leg">
          <joint name="j1"/>
          <body name="shin"><joint name="j2" class="knee"/><joint name="j3" class="main" pos="0 0 0"/></body>
        </body>
      </body></worldbody></mujoco>"#;
    let r = read(xml);
    let got: Vec<(String, Vector3<f64>, f64)> = r
        .active_joints()
        .map(|j| match j.kind {
            crate::model::JointKind::Revolute { axis } => {
                (j.name.clone(), axis.into_inner(), j.limit.upper)
            }
            _ => panic!("{} is not a hinge", j.name),
        })
        .collect();
    let want = [
        ("j0", Vector3::y(), 1.0),
        ("j1", Vector3::y(), 2.0),
        ("j2", Vector3::x(), 2.0),
        ("j3", Vector3::y(), 1.0),
    ];
    assert_eq!(got.len(), 4);
    for ((n, a, u), (wn, wa, wu)) in got.iter().zip(want) {
        assert_eq!((n.as_str(), *a, *u), (wn, wa, wu));
    }
    // An undefined class is an error naming it.
    let e = Robot::from_mjcf_str(
        &model("", r#"<body name="a"><joint class="arm"/></body>"#),
        &fixed(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("class `arm`") && e.contains("<joint>"), "{e}");
}

#[test]
fn an_include_is_read_from_the_models_folder() {
    let dir = std::env::temp_dir().join(format!("iktc_mjcf_include_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("arm.xml"),
        r#"<mujoco><worldbody><body name="base"><body name="arm" pos="0 0 1"><joint name="j" type="slide" range="0 1"/></body></body></worldbody></mujoco>"#,
    )
    .unwrap();
    let main = r#"<mujoco model="m"><compiler angle="radian"/><include file="arm.xml"/></mujoco>"#;
    std::fs::write(dir.join("main.xml"), main).unwrap();
    let r = Robot::from_mjcf_file(&dir.join("main.xml"), &fixed()).unwrap();
    assert_eq!(r.name(), "m");
    assert!((pose(&r, &[0.5], "arm").translation.z - 1.5).abs() < EXACT);
    // From text without a folder, an include cannot be read.
    let e = Robot::from_mjcf_str(main, &fixed())
        .unwrap_err()
        .to_string();
    assert!(e.contains("<include>") && e.contains("arm.xml"), "{e}");
    // A file including itself is an error, not an endless recursion.
    std::fs::write(
        dir.join("loop.xml"),
        r#"<mujoco><include file="loop.xml"/></mujoco>"#,
    )
    .unwrap();
    let e = Robot::from_mjcf_file(&dir.join("loop.xml"), &fixed())
        .unwrap_err()
        .to_string();
    assert!(e.contains("loop.xml") && e.contains("cycle"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn fullinertia_and_diaginertia_with_a_quat_agree() {
    // A principal frame turned 90° about z: the diagonal (1, 2, 3) becomes (2, 1, 3).
    let r = read(&model(
        "",
        r#"<body name="a"><inertial pos="0.1 0 0" mass="2" quat="0.7071067811865476 0 0 0.7071067811865476" diaginertia="1 2 3"/></body>
           <body name="b"><inertial pos="0.1 0 0" mass="2" fullinertia="2 1 3 0 0 0"/></body>
           <body name="c"><inertial mass="1" fullinertia="2 3 4 0.5 -0.25 0.125"/></body>"#,
    ));
    let link = |n: &str| r.links().iter().find(|l| l.name == n).unwrap();
    assert!((link("a").inertia - link("b").inertia).abs().max() < EXACT);
    assert_eq!(link("a").com, Vector3::new(0.1, 0.0, 0.0));
    let want = Matrix3::new(2.0, 0.5, -0.25, 0.5, 3.0, 0.125, -0.25, 0.125, 4.0);
    assert!((link("c").inertia - want).abs().max() < EXACT);
    assert!((r.total_mass() - 5.0).abs() < EXACT);
}

#[test]
fn without_inertial_the_mass_comes_from_primitive_geoms() {
    // A sphere (r 0.1, 1000 kg/m³) at x = 0.2 and a 3 kg box at x = −0.2.
    let r = read(&model(
        "",
        r#"<body name="a"><geom type="sphere" size="0.1" pos="0.2 0 0"/>
           <geom type="box" size="0.1 0.2 0.3" pos="-0.2 0 0" mass="3"/></body>"#,
    ));
    let a = r.links().iter().find(|l| l.name == "a").unwrap();
    let ms = 4.0 / 3.0 * std::f64::consts::PI * 1e-3 * 1000.0;
    assert!((a.mass - (ms + 3.0)).abs() < EXACT);
    assert!((a.com.x - (0.2 * ms - 0.6) / (ms + 3.0)).abs() < EXACT);
    // About y: sphere 2/5 m r², box m (a² + c²)/3 with half sizes, both moved to the centre.
    let d = |x: f64| x - a.com.x;
    let iyy =
        0.4 * ms * 0.01 + ms * d(0.2).powi(2) + 3.0 * (0.01 + 0.09) / 3.0 + 3.0 * d(-0.2).powi(2);
    assert!(
        (a.inertia[(1, 1)] - iyy).abs() < EXACT,
        "{} vs {iyy}",
        a.inertia[(1, 1)]
    );
    // inertiafromgeom="false": massless.
    let r = read(&model(
        r#"<compiler inertiafromgeom="false"/>"#,
        r#"<body name="a"><geom type="sphere" size="0.1"/></body>"#,
    ));
    assert_eq!(r.total_mass(), 0.0);
}

#[test]
fn a_joint_off_the_body_origin_turns_about_its_own_point_and_ref_is_the_zero() {
    // Hinge about z through (1, 0, 0) of body `a` (at the origin): at q = 90° the body's
    // origin goes to (1, −1, 0).
    let r = read(&model(
        r#"<compiler angle="radian"/>"#,
        r#"<body name="a"><joint name="j" pos="1 0 0" axis="0 0 1"/>
           <body name="b" pos="0 0 1"><joint name="k" ref="0.5" axis="1 0 0"/></body></body>"#,
    ));
    let p = pose(&r, &[FRAC_PI_2, 0.5], "a");
    assert!((p.translation.vector - Vector3::new(1.0, -1.0, 0.0)).norm() < EXACT);
    // `ref`: at q = ref the body is as written.
    assert!(pose(&r, &[0.0, 0.5], "b").rotation.angle() < EXACT);
    assert!(
        (pose(&r, &[0.0, 0.0], "b")
            .rotation
            .angle_to(&UnitQuaternion::from_axis_angle(&Vector3::x_axis(), -0.5)))
            < EXACT
    );
    // The unlimited hinge is continuous; the chain link for the off-origin joint is massless.
    assert!(r
        .active_joints()
        .all(|j| j.limit.lower == f64::NEG_INFINITY));
    assert!(r.links().iter().any(|l| l.name == "a__j" && l.mass == 0.0));
}

#[test]
fn a_free_joint_is_the_floating_base_and_a_ball_joint_an_error() {
    let xml = r#"<mujoco><worldbody><body name="torso" pos="0 0 1"><freejoint name="root"/>
        <body name="leg"><joint name="hip"/></body></body>
        <body name="target" mocap="true"/></worldbody></mujoco>"#;
    let floating = ModelOptions {
        base: BaseKind::Floating,
        ..ModelOptions::default()
    };
    let r = Robot::from_mjcf_str(xml, &floating).unwrap();
    assert_eq!((r.nq(), r.nv()), (8, 7));
    assert_eq!(r.links()[r.root_link()].name, "torso");
    assert!(r.warnings().iter().any(|w| w.contains("`target` left out")));
    assert_eq!(
        crate::model::declared_base(xml, None).unwrap(),
        Some(BaseKind::Floating)
    );
    // Read fixed, with a warning.
    let r = Robot::from_mjcf_str(xml, &fixed()).unwrap();
    assert!(r.warnings().iter().any(|w| w.contains("free joint `root`")));
    let e = Robot::from_mjcf_str(
        &model(
            "",
            r#"<body name="a"><joint name="shoulder" type="ball"/></body>"#,
        ),
        &fixed(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("`shoulder`") && e.contains("ball"), "{e}");
}

#[test]
fn malformed_xml_and_unknown_types_are_errors_naming_the_place() {
    let e = Robot::from_mjcf_str(
        "<mujoco>\n<worldbody>\n<body name=\"a\">\n</mujoco>",
        &fixed(),
    )
    .unwrap_err();
    assert!(matches!(&e, Error::Parse { line, .. } if *line > 1), "{e}");
    assert!(e.to_string().contains("malformed XML"), "{e}");
    let e = Robot::from_mjcf_str(
        "<mujoco><worldbody><body name=\"a\">\n<joint name=\"w\" type=\"screw\"/></body></worldbody></mujoco>",
        &fixed(),
    )
    .unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("<joint name=\"w\">") && text.contains(":2") && text.contains("screw"),
        "{text}"
    );
    let e = Robot::from_mjcf_str(
        &model("", r#"<body name="a"><geom type="cone"/></body>"#),
        &fixed(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("type=\"cone\""), "{e}");
    let e =
        Robot::from_mjcf_str(&model("", r#"<body name="a" pos="0 1"/>"#), &fixed()).unwrap_err();
    assert!(
        e.to_string().contains("pos=\"0 1\"") && e.to_string().contains("3 finite"),
        "{e}"
    );
    let e = Robot::from_mjcf_str("<robot name=\"r\"/>", &fixed()).unwrap_err();
    assert!(e.to_string().contains("<mujoco>"), "{e}");
}

#[test]
fn a_missing_mesh_file_is_a_warning_and_the_model_loads() {
    let dir = std::env::temp_dir().join(format!("iktc_mjcf_mesh_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let xml = r#"<mujoco><compiler meshdir="meshes"/><asset><mesh file="foot.stl"/></asset>
        <worldbody><body name="base"><inertial mass="1" diaginertia="1 1 1"/><geom type="mesh" mesh="foot"/></body></worldbody></mujoco>"#;
    std::fs::write(dir.join("m.xml"), xml).unwrap();
    let r = Robot::from_mjcf_file(&dir.join("m.xml"), &fixed()).unwrap();
    assert!(
        r.warnings()
            .iter()
            .any(|w| w.contains("meshes/foot.stl") && w.contains("not found")),
        "{:?}",
        r.warnings()
    );
    assert_eq!(r.total_mass(), 1.0);
    // A geom naming no mesh asset is an error.
    let e = Robot::from_mjcf_str(&model("", r#"<geom type="mesh" mesh="hand"/>"#), &fixed())
        .unwrap_err();
    assert!(e.to_string().contains("mesh=\"hand\""), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_linear_joint_equality_is_a_mimic() {
    let r = read(
        r#"<mujoco><compiler angle="radian"/><worldbody><body name="base">
           <body name="a"><joint name="m" range="-1 1" ref="0.1"/>
             <body name="b"><joint name="f" range="-2 2" ref="0.2"/></body>
             <body name="c"><joint name="g" range="-2 2"/></body></body></body></worldbody>
           <equality><joint joint1="f" joint2="m" polycoef="0.3 2 0 0 0"/>
             <joint joint1="g" joint2="m" polycoef="0 1 0.5 0 0"/></equality></mujoco>"#,
    );
    let f = r.joints().iter().find(|j| j.name == "f").unwrap();
    // q_f − 0.2 = 0.3 + 2 (q_m − 0.1): q_f = 2 q_m + 0.3.
    match f.role {
        JointRole::Mimic {
            master,
            multiplier,
            offset,
        } => {
            assert_eq!(master, 0);
            assert!((multiplier - 2.0).abs() < EXACT && (offset - 0.3).abs() < EXACT);
        }
        other => panic!("{other:?}"),
    }
    assert!(r.warnings().iter().any(|w| w.contains("not linear")));
}

/// Largest error of a vertex after the viewer's 16-bit quantization \[m\]: half a step over
/// the 2 m bounding box, 2/65535/2 ≈ 1.5e-5 m, plus f32 round-off.
const QUANTIZED: f64 = 1e-4;

/// A binary STL of the triangle (0,0,0), (1,0,0), (0,1,0).
fn triangle_stl() -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend(1u32.to_le_bytes());
    let corners = [0f32, 0., 0., 0., 0., 0., 1., 0., 0., 0., 1., 0.];
    for x in corners {
        b.extend(x.to_le_bytes());
    }
    b.extend([0u8, 0]);
    b
}

#[test]
fn visual_mesh_geoms_reach_the_viewer_placed_by_the_geom_and_scaled_by_the_asset() {
    let dir = std::env::temp_dir().join(format!("iktc_mjcf_viewer_{}", std::process::id()));
    std::fs::create_dir_all(dir.join("assets")).unwrap();
    std::fs::write(dir.join("assets/t.stl"), triangle_stl()).unwrap();
    // The mesh scaled by 2 along x, turned 90° about z, lifted by 1 m; a colliding box on the
    // same body is not a visual (the body has a visual-only geom).
    let xml = r#"<mujoco><compiler meshdir="assets"/><asset><mesh file="t.stl" scale="2 1 1"/>
        <material name="red" rgba="1 0 0 1"/></asset>
        <worldbody><body name="base"><inertial mass="1" diaginertia="1 1 1"/>
          <geom type="mesh" mesh="t" pos="0 0 1" euler="0 0 90" contype="0" conaffinity="0" material="red"/>
          <geom type="box" size="0.1 0.1 0.1"/></body></worldbody></mujoco>"#;
    let m = crate::mesh::urdf::meshes_from_urdf(xml, &dir, 0.001).unwrap();
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    assert_eq!(m.set.meshes.len(), 1);
    let lm = &m.set.meshes[0];
    assert_eq!((lm.link.as_str(), lm.color), ("base", [255, 0, 0]));
    // (1,0,0) → (2,0,0) → (0,2,0) → (0,2,1); (0,1,0) → (−1,0,1).
    let want = [[0.0, 0.0, 1.0], [0.0, 2.0, 1.0], [-1.0, 0.0, 1.0]];
    for (a, b) in lm.mesh.vertices().iter().zip(want) {
        for k in 0..3 {
            assert!((f64::from(a[k]) - b[k]).abs() < QUANTIZED, "{a:?} vs {b:?}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
