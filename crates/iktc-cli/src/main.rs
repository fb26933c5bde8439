//! The `iktc` command-line tool: argument parsing and output files only; every algorithm lives
//! in the `iktc` library.

use clap::{Parser, Subcommand};

mod cmd_model;
mod robot_arg;

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
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Model(a) => cmd_model::run(a),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
