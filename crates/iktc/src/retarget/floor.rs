//! The floor under a swing foot: the lowest sole corner kept at or above the ground (z = 0).
//!
//! Per swing foot and tick, from the robot's state: the sole's lowest corner height `e` \[m\]
//! above the ground and its vertical speed `ė` \[m/s\] (`ė = v_z + (ω × R c)_z`, corner `c` in
//! the foot frame). The floor bounds the corner's vertical acceleration from below by the
//! slowest approach that never passes the ground:
//!
//! * `a_PD = −k_p e − k_v ė`, a critically damped approach (`k_v = 2√k_p`, `ω = √k_p`): from
//!   `e₀ ≥ 0` it stays at or above the ground iff `ė₀ ≥ −ω e₀` (the solution
//!   `e(t) = (e₀ + (ė₀ + ω e₀) t) e^{−ωt}`); below the ground it returns without overshoot;
//! * `a_brake = ė² / 2e`, the constant deceleration that stops the corner exactly at the
//!   ground, for the case `ė₀ < −ω e₀` above the ground.
//!
//! `a_min = a_PD` where the approach is viable (`ė ≥ −ω e`, or at or below the ground), else
//! `max(a_PD, a_brake)`: any acceleration above `a_min` keeps the corner at or above the
//! comparison solution, which never passes the ground (the two branches meet at `ė = −ω e`,
//! where `a_PD = ω² e > a_brake = ω² e / 2`, so the bound is continuous). The
//! floor joins the stack ([`super::tracker`]) once `a_min ≥ −`[`FLOOR_ENGAGE`] (the foot is
//! low, or descends fast enough that the floor will soon have to brake it): the foot's height
//! is then asked `z̈ = max(a_ref, a_min)`, `a_ref` the acceleration its own reference asks
//! (`z̈_d + k_v(ż_d − ż) + k_p(z_d − z)`), so the floor only ever pushes up, and the foot's
//! roll and pitch are asked to follow the reference (flat) in the same level. The task's row is
//! the foot frame's origin, not a corner: `a_min` is moved to the origin through the turning
//! that the same level asks ([`origin_floor_acceleration`]), for every corner.

use nalgebra::{Isometry3, Point3, Vector3, Vector6};

use crate::task::Gains;

/// The floor joins the stack once it bounds the lowest corner's downward acceleration to less
/// than this \[m/s²\] (see the module documentation): larger values engage it earlier (higher
/// above the ground), smaller ones later, with harder braking.
pub(crate) const FLOOR_ENGAGE: f64 = 2.0;

/// The corners of a sole in the foot frame \[m\]: `sole_offset_x ± l/2`, `± w/2`, `−ankle_height`.
pub(crate) fn sole_corners(support: &crate::sim::imitate::SupportSettings) -> [Vector3<f64>; 4] {
    let (hl, hw) = (0.5 * support.sole_length, 0.5 * support.sole_width);
    [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)].map(|(sx, sy)| {
        Vector3::new(
            support.sole_offset_x + sx * hl,
            sy * hw,
            -support.ankle_height,
        )
    })
}

/// The linear and angular parts of a twist or acceleration (world axes).
fn parts(x: &Vector6<f64>) -> (Vector3<f64>, Vector3<f64>) {
    (
        x.fixed_rows::<3>(0).into_owned(),
        x.fixed_rows::<3>(3).into_owned(),
    )
}

/// Corner `c` (foot frame) of a foot at `pose` whose origin moves at `v` \[m/s\] and which
/// turns at `w` \[rad/s\]: its arm `r = R c` (world axes) \[m\], height \[m\] and vertical
/// speed `v_z + (ω × r)_z` \[m/s\].
fn corner_state(
    pose: &Isometry3<f64>,
    v: &Vector3<f64>,
    w: &Vector3<f64>,
    c: &Vector3<f64>,
) -> (Vector3<f64>, f64, f64) {
    let r = pose.rotation * c;
    let z = (pose * Point3::from(*c)).z;
    (r, z, v.z + w.cross(&r).z)
}

/// The lowest corner's height \[m\] and vertical speed \[m/s\] of a foot at `pose` moving with
/// the twist `velocity` (linear velocity of the frame's origin \[m/s\], angular velocity
/// \[rad/s\], world axes).
pub(crate) fn lowest_corner(
    pose: &Isometry3<f64>,
    velocity: &Vector6<f64>,
    corners: &[Vector3<f64>; 4],
) -> (f64, f64) {
    let (v, w) = parts(velocity);
    let mut best = (f64::INFINITY, 0.0);
    for c in corners {
        let (_, z, z_dot) = corner_state(pose, &v, &w, c);
        if z < best.0 {
            best = (z, z_dot);
        }
    }
    best
}

/// The largest speed \[m/s\] of the sole corners `corners` (foot frame) of a foot at `pose`
/// moving with the twist `velocity` (origin's linear velocity \[m/s\], angular velocity
/// \[rad/s\], world axes): `max_c |v + ω × R c|`. A foot can move its ankle slowly and still
/// turn its sole (a pivot at 3.4 rad/s with the ankle at 0.02 m/s, G1 on a clip of Bandai
/// Namco's dataset).
pub(crate) fn fastest_corner(
    pose: &Isometry3<f64>,
    velocity: &Vector6<f64>,
    corners: &[Vector3<f64>; 4],
) -> f64 {
    let (v, w) = parts(velocity);
    corners
        .iter()
        .map(|c| (v + w.cross(&(pose.rotation * c))).norm())
        .fold(0.0, f64::max)
}

/// The floor's lower bound on the lowest corner's vertical acceleration `a_min` \[m/s²\] at
/// height `e` \[m\] and vertical speed `ė` \[m/s\] (see the module documentation).
pub(crate) fn floor_acceleration(e: f64, e_dot: f64, gains: &Gains) -> f64 {
    let pd = -gains.kp * e - gains.kv * e_dot;
    if e > 0.0 && e_dot < -gains.kp.sqrt() * e {
        pd.max(e_dot * e_dot / (2.0 * e))
    } else {
        pd
    }
}

/// The floor's bound on the vertical acceleration of the foot frame's origin \[m/s²\] that
/// keeps every sole corner at or above its own floor bound, for a foot at `pose` moving with
/// the twist `velocity` (origin's linear velocity \[m/s\], angular velocity \[rad/s\], world
/// axes) whose angular acceleration is asked to be `alpha` \[rad/s²\] (world axes; its z
/// component does not move a corner vertically). A corner `c` with arm `r = R c` accelerates
/// vertically at `z̈_c = z̈ + (α × r + ω × (ω × r))_z`, so its bound `a_min(e_c, ė_c)` holds iff
/// `z̈ ≥ a_min(e_c, ė_c) − (α × r + ω × (ω × r))_z`; the largest over the corners. Asking the
/// origin the lowest corner's bound alone lets a tilting foot's corner pass the ground (0.5 mm
/// on JVRC-1, CMU 131_01, as the foot spun at 3 rad/s on the ground, tilted 3 mrad).
pub(crate) fn origin_floor_acceleration(
    pose: &Isometry3<f64>,
    velocity: &Vector6<f64>,
    alpha: &Vector3<f64>,
    corners: &[Vector3<f64>; 4],
    gains: &Gains,
) -> f64 {
    let (v, w) = parts(velocity);
    corners
        .iter()
        .map(|c| {
            let (r, z, z_dot) = corner_state(pose, &v, &w, c);
            let turning = (alpha.cross(&r) + w.cross(&w.cross(&r))).z;
            floor_acceleration(z, z_dot, gains) - turning
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

/// The lowest height \[m\] over the sole corners `corners` (foot frame) after `dt` \[s\], for a
/// foot at `pose` with the twist `velocity` (origin's linear velocity \[m/s\], angular velocity
/// \[rad/s\], world axes) and the acceleration `acceleration` (origin's classical acceleration
/// \[m/s²\], angular acceleration \[rad/s²\]) held over `dt`: per corner `c` with arm `r = R c`,
/// `z + ż dt + ½ z̈ dt²` with `ż = v_z + (ω × r)_z` and `z̈ = a_z + (α × r + ω × (ω × r))_z` (the
/// second-order expansion of the corner's height).
pub(crate) fn lowest_after(
    pose: &Isometry3<f64>,
    velocity: &Vector6<f64>,
    acceleration: &Vector6<f64>,
    corners: &[Vector3<f64>; 4],
    dt: f64,
) -> f64 {
    let ((v, w), (a, al)) = (parts(velocity), parts(acceleration));
    corners
        .iter()
        .map(|c| {
            let (r, z, z_dot) = corner_state(pose, &v, &w, c);
            let z_ddot = a.z + (al.cross(&r) + w.cross(&w.cross(&r))).z;
            z + z_dot * dt + 0.5 * z_ddot * dt * dt
        })
        .fold(f64::INFINITY, f64::min)
}

/// Whether the floor joins the stack at `a_min` \[m/s²\] ([`FLOOR_ENGAGE`]).
pub(crate) fn engaged(a_min: f64) -> bool {
    a_min >= -FLOOR_ENGAGE
}

#[cfg(test)]
mod tests {
    use super::*;

    const GAINS: Gains = Gains {
        kp: 100.0,
        kv: 20.0,
    };

    /// Integrates a point under `z̈ = a_min(z, ż)` (the floor binding all the way), constant
    /// acceleration over each step \[s\]; returns the lowest height reached \[m\].
    fn lowest_under_floor(z0: f64, v0: f64, dt: f64, steps: usize) -> f64 {
        let (mut z, mut v, mut low) = (z0, v0, z0);
        for _ in 0..steps {
            let a = floor_acceleration(z, v, &GAINS);
            z += v * dt + 0.5 * a * dt * dt;
            v += a * dt;
            low = low.min(z);
        }
        low
    }

    #[test]
    fn a_falling_foot_stops_at_the_ground_not_below() {
        // From 0.2 m at up to 3 m/s down, and from 5 mm at 1 m/s (the braking branch), at the
        // control rate: the corner never passes the ground by more than the step's rounding
        // of the braking parabola (a micrometre).
        for (z0, v0) in [
            (0.2, 0.0),
            (0.2, -1.0),
            (0.2, -3.0),
            (0.005, -1.0),
            (0.05, -0.2),
        ] {
            let low = lowest_under_floor(z0, v0, 0.005, 400);
            assert!(low >= -1e-6, "from {z0} m at {v0} m/s: {low} m");
        }
    }

    #[test]
    fn the_braking_branch_is_the_constant_deceleration_to_rest_at_the_ground() {
        // 0.01 m above, 2 m/s down (ė < −ω e, and a_PD = −1 + 40 = 39 < a_brake): a = ė²/2e
        // = 200 m/s², and under it the corner reaches rest after ė/a = 0.01 s at exactly the
        // ground.
        let a = floor_acceleration(0.01, -2.0, &GAINS);
        assert!((a - 200.0).abs() < 1e-9, "{a}");
        let (t, z) = (
            2.0 / a,
            0.01 - 2.0 * (2.0 / a) + 0.5 * a * (2.0 / a).powi(2),
        );
        assert!((t - 0.01).abs() < 1e-12 && z.abs() < 1e-12, "{t} {z}");
        // A slow descent high above is not braked: the bound is the PD's, below zero.
        let slow = floor_acceleration(0.25, -0.17, &GAINS);
        assert!((slow - (-25.0 + 3.4)).abs() < 1e-12, "{slow}");
        // Below the ground it pushes up; at rest high above it does not engage.
        assert!(floor_acceleration(-0.01, 0.0, &GAINS) > 0.0);
        assert!(!engaged(floor_acceleration(0.5, 0.0, &GAINS)));
        assert!(engaged(floor_acceleration(0.01, 0.0, &GAINS)));
        assert!(engaged(floor_acceleration(0.3, -2.0, &GAINS)));
    }

    /// The corners of a 0.2 × 0.1 m sole 0.05 m below its ankle, its centre `offset_x` \[m\]
    /// ahead of it.
    fn corners_of(offset_x: f64) -> [Vector3<f64>; 4] {
        sole_corners(&crate::sim::imitate::SupportSettings {
            sole_length: 0.2,
            sole_width: 0.1,
            sole_offset_x: offset_x,
            ankle_height: 0.05,
        })
    }

    /// The second-order prediction against the corner's exact motion: a foot turning about
    /// y at constant angular acceleration from a constant-acceleration translation, its lowest
    /// corner integrated in fine steps; the difference is third order in `dt`.
    #[test]
    fn the_lowest_corner_after_a_tick_is_its_second_order_expansion() {
        let corners = corners_of(0.03);
        let (z0, vz, az) = (0.06, -0.8, 30.0);
        let (th0, w0, al) = (0.05, 2.0, -40.0);
        let pose_at = |t: f64| {
            Isometry3::new(
                Vector3::new(0.1 * t, 0.0, z0 + vz * t + 0.5 * az * t * t),
                Vector3::new(0.0, th0 + w0 * t + 0.5 * al * t * t, 0.0),
            )
        };
        let low = |t: f64| {
            let p = pose_at(t);
            corners
                .iter()
                .map(|c| (p * Point3::from(*c)).z)
                .fold(f64::INFINITY, f64::min)
        };
        let v = Vector6::new(0.1, 0.0, vz, 0.0, w0, 0.0);
        let a = Vector6::new(0.0, 0.0, az, 0.0, al, 0.0);
        for dt in [0.005, 0.0025] {
            let predicted = lowest_after(&pose_at(0.0), &v, &a, &corners, dt);
            // Third order: |error| ≤ C dt³, C ≈ (3 α ω + ω³) |r| / 6 ≈ 4 m/s³ here.
            assert!(
                (predicted - low(dt)).abs() < 10.0 * dt.powi(3),
                "{dt}: {predicted} {}",
                low(dt)
            );
        }
        // Halving dt divides the error by about 8.
        let e1 = lowest_after(&pose_at(0.0), &v, &a, &corners, 0.01) - low(0.01);
        let e2 = lowest_after(&pose_at(0.0), &v, &a, &corners, 0.005) - low(0.005);
        assert!((e1 / e2 - 8.0).abs() < 1.0, "{e1} {e2}");
        // At rest on the ground, nothing moves it below.
        let flat = Isometry3::translation(0.0, 0.0, 0.05);
        let zero = Vector6::zeros();
        assert!(lowest_after(&flat, &zero, &zero, &corners, 0.005).abs() < 1e-15);
    }

    #[test]
    fn the_lowest_corner_of_a_tilted_foot_moves_with_the_rotation() {
        // A foot pitched 0.1 rad nose down (about +y), its ankle 0.1 m up, turning at 1 rad/s
        // about +y: the front corners are lowest, at 0.1 − 0.1 sin θ − 0.05 cos θ, and drop
        // at (ω × R c)_z, compared with the finite difference of the height.
        let corners = corners_of(0.0);
        let pose =
            |th: f64| Isometry3::new(Vector3::new(0.0, 0.0, 0.1), Vector3::new(0.0, th, 0.0));
        let twist = Vector6::new(0.0, 0.0, 0.0, 0.0, 1.0, 0.0);
        let (h, hd) = lowest_corner(&pose(0.1), &twist, &corners);
        let expected = 0.1 - 0.1 * 0.1_f64.sin() - 0.05 * 0.1_f64.cos();
        assert!((h - expected).abs() < 1e-12, "{h} {expected}");
        let d = 1e-6;
        let fd = (lowest_corner(&pose(0.1 + d), &twist, &corners).0
            - lowest_corner(&pose(0.1 - d), &twist, &corners).0)
            / (2.0 * d);
        assert!((hd - fd).abs() < 1e-6, "{hd} {fd}");
    }

    /// A foot at a seeded random pose, its origin `height ± 0.05` m up and tilted up to `tilt`
    /// \[rad\] about x and y, with a random twist (origin's linear velocity up to 1 m/s,
    /// angular velocity up to 4 rad/s).
    fn random_foot(
        rng: &mut rand::rngs::StdRng,
        height: f64,
        tilt: f64,
    ) -> (Isometry3<f64>, Vector6<f64>) {
        use rand::Rng;
        let mut u = |r: f64| rng.random_range(-r..r);
        let pose = Isometry3::new(
            Vector3::new(u(0.5), u(0.5), height + u(0.05)),
            Vector3::new(u(tilt), u(tilt), u(3.0)),
        );
        let v = Vector6::new(u(1.0), u(1.0), u(0.5), u(2.0), u(2.0), u(4.0));
        (pose, v)
    }

    /// The origin's bound against each corner's motion computed independently: the foot moved
    /// at constant linear and angular acceleration (`R(t) = exp([ω t + ½ α t²]×) R₀`), each
    /// corner's height differentiated twice by central differences. At the origin's bound every
    /// corner accelerates at least at its own floor bound, and the binding one exactly.
    #[test]
    fn at_the_origins_bound_every_corner_meets_its_own() {
        use rand::{Rng, SeedableRng};
        let corners = corners_of(0.03);
        let mut rng = rand::rngs::StdRng::seed_from_u64(23);
        // Finite-difference step [s] and the agreement it allows [m/s²] (error O(h²)).
        let (h, tol) = (1e-4, 1e-4);
        for _ in 0..200 {
            let (pose, v) = random_foot(&mut rng, 0.15, 0.2);
            let mut u = |r: f64| rng.random_range(-r..r);
            let alpha = Vector3::new(u(50.0), u(50.0), u(50.0));
            let a_z = origin_floor_acceleration(&pose, &v, &alpha, &corners, &GAINS);
            let (lin, w) = parts(&v);
            let a = Vector3::new(u(5.0), u(5.0), a_z);
            let height = |c: &Vector3<f64>, t: f64| {
                let turn = nalgebra::UnitQuaternion::from_scaled_axis(w * t + 0.5 * alpha * t * t);
                let p = pose.translation.vector + lin * t + 0.5 * a * t * t;
                (p + turn * (pose.rotation * c)).z
            };
            let mut binding = f64::INFINITY;
            for c in &corners {
                let (z0, zp, zm) = (height(c, 0.0), height(c, h), height(c, -h));
                let (z_dot, z_ddot) = ((zp - zm) / (2.0 * h), (zp - 2.0 * z0 + zm) / (h * h));
                let slack = z_ddot - floor_acceleration(z0, z_dot, &GAINS);
                assert!(slack > -tol, "a corner below its bound by {slack} m/s²");
                binding = binding.min(slack);
            }
            assert!(binding.abs() < tol, "no corner binds: {binding} m/s²");
        }
    }

    /// The corners' speeds by central differences of their positions along the motion
    /// (`R(t) = exp([ω t]×) R₀`, the origin at constant velocity), the largest of them; and a
    /// foot pivoting about its still ankle is fast at its corners.
    #[test]
    fn the_fastest_corner_is_the_largest_corner_speed() {
        use rand::SeedableRng;
        let corners = corners_of(0.03);
        let mut rng = rand::rngs::StdRng::seed_from_u64(29);
        // Finite-difference step [s] and the agreement it allows [m/s] (error O(h²)).
        let (h, tol) = (1e-5, 1e-8);
        for _ in 0..100 {
            let (pose, v) = random_foot(&mut rng, 0.1, 0.3);
            let (lin, w) = parts(&v);
            let at = |c: &Vector3<f64>, t: f64| {
                let turn = nalgebra::UnitQuaternion::from_scaled_axis(w * t);
                pose.translation.vector + lin * t + turn * (pose.rotation * c)
            };
            let fd = corners
                .iter()
                .map(|c| ((at(c, h) - at(c, -h)) / (2.0 * h)).norm())
                .fold(0.0, f64::max);
            let fastest = fastest_corner(&pose, &v, &corners);
            assert!((fastest - fd).abs() < tol, "{fastest} {fd}");
        }
        // A flat foot turning at 3.4 rad/s about its still ankle: its farthest corner, at
        // √(0.13² + 0.05²) m from the ankle's axis, moves at 3.4 × that.
        let flat = Isometry3::translation(0.0, 0.0, 0.05);
        let spin = Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, 3.4);
        let expected = 3.4 * (0.13_f64.powi(2) + 0.05_f64.powi(2)).sqrt();
        assert!((fastest_corner(&flat, &spin, &corners) - expected).abs() < 1e-12);
    }
}
