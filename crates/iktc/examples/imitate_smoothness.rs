//! Smoothness of the paper's imitation run (JVRC-1, the default clip, L_KNEE and L_HIP_R
//! narrowed) under Algorithm 2 as printed with the viable bounds, and under the smoothing
//! settings added one at a time: the quiet bounds, the level hold, the soft approach to the
//! range ends (`ViableSettings::approach_rate`), the clip low-passed before retargeting
//! (`ImitateConfig::smoothing`; with all four, the defaults), and the defaults with the
//! continuity term.
//!
//! ```sh
//! cargo run --release -p iktc --example imitate_smoothness
//! ```
//!
//! Per variant: level changes (and those undone at the next tick), RMS commanded jerk
//! `(q̈ₖ − q̈ₖ₋₁)/Δt` over all joints, and per narrowed joint its RMS jerk and the share of ticks
//! where the change of q̈ reverses its sign; and the largest excursion beyond a limit.

use iktc::limits::BoundMethod;
use iktc::sim::{Experiment, ImitateConfig, ImitateSummary};
use iktc::solver::SolverSettings;

fn main() -> iktc::Result<()> {
    let (e, defaults) = Experiment::jvrc1()?;
    let printed = SolverSettings {
        level_hold: 1,
        continuity: 0.0,
        ..defaults.solver
    };
    let hold = SolverSettings {
        level_hold: defaults.solver.level_hold,
        ..printed
    };
    let no_approach = defaults.bounds.with_approach_rate(0.0)?;
    let with_hold = format!("quiet bounds, hold {} ticks", defaults.solver.level_hold);
    let with_approach = format!(
        "quiet bounds, hold {}, approach ω = {} /s",
        defaults.solver.level_hold,
        defaults.bounds.approach_rate()
    );
    let with_all = format!(
        "the defaults: quiet bounds, hold {}, approach ω = {} /s, clip low-passed at {} Hz",
        defaults.solver.level_hold,
        defaults.bounds.approach_rate(),
        defaults.smoothing.unwrap_or(f64::NAN)
    );
    let variants = [
        (
            "Algorithm 2, viable bounds",
            BoundMethod::viable(),
            printed,
            None,
        ),
        ("quiet bounds", no_approach, printed, None),
        (with_hold.as_str(), no_approach, hold, None),
        (
            with_approach.as_str(),
            defaults.bounds,
            defaults.solver,
            None,
        ),
        (
            "the defaults without the approach",
            no_approach,
            defaults.solver,
            defaults.smoothing,
        ),
        (
            with_all.as_str(),
            defaults.bounds,
            defaults.solver,
            defaults.smoothing,
        ),
        (
            "the defaults with the continuity term, μ = 0.3",
            defaults.bounds,
            SolverSettings {
                continuity: 0.3,
                ..defaults.solver
            },
            defaults.smoothing,
        ),
    ];
    for (name, bounds, solver, smoothing) in variants {
        let mut cfg = ImitateConfig {
            bounds,
            solver,
            smoothing,
            ..defaults.clone()
        };
        cfg.health.keep_going = true;
        print_variant(name, &e.imitate(&cfg)?.summary);
    }
    Ok(())
}

/// One line per variant: level changes (and those undone), RMS jerk over all joints
/// \[rad/s³\], each narrowed joint's RMS jerk and reversal share, the worst excursion \[rad\].
fn print_variant(name: &str, s: &ImitateSummary) {
    let all = (s
        .smoothness
        .iter()
        .map(|j| j.smoothness.rms_jerk.powi(2))
        .sum::<f64>()
        / s.smoothness.len() as f64)
        .sqrt();
    print!(
        "{name}: level changes {} ({} undone), RMS jerk {all:.0} rad/s³",
        s.level_switches.switches, s.level_switches.flips
    );
    for j in &s.narrowed_smoothness {
        print!(
            "; {} {:.0} rad/s³, reversals {:.1} %",
            j.joint,
            j.smoothness.rms_jerk,
            100.0 * j.smoothness.reversal_share
        );
    }
    println!(
        "; worst excursion {:.1e} rad",
        s.worst_position_margin.max(0.0)
    );
}
