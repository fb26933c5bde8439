//! Robots whose file gives no velocity limits (MJCF never does): `profile init` writes a
//! guessed `velocity.default`, the profile's `velocity` table sets the limits (and through
//! them the acceleration limits), and the keypoint route refuses a joint it cannot bound
//! instead of running until its answer is not finite.

use iktc::model::RobotFiles;
use std::path::{Path, PathBuf};

use iktc::motion::DEFAULT_MAX_GAP;
use iktc::profile::{init_profile_toml_at, ProfileOrigin, RobotProfile, GUESSED_VELOCITY};
use iktc::retarget::{builtin_motion, retarget_keypoints, KeypointSettings};

/// Booster T1 in MJCF (GMR's model, its licence beside it): 21 hinges, no velocity limits.
fn t1() -> (String, PathBuf) {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/mjcf/booster_t1/t1_mocap.xml");
    (std::fs::read_to_string(&path).unwrap(), path)
}

/// T1's profile as `profile init` writes it, with `edit` applied to its text.
fn t1_profile(edit: impl Fn(String) -> String) -> RobotProfile {
    let (text, path) = t1();
    let dir = path.parent().unwrap();
    let toml = init_profile_toml_at(&text, path.to_str().unwrap(), Some(dir)).unwrap();
    RobotProfile::from_toml_str(
        &edit(toml),
        "t1 profile",
        ProfileOrigin::Directory(dir.to_path_buf()),
    )
    .unwrap()
}

#[test]
fn profile_init_guesses_a_velocity_limit_for_a_file_without_any() {
    let (text, path) = t1();
    let toml = init_profile_toml_at(&text, path.to_str().unwrap(), path.parent()).unwrap();
    assert!(toml.contains("[velocity]"), "{toml}");
    assert!(
        toml.contains("no velocity limit for 21 of 21 joints"),
        "{toml}"
    );
    let p = t1_profile(|t| t);
    assert_eq!(p.velocity.default, Some(GUESSED_VELOCITY));
    let robot = p.robot().unwrap();
    for j in robot.active_joints() {
        assert_eq!(j.limit.velocity, GUESSED_VELOCITY, "{}", j.name);
        // The profile's ratio (10 s⁻¹) turns it into an acceleration limit.
        assert_eq!(
            j.limit.acceleration,
            p.acceleration.per_velocity * GUESSED_VELOCITY,
            "{}",
            j.name
        );
    }
}

#[test]
fn profile_init_writes_no_velocity_table_when_the_file_has_its_limits() {
    let g1 = RobotProfile::builtin("g1").unwrap();
    let text = g1.urdf_text().unwrap();
    let toml = init_profile_toml_at(&text, "g1.urdf", g1.urdf_dir().as_deref()).unwrap();
    assert!(!toml.contains("[velocity]"), "{toml}");
}

#[test]
fn velocity_limits_by_joint_replace_the_default_and_bad_ones_name_their_key() {
    let p = t1_profile(|t| {
        t.replace(
            "[velocity]\n",
            "[velocity]\nlimits = { Left_Knee_Pitch = 7.5 }\n",
        )
    });
    let robot = p.robot().unwrap();
    let knee = robot
        .active_joints()
        .find(|j| j.name == "Left_Knee_Pitch")
        .unwrap();
    assert_eq!(knee.limit.velocity, 7.5);
    assert_eq!(knee.limit.acceleration, 75.0);
    let other = robot
        .active_joints()
        .find(|j| j.name == "Right_Knee_Pitch")
        .unwrap();
    assert_eq!(other.limit.velocity, GUESSED_VELOCITY);

    let (_, path) = t1();
    let origin = ProfileOrigin::Directory(path.parent().unwrap().to_path_buf());
    for (table, key) in [
        ("[velocity]\ndefault = -1.0\n", "velocity.default"),
        (
            "[velocity]\nlimits = { Left_Knee_Pitch = 0.0 }\n",
            "velocity.limits.Left_Knee_Pitch",
        ),
    ] {
        let toml = format!("name = \"t1\"\nurdf = \"t1_mocap.xml\"\nbase = \"floating\"\n{table}");
        let err = RobotProfile::from_toml_str(&toml, "t1", origin.clone())
            .and_then(|p| p.check_values().map(|_| p))
            .unwrap_err()
            .to_string();
        assert!(err.contains(key), "{err}");
    }
    let toml =
        "name = \"t1\"\nurdf = \"t1_mocap.xml\"\nbase = \"floating\"\n[velocity]\nlimits = { No_Such_Joint = 3.0 }\n";
    let err = RobotProfile::from_toml_str(toml, "t1", origin)
        .and_then(|p| p.robot())
        .unwrap_err()
        .to_string();
    assert!(err.contains("velocity.limits.No_Such_Joint"), "{err}");
}

#[test]
fn the_keypoint_route_refuses_a_joint_without_any_limit_and_runs_with_the_guessed_one() {
    let kp = builtin_motion("humanoid3d_walk")
        .unwrap()
        .keypoints(DEFAULT_MAX_GAP)
        .unwrap();
    let s = KeypointSettings::default();
    let unlimited = t1_profile(|t| {
        let start = t.find("[velocity]").unwrap();
        let end = start + t[start..].find("\n\n").unwrap_or(t.len() - start);
        format!("{}{}", &t[..start], &t[end..])
    });
    assert_eq!(unlimited.velocity.default, None);
    let err = retarget_keypoints(&unlimited, &kp, None, &s)
        .unwrap_err()
        .to_string();
    assert!(err.contains("acceleration limit of joint"), "{err}");
    assert!(err.contains("velocity.default"), "{err}");

    let p = t1_profile(|t| t);
    let run = retarget_keypoints(&p, &kp, None, &s).unwrap();
    let robot = p.robot().unwrap();
    let nb = robot.base_nv();
    for (qd, qdd) in run.velocities.iter().zip(&run.accelerations) {
        for (i, j) in robot.active_joints().enumerate() {
            assert!(
                qd[nb + i].abs() <= j.limit.velocity * (1.0 + 1e-9),
                "{}",
                j.name
            );
            assert!(
                qdd[nb + i].abs() <= j.limit.acceleration * (1.0 + 1e-9),
                "{}",
                j.name
            );
        }
    }
}

#[test]
fn a_fallback_velocity_that_is_not_positive_is_refused_by_the_model() {
    let (text, path) = t1();
    for bad in [0.0, -1.0, f64::NAN] {
        let options = iktc::model::ModelOptions {
            fallback_velocity: bad,
            ..iktc::model::ModelOptions::default()
        };
        let err = iktc::model::Robot::from_description_str(&text, path.parent(), &options)
            .unwrap_err()
            .to_string();
        assert!(err.contains("fallback_velocity"), "{bad}: {err}");
    }
}
