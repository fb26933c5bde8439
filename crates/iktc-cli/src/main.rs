//! The `iktc` command-line tool: argument parsing and output files only; every algorithm lives
//! in the `iktc` library.

use clap::{Parser, Subcommand};

mod cmd_balance;
mod cmd_imitate;
mod cmd_map;
mod cmd_model;
mod cmd_reproduce;
mod cmd_run;
mod cmd_walk;
mod robot_arg;
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
    /// Print a built-in map, or find the body points of a motion file and write a body map.
    Map(cmd_map::Args),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Model(a) => cmd_model::run(&a),
        Command::Run(a) => cmd_run::run(&a),
        Command::Reproduce(a) => cmd_reproduce::run(&a),
        Command::Balance(a) => cmd_balance::run(a),
        Command::Imitate(a) => cmd_imitate::run(&a),
        Command::Map(a) => cmd_map::run(&a),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
