//! `iktc balance`: the damping-controller scenarios of Section 4 (identify, design, push).
//! Argument parsing and output files only; the scenarios live in `iktc::balance::scenario`.

use std::path::PathBuf;

use clap::{Args, Subcommand, ValueEnum};
use iktc::balance::SupportPhase;

mod section;
mod write;

pub use section::balance_section;
use write::{design, identify, push};

/// Arguments of `iktc balance`.
#[derive(Args)]
pub struct BalanceArgs {
    #[command(subcommand)]
    command: BalanceCommand,
}

#[derive(Subcommand)]
enum BalanceCommand {
    /// Sine sweep on the simulated plant, Bode plot with the fitted model (Fig. 12).
    Identify {
        /// Output directory.
        #[arg(long, default_value = "out/balance")]
        out: PathBuf,
        /// Seed of the sensor noise.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Pole placement: gain, closed-loop poles, root locus (Fig. 13).
    Design {
        /// Output directory.
        #[arg(long, default_value = "out/balance")]
        out: PathBuf,
    },
    /// ZMP after a push on the COM with and without the controller (Figs. 16–17).
    Push {
        /// Support phase.
        #[arg(long, value_enum, default_value_t = Phase::Dsp)]
        phase: Phase,
        /// Output directory.
        #[arg(long, default_value = "out/balance")]
        out: PathBuf,
        /// Seed of the sensor noise.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Phase {
    /// Single support.
    Ssp,
    /// Double support.
    Dsp,
}

impl Phase {
    fn support(self) -> SupportPhase {
        match self {
            Phase::Ssp => SupportPhase::Single,
            Phase::Dsp => SupportPhase::Double,
        }
    }
    fn name(self) -> &'static str {
        match self {
            Phase::Ssp => "ssp",
            Phase::Dsp => "dsp",
        }
    }
}

/// Runs `iktc balance …`.
pub fn run(args: BalanceArgs) -> anyhow::Result<()> {
    match args.command {
        BalanceCommand::Identify { out, seed } => {
            let r = identify(&out, seed)?;
            for c in &r.comparison {
                crate::outln!(
                    "{:<32} true {:>10.5}  identified {:>10.5} ± {:.5} {}  ({:+.2} %)",
                    c.name,
                    c.true_value,
                    c.identified,
                    c.std_error,
                    c.unit,
                    100.0 * c.relative_error
                )?;
            }
            crate::outln!(
                "RMS fit error: {:.2} dB, {:.2} deg -> {}",
                r.identification.rms_magnitude_error_db,
                r.identification.rms_phase_error_deg,
                out.join("identify").display()
            )?;
        }
        BalanceCommand::Design { out } => {
            let r = design(&out)?;
            crate::outln!(
                "K_f = [{:.6}, {:.6}], N = {:.6}; closed-loop IPCJ poles {:.5} ± {:.5}j -> {}",
                r.continuous.gain[0],
                r.continuous.gain[1],
                r.continuous.feedforward,
                r.continuous.closed_loop_poles[0][0],
                r.continuous.closed_loop_poles[0][1],
                out.join("design").display()
            )?;
        }
        BalanceCommand::Push { phase, out, seed } => {
            let r = push(&out, phase, seed)?;
            for m in &r.metrics {
                crate::outln!(
                    "{:?}: peak {:.1} -> {:.1} mm, settling {} -> {} s, ζ {:.3} -> {:.3} (designed {:.2}), static gain {:.4} / {:.4} m/rad",
                    m.plane,
                    1e3 * m.open.peak,
                    1e3 * m.closed.peak,
                    fmt_opt(m.open.settling_time),
                    fmt_opt(m.closed.settling_time),
                    m.open.damping_ratio,
                    m.closed.damping_ratio,
                    m.designed_damping_ratio,
                    m.static_gain_open,
                    m.static_gain_closed
                )?;
            }
            crate::outln!(
                "ZMP outside the support polygon by at most {:.4} m without the controller, {:.4} m with it; {}",
                r.zmp_excursion_open,
                r.zmp_excursion_closed,
                crate::scenario::health_text(&r.health)
            )?;
            crate::outln!(
                "-> {}",
                out.join(format!("push-{}", phase.name())).display()
            )?;
        }
    }
    Ok(())
}

/// A time [s] to two decimals, or "—" for none.
fn fmt_opt(v: Option<f64>) -> String {
    v.map_or("—".into(), |x| format!("{x:.2}"))
}
