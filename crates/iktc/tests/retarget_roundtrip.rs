//! Retargeting gives back the robot joint angles a clip was generated from, for both built-in
//! maps; the pelvis references follow the root; the map file is checked.

use iktc::model::{jvrc1, ModelOptions};
use iktc::motion::*;
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn rot(axis: Vector3<f64>, angle: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle)
}

/// JVRC-1's joint axes at zero, robot coordinates, written down from the URDF by hand.
fn axis_of(joint: &str) -> Vector3<f64> {
    let suffix = joint.rsplit('_').next().unwrap_or("");
    match suffix {
        "P" => Vector3::y(),
        "R" => Vector3::x(),
        "Y" => Vector3::z(),
        _ => panic!("no axis for {joint}"),
    }
}

/// Generates frames from random robot angles through the inverse of the map's formula, then
/// checks that `retarget` returns those angles.
fn roundtrip(map: &RetargetMap, skeleton: Skeleton, frames: usize, seed: u64) {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let b: Matrix3<f64> = *map.basis.matrix();
    let b = Rotation3::from_matrix_unchecked(b);
    let mut expected: Vec<Vec<f64>> = vec![Vec::new(); map.robot_joints().len()];
    let mut poses = Vec::new();
    let mut times = Vec::new();
    let mut expected_height = Vec::new();
    let mut expected_pitch = Vec::new();
    let mut expected_roll = Vec::new();
    for f in 0..frames {
        let mut pose = skeleton.rest_pose();
        let mut col = 0;
        for jm in &map.joints {
            let src = skeleton.index_of(&jm.source).unwrap();
            let mut r = Rotation3::identity();
            for t in &jm.targets {
                // A smooth random walk inside ±1 rad of the offset.
                let theta: f64 = 0.8 * ((f as f64) * 0.05 + rng.random_range(-1.0..1.0)).sin();
                r *= rot(axis_of(&t.joint), theta);
                expected[col].push(t.offset + t.sign * t.scale * theta);
                col += 1;
            }
            let pr = Rotation3::from_scaled_axis(Vector3::from(jm.parent_rest_rotation));
            let rest = Rotation3::from_scaled_axis(Vector3::from(jm.rest_rotation));
            let q = b.transpose() * (pr * r * rest.transpose()) * b;
            pose.rotations[src] = UnitQuaternion::from_rotation_matrix(&q);
        }
        for h in &map.holds {
            expected[col].push(h.value);
            col += 1;
        }
        let (yaw, pitch, roll) = (
            0.3 * (f as f64 * 0.1).sin(),
            0.2 * (f as f64 * 0.13).cos(),
            0.1 * (f as f64 * 0.07).sin(),
        );
        let r_body = rot(Vector3::z(), yaw) * rot(Vector3::y(), pitch) * rot(Vector3::x(), roll);
        pose.root_orientation = UnitQuaternion::from_rotation_matrix(&(b.transpose() * r_body * b));
        let z = 0.9 + 0.05 * (f as f64 * 0.2).sin();
        pose.root_position = b.transpose() * Vector3::new(0.1, 0.0, z);
        expected_height.push(z);
        expected_pitch.push(pitch);
        expected_roll.push(roll);
        poses.push(pose);
        times.push(f as f64 / 30.0);
    }
    let clip = Clip::new("generated", skeleton, times, poses, UpAxis::Y).unwrap();
    let out = retarget_joint_angles(&clip, &robot, map).unwrap();
    assert_eq!(out.joint_names, map.robot_joints());
    for (j, name) in out.joint_names.iter().enumerate() {
        for (f, (&got, &want)) in out.joint_angles[j].iter().zip(&expected[j]).enumerate() {
            assert!(
                (got - want).abs() < 1e-8,
                "{name} frame {f}: got {got}, want {want}"
            );
        }
    }
    for r in &out.residuals {
        assert!(*r < 1e-8, "residual {r}");
    }
    for f in 0..frames {
        let dh = map.root.height_scale * (expected_height[f] - expected_height[0]);
        assert!((out.pelvis_height[f] - dh).abs() < 1e-12);
        let dp = map.root.pitch_scale * (expected_pitch[f] - expected_pitch[0]);
        let dr = map.root.roll_scale * (expected_roll[f] - expected_roll[0]);
        assert!(
            (out.pelvis_angles[1][f] - dp).abs() < 1e-9,
            "pitch frame {f}"
        );
        assert!(
            (out.pelvis_angles[2][f] - dr).abs() < 1e-9,
            "roll frame {f}"
        );
        assert!(out.pelvis_angles[0][f].abs() < 1e-12 || map.root.yaw_scale != 0.0);
    }
}

#[test]
fn deepmimic_map_gives_back_the_robot_angles() {
    let map = builtin_map("deepmimic_jvrc1").unwrap();
    assert_eq!(map.robot_joints().len(), 20);
    roundtrip(&map, deepmimic_skeleton().unwrap(), 40, 7);
}

fn bvh_skeleton() -> Skeleton {
    let j = |name: &str, parent: Option<usize>, offset: [f64; 3], kind: JointKind| SkeletonJoint {
        name: name.into(),
        parent,
        offset: Vector3::from(offset),
        kind,
    };
    Skeleton::new(vec![
        j("Hips", None, [0.0, 0.9, 0.0], JointKind::Root),
        j("Spine", Some(0), [0.0, 0.1, 0.0], JointKind::Spherical),
        j("Neck", Some(1), [0.0, 0.4, 0.0], JointKind::Spherical),
        j("RightArm", Some(1), [-0.2, 0.35, 0.0], JointKind::Spherical),
        j(
            "RightForeArm",
            Some(3),
            [-0.3, 0.0, 0.0],
            JointKind::Spherical,
        ),
        j("LeftArm", Some(1), [0.2, 0.35, 0.0], JointKind::Spherical),
        j(
            "LeftForeArm",
            Some(5),
            [0.3, 0.0, 0.0],
            JointKind::Spherical,
        ),
    ])
    .unwrap()
}

#[test]
fn bvh_map_gives_back_the_robot_angles() {
    let map = builtin_map("bvh_jvrc1").unwrap();
    assert_eq!(map.robot_joints().len(), 20);
    roundtrip(&map, bvh_skeleton(), 30, 11);
}

#[test]
fn bvh_t_pose_rest_maps_to_raised_arms() {
    // At the T-pose rest the robot's arms are raised sideways (shoulder roll ∓90°), forearms
    // straight: the map's rest rotations take the robot's hanging arm to the source's
    // horizontal one.
    let map = builtin_map("bvh_jvrc1").unwrap();
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let sk = bvh_skeleton();
    let rest = sk.rest_pose();
    let clip = Clip::new(
        "rest",
        sk,
        vec![0.0, 0.1],
        vec![rest.clone(), rest],
        UpAxis::Y,
    )
    .unwrap();
    let out = retarget_joint_angles(&clip, &robot, &map).unwrap();
    for (name, track) in out.joint_names.iter().zip(&out.joint_angles) {
        let want = match name.as_str() {
            "R_SHOULDER_R" => -std::f64::consts::FRAC_PI_2,
            "L_SHOULDER_R" => std::f64::consts::FRAC_PI_2,
            _ => 0.0,
        };
        assert!((track[0] - want).abs() < 1e-9, "{name} = {}", track[0]);
    }
}

#[test]
fn builtin_clip_retargets_and_resamples() {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let clip = builtin_clip("humanoid3d_dance_b").unwrap();
    let map = builtin_map("deepmimic_jvrc1").unwrap();
    let out = retarget_joint_angles(&clip, &robot, &map).unwrap();
    let refs = out.resample(0.005).unwrap();
    assert!(refs.len() > 100);
    assert_eq!(refs.joints.len(), 20);
    // Samples coincide with the frames at frame times (the spline interpolates).
    let k = (clip.times()[3] / 0.005).round() as usize;
    if (k as f64 * 0.005 - clip.times()[3]).abs() < 1e-12 {
        assert!((refs.joints[0].position[k] - out.joint_angles[0][3]).abs() < 1e-9);
    }
    // Angular velocity and acceleration agree with finite differences of the attitude (on a
    // fine resampling, so that the O(Δt²) error of the differences is small).
    let refs = out.resample(1e-4).unwrap();
    let dt = refs.dt;
    for k in (1..refs.len() - 1).step_by(997) {
        let dq = refs.attitude[k + 1] * refs.attitude[k - 1].inverse();
        let w_fd = dq.scaled_axis() / (2.0 * dt);
        assert!(
            (w_fd - refs.angular_velocity[k]).norm() < 1e-3 * (1.0 + w_fd.norm()),
            "ω at {k}: {w_fd} vs {}",
            refs.angular_velocity[k]
        );
        let a_fd = (refs.angular_velocity[k + 1] - refs.angular_velocity[k - 1]) / (2.0 * dt);
        assert!(
            (a_fd - refs.angular_acceleration[k]).norm() < 1e-2 * (1.0 + a_fd.norm()),
            "ω̇ at {k}: {a_fd} vs {}",
            refs.angular_acceleration[k]
        );
    }
}

#[test]
fn malformed_maps_are_errors() {
    let bad_basis = "basis = [[1,0,0],[0,1,0],[0,0,-1]]";
    assert!(matches!(
        RetargetMap::from_toml_str(bad_basis, "m.toml"),
        Err(iktc::Error::InvalidSetting { .. })
    ));
    let unknown_key = "basis = [[1,0,0],[0,1,0],[0,0,1]]\nfoo = 1\n";
    match RetargetMap::from_toml_str(unknown_key, "m.toml") {
        Err(iktc::Error::Parse { line, .. }) => assert_eq!(line, 2, "the unknown key is on line 2"),
        other => panic!("{other:?}"),
    }
    let bad_sign = "basis = [[1,0,0],[0,1,0],[0,0,1]]\n[[joint]]\nsource = \"a\"\ntargets = [{ joint = \"X\", sign = 2 }]\n";
    assert!(RetargetMap::from_toml_str(bad_sign, "m.toml").is_err());
    // Unknown robot or source joints are named in the error.
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let clip = builtin_clip("humanoid3d_walk").unwrap();
    let unknown = "basis = [[1,0,0],[0,1,0],[0,0,1]]\n[[joint]]\nsource = \"chest\"\ntargets = [{ joint = \"NOPE\" }]\n";
    let map = RetargetMap::from_toml_str(unknown, "m.toml").unwrap();
    let e = retarget_joint_angles(&clip, &robot, &map)
        .unwrap_err()
        .to_string();
    assert!(e.contains("NOPE"), "{e}");
    let not_chain = "basis = [[1,0,0],[0,1,0],[0,0,1]]\n[[joint]]\nsource = \"chest\"\ntargets = [{ joint = \"WAIST_Y\" }, { joint = \"NECK_Y\" }]\n";
    let map = RetargetMap::from_toml_str(not_chain, "m.toml").unwrap();
    assert!(retarget_joint_angles(&clip, &robot, &map).is_err());
}

#[test]
fn spline_is_c2_and_interpolates() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut t = vec![0.0];
    for _ in 0..9 {
        let last = *t.last().unwrap();
        t.push(last + rng.random_range(0.05..0.3));
    }
    let y: Vec<f64> = t.iter().map(|_| rng.random_range(-1.0..1.0)).collect();
    let s = CubicSpline::new(&t, &y).unwrap();
    for (ti, yi) in t.iter().zip(&y) {
        assert!((s.eval(*ti)[0] - yi).abs() < 1e-12);
    }
    let e = 1e-10;
    for ti in &t[1..t.len() - 1] {
        let (l, r) = (s.eval(ti - e), s.eval(ti + e));
        assert!((l[1] - r[1]).abs() < 1e-6, "velocity jump at {ti}");
        assert!((l[2] - r[2]).abs() < 1e-5, "acceleration jump at {ti}");
    }
    // Derivatives match finite differences inside a segment.
    let tm = 0.5 * (t[2] + t[3]);
    let h = 1e-5;
    let fd1 = (s.eval(tm + h)[0] - s.eval(tm - h)[0]) / (2.0 * h);
    let fd2 = (s.eval(tm + h)[1] - s.eval(tm - h)[1]) / (2.0 * h);
    assert!((fd1 - s.eval(tm)[1]).abs() < 1e-6);
    assert!((fd2 - s.eval(tm)[2]).abs() < 1e-5);
    // Natural ends.
    assert!(s.eval(t[0] + 1e-12)[2].abs() < 1e-6);
    // A straight line is reproduced exactly.
    let line: Vec<f64> = t.iter().map(|x| 2.0 * x - 1.0).collect();
    let s = CubicSpline::new(&t, &line).unwrap();
    let v = s.eval(tm);
    assert!(
        (v[0] - (2.0 * tm - 1.0)).abs() < 1e-12 && (v[1] - 2.0).abs() < 1e-10 && v[2].abs() < 1e-9
    );
    assert!(CubicSpline::new(&[0.0, 0.0], &[1.0, 2.0]).is_err());
    assert!(CubicSpline::new(&[], &[]).is_err());
}

/// `values_at` equals `eval(t)[0]` bit for bit at ascending times inside, at and outside the
/// knots (seeded), and at times that step back.
#[test]
fn spline_values_at_ascending_times_equal_eval() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut t = vec![0.0];
    for _ in 0..40 {
        let last = *t.last().unwrap();
        t.push(last + rng.random_range(0.01..0.2));
    }
    let y: Vec<f64> = t.iter().map(|_| rng.random_range(-1.0..1.0)).collect();
    let s = CubicSpline::new(&t, &y).unwrap();
    let (a, b) = s.span();
    let mut times: Vec<f64> = (0..500)
        .map(|_| rng.random_range(a - 0.3..b + 0.3))
        .collect();
    times.extend_from_slice(&t);
    times.sort_by(f64::total_cmp);
    // Steps back and a NaN, as `eval` takes them.
    times.extend_from_slice(&[0.5 * (a + b), a, f64::NAN, b]);
    let mut out = vec![0.0; times.len()];
    s.values_at(&times, &mut out).unwrap();
    for (t, v) in times.iter().zip(&out) {
        let e = s.eval(*t)[0];
        assert!(e.to_bits() == v.to_bits(), "t = {t}: {v} against {e}");
    }
    assert!(s.values_at(&times, &mut out[1..]).is_err());
}
