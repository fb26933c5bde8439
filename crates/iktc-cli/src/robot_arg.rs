//! Turning a `--robot NAME|profile.toml|robot.urdf|model.xml` argument and the profile flags into a robot
//! profile and its model. Every error names its source: the flag, or the profile key (and the
//! profile it is in) that produced a wrong or missing value.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use iktc::model::{builtin_robot, declared_base, BaseKind, Robot};
use iktc::profile::{
    Feet, Foot, LockRule, ProfileOrigin, RobotProfile, Sole, BUILTIN_PROFILES, MISSING,
};

use crate::pairs::{number, parse_assignments, range};

/// Robot-level options of every command that loads a robot; they override the profile.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct RobotOptions {
    /// Floating base (profile key `base`); a URDF without a profile is fixed otherwise, an MJCF
    /// model floats when it has a free joint.
    #[arg(long)]
    pub floating: bool,
    /// Lock joints at a value [rad or m]: PATTERN=VALUE, PATTERN a glob (`*` any run, `?` one
    /// character), e.g. `*_FINGER_*=0` (repeatable, or comma-separated; profile key `lock`).
    #[arg(long = "lock", value_delimiter = ',')]
    pub lock: Vec<String>,
    /// Acceleration limit of a joint [rad/s² or m/s²]: NAME=VALUE (repeatable, or
    /// comma-separated; profile key `acceleration.limits`).
    #[arg(long = "accel", value_delimiter = ',')]
    pub accel: Vec<String>,
    /// Default acceleration limit as a multiple of the velocity limit [1/s] (profile key
    /// `acceleration.per_velocity`; default 10).
    #[arg(long)]
    pub accel_per_velocity: Option<f64>,
}

/// Profile fields a standing robot needs (feet, pelvis, posture, narrowed ranges); each flag
/// overrides its profile key, and gives it for a URDF without a profile.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct ProfileFlags {
    /// Foot frames LEFT,RIGHT (profile keys `feet.left.frame`, `feet.right.frame`), in the order
    /// `iktc profile init --feet` takes them.
    #[arg(long = "feet", value_delimiter = ',')]
    pub feet: Vec<String>,
    /// Sole rectangle LENGTH,WIDTH[,OFFSET_X] in the foot frame [m] (profile keys
    /// `feet.*.sole`).
    #[arg(long)]
    pub sole: Option<String>,
    /// Height of the foot frames above the soles [m] (profile keys `feet.*.ankle_height`).
    #[arg(long)]
    pub ankle_height: Option<f64>,
    /// Pelvis frame (profile key `frames.pelvis`).
    #[arg(long)]
    pub pelvis: Option<String>,
    /// Initial joint angles [rad]: NAME=VALUE,...; `none` for the zero posture (profile key
    /// `posture`).
    #[arg(long)]
    pub posture: Option<String>,
    /// Narrowed joint ranges [rad]: NAME=lo:hi,...; `none` for none (profile key `narrow`).
    #[arg(long)]
    pub narrow: Option<String>,
}

/// A resolved `--robot`: its profile (none for the built-in planar 3R arm), the model, and
/// where each profile key came from (for the errors).
pub struct ResolvedRobot {
    /// The profile, with the flags applied.
    pub profile: Option<RobotProfile>,
    /// The model.
    pub robot: Robot,
    /// What the profile is: `built-in profile `g1``, `profile file x.toml`, `URDF x.urdf`.
    pub source: String,
    /// Profile key prefixes set by flags, with the flag.
    pub flag_keys: Vec<(String, &'static str)>,
}

fn parse_sole(s: &str) -> Result<Sole> {
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

/// The profile a `--robot` names, before flags: built-in, file, or an empty one for a URDF.
fn base_profile(spec: &str) -> Result<(RobotProfile, String)> {
    if BUILTIN_PROFILES.contains(&spec) {
        return Ok((
            RobotProfile::builtin(spec)?,
            format!("built-in profile `{spec}`"),
        ));
    }
    let path = Path::new(spec);
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if ext.as_deref() == Some("toml") {
        let p = RobotProfile::load(path).with_context(|| format!("loading profile {spec}"))?;
        return Ok((p, format!("profile file {spec}")));
    }
    let description = matches!(ext.as_deref(), Some("urdf") | Some("xml"));
    if description || (path.is_file() && ext.as_deref() != Some("toml")) {
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "robot".into());
        // An MJCF model with a free joint floats; a URDF (which does not say) is fixed.
        let base = match std::fs::read_to_string(path) {
            Ok(text) => declared_base(&text, path.parent())
                .with_context(|| format!("reading {spec}"))?
                .unwrap_or(BaseKind::Fixed),
            Err(_) => BaseKind::Fixed,
        };
        let kind = match ext.as_deref() {
            Some("xml") => "MJCF",
            _ => "URDF",
        };
        let p = RobotProfile {
            name,
            urdf: spec.to_string(),
            base,
            lock: Vec::new(),
            feet: None,
            added_frames: Vec::new(),
            frames: Default::default(),
            posture: Default::default(),
            narrow: Default::default(),
            velocity: Default::default(),
            acceleration: Default::default(),
            jerk: Default::default(),
            imitate: Default::default(),
            walk: Default::default(),
            origin: ProfileOrigin::Directory(PathBuf::new()),
        };
        return Ok((p, format!("{kind} {spec}")));
    }
    anyhow::bail!(
        "--robot `{spec}` is neither a built-in robot ({}, planar3r) nor a profile (.toml) nor a URDF (.urdf) or MJCF (.xml) file",
        BUILTIN_PROFILES.join(", ")
    )
}

/// The profile key prefixes set by flags, each with its flag.
type FlagKeys = Vec<(String, &'static str)>;

/// Applies the flags to `p`; returns the key prefixes they set.
fn apply_flags(
    p: &mut RobotProfile,
    o: &RobotOptions,
    f: Option<&ProfileFlags>,
) -> Result<FlagKeys> {
    let mut keys: FlagKeys = Vec::new();
    apply_robot_options(p, o, &mut keys)?;
    let Some(f) = f else {
        return Ok(keys);
    };
    apply_feet(p, f, &mut keys)?;
    apply_sole_and_ankle(p, f, &mut keys)?;
    if let Some(pelvis) = &f.pelvis {
        p.frames.pelvis = Some(pelvis.trim().to_string());
        keys.push(("frames.pelvis".into(), "--pelvis"));
    }
    apply_posture_and_narrow(p, f, &mut keys)?;
    Ok(keys)
}

/// Applies `--floating`, `--lock`, `--accel` and `--accel-per-velocity` to `p`.
fn apply_robot_options(p: &mut RobotProfile, o: &RobotOptions, keys: &mut FlagKeys) -> Result<()> {
    if o.floating {
        p.base = BaseKind::Floating;
        keys.push(("base".into(), "--floating"));
    }
    let first_flag_lock = p.lock.len();
    for (pattern, value) in parse_assignments("--lock", &o.lock, "a number", number)? {
        p.lock.push(LockRule {
            joints: pattern,
            value,
        });
    }
    for i in first_flag_lock..p.lock.len() {
        keys.push((format!("lock[{i}]"), "--lock"));
    }
    for (n, v) in parse_assignments("--accel", &o.accel, "a number [rad/s² or m/s²]", number)? {
        keys.push((format!("acceleration.limits.{n}"), "--accel"));
        p.acceleration.limits.insert(n, v);
    }
    if let Some(r) = o.accel_per_velocity {
        p.acceleration.per_velocity = r;
        keys.push(("acceleration.per_velocity".into(), "--accel-per-velocity"));
    }
    Ok(())
}

/// Applies `--feet` to `p`: the foot frames, and for a profile without feet the feet themselves
/// (which then need `--sole` and `--ankle-height`).
fn apply_feet(p: &mut RobotProfile, f: &ProfileFlags, keys: &mut FlagKeys) -> Result<()> {
    if f.feet.is_empty() {
        return Ok(());
    }
    let [left, right] = &f.feet[..] else {
        anyhow::bail!(
            "--feet `{}`: expected two foot frames LEFT,RIGHT (profile keys `feet.left.frame`, `feet.right.frame`)",
            f.feet.join(",")
        );
    };
    let (right, left) = (right.trim().to_string(), left.trim().to_string());
    match &mut p.feet {
        Some(feet) => {
            feet.right.frame = right;
            feet.left.frame = left;
        }
        None => {
            let sole = f.sole.as_deref().map(parse_sole).transpose()?.with_context(|| {
                "--feet is given but not the sole: pass --sole LENGTH,WIDTH[,OFFSET_X] [m] (profile keys `feet.left.sole`, `feet.right.sole`)"
            })?;
            let ankle_height = f.ankle_height.with_context(|| {
                "--feet is given but not the ankle height: pass --ankle-height H [m] (profile keys `feet.left.ankle_height`, `feet.right.ankle_height`)"
            })?;
            let foot = |frame| Foot {
                frame,
                ankle_height,
                sole,
            };
            p.feet = Some(Feet {
                left: foot(left),
                right: foot(right),
            });
        }
    }
    keys.push(("feet.right.frame".into(), "--feet"));
    keys.push(("feet.left.frame".into(), "--feet"));
    Ok(())
}

/// Applies `--sole` [m] and `--ankle-height` [m] to both feet of `p` (which must have feet).
fn apply_sole_and_ankle(p: &mut RobotProfile, f: &ProfileFlags, keys: &mut FlagKeys) -> Result<()> {
    if let Some(feet) = &mut p.feet {
        if let Some(s) = &f.sole {
            let sole = parse_sole(s)?;
            feet.left.sole = sole;
            feet.right.sole = sole;
            keys.push(("feet.left.sole".into(), "--sole"));
            keys.push(("feet.right.sole".into(), "--sole"));
        }
        if let Some(h) = f.ankle_height {
            feet.left.ankle_height = h;
            feet.right.ankle_height = h;
            keys.push(("feet.left.ankle_height".into(), "--ankle-height"));
            keys.push(("feet.right.ankle_height".into(), "--ankle-height"));
        }
    } else if f.sole.is_some() || f.ankle_height.is_some() {
        anyhow::bail!("--sole and --ankle-height need the foot frames: pass --feet LEFT,RIGHT (profile keys `feet.left.frame`, `feet.right.frame`)");
    }
    Ok(())
}

/// Applies `--posture` and `--narrow` [rad] to `p`.
fn apply_posture_and_narrow(
    p: &mut RobotProfile,
    f: &ProfileFlags,
    keys: &mut FlagKeys,
) -> Result<()> {
    if let Some(s) = &f.posture {
        p.posture = parse_assignments(
            "--posture",
            std::slice::from_ref(s),
            "a number [rad]",
            number,
        )?
        .into_iter()
        .collect();
        keys.push(("posture".into(), "--posture"));
    }
    if let Some(s) = &f.narrow {
        p.narrow = parse_assignments(
            "--narrow",
            std::slice::from_ref(s),
            "lo:hi with numbers [rad]",
            range,
        )?
        .into_iter()
        .map(|(joint, [lower, upper])| iktc::limits::NarrowedJoint {
            joint,
            lower,
            upper,
        })
        .collect();
        keys.push(("narrow".into(), "--narrow"));
    }
    Ok(())
}

/// The flag that gives each profile key a command needs, for a missing key.
const FLAG_OF_KEY: [(&str, &str); 5] = [
    (
        "feet",
        "--feet LEFT,RIGHT --sole LENGTH,WIDTH[,OFFSET_X] --ankle-height H",
    ),
    ("frames.pelvis", "--pelvis FRAME"),
    ("imitate.maps", "--map NAME|FILE"),
    ("posture", "--posture NAME=VALUE,..."),
    ("narrow", "--narrow NAME=lo:hi,..."),
];

impl ResolvedRobot {
    /// Explains a library error: for a profile key, the flag that set it (or that would set
    /// it, when it is missing) and the profile it is in.
    pub fn explain(&self, e: iktc::Error) -> anyhow::Error {
        explain(&self.source, &self.flag_keys, e)
    }
}

fn explain(source: &str, flag_keys: &[(String, &'static str)], e: iktc::Error) -> anyhow::Error {
    let iktc::Error::Profile { key, value, .. } = &e else {
        return e.into();
    };
    let under = |prefix: &str| key == prefix || key.starts_with(&format!("{prefix}."));
    if let Some((_, flag)) = flag_keys.iter().find(|(k, _)| under(k)) {
        return anyhow::anyhow!("{flag}: {e}");
    }
    if value == MISSING {
        // A URDF without a profile: `iktc profile init` guesses feet, soles, pelvis and hands.
        let init = source
            .strip_prefix("URDF ")
            .or_else(|| source.strip_prefix("MJCF "))
            .map(|u| {
                format!(
                    "; or write a profile with its keys guessed from the model: `iktc profile init {u} --out {}`",
                    Path::new(u).with_extension("toml").display()
                )
            })
            .unwrap_or_default();
        if let Some((_, flag)) = FLAG_OF_KEY.iter().find(|(k, _)| under(k)) {
            return anyhow::anyhow!("{source}: {e}; set the key or pass {flag}{init}");
        }
        if !init.is_empty() {
            return anyhow::anyhow!("{source}: {e}{init}");
        }
    }
    anyhow::anyhow!("{source}: {e}")
}

/// Resolves `--robot` (a built-in profile name, `planar3r`, a profile file or a URDF file)
/// with the robot options and, for commands that use them, the profile flags.
pub fn resolve_robot(
    spec: &str,
    o: &RobotOptions,
    flags: Option<&ProfileFlags>,
) -> Result<ResolvedRobot> {
    if spec == "planar3r" {
        if !o.lock.is_empty() || !o.accel.is_empty() || o.floating || o.accel_per_velocity.is_some()
        {
            anyhow::bail!("--floating, --lock and --accel apply to robots with a URDF, not to the built-in `planar3r`");
        }
        return Ok(ResolvedRobot {
            profile: None,
            robot: builtin_robot(spec)?,
            source: "built-in robot `planar3r`".into(),
            flag_keys: Vec::new(),
        });
    }
    let (mut profile, source) = base_profile(spec)?;
    let flag_keys = apply_flags(&mut profile, o, flags)?;
    profile
        .check_values()
        .map_err(|e| explain(&source, &flag_keys, e))?;
    let robot = profile
        .robot()
        .map_err(|e| explain(&source, &flag_keys, e))?;
    for w in robot.warnings() {
        eprintln!("warning: {w}");
    }
    Ok(ResolvedRobot {
        profile: Some(profile),
        robot,
        source,
        flag_keys,
    })
}

/// Loads a robot (see [`resolve_robot`]) without the profile flags.
pub fn load_robot(spec: &str, o: &RobotOptions) -> Result<Robot> {
    Ok(resolve_robot(spec, o, None)?.robot)
}
