//! Timeline, ZMP reference and support polygons.

use iktc::walk::{
    smoothstep, FootstepPlan, Phase, Pose2, PreviewSettings, Side, SupportPolygon, Timeline,
    WalkSettings, WalkingPattern,
};

const EPS: f64 = 1e-12;

fn area(v: &[(f64, f64)]) -> f64 {
    // Shoelace formula; positive for counter-clockwise order.
    let n = v.len();
    (0..n)
        .map(|i| {
            let (a, b) = (v[i], v[(i + 1) % n]);
            a.0 * b.1 - b.0 * a.1
        })
        .sum::<f64>()
        / 2.0
}

#[test]
fn timeline_has_the_planned_phases_and_durations() {
    let w = WalkSettings::default();
    let plan = FootstepPlan::forward(4, 0.2, &w).unwrap();
    let tl = Timeline::new(&plan, &w).unwrap();
    let ph = tl.phases();
    assert_eq!(ph.len(), 2 * 4 + 1);
    // Hand computation of the total duration.
    let total =
        w.initial_dsp_duration + 4.0 * w.ssp_duration + 3.0 * w.dsp_duration + w.final_dsp_duration;
    assert!((tl.duration() - total).abs() < EPS);
    assert_eq!(ph[0].phase, Phase::DoubleSupport);
    assert!((ph[0].end - w.initial_dsp_duration).abs() < EPS);
    for (i, p) in ph.iter().enumerate() {
        if i > 0 {
            assert_eq!(p.start, ph[i - 1].end, "phases must tile the time axis");
        }
        if i % 2 == 1 {
            let step = plan.steps()[i / 2];
            assert_eq!(
                p.phase,
                Phase::SingleSupport {
                    stance: step.side.opposite()
                }
            );
            assert!((p.end - p.start - w.ssp_duration).abs() < EPS);
            assert_eq!(p.swing_target, Some(step.pose));
        } else {
            assert_eq!(p.phase, Phase::DoubleSupport);
        }
    }
    // phase_at inside, at boundaries (start inclusive) and outside.
    let t1 = ph[1].start;
    assert_eq!(tl.phase_at(t1 - 1e-9), Phase::DoubleSupport);
    assert_eq!(
        tl.phase_at(t1),
        Phase::SingleSupport {
            stance: Side::Right
        }
    );
    assert_eq!(
        tl.phase_at(t1 + 0.3),
        Phase::SingleSupport {
            stance: Side::Right
        }
    );
    assert_eq!(tl.phase_at(-5.0), Phase::DoubleSupport);
    assert_eq!(tl.phase_at(1e3), Phase::DoubleSupport);
    assert_eq!(tl.index_at(1e3), ph.len() - 1);
}

#[test]
fn smoothstep_is_the_quintic_with_flat_ends() {
    for &tau in &[0.0, 0.1, 0.37, 0.5, 0.9, 1.0] {
        let (s, ds, dds) = smoothstep(1.0, 3.0, 1.0 + 2.0 * tau);
        let t: f64 = tau;
        assert!((s - (10.0 * t.powi(3) - 15.0 * t.powi(4) + 6.0 * t.powi(5))).abs() < EPS);
        // Finite differences.
        let h = 1e-6;
        let (sp, dsp, _) = smoothstep(1.0, 3.0, 1.0 + 2.0 * tau + h);
        let (sm, dsm, _) = smoothstep(1.0, 3.0, 1.0 + 2.0 * tau - h);
        if tau > 0.0 && tau < 1.0 {
            assert!((ds - (sp - sm) / (2.0 * h)).abs() < 1e-8);
            assert!((dds - (dsp - dsm) / (2.0 * h)).abs() < 1e-6);
        } else {
            assert_eq!((ds, dds), (0.0, 0.0));
        }
    }
}

#[test]
fn zmp_reference_rests_on_the_stance_foot_and_shifts_inside_the_polygon() {
    let w = WalkSettings::default();
    let plan = FootstepPlan::forward(6, 0.2, &w).unwrap();
    let pattern = WalkingPattern::new(&plan, &w, &PreviewSettings::default()).unwrap();
    let tl = pattern.timeline();
    let mut poly = SupportPolygon::default();
    for p in tl.phases() {
        if let Phase::SingleSupport { stance } = p.phase {
            for f in [0.0, 0.3, 0.99] {
                let t = p.start + f * (p.end - p.start);
                let z = tl.zmp_reference(t);
                let foot = p.foot(stance);
                assert!((z.0 - foot.x).abs() < EPS && (z.1 - foot.y).abs() < EPS);
            }
        }
    }
    // Initial stance: midpoint; end: midpoint of the final feet.
    let z0 = tl.zmp_reference(0.0);
    assert!(z0.0.abs() < EPS && z0.1.abs() < EPS);
    let ze = tl.zmp_reference(tl.duration());
    assert!((ze.0 - 1.0).abs() < EPS && ze.1.abs() < EPS);
    // Everywhere inside the support polygon by at least half the sole width: with both soles
    // equally oriented, the hull of two soles is the Minkowski sum of one sole and the segment
    // between their centres, so a point of that segment is at least the sole's inradius
    // (half its width) from the hull's boundary.
    let n = (tl.duration() / 0.001) as usize;
    for k in 0..=n {
        let t = k as f64 * 0.001;
        pattern.support_polygon_into(t, &mut poly).unwrap();
        let m = poly.margin(tl.zmp_reference(t));
        assert!(m >= 0.5 * w.sole_width - 1e-9, "t = {t}: margin {m}");
    }
}

#[test]
fn support_polygons_have_the_expected_shape() {
    let w = WalkSettings::default();
    let plan = FootstepPlan::turn(3, 0.3, &w).unwrap();
    let pattern = WalkingPattern::new(&plan, &w, &PreviewSettings::default()).unwrap();
    let (l, wd) = (w.sole_length, w.sole_width);
    // Initial DSP, feet side by side: rectangle l × (separation + width).
    let v = pattern.support_polygon(0.5).unwrap();
    assert_eq!(v.len(), 4);
    assert!((area(&v) - l * (w.foot_separation + wd)).abs() < 1e-12);
    let mut buf = SupportPolygon::default();
    for p in pattern.timeline().phases() {
        let t = 0.5 * (p.start + p.end);
        pattern.support_polygon_into(t, &mut buf).unwrap();
        assert_eq!(
            buf.vertices(),
            pattern.support_polygon(t).unwrap().as_slice()
        );
        let v = buf.vertices();
        assert!(area(v) > 0.0, "counter-clockwise");
        // Convex: every turn is to the left.
        for i in 0..v.len() {
            let (a, b, c) = (v[i], v[(i + 1) % v.len()], v[(i + 2) % v.len()]);
            assert!((b.0 - a.0) * (c.1 - b.1) - (b.1 - a.1) * (c.0 - b.0) > 0.0);
        }
        match p.phase {
            Phase::SingleSupport { stance } => {
                assert_eq!(v.len(), 4);
                assert!((area(v) - l * wd).abs() < 1e-12);
                let f = p.foot(stance);
                assert!((buf.margin((f.x, f.y)) - 0.5 * wd).abs() < 1e-12);
            }
            Phase::DoubleSupport => {
                // Contains every corner of both soles, and its area is at most the bounding
                // box's and at least both soles'.
                for foot in [p.left, p.right] {
                    for c in iktc::walk::sole_corners(&foot, l, wd) {
                        assert!(buf.margin(c) >= -1e-12);
                    }
                }
                assert!(area(v) >= 2.0 * l * wd - 1e-12);
            }
        }
    }
}

#[test]
fn polygon_margin_matches_hand_computation() {
    let mut p = SupportPolygon::default();
    p.set_sole(&Pose2::new(1.0, 2.0, std::f64::consts::FRAC_PI_2), 0.2, 0.1);
    // Rotated by 90°: x extent ±0.05, y extent ±0.1.
    assert!((p.margin((1.0, 2.0)) - 0.05).abs() < EPS);
    assert!((p.margin((1.03, 2.0)) - 0.02).abs() < EPS);
    assert!((p.margin((1.0, 2.08)) - 0.02).abs() < EPS);
    assert!((p.margin((1.1, 2.0)) + 0.05).abs() < EPS);
    assert!(p.contains((1.0, 2.0), 0.04));
    assert!(!p.contains((1.0, 2.0), 0.06));
}
