//! The 3R experiment reproduces errata 2.1's qualitative outcome.

use iktc::limits::BoundMethod;
use iktc::sim::*;
use iktc::solver::Method;

const DEG: f64 = std::f64::consts::PI / 180.0;

fn run(method: Method, bounds: BoundMethod) -> Planar3rRun {
    run_planar3r(&Planar3rConfig {
        method,
        bounds,
        ..Default::default()
    })
    .unwrap()
}

#[test]
fn iktc_viable_reproduces_errata_2_1() {
    let r = run(Method::Iktc, BoundMethod::viable());
    let s = &r.summary;
    println!("{}", serde_json::to_string_pretty(s).unwrap());
    // q1 stops at its 60° lower limit, never below (in-step peaks included).
    assert!(
        s.worst_position_margin <= 1e-9,
        "position margin {}",
        s.worst_position_margin
    );
    assert!(s.worst_velocity_margin <= 1e-9);
    assert!(
        (s.min_q1 - 60.0 * DEG).abs() < 0.5 * DEG,
        "q1 min {}°",
        s.min_q1 / DEG
    );
    // θ3 sacrificed by about 33° at the end; P_x and P_y tracked.
    assert!(
        (s.final_error[2].abs() / DEG - 33.0).abs() < 3.0,
        "θ3 error {}°",
        s.final_error[2] / DEG
    );
    assert!(
        s.final_error[0].abs() < 1e-3 && s.final_error[1].abs() < 1e-3,
        "{:?}",
        s.final_error
    );
    // Corrections only at the lowest level.
    assert!(s.corrected_steps > 0);
    assert_eq!(s.climbed_steps, 0);
    assert!(s.qp_per_step_max <= 1);
}

#[test]
fn gf_agrees_with_iktc_when_only_the_lowest_level_is_corrected() {
    let a = run(Method::Iktc, BoundMethod::viable());
    let b = run(Method::Cascade, BoundMethod::viable());
    assert_eq!(b.summary.qp_per_step_max, 3, "GF solves one QP per level");
    assert!(b.summary.worst_position_margin <= 1e-9);
    for (x, y) in a.steps.iter().zip(&b.steps) {
        for k in 0..3 {
            assert!(
                (x.q[k] - y.q[k]).abs() < 1e-4,
                "t = {}: q{} {} vs {}",
                x.t,
                k + 1,
                x.q[k],
                y.q[k]
            );
        }
    }
}

#[test]
fn paper_bound_overshoots_in_discrete_time() {
    let r = run(Method::Iktc, BoundMethod::Paper);
    let s = &r.summary;
    // Errata 3.1: q1 goes about 0.5° past 60° with eq. (14) as printed.
    assert!(
        s.worst_position_margin > 0.1 * DEG,
        "margin {}°",
        s.worst_position_margin / DEG
    );
    assert!(s.worst_position_margin < 2.0 * DEG);
}
