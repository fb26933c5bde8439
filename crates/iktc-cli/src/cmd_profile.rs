//! `iktc profile`: print a built-in robot profile, or write a starting one for a URDF.

use std::path::PathBuf;

use anyhow::{Context, Result};
use iktc::profile::{builtin_profile_text, init_profile_toml_at, urdf_key};

/// Arguments of `iktc profile`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(subcommand)]
    pub command: ProfileCommand,
}

/// What `iktc profile` does.
#[derive(clap::Subcommand, Debug)]
pub enum ProfileCommand {
    /// Print a built-in profile (jvrc1, g1) as TOML.
    Show {
        /// The built-in profile's name.
        name: String,
    },
    /// Write a starting profile for a URDF: feet, pelvis, torso, head and hands guessed from
    /// its tree, each guess marked `# guessed`.
    Init {
        /// The URDF file.
        urdf: PathBuf,
        /// Write the profile to this file (its `urdf` key relative to the file's directory)
        /// instead of standard output.
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// Runs `iktc profile`.
pub fn run(a: &Args) -> Result<()> {
    match &a.command {
        ProfileCommand::Show { name } => {
            crate::out::write_out(format_args!("{}", builtin_profile_text(name)?))?;
            Ok(())
        }
        ProfileCommand::Init { urdf, out } => {
            let text = std::fs::read_to_string(urdf)
                .with_context(|| format!("reading {}", urdf.display()))?;
            let toml =
                init_profile_toml_at(&text, &urdf_key(urdf, out.as_deref())?, urdf.parent())?;
            match out {
                Some(path) => {
                    std::fs::write(path, toml)
                        .with_context(|| format!("writing {}", path.display()))?;
                    crate::outln!("wrote {}", path.display())?;
                }
                None => crate::out::write_out(format_args!("{toml}"))?,
            }
            Ok(())
        }
    }
}
