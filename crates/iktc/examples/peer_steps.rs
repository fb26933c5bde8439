//! Runs the peer problem (`benches/peer/problem.rs`) for a repeatable instruction
//! count: the 50 warm-up steps, then the 2 000 timed steps inside [`timed`], which a profiler
//! can select, e.g.
//!
//! `valgrind --tool=callgrind --toggle-collect='*timed*' target/release/examples/peer_steps iktc`
//!
//! and divide the instructions collected by 2 000. The argument picks the method: `iktc`
//! (default), `iktc_cold` (no warm start) or `gf`.

#[path = "../benches/peer/problem.rs"]
mod peer;

use iktc::solver::{Method, SolverSettings};
use peer::{PeerProblem, TIMED, WARMUP};

/// The timed steps; a separate function so that a profiler can collect it alone.
#[inline(never)]
fn timed(p: &mut PeerProblem) -> iktc::Result<usize> {
    let mut qps = 0;
    for _ in 0..TIMED {
        qps += std::hint::black_box(p.step()?.qp_solves);
    }
    Ok(qps)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let which = std::env::args().nth(1).unwrap_or_else(|| "iktc".into());
    let (method, settings) = match which.as_str() {
        "iktc" => (Method::Iktc, SolverSettings::default()),
        "iktc_cold" => (
            Method::Iktc,
            SolverSettings {
                warm_start: false,
                ..SolverSettings::default()
            },
        ),
        "gf" => (Method::Cascade, SolverSettings::default()),
        other => return Err(format!("unknown method `{other}` (iktc, iktc_cold, gf)").into()),
    };
    let mut p = PeerProblem::new(method, settings)?;
    for _ in 0..WARMUP {
        p.step()?;
    }
    let qps = timed(&mut p)?;
    println!(
        "{which}: {TIMED} timed steps, {qps} QPs, final q̈ norm {:.6e}",
        p.qdd().norm()
    );
    Ok(())
}
