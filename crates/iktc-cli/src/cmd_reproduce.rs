//! `iktc reproduce`: every experiment that exists, into one offline report.

use std::path::PathBuf;

use anyhow::Result;
use iktc_report::{write_report, Report};

/// Arguments of `iktc reproduce`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Output directory; the report is DIR/index.html.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
}

/// Runs `iktc reproduce`.
pub fn run(a: &Args) -> Result<()> {
    std::fs::create_dir_all(&a.out)?;
    let mut report = Report::new("iktc — reproducing Kim & Oh, Inverse Kinematic Control of Humanoids Under Joint Constraints")
        .intro("<p>Every figure below was computed by this run of <code>iktc reproduce</code>; the numbers in the tables come from the runs' <code>summary.json</code> files. The printed equations of the paper are used with the corrections of the project's errata.</p>");
    eprintln!("running the 3R experiment (Section 3.3)…");
    report = report.section(crate::cmd_run::planar3r_section(&a.out)?);
    eprintln!("running the damping-controller experiments (Sections 4 and 5.2)…");
    report = report.section(crate::cmd_balance::balance_section(&a.out)?);
    eprintln!("running the imitation experiment (Section 5.3)…");
    report = report.section(crate::cmd_imitate::imitate_section(&a.out)?);
    eprintln!("running the walking imitation with the damping controller (Sections 4 and 5.3)…");
    report = report.section(crate::cmd_walk::walk_section(&a.out)?);
    let path = write_report(&report, &a.out)?;
    crate::outln!("report: {}", path.display())?;
    Ok(())
}
