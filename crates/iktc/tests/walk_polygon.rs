//! The support polygon as the convex hull of up to four soles, against properties any convex
//! hull has: every sole corner inside or on it, every vertex a sole corner, convex and
//! counter-clockwise; and against the closed form of four equal soles on a square.

#[path = "../../iktc-core/tests/common/mod.rs"]
mod common;

use iktc::walk::{sole_corners, Pose2, SupportPolygon, MAX_SOLES};
use rand::Rng;

/// Rounding allowed on signed distances of points of order 1 m \[m\].
const ROUNDING: f64 = 1e-12;

fn cross(o: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
}

#[test]
fn the_hull_of_random_soles_holds_every_corner_and_is_convex() {
    let mut rng = common::rng(41);
    for case in 0..2000 {
        let n = rng.random_range(1..=MAX_SOLES);
        let soles: Vec<Pose2> = (0..n)
            .map(|_| {
                Pose2::new(
                    rng.random_range(-0.5..0.5),
                    rng.random_range(-0.5..0.5),
                    rng.random_range(-3.2..3.2),
                )
            })
            .collect();
        let (l, w) = (rng.random_range(0.05..0.3), rng.random_range(0.03..0.15));
        let mut p = SupportPolygon::default();
        p.set_hull_of_sole_poses(&soles, l, w);
        let v = p.vertices();
        assert!(v.len() >= 3, "case {case}: {v:?}");
        let corners: Vec<(f64, f64)> = soles.iter().flat_map(|s| sole_corners(s, l, w)).collect();
        for c in &corners {
            assert!(
                p.margin(*c) >= -ROUNDING,
                "case {case}: corner {c:?} outside {v:?}"
            );
        }
        for x in v {
            assert!(
                corners.contains(x),
                "case {case}: vertex {x:?} is not a corner"
            );
        }
        for i in 0..v.len() {
            let (a, b, c) = (v[i], v[(i + 1) % v.len()], v[(i + 2) % v.len()]);
            assert!(
                cross(a, b, c) > 0.0,
                "case {case}: not a left turn at {b:?}"
            );
        }
    }
}

#[test]
fn four_soles_on_a_square_give_the_closed_form_hull() {
    // Soles of 0.2 × 0.1 m at (±0.5, ±0.5), heading 0: the hull is the rectangle
    // [−0.6, 0.6] × [−0.55, 0.55], so the origin is 0.55 m inside.
    let soles =
        [(0.5, 0.5), (-0.5, 0.5), (-0.5, -0.5), (0.5, -0.5)].map(|(x, y)| Pose2::new(x, y, 0.0));
    let mut p = SupportPolygon::default();
    p.set_hull_of_sole_poses(&soles, 0.2, 0.1);
    let mut v = p.vertices().to_vec();
    v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    assert_eq!(
        v,
        vec![(-0.6, -0.55), (-0.6, 0.55), (0.6, -0.55), (0.6, 0.55)]
    );
    assert!((p.margin((0.0, 0.0)) - 0.55).abs() < ROUNDING);
    // Two of them: the two-sole hull.
    let mut two = SupportPolygon::default();
    two.set_hull_of_soles(&soles[0], &soles[2], 0.2, 0.1);
    let mut q = SupportPolygon::default();
    q.set_hull_of_sole_poses(&[soles[0], soles[2]], 0.2, 0.1);
    assert_eq!(two, q);
    // Soles beyond the most a polygon holds are ignored, none empties it.
    let mut five = SupportPolygon::default();
    let extra = [
        soles[0],
        soles[1],
        soles[2],
        soles[3],
        Pose2::new(9.0, 9.0, 0.0),
    ];
    five.set_hull_of_sole_poses(&extra, 0.2, 0.1);
    assert_eq!(five, p);
    five.set_hull_of_sole_poses(&[], 0.2, 0.1);
    assert!(five.vertices().is_empty());
}

/// `pull_towards` on a 0.2 m × 0.1 m sole centred at the origin, margin 0.01 m: a point already
/// that far inside stays; one outside moves along the segment to the target until it is 0.01 m
/// inside (here the edge x = 0.1 − 0.01, a closed form); a target itself nearer the edge is
/// returned.
#[test]
fn pull_towards_stops_at_the_margin_on_the_segment() {
    let mut p = SupportPolygon::default();
    p.set_sole(&Pose2::new(0.0, 0.0, 0.0), 0.2, 0.1);
    assert_eq!(p.pull_towards((0.05, 0.0), (0.0, 0.0), 0.01), (0.05, 0.0));
    let q = p.pull_towards((0.3, 0.02), (0.0, 0.0), 0.01);
    assert!((q.0 - 0.09).abs() < 1e-10, "{q:?}");
    assert!((q.1 - 0.02 * 0.09 / 0.3).abs() < 1e-10, "{q:?}");
    assert!((p.margin(q) - 0.01).abs() < 1e-10);
    assert_eq!(p.pull_towards((0.3, 0.0), (0.095, 0.0), 0.01), (0.095, 0.0));
}
