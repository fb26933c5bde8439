//! ZMP from foot sensors (eqs. 29–30) against hand-computed cases. Sensor readings are
//! built from a known ground-reaction force acting at a known centre of pressure `P`:
//! the sensor at `p` then reads the torque `(P − p) × f`.

use iktc::balance::{measure_zmp, Foot, FootSensor, ZmpSettings, ZmpStatus};
use iktc::Error;
use nalgebra::Vector3;

/// A sensor at `sensor` reading the force `force` that the ground applies at `cop` (z = 0).
fn reading(sensor: [f64; 3], cop: [f64; 2], force: [f64; 3]) -> FootSensor {
    let p = Vector3::from(sensor);
    let f = Vector3::from(force);
    let c = Vector3::new(cop[0], cop[1], 0.0);
    FootSensor {
        position: p,
        force: f,
        torque: (c - p).cross(&f),
    }
}

fn unloaded(sensor: [f64; 3]) -> FootSensor {
    FootSensor {
        position: Vector3::from(sensor),
        force: Vector3::zeros(),
        // A lifted foot's sensor offset: must be ignored.
        torque: Vector3::new(3.0, -2.0, 0.5),
    }
}

fn close(a: [f64; 2], b: [f64; 2]) -> bool {
    (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12
}

#[test]
fn single_support_sensor_at_sole() {
    // Hand computation: τ = (4, −8, 0) N·m, f_z = 400 N at the origin:
    // x = −τ_y/f_z = 0.02 m, y = τ_x/f_z = 0.01 m.
    let right = FootSensor {
        position: Vector3::zeros(),
        force: Vector3::new(0.0, 0.0, 400.0),
        torque: Vector3::new(4.0, -8.0, 0.0),
    };
    let m = measure_zmp(&unloaded([0.0, 0.2, 0.0]), &right, &ZmpSettings::default()).unwrap();
    assert_eq!(m.status, ZmpStatus::OneFoot(Foot::Right));
    assert!(close(m.position.unwrap(), [0.02, 0.01]));
    assert_eq!(m.normal_force, 400.0);
}

#[test]
fn double_support_is_force_weighted_centre_of_pressure() {
    // Feet at y = ±0.1 m, 300 N on the left, 100 N on the right, each loaded at its centre:
    // y = (0.1·300 − 0.1·100)/400 = 0.05 m, x = 0.
    let left = reading([0.0, 0.1, 0.0], [0.0, 0.1], [0.0, 0.0, 300.0]);
    let right = reading([0.0, -0.1, 0.0], [0.0, -0.1], [0.0, 0.0, 100.0]);
    let m = measure_zmp(&left, &right, &ZmpSettings::default()).unwrap();
    assert_eq!(m.status, ZmpStatus::BothFeet);
    assert!(close(m.position.unwrap(), [0.0, 0.05]));
    // Off-centre pressure in each foot: (0.03, 0.12)·250 N and (−0.01, −0.08)·150 N.
    let left = reading([0.0, 0.1, 0.0], [0.03, 0.12], [0.0, 0.0, 250.0]);
    let right = reading([0.0, -0.1, 0.0], [-0.01, -0.08], [0.0, 0.0, 150.0]);
    let m = measure_zmp(&left, &right, &ZmpSettings::default()).unwrap();
    let want = [
        (0.03 * 250.0 - 0.01 * 150.0) / 400.0,
        (0.12 * 250.0 - 0.08 * 150.0) / 400.0,
    ];
    assert!(close(m.position.unwrap(), want));
}

#[test]
fn sensors_above_the_sole_count_the_tangential_force() {
    // Sensor 5 cm above the sole at the foot centre, ground force (20, −10, 400) N at the
    // centre of the sole: the sensor reads τ = (0,0,−0.05) × f = (−0.5, −1.0, 0) N·m.
    // The printed eq. (30), OP × (0, 0, f_z), would drop the height term and put the ZMP at
    // (0.0025, −0.00125) m; the true one is at the origin.
    let s = reading([0.0, 0.0, 0.05], [0.0, 0.0], [20.0, -10.0, 400.0]);
    assert!((s.torque - Vector3::new(-0.5, -1.0, 0.0)).norm() < 1e-12);
    let m = measure_zmp(&unloaded([0.0, 0.2, 0.0]), &s, &ZmpSettings::default()).unwrap();
    assert!(close(m.position.unwrap(), [0.0, 0.0]));
    // Both feet above the sole with shear, centres of pressure off the sensor axes.
    let left = reading([0.02, 0.1, 0.04], [0.05, 0.11], [15.0, 5.0, 200.0]);
    let right = reading([-0.01, -0.1, 0.04], [-0.02, -0.07], [-8.0, 12.0, 300.0]);
    let m = measure_zmp(&left, &right, &ZmpSettings::default()).unwrap();
    let want = [
        (0.05 * 200.0 - 0.02 * 300.0) / 500.0,
        (0.11 * 200.0 - 0.07 * 300.0) / 500.0,
    ];
    assert!(close(m.position.unwrap(), want), "{m:?} vs {want:?}");
}

#[test]
fn no_load_is_a_status_not_a_division_by_zero() {
    let m = measure_zmp(
        &unloaded([0.0, 0.1, 0.0]),
        &unloaded([0.0, -0.1, 0.0]),
        &ZmpSettings::default(),
    )
    .unwrap();
    assert_eq!(m.status, ZmpStatus::NoContact);
    assert_eq!(m.position, None);
    // A foot below the threshold (here 3 N < 5 N) is left out.
    let light = reading([0.0, 0.1, 0.0], [0.5, 0.5], [0.0, 0.0, 3.0]);
    let right = reading([0.0, -0.1, 0.0], [0.01, -0.1], [0.0, 0.0, 400.0]);
    let m = measure_zmp(&light, &right, &ZmpSettings::default()).unwrap();
    assert_eq!(m.status, ZmpStatus::OneFoot(Foot::Right));
    assert!(close(m.position.unwrap(), [0.01, -0.1]));
    // A pulling (negative) normal force is no load either.
    let pulled = reading([0.0, 0.1, 0.0], [0.0, 0.1], [0.0, 0.0, -50.0]);
    let m = measure_zmp(&pulled, &light, &ZmpSettings::default()).unwrap();
    assert_eq!(m.status, ZmpStatus::NoContact);
}

#[test]
fn non_finite_input_and_bad_settings_are_errors() {
    let mut s = reading([0.0, 0.1, 0.0], [0.0, 0.1], [0.0, 0.0, 300.0]);
    s.torque.x = f64::NAN;
    let r = measure_zmp(&s, &unloaded([0.0, -0.1, 0.0]), &ZmpSettings::default());
    assert!(matches!(r, Err(Error::NonFinite { .. })), "{r:?}");
    let bad = ZmpSettings {
        min_normal_force: -1.0,
    };
    let ok = reading([0.0, 0.1, 0.0], [0.0, 0.1], [0.0, 0.0, 300.0]);
    assert!(measure_zmp(&ok, &ok, &bad).is_err());
}
