//! The `iktc` command-line tool: argument parsing and output files only; every algorithm lives
//! in the `iktc` library.

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
enum Command {}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {}
}
