//! The ZMP of a sampled multibody motion: the robot's links, not the cart-table.
//!
//! For bodies `i` of mass `m_i` with centre of mass `c_i` (world) and angular momentum about it
//! `L_i = R_i I_i R_iᵀ ω_i` (`I_i` the inertia about the centre of mass in body axes), the
//! ground must supply the force `Σ m_i (c̈_i + g e_z)` and, about the ground point
//! `P = (p_x, p_y, h)`, the moment `Σ (c_i − P) × m_i (c̈_i + g e_z) + Σ L̇_i`. The ZMP is the
//! point where the moment's horizontal part vanishes:
//!
//! ```text
//! p_x = (Σ m_i (z̈_i + g) x_i − Σ m_i ẍ_i (z_i − h) − Σ L̇_{i,y}) / Σ m_i (z̈_i + g)
//! p_y = (Σ m_i (z̈_i + g) y_i − Σ m_i ÿ_i (z_i − h) + Σ L̇_{i,x}) / Σ m_i (z̈_i + g)
//! ```
//!
//! (`c_i = (x_i, y_i, z_i)`). From samples at period Δt, by central differences:
//! `c̈_k = (c_{k+1} − 2 c_k + c_{k−1}) / Δt²`, `ω_k = log(R_{k+1} R_{k−1}ᵀ) / 2Δt` and
//! `L̇_k = (L_{k+1} − L_{k−1}) / 2Δt`; a sample without both neighbours takes the nearest
//! sample's derivatives (`ω` and `L̇` two samples in). With every body at rest the ZMP is the
//! centre of mass' ground projection.

use nalgebra::{Isometry3, Matrix3, Point3, UnitQuaternion, Vector3};

use crate::error::{check_all_finite, Error, Result};
use crate::model::{Kinematics, Robot, State};

/// One body's mass properties: mass \[kg\], centre of mass in the body frame \[m\], inertia
/// about it in body axes \[kg·m²\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyMass {
    /// Mass \[kg\].
    pub mass: f64,
    /// Centre of mass in the body frame \[m\].
    pub com: Vector3<f64>,
    /// Inertia about the centre of mass, body axes \[kg·m²\].
    pub inertia: Matrix3<f64>,
}

/// The mass properties of a robot's links, in its link order.
pub fn link_masses(robot: &Robot) -> Vec<BodyMass> {
    robot
        .links()
        .iter()
        .map(|l| BodyMass {
            mass: l.mass,
            com: l.com,
            inertia: l.inertia,
        })
        .collect()
}

/// The ZMP \[m\] (world x, y, on the plane `z = ground` \[m\]) of the robot moving through the
/// configurations `qs` (one `q` per sample, each of length `nq`; base position, quaternion
/// x y z w, joints) sampled every `dt` \[s\], under `gravity` \[m/s²\]: the links' ZMP
/// ([`multibody_zmp`], `None` where the ground would have to pull) of their poses by forward
/// kinematics. Errors: a configuration of the wrong length or not valid for the robot, and
/// [`multibody_zmp`]'s.
pub fn configuration_zmp(
    robot: &Robot,
    qs: &[&[f64]],
    dt: f64,
    ground: f64,
    gravity: f64,
) -> Result<Vec<Option<[f64; 2]>>> {
    let mut state = State::neutral(robot);
    let mut kin: Option<Kinematics> = None;
    let mut poses = Vec::with_capacity(qs.len());
    for (k, q) in qs.iter().enumerate() {
        if q.len() != robot.nq() {
            return Err(Error::DimensionMismatch {
                what: format!("configuration {k} (nq)"),
                expected: robot.nq(),
                got: q.len(),
            });
        }
        state.q.as_mut_slice().copy_from_slice(q);
        state.validate(robot)?;
        match kin.as_mut() {
            Some(kn) => kn.update(robot, &state)?,
            None => kin = Some(Kinematics::new(robot, &state)?),
        }
        if let Some(kn) = &kin {
            poses.push(kn.link_poses().to_vec());
        }
    }
    multibody_zmp(&link_masses(robot), &poses, dt, ground, gravity)
}

/// Checks [`multibody_zmp`]'s inputs: at least three samples, a positive and finite `dt`
/// \[s\] and `gravity` \[m/s²\], a finite `ground` \[m\], one pose per body in each sample, finite
/// poses.
fn check_inputs(
    bodies: &[BodyMass],
    poses: &[Vec<Isometry3<f64>>],
    dt: f64,
    ground: f64,
    gravity: f64,
) -> Result<()> {
    let n = poses.len();
    if n < 3 {
        return Err(Error::InsufficientData {
            what: "multibody ZMP".into(),
            message: format!("{n} samples (expected at least 3 for the accelerations)"),
        });
    }
    if !(dt > 0.0 && dt.is_finite() && gravity > 0.0 && gravity.is_finite()) {
        return Err(Error::InvalidSetting {
            name: "multibody ZMP dt, gravity".into(),
            value: format!("{dt} s, {gravity} m/s²"),
            expected: "positive and finite".into(),
        });
    }
    check_all_finite("multibody ZMP ground [m]", &[ground])?;
    if let Some((k, p)) = poses
        .iter()
        .enumerate()
        .find(|(_, p)| p.len() != bodies.len())
    {
        return Err(Error::InsufficientData {
            what: "multibody ZMP".into(),
            message: format!(
                "sample {k} has {} poses (expected one per body: {})",
                p.len(),
                bodies.len()
            ),
        });
    }
    for (k, sample) in poses.iter().enumerate() {
        for p in sample {
            let t = p.translation.vector;
            let q = p.rotation.coords;
            if !t.iter().chain(q.iter()).all(|v| v.is_finite()) {
                return Err(Error::InvalidSetting {
                    name: format!("multibody ZMP pose at sample {k}"),
                    value: format!("{p:?}"),
                    expected: "finite".into(),
                });
            }
        }
    }
    Ok(())
}

/// The ZMP \[m\] (world x, y) on the ground plane `z = ground` \[m\] of bodies with masses
/// `bodies` whose frames are `poses[k][i]` (world) at `t_k = k dt` \[s\], under gravity
/// `gravity` \[m/s²\] (module documentation); `None` at a sample whose total vertical force
/// `Σ m_i (z̈_i + g)` is not positive (the bodies falling at least as fast as gravity: the
/// ground would have to pull). Errors: fewer than three samples, a sample without one pose per
/// body, a non-positive `dt` or `gravity`, non-finite poses.
pub fn multibody_zmp(
    bodies: &[BodyMass],
    poses: &[Vec<Isometry3<f64>>],
    dt: f64,
    ground: f64,
    gravity: f64,
) -> Result<Vec<Option<[f64; 2]>>> {
    check_inputs(bodies, poses, dt, ground, gravity)?;
    let n = poses.len();
    let com = |k: usize, i: usize| (poses[k][i] * Point3::from(bodies[i].com)).coords;
    let rot = |k: usize, i: usize| poses[k][i].rotation;
    // Angular momentum of body i at sample k (1 ≤ k ≤ n − 2).
    let momentum = |k: usize, i: usize| -> Vector3<f64> {
        let r: UnitQuaternion<f64> = rot(k, i);
        let w = (rot(k + 1, i) * rot(k - 1, i).inverse()).scaled_axis() / (2.0 * dt);
        let m = r.to_rotation_matrix();
        m * bodies[i].inertia * m.transpose() * w
    };
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        // Accelerations at the nearest sample with both neighbours; L̇ two samples in.
        let ka = k.clamp(1, n - 2);
        let kl = if n >= 5 { k.clamp(2, n - 3) } else { 0 };
        let (mut fz, mut mx, mut my) = (0.0, 0.0, 0.0);
        for (i, b) in bodies.iter().enumerate() {
            if b.mass == 0.0 && b.inertia == Matrix3::zeros() {
                continue;
            }
            let c = com(k, i);
            let a = (com(ka + 1, i) - 2.0 * com(ka, i) + com(ka - 1, i)) / (dt * dt);
            let vertical = b.mass * (a.z + gravity);
            fz += vertical;
            // Numerators of p_x and p_y.
            my += vertical * c.x - b.mass * a.x * (c.z - ground);
            mx += vertical * c.y - b.mass * a.y * (c.z - ground);
            if n >= 5 && b.inertia != Matrix3::zeros() {
                let ld = (momentum(kl + 1, i) - momentum(kl - 1, i)) / (2.0 * dt);
                my -= ld.y;
                mx += ld.x;
            }
        }
        out.push((fz > 0.0).then(|| [my / fz, mx / fz]));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Translation3;

    fn point(mass: f64) -> BodyMass {
        BodyMass {
            mass,
            com: Vector3::zeros(),
            inertia: Matrix3::zeros(),
        }
    }

    fn at(x: f64, y: f64, z: f64) -> Isometry3<f64> {
        Isometry3::from_parts(Translation3::new(x, y, z), UnitQuaternion::identity())
    }

    #[test]
    fn bodies_at_rest_put_the_zmp_under_their_centre_of_mass() {
        let bodies = [point(2.0), point(6.0)];
        let sample = vec![at(0.1, -0.2, 0.5), at(0.3, 0.2, 0.9)];
        let zmp = multibody_zmp(&bodies, &vec![sample; 4], 0.005, 0.0, 9.81).unwrap();
        let c = [
            (2.0 * 0.1 + 6.0 * 0.3) / 8.0,
            (2.0 * -0.2 + 6.0 * 0.2) / 8.0,
        ];
        for p in zmp {
            let p = p.unwrap();
            assert!(
                (p[0] - c[0]).abs() < 1e-12 && (p[1] - c[1]).abs() < 1e-12,
                "{p:?}"
            );
        }
    }

    #[test]
    fn an_accelerating_point_mass_is_the_cart_table() {
        // x(t) = a t² / 2 at height z above the ground h: p_x = x − a (z − h) / g.
        let (a, z, h, g, dt) = (1.5, 0.8, 0.05, 9.81, 0.005);
        let poses: Vec<Vec<Isometry3<f64>>> = (0..7)
            .map(|k| {
                let t = k as f64 * dt;
                vec![at(0.5 * a * t * t, 0.0, z)]
            })
            .collect();
        let zmp = multibody_zmp(&[point(3.0)], &poses, dt, h, g).unwrap();
        for (k, p) in zmp.iter().enumerate().skip(1).take(5) {
            let p = p.unwrap();
            let t = k as f64 * dt;
            let expected = 0.5 * a * t * t - a * (z - h) / g;
            assert!(
                (p[0] - expected).abs() < 1e-9,
                "{k}: {} vs {expected}",
                p[0]
            );
            assert!(p[1].abs() < 1e-12);
        }
    }

    #[test]
    fn a_spinning_up_flywheel_moves_the_zmp_by_its_momentum_rate() {
        // A wheel about world y with angular acceleration α: L̇_y = I_yy α, p_x = x − I_yy α / (m g).
        let (m, iyy, alpha, dt, g) = (4.0, 0.2, 3.0, 0.01, 9.81);
        let body = BodyMass {
            mass: m,
            com: Vector3::zeros(),
            inertia: Matrix3::from_diagonal(&Vector3::new(0.1, iyy, 0.1)),
        };
        let poses: Vec<Vec<Isometry3<f64>>> = (0..9)
            .map(|k| {
                let t = k as f64 * dt;
                let angle = 0.5 * alpha * t * t;
                vec![Isometry3::from_parts(
                    Translation3::new(0.2, 0.0, 0.6),
                    UnitQuaternion::from_axis_angle(&Vector3::y_axis(), angle),
                )]
            })
            .collect();
        let zmp = multibody_zmp(&[body], &poses, dt, 0.0, g).unwrap();
        let expected = 0.2 - iyy * alpha / (m * g);
        for p in &zmp[2..7] {
            let p = p.unwrap();
            assert!((p[0] - expected).abs() < 1e-6, "{} vs {expected}", p[0]);
        }
    }

    #[cfg(feature = "urdf")]
    #[test]
    fn a_robot_at_rest_has_its_zmp_under_its_com_and_a_wrong_q_is_an_error() {
        let robot = crate::model::builtin_robot("jvrc1").unwrap();
        let mut state = State::neutral(&robot);
        let j = robot.nq() - 1;
        state.q[j] = 0.4;
        let kin = Kinematics::new(&robot, &state).unwrap();
        let q = state.q.as_slice();
        let z = configuration_zmp(&robot, &[q, q, q, q, q], 0.005, 0.0, 9.81).unwrap();
        let c = kin.com();
        for p in z {
            let p = p.unwrap();
            assert!(
                (p[0] - c.x).abs() < 1e-12 && (p[1] - c.y).abs() < 1e-12,
                "{p:?} {c}"
            );
        }
        let short = &q[..q.len() - 1];
        let e = configuration_zmp(&robot, &[q, short, q], 0.005, 0.0, 9.81).unwrap_err();
        assert!(e.to_string().contains("configuration 1"), "{e}");
    }

    #[test]
    fn a_turned_wheel_spinning_up_about_x_moves_the_zmp_sideways_by_its_momentum_rate() {
        // The body turned 90° about z (its x axis along world y, its y axis along −x), then
        // spun about world x with angular acceleration α: about world x it presents its
        // body-y moment I_yy, and L̇_x = I_yy α moves p_y by + I_yy α / (m g).
        let (m, alpha, dt, g) = (2.0, 4.0, 0.01, 9.81);
        let body = BodyMass {
            mass: m,
            com: Vector3::zeros(),
            inertia: Matrix3::from_diagonal(&Vector3::new(0.05, 0.3, 0.1)),
        };
        let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2);
        let poses: Vec<Vec<Isometry3<f64>>> = (0..9)
            .map(|k| {
                let t = k as f64 * dt;
                let spin = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 0.5 * alpha * t * t);
                vec![Isometry3::from_parts(
                    Translation3::new(0.0, -0.1, 0.7),
                    spin * turn,
                )]
            })
            .collect();
        let zmp = multibody_zmp(&[body], &poses, dt, 0.0, g).unwrap();
        let expected = -0.1 + 0.3 * alpha / (m * g);
        for p in &zmp[2..7] {
            let p = p.unwrap();
            assert!((p[1] - expected).abs() < 1e-6, "{} vs {expected}", p[1]);
            assert!(p[0].abs() < 1e-9, "{}", p[0]);
        }
    }

    #[test]
    fn bad_samples_are_errors() {
        let bodies = [point(1.0)];
        let few = vec![vec![at(0.0, 0.0, 1.0)]; 2];
        assert!(multibody_zmp(&bodies, &few, 0.005, 0.0, 9.81).is_err());
        let mut wrong = vec![vec![at(0.0, 0.0, 1.0)]; 3];
        wrong[1].push(at(0.0, 0.0, 1.0));
        let e = multibody_zmp(&bodies, &wrong, 0.005, 0.0, 9.81).unwrap_err();
        assert!(e.to_string().contains("sample 1"), "{e}");
        let nan = vec![vec![at(f64::NAN, 0.0, 1.0)]; 3];
        assert!(multibody_zmp(&bodies, &nan, 0.005, 0.0, 9.81).is_err());
        let ok = vec![vec![at(0.0, 0.0, 1.0)]; 3];
        assert!(multibody_zmp(&bodies, &ok, 0.0, 0.0, 9.81).is_err());
        // Falling faster than gravity (z = −g t², 2 g down), and at exactly g: no ZMP.
        for rate in [9.81, 0.5 * 9.81] {
            let falling: Vec<Vec<Isometry3<f64>>> = (0..3)
                .map(|k| {
                    let t = k as f64 * 0.01;
                    vec![at(0.0, 0.0, 1.0 - rate * t * t)]
                })
                .collect();
            let z = multibody_zmp(&bodies, &falling, 0.01, 0.0, 9.81).unwrap();
            assert!(z.iter().all(Option::is_none), "{rate}: {z:?}");
        }
    }
}
