//! The `iktc` command-line tool: argument parsing and output files only; every algorithm lives
//! in the `iktc` library.

mod cmd_balance;

use clap::{Parser, Subcommand};

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
    /// The ZMP damping controller of Section 4: identify, design, push.
    Balance(cmd_balance::BalanceArgs),
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Balance(args) => cmd_balance::run(args),
    }
}
