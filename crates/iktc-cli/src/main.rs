//! The `iktc` command-line tool: argument parsing and output files only; every algorithm lives
//! in the `iktc` library.

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

mod cmd_balance;
mod cmd_evaluate;
mod cmd_imitate;
mod cmd_keypoints;
mod cmd_map;
mod cmd_model;
mod cmd_profile;
mod cmd_reproduce;
mod cmd_retarget;
mod cmd_run;
mod cmd_walk;
mod columns;
mod finite;
mod out;
mod pairs;
mod retarget_report;
mod robot_arg;
mod scenario;
mod viewer;

#[derive(Parser)]
#[command(
    name = "iktc",
    version,
    about = "Inverse kinematic control of humanoids under joint constraints"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Describe a robot model; with --config, its kinematics at a configuration.
    Model(cmd_model::Args),
    /// Run a scenario (the 3R arm of Section 3.3) and write its trajectory, summary and figures.
    Run(cmd_run::Args),
    /// Run every experiment and write one offline report, DIR/index.html.
    Reproduce(cmd_reproduce::Args),
    /// The ZMP damping controller of Section 4: identify, design, push.
    Balance(cmd_balance::BalanceArgs),
    /// Imitate a captured motion with a humanoid (Section 5.3): figures, summary, 3D viewer.
    Imitate(Box<cmd_imitate::Args>),
    /// Walk while imitating a captured motion, with the ZMP damping controller in the loop
    /// (Sections 4 and 5.3): ZMP, footsteps, phases, summary, 3D viewer.
    Walk(Box<cmd_walk::Args>),
    /// Robot profiles: print a built-in one, or write a starting one for a URDF.
    Profile(cmd_profile::Args),
    /// Print a built-in map, or find the body points of a motion file and write a body map.
    Map(cmd_map::Args),
    /// Retarget whole datasets on every core: per clip CSV, NPZ, quality summary and viewer,
    /// and one dataset report, OUT/index.html.
    Retarget(Box<cmd_retarget::Args>),
    /// Score any robot trajectory (iktc's motion.csv/.npz, or a CSV of time, base pose and
    /// joints) against the captured motion with iktc's neutral fidelity figures.
    Evaluate(Box<cmd_evaluate::Args>),
}

/// The command line's grammar, with every option value allowed to be a negative number
/// (`--dt -0.005` reaches the range check instead of reading as an unknown option `-0`).
fn command() -> clap::Command {
    fn negatives(cmd: clap::Command) -> clap::Command {
        cmd.mut_args(|a| {
            if a.get_action().takes_values() {
                a.allow_negative_numbers(true)
            } else {
                a
            }
        })
        .mut_subcommands(negatives)
    }
    // `iktc retarget` takes its motions as arguments: the shared --motion is hidden there.
    negatives(Cli::command()).mut_subcommand("retarget", |c| c.mut_arg("motion", |a| a.hide(true)))
}

fn main() -> std::process::ExitCode {
    let cli = match Cli::from_arg_matches(&command().get_matches()) {
        Ok(cli) => cli,
        Err(e) => e.exit(),
    };
    let result = match cli.command {
        Command::Model(a) => cmd_model::run(&a),
        Command::Run(a) => cmd_run::run(&a),
        Command::Reproduce(a) => cmd_reproduce::run(&a),
        Command::Balance(a) => cmd_balance::run(a),
        Command::Imitate(a) => cmd_imitate::run(&a),
        Command::Walk(a) => cmd_walk::run(&a),
        Command::Profile(a) => cmd_profile::run(&a),
        Command::Map(a) => cmd_map::run(&a),
        Command::Retarget(a) => cmd_retarget::run(&a),
        Command::Evaluate(a) => cmd_evaluate::run(&a),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        // The reader of our standard output has gone (`| head`): nothing more to say.
        Err(e) if out::is_broken_pipe(&e) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
