//! AMASS archives read with a body model file: a synthetic SMPL-X and SMPL-H model and archive
//! ([`amass_fixture`]) whose joints are computed by hand, errors for what is missing or
//! malformed, the body points recognised without a map, and a walk retargeted onto G1.

mod amass_fixture;

use std::f64::consts::FRAC_PI_2;
use std::path::PathBuf;

use amass_fixture::{expected_joints, skeleton, Archive, ModelSpec, SMPLH, SMPLX};
use iktc::motion::amass::{read_amass, AmassArchive, BodyModel, SmplLayout};
use iktc::motion::{
    detect_format, load_motion, BodyPoint, Measured, MotionFormat, MotionOptions, PointSource,
    UpAxis, DEFAULT_MAX_GAP,
};
use iktc::profile::RobotProfile;
use iktc::resources::ReadLimits;
use iktc::retarget::{retarget_keypoints, KeypointSettings};
use iktc::solver::SolverSettings;
use nalgebra::Vector3;

/// Agreement of computed and hand-computed joints [m]: both are sums of a few products of
/// values below 2 m in `f64` (and a 90° rotation's quaternion, exact to rounding), so they
/// differ by a few units of 1e-16.
const TOL: f64 = 1e-12;

/// Agreement when the files hold `f32` values [m]: each stored value is rounded to 24 bits
/// (relative 6e-8, so 1.2e-7 m on 2 m), and a joint sums a few of them.
const F32_TOL: f64 = 1e-6;

fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("iktc-amass-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(dir: &std::path::Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn close(a: &Vector3<f64>, b: &Vector3<f64>, tol: f64, what: &str) {
    assert!((a - b).norm() <= tol, "{what}: {a:?} vs {b:?}");
}

/// `Rz(90°) v` and `Rx(90°) v`, by hand.
fn rz(v: Vector3<f64>) -> Vector3<f64> {
    Vector3::new(-v.y, v.x, v.z)
}
fn rx(v: Vector3<f64>) -> Vector3<f64> {
    Vector3::new(v.x, -v.z, v.y)
}

#[test]
fn smplx_model_joints_are_the_regressor_on_the_shaped_template() {
    let d = dir("regressor");
    let spec = ModelSpec::smplx();
    let path = write(&d, "SMPLX_FEMALE.npz", &spec.bytes());
    let model = BodyModel::read(&path).unwrap();
    assert_eq!(model.joint_count(), SMPLX);
    assert_eq!(model.shape_count(), 16);
    assert_eq!(model.layout(), Some(SmplLayout::SmplX));
    let (_, parents) = skeleton(SMPLX);
    let want: Vec<Option<usize>> = parents.iter().map(|p| usize::try_from(*p).ok()).collect();
    assert_eq!(model.parents(), want);
    for betas in [vec![], vec![0.5, -0.4], vec![-1.5, 2.0, 0.7, 0.0, 3.0]] {
        let got = model.joints(&betas).unwrap();
        for (j, (g, e)) in got.iter().zip(expected_joints(SMPLX, &betas)).enumerate() {
            close(g, &e, TOL, &format!("joint {j} for betas {betas:?}"));
        }
    }
}

#[test]
fn smplx_archive_joints_follow_the_poses_forward_kinematics() {
    let d = dir("fk");
    let model = write(&d, "SMPLX_FEMALE.npz", &ModelSpec::smplx().bytes());
    let mut a = Archive::rest(SMPLX, 2);
    a.set(1, 0, Vector3::new(0.0, 0.0, FRAC_PI_2));
    a.set(1, 4, Vector3::new(FRAC_PI_2, 0.0, 0.0));
    a.trans[1] = Vector3::new(1.0, 2.0, 3.0);
    a.deflate = true;
    let bytes = a.bytes();
    assert_eq!(detect_format(&bytes), Some(MotionFormat::Amass));
    let clip = read_amass(&bytes, "walk.npz", Some(&model), &ReadLimits::default()).unwrap();
    assert_eq!(clip.frame_count(), 2);
    assert_eq!(clip.times(), [0.0, 1.0 / 30.0]);
    assert_eq!(clip.up_axis(), UpAxis::Z);
    let names: Vec<&str> = clip
        .skeleton()
        .joints()
        .iter()
        .map(|j| j.name.as_str())
        .collect();
    assert_eq!(
        names[..5],
        ["pelvis", "left_hip", "right_hip", "spine1", "left_knee"]
    );
    assert_eq!(
        names[22..25],
        ["jaw", "left_eye_smplhf", "right_eye_smplhf"]
    );
    assert_eq!(names[54], "right_thumb3");
    let j = expected_joints(SMPLX, &a.betas);
    // Frame 0, the rest pose at trans 0: the joints themselves.
    for (i, (g, e)) in clip.world_positions(0).unwrap().iter().zip(&j).enumerate() {
        close(g, e, TOL, &format!("rest joint {i}"));
    }
    // Frame 1: root turned 90° about z and moved by trans, the left knee bent 90° about x.
    let w = clip.world_positions(1).unwrap();
    let trans = a.trans[1];
    let pelvis = j[0] + trans;
    let hip = pelvis + rz(j[1] - j[0]);
    let knee = hip + rz(j[4] - j[1]);
    let ankle = knee + rz(rx(j[7] - j[4]));
    let foot = ankle + rz(rx(j[10] - j[7]));
    let right_ankle = pelvis + rz(j[2] - j[0]) + rz(j[5] - j[2]) + rz(j[8] - j[5]);
    let head = pelvis + rz(j[15] - j[0]);
    for (i, e) in [
        (0, pelvis),
        (1, hip),
        (4, knee),
        (7, ankle),
        (10, foot),
        (8, right_ankle),
        (15, head),
    ] {
        close(&w[i], &e, TOL, &format!("frame 1 joint {i} ({})", names[i]));
    }
}

#[test]
fn smplh_layout_in_float32_and_stored_members() {
    let d = dir("smplh");
    let spec = ModelSpec {
        joints: SMPLH,
        shapes: 16,
        float32: true,
        deflate: false,
    };
    let model = write(&d, "model.npz", &spec.bytes());
    let mut a = Archive::rest(SMPLH, 2);
    a.float32 = true;
    a.gender = "male";
    // Frame 1: the root stood up (90° about x), the right knee bent 90°.
    a.set(1, 0, Vector3::new(FRAC_PI_2, 0.0, 0.0));
    a.set(1, 5, Vector3::new(FRAC_PI_2, 0.0, 0.0));
    a.trans[1] = Vector3::new(0.5, -0.25, 0.125);
    let bytes = a.bytes();
    let archive = AmassArchive::from_reader(
        std::io::Cursor::new(&bytes),
        "h.npz",
        &ReadLimits::default(),
    )
    .unwrap();
    assert_eq!(archive.layout(), Some(SmplLayout::SmplH));
    assert_eq!(archive.gender.as_deref(), Some("male"));
    assert_eq!(archive.frame_rate, 30.0);
    let clip = read_amass(&bytes, "h.npz", Some(&model), &ReadLimits::default()).unwrap();
    let names = SmplLayout::SmplH.joint_names();
    assert_eq!(names[22], "left_index1");
    assert_eq!(clip.skeleton().joints()[51].name, "right_thumb3");
    let j = expected_joints(SMPLH, &a.betas);
    let w = clip.world_positions(1).unwrap();
    let pelvis = j[0] + a.trans[1];
    let knee = pelvis + rx(j[2] - j[0]) + rx(j[5] - j[2]);
    let ankle = knee + rx(rx(j[8] - j[5]));
    let wrist = pelvis + rx(j[3] - j[0]) + rx(j[6] - j[3]) + rx(j[9] - j[6]);
    let wrist = wrist + rx(j[13] - j[9]) + rx(j[16] - j[13]) + rx(j[18] - j[16]);
    let wrist = wrist + rx(j[20] - j[18]);
    for (i, e) in [(0, pelvis), (5, knee), (8, ankle), (20, wrist)] {
        close(&w[i], &e, F32_TOL, &format!("joint {i} ({})", names[i]));
    }
}

#[test]
fn a_clip_loads_with_its_body_points_recognised_in_metres_and_z_up() {
    let d = dir("recognise");
    for (joints, name) in [(SMPLX, "SMPLX_NEUTRAL.npz"), (SMPLH, "model.npz")] {
        let model = write(
            &d,
            name,
            &ModelSpec {
                joints,
                ..ModelSpec::smplx()
            }
            .bytes(),
        );
        let clip = write(
            &d,
            &format!("walk{joints}.npz"),
            &Archive::walk(joints, 1.0).bytes(),
        );
        let options = MotionOptions {
            body_model: Some(model),
            ..MotionOptions::default()
        };
        let m = load_motion(&clip, &options).unwrap();
        assert_eq!(m.format, MotionFormat::Amass);
        assert_eq!(m.up.up, UpAxis::Z);
        assert_eq!(m.up.measured_on, Measured::Format);
        assert_eq!(m.units.unit.metres_per_unit(), 1.0);
        let map = m.body_map.as_ref().unwrap();
        for p in BodyPoint::ALL {
            assert!(map.get(p).is_some(), "{p} not found on {joints} joints");
        }
        let joint = |p: BodyPoint| match map.get(p) {
            Some(PointSource::Joint(j)) => j.clone(),
            other => panic!("{p}: {other:?}"),
        };
        for (p, j) in [
            (BodyPoint::Pelvis, "pelvis"),
            (BodyPoint::Chest, "spine3"),
            (BodyPoint::Neck, "neck"),
            (BodyPoint::Head, "head"),
            (BodyPoint::LeftHip, "left_hip"),
            (BodyPoint::RightKnee, "right_knee"),
            (BodyPoint::LeftAnkle, "left_ankle"),
            (BodyPoint::RightToe, "right_foot"),
            (BodyPoint::LeftShoulder, "left_shoulder"),
            (BodyPoint::RightElbow, "right_elbow"),
            (BodyPoint::LeftWrist, "left_wrist"),
        ] {
            assert_eq!(joint(p), j);
        }
        // Standing in AMASS's Z-up world: the head above the pelvis above the ankles.
        let kp = m.keypoints(DEFAULT_MAX_GAP).unwrap();
        let z = |p| kp.position(0, p).unwrap().z;
        assert!(z(BodyPoint::Head) > z(BodyPoint::Pelvis));
        assert!(z(BodyPoint::Pelvis) > z(BodyPoint::LeftAnkle));
        // The right leg straight under the body in the first frame: its foot joint at the
        // template's height above the ground [m].
        assert!((z(BodyPoint::RightToe) - 0.02).abs() < TOL);
    }
}

#[test]
fn without_a_body_model_the_error_names_the_model_and_the_flag() {
    let d = dir("no-model");
    let x = write(&d, "x.npz", &Archive::rest(SMPLX, 3).bytes());
    let e = load_motion(&x, &MotionOptions::default())
        .unwrap_err()
        .to_string();
    for word in [
        "SMPL-X",
        "165",
        "SMPLX_FEMALE.npz",
        "female",
        "smpl-x.is.tue.mpg.de",
        "--body-model",
        "body_model=",
        "ship",
    ] {
        assert!(e.contains(word), "`{word}` missing from: {e}");
    }
    let mut h = Archive::rest(SMPLH, 3);
    h.gender = "male";
    let h = write(&d, "h.npz", &h.bytes());
    let e = load_motion(&h, &MotionOptions::default())
        .unwrap_err()
        .to_string();
    for word in [
        "SMPL-H",
        "156",
        "male",
        "mano.is.tue.mpg.de",
        "--body-model",
    ] {
        assert!(e.contains(word), "`{word}` missing from: {e}");
    }
}

#[test]
fn a_model_of_another_layout_is_an_error_naming_both_joint_counts() {
    let d = dir("mismatch");
    let h_model = write(
        &d,
        "model.npz",
        &ModelSpec {
            joints: SMPLH,
            ..ModelSpec::smplx()
        }
        .bytes(),
    );
    let x = write(&d, "x.npz", &Archive::rest(SMPLX, 3).bytes());
    let options = MotionOptions {
        body_model: Some(h_model),
        ..MotionOptions::default()
    };
    let e = load_motion(&x, &options).unwrap_err().to_string();
    for word in ["52 joints, SMPL-H", "55 joints, SMPL-X", "165"] {
        assert!(e.contains(word), "`{word}` missing from: {e}");
    }
}

/// Reads `bytes` as `x.npz` with an SMPL-X model of `shapes` shape components; the error.
fn error_of(d: &std::path::Path, bytes: &[u8], shapes: usize) -> String {
    let model = write(
        d,
        "SMPLX_FEMALE.npz",
        &ModelSpec {
            shapes,
            ..ModelSpec::smplx()
        }
        .bytes(),
    );
    let path = write(d, "x.npz", bytes);
    let options = MotionOptions {
        body_model: Some(model),
        ..MotionOptions::default()
    };
    load_motion(&path, &options).unwrap_err().to_string()
}

#[test]
fn malformed_archives_are_errors_naming_what_is_wrong() {
    let d = dir("malformed");
    let good = Archive::rest(SMPLX, 4);
    let without = |name: &str| {
        let members: Vec<_> = good
            .members()
            .into_iter()
            .filter(|(n, _)| *n != name)
            .collect();
        amass_fixture::npz(&members, false)
    };
    let e = error_of(&d, &without("poses"), 16);
    assert!(e.contains("no array `poses`") && e.contains("trans"), "{e}");
    let e = error_of(&d, &without("mocap_frame_rate"), 16);
    assert!(
        e.contains("mocap_framerate") && e.contains("mocap_frame_rate"),
        "{e}"
    );
    let mut nan = good.clone();
    nan.poses[2][7] = f64::NAN;
    let e = error_of(&d, &nan.bytes(), 16);
    assert!(e.contains("`poses` at frame 2 column 7"), "{e}");
    let mut short = good.clone();
    short.trans.pop();
    let e = error_of(&d, &short.bytes(), 16);
    assert!(
        e.contains("`trans` has shape [3, 3], expected (4, 3)"),
        "{e}"
    );
    let mut odd = good.clone();
    for p in &mut odd.poses {
        p.pop();
    }
    let e = error_of(&d, &odd.bytes(), 16);
    assert!(e.contains("`poses` has shape [4, 164]"), "{e}");
    let mut rate = good.clone();
    rate.rate = 0.0;
    let e = error_of(&d, &rate.bytes(), 16);
    assert!(e.contains("frame rate > 0"), "{e}");
    // Cut short anywhere: an error, never a panic.
    let bytes = good.bytes();
    for cut in [bytes.len() / 3, bytes.len() / 2, bytes.len() - 10] {
        let e = error_of(&d, &bytes[..cut], 16);
        assert!(e.contains("zip"), "cut at {cut}: {e}");
    }
    // Betas past the model's shape components: zeros are accepted, others are an error.
    let mut long = good.clone();
    long.betas[12] = 0.25;
    let e = error_of(&d, &long.bytes(), 10);
    assert!(
        e.contains("betas[12] = 0.25") && e.contains("10 shape components"),
        "{e}"
    );
    let model = write(
        &d,
        "SMPLX_B10.npz",
        &ModelSpec {
            shapes: 10,
            ..ModelSpec::smplx()
        }
        .bytes(),
    );
    // Only betas[0], [1], [5] are non-zero in `good`: a 10-component model reads it.
    read_amass(&good.bytes(), "x.npz", Some(&model), &ReadLimits::default()).unwrap();
    // More frames than the limits allow.
    let limits = ReadLimits {
        max_clip_frames: 3,
        ..ReadLimits::default()
    };
    let e = read_amass(&good.bytes(), "x.npz", Some(&model), &limits)
        .unwrap_err()
        .to_string();
    assert!(e.contains("max_clip_frames"), "{e}");
}

#[test]
fn malformed_models_are_errors_naming_the_model_and_the_array() {
    let d = dir("bad-model");
    let archive = Archive::rest(SMPLX, 2).bytes();
    let spec = ModelSpec::smplx();
    let read = |bytes: &[u8]| {
        let path = write(&d, "SMPLX_FEMALE.npz", bytes);
        read_amass(&archive, "x.npz", Some(&path), &ReadLimits::default())
            .unwrap_err()
            .to_string()
    };
    let full = spec.bytes();
    let e = read(&full[..full.len() / 2]);
    assert!(e.contains("SMPLX_FEMALE.npz") && e.contains("zip"), "{e}");
    let without: Vec<_> = spec
        .members()
        .into_iter()
        .filter(|(n, _)| *n != "J_regressor")
        .collect();
    let e = read(&amass_fixture::npz(&without, true));
    assert!(e.contains("no array `J_regressor`"), "{e}");
    let mut swapped = spec.members();
    for m in &mut swapped {
        if m.0 == "shapedirs" {
            m.1 = amass_fixture::npy_floats(&[3, 2 * SMPLX, 1], &vec![0.0; 6 * SMPLX], false);
        }
    }
    let e = read(&amass_fixture::npz(&swapped, true));
    assert!(e.contains("`shapedirs` has shape [3, 110, 1]"), "{e}");
    let mut text = spec.members();
    for m in &mut text {
        if m.0 == "v_template" {
            m.1 = amass_fixture::npy_text("not an array");
        }
    }
    let e = read(&amass_fixture::npz(&text, true));
    assert!(
        e.contains("`v_template`") && e.contains("not a number"),
        "{e}"
    );
    let e = read_amass(
        &archive,
        "x.npz",
        Some(&d.join("absent.npz")),
        &ReadLimits::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("absent.npz") && e.contains("cannot read"), "{e}");
}

#[test]
fn a_walk_is_retargeted_onto_g1_within_its_joint_limits() {
    let d = dir("walk");
    let model = write(&d, "SMPLX_NEUTRAL.npz", &ModelSpec::smplx().bytes());
    let clip = write(&d, "walk.npz", &Archive::walk(SMPLX, 3.0).bytes());
    let options = MotionOptions {
        body_model: Some(model),
        ..MotionOptions::default()
    };
    let kp = load_motion(&clip, &options)
        .unwrap()
        .keypoints(DEFAULT_MAX_GAP)
        .unwrap();
    let profile = RobotProfile::builtin("g1").unwrap();
    let s = KeypointSettings::default();
    let run = retarget_keypoints(&profile, &kp, None, &s).unwrap();
    let q = &run.quality;
    let tol = SolverSettings::default().box_tolerance;
    assert!(q.position_margin <= tol, "{}", q.position_margin);
    assert!(q.velocity_margin <= tol, "{}", q.velocity_margin);
    assert!(q.acceleration_margin <= tol, "{}", q.acceleration_margin);
    assert!(q.stance_ticks > 0, "no foot ever on the ground");
    assert!(run.trajectory.iter().flatten().all(|x| x.is_finite()));
    eprintln!(
        "ticks {} stance {} mean {:.2} cm",
        q.ticks, q.stance_ticks, q.mean_cm
    );
}
