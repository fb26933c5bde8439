//! `iktc profile`: print a built-in robot profile, or write a starting one for a URDF.

use std::path::PathBuf;

use anyhow::{Context, Result};
use iktc::profile::{builtin_profile_text, init_profile_toml_with, urdf_key, InitOptions, Sole};

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
    /// Write a starting profile for a URDF or MuJoCo MJCF model: feet, soles, pelvis, torso,
    /// head and hands guessed from the shape of its tree, each guess marked `# guessed`; the
    /// flags give parts instead. A model the loader rejects gets no profile.
    Init {
        /// The URDF (.urdf) or MJCF (.xml) file.
        urdf: PathBuf,
        /// Write the profile to this file (its `urdf` key relative to the file's directory)
        /// instead of standard output.
        #[arg(long)]
        out: Option<PathBuf>,
        /// The foot links instead of the guess: LEFT,RIGHT.
        #[arg(long, value_name = "LEFT,RIGHT")]
        feet: Option<String>,
        /// The hand links (or frames fixed to them) instead of the guess: LEFT,RIGHT.
        #[arg(long, value_name = "LEFT,RIGHT")]
        hands: Option<String>,
        /// The head link instead of the guess.
        #[arg(long)]
        head: Option<String>,
        /// The torso link instead of the guess.
        #[arg(long)]
        torso: Option<String>,
        /// The pelvis link instead of the guess (the base).
        #[arg(long)]
        pelvis: Option<String>,
        /// Both feet's sole instead of the guess: LENGTH,WIDTH[,OFFSET_X] [m] in the foot frame.
        #[arg(long, value_name = "LENGTH,WIDTH[,OFFSET_X]")]
        sole: Option<String>,
    },
}

/// `LEFT,RIGHT` as two non-empty names.
fn pair(flag: &str, s: &str) -> Result<[String; 2]> {
    match s.split(',').map(str::trim).collect::<Vec<_>>()[..] {
        [l, r] if !l.is_empty() && !r.is_empty() => Ok([l.to_string(), r.to_string()]),
        _ => anyhow::bail!("--{flag} `{s}`: expected LEFT,RIGHT (two link names)"),
    }
}

/// `LENGTH,WIDTH[,OFFSET_X]` [m].
fn sole(s: &str) -> Result<Sole> {
    let bad = || format!("--sole `{s}`: expected LENGTH,WIDTH[,OFFSET_X] in metres");
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .with_context(bad)?;
    match v[..] {
        [length, width] => Ok(Sole {
            length,
            width,
            offset_x: 0.0,
        }),
        [length, width, offset_x] => Ok(Sole {
            length,
            width,
            offset_x,
        }),
        _ => Err(anyhow::anyhow!(bad())),
    }
}

/// Runs `iktc profile`.
pub fn run(a: &Args) -> Result<()> {
    match &a.command {
        ProfileCommand::Show { name } => {
            crate::out::write_out(format_args!("{}", builtin_profile_text(name)?))?;
            Ok(())
        }
        ProfileCommand::Init {
            urdf,
            out,
            feet,
            hands,
            head,
            torso,
            pelvis,
            sole: sole_text,
        } => {
            let options = InitOptions {
                feet: feet.as_deref().map(|s| pair("feet", s)).transpose()?,
                hands: hands.as_deref().map(|s| pair("hands", s)).transpose()?,
                head: head.clone(),
                torso: torso.clone(),
                pelvis: pelvis.clone(),
                sole: sole_text.as_deref().map(sole).transpose()?,
            };
            let text = std::fs::read_to_string(urdf)
                .with_context(|| format!("reading {}", urdf.display()))?;
            let toml = init_profile_toml_with(
                &text,
                &urdf_key(urdf, out.as_deref())?,
                urdf.parent(),
                &options,
            )
            .with_context(|| format!("no profile written for {}", urdf.display()))?;
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
