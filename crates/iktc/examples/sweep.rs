//! The robustness sweep: every built-in clip × IKTC / GF / clamp × Δt ∈ {2, 5, 10, 20, 50} ms
//! with viable bounds on JVRC-1, one table row per case. Run it with
//! `cargo run --release -p iktc --example sweep` (a few minutes on one core).

use iktc::model::{jvrc1, ModelOptions};
use iktc::motion::BUILTIN_CLIP_NAMES;
use iktc::sim::sweep::{sweep_case, SWEEP_METHODS, SWEEP_PERIODS};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let robot = jvrc1(&ModelOptions::default())?;
    println!(
        "| clip | solver | dt [s] | ticks | max excursion q [rad] / q̇ [rad/s] / q̈ [rad/s²] | empty-box ticks | fallbacks | health |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for clip in BUILTIN_CLIP_NAMES {
        for method in SWEEP_METHODS {
            for dt in SWEEP_PERIODS {
                match sweep_case(&robot, clip, method, dt) {
                    Ok(r) => {
                        let fallbacks = if r.fallbacks.is_empty() {
                            "0".to_string()
                        } else {
                            r.fallbacks
                                .iter()
                                .map(|(k, n)| format!("{k}: {n}"))
                                .collect::<Vec<_>>()
                                .join(", ")
                        };
                        println!(
                            "| {} | {} | {} | {} | {:+.1e} / {:+.1e} / {:+.1e} | {} | {} | {} |",
                            r.clip,
                            r.solver,
                            r.dt,
                            r.steps,
                            r.position_excursion,
                            r.velocity_excursion,
                            r.acceleration_excursion,
                            r.empty_box_steps,
                            fallbacks,
                            if r.healthy {
                                "healthy".to_string()
                            } else {
                                format!("FAILED: {}", r.first_failure)
                            }
                        );
                    }
                    Err(e) => println!(
                        "| {clip} | {} | {dt} | – | – | – | – | ERROR: {e} |",
                        method.name()
                    ),
                }
            }
        }
    }
    Ok(())
}
