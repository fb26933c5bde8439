//! `iktc map`: print a built-in map; find the body points of a motion file and write them as an
//! editable body map. Also the motion-file options shared with `iktc imitate`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use iktc::motion::{
    builtin_body_map, builtin_map_text, draft_body_map_toml, load_motion, marker_points,
    skeleton_points, BodyMap, Motion, MotionContent, MotionOptions, BUILTIN_BODY_MAP_NAMES,
    BUILTIN_MAP_NAMES,
};

/// How a motion file is read: units, up axis, skeleton.
#[derive(clap::Args, Debug, Clone)]
pub struct MotionArgs {
    /// Length unit of the motion file: m, cm, mm, inch, cmu (1/0.45 inch) or auto (decided
    /// from the subject's standing height, 1.2–2.1 m).
    #[arg(long, default_value = "auto")]
    pub units: String,
    /// Up axis of the motion file: y, z or auto (decided from the rest pose, ankles to head).
    #[arg(long, default_value = "auto")]
    pub up: String,
    /// ASF skeleton of an AMC motion (default: the .asf beside it with the same stem, else the
    /// only .asf in its folder).
    #[arg(long)]
    pub skeleton: Option<PathBuf>,
    /// Longest clip accepted from a file [s].
    #[arg(long, default_value_t = iktc::resources::ReadLimits::default().max_clip_duration)]
    pub max_clip_duration: f64,
    /// Body model of AMASS archives (.npz): the SMPL-H or SMPL-X model file of the subject's
    /// gender, as its authors distribute it (iktc ships none). With it, folders are also
    /// searched for AMASS archives.
    #[arg(long, value_name = "PATH")]
    pub body_model: Option<PathBuf>,
}

impl MotionArgs {
    /// The library's options these arguments give (no body map).
    pub fn options(&self) -> Result<MotionOptions> {
        Ok(MotionOptions {
            units: self.units.parse()?,
            up: self.up.parse()?,
            skeleton: self.skeleton.clone(),
            limits: iktc::resources::ReadLimits {
                max_clip_duration: self.max_clip_duration,
                ..iktc::resources::ReadLimits::default()
            },
            body_model: self.body_model.clone(),
            ..MotionOptions::default()
        })
    }
}

/// Reads a motion file with these options (and a body map, if given) and prints what was
/// decided.
pub fn load(path: &Path, args: &MotionArgs, body_map: Option<BodyMap>) -> Result<Motion> {
    let options = MotionOptions {
        body_map,
        ..args.options()?
    };
    let m = load_motion(path, &options)
        .with_context(|| format!("reading the motion `{}`", path.display()))?;
    crate::outln!(
        "motion {} ({}): units {}; up {}",
        m.source,
        m.format.name(),
        m.units,
        m.up
    )?;
    Ok(m)
}

/// Arguments of `iktc map`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(subcommand)]
    pub command: MapCommand,
}

/// The `iktc map` subcommands.
#[derive(clap::Subcommand, Debug)]
pub enum MapCommand {
    /// Print a built-in map: a retargeting map (deepmimic_jvrc1, bvh_jvrc1) or a body map
    /// (plug_in_gait, deepmimic).
    Show {
        /// The map's name.
        name: String,
    },
    /// Find the body points of a motion file (or check a body map against it), print them
    /// and write them as an editable body map; when some required points are not found, the
    /// map holds those found and a commented entry for each missing one, to fill in.
    Init {
        /// The motion file (.bvh, .amc, .asf, DeepMimic, .c3d, .csv, AMASS .npz with
        /// --body-model).
        #[arg(long)]
        motion: PathBuf,
        #[command(flatten)]
        options: MotionArgs,
        /// A body map to check instead of recognising the body points.
        #[arg(long)]
        map: Option<PathBuf>,
        /// Where to write the map. Default: `<motion stem>.map.toml` in the current folder.
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// Runs `iktc map`.
pub fn run(a: &Args) -> Result<()> {
    match &a.command {
        MapCommand::Show { name } => show(name),
        MapCommand::Init {
            motion,
            options,
            map,
            out,
        } => init(motion, options, map.as_deref(), out.as_deref()),
    }
}

/// Prints the built-in retargeting or body map `name`.
fn show(name: &str) -> Result<()> {
    if BUILTIN_MAP_NAMES.contains(&name) {
        crate::out::write_out(format_args!("{}", builtin_map_text(name)?))?;
    } else if BUILTIN_BODY_MAP_NAMES.contains(&name) {
        crate::out::write_out(format_args!("{}", builtin_body_map(name)?.to_toml_string()))?;
    } else {
        anyhow::bail!(
            "no built-in map `{name}`; retargeting maps: {}; body maps: {}",
            BUILTIN_MAP_NAMES.join(", "),
            BUILTIN_BODY_MAP_NAMES.join(", ")
        );
    }
    Ok(())
}

/// The motion file's stem, or "motion".
fn motion_stem(motion: &Path) -> String {
    motion
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "motion".to_string())
}

/// Finds the body points of `motion` (with the body map `map`, if given) and prints and writes
/// the body map to `out` (default `<motion stem>.map.toml`).
fn init(motion: &Path, options: &MotionArgs, map: Option<&Path>, out: Option<&Path>) -> Result<()> {
    let given = match map {
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .with_context(|| format!("reading the body map `{}`", p.display()))?;
            Some(BodyMap::from_toml_str(&text, &p.display().to_string())?)
        }
        None => None,
    };
    let out = out
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from(format!("{}.map.toml", motion_stem(motion))));
    let name = motion_stem(motion);
    let m = match load(motion, options, given.clone()) {
        Ok(m) => m,
        // Without a body map the up axis cannot be decided: read the file with one
        // assumed, only for its names, and write what was found.
        Err(first) if given.is_none() => {
            let assumed = MotionArgs {
                up: "z".into(),
                units: "m".into(),
                ..options.clone()
            };
            load(motion, &assumed, None).map_err(|_| first)?
        }
        Err(e) => return Err(e),
    };
    let text = body_map_text(&m, &name)?;
    crate::out::write_out(format_args!("{text}"))?;
    std::fs::write(&out, &text).with_context(|| format!("writing `{}`", out.display()))?;
    crate::outln!("wrote {}", out.display())?;
    if m.body_map.is_ok() {
        let keypoints = m.keypoints(iktc::motion::DEFAULT_MAX_GAP)?;
        crate::outln!("{}", keypoints.summary())?;
    }
    Ok(())
}

/// The body map of `m` named `name` as TOML; when not every required body point was
/// recognised, a draft with what was found and a commented entry for each point to fill in.
fn body_map_text(m: &Motion, name: &str) -> Result<String> {
    Ok(match &m.body_map {
        Ok(body_map) => {
            let mut body_map = body_map.clone();
            body_map.name = name.to_string();
            body_map.to_toml_string()
        }
        Err(e) => {
            let (found, what, available) = match &m.content {
                MotionContent::Markers(set) => {
                    (marker_points(&set.names), "markers", set.names.clone())
                }
                MotionContent::Skeleton(clip) => (
                    skeleton_points(clip.skeleton()),
                    "joints",
                    clip.skeleton()
                        .joints()
                        .iter()
                        .map(|j| j.name.clone())
                        .collect(),
                ),
            };
            crate::outln!(
                "not every required body point was recognised ({e}); the map holds what was found and a commented entry for each point to fill in"
            )?;
            draft_body_map_toml(name, &found, what, &available)
        }
    })
}
