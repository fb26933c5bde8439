//! Experiments of Section 5.3 as library calls: a robot, a captured clip and the map between
//! them ([`Experiment`]), clips and maps loaded by name or path ([`load_clip`], [`load_map`]),
//! the one reference pipeline ([`Experiment::references`]: retarget, clamp into the
//! narrowed ranges, resample at Δt) shared by the imitation and walking runs, and the runs
//! themselves ([`Experiment::imitate`], [`Experiment::walk`]).

use std::path::Path;

use crate::error::{Error, Result};
use crate::model::Robot;
use crate::motion::{
    builtin_clip, builtin_map, load_motion, Clip, MotionFormat, MotionOptions, RetargetMap,
    RobotReferences, BUILTIN_CLIP_NAMES, BUILTIN_MAP_NAMES,
};
use crate::sim::{
    imitation_references, run_imitate, run_walk_imitate, ImitateConfig, ImitateRun,
    WalkImitateConfig, WalkRun,
};

/// The built-in clip of the default experiments.
pub const DEFAULT_CLIP: &str = "humanoid3d_dance_b";

/// Everything one imitation or walking run needs besides its settings.
#[derive(Debug, Clone)]
pub struct Experiment {
    /// The robot.
    pub robot: Robot,
    /// The captured motion, lengths in metres.
    pub clip: Clip,
    /// How the clip's joints map onto the robot's.
    pub map: RetargetMap,
}

/// A clip loaded by [`load_clip`].
#[derive(Debug, Clone)]
pub struct LoadedClip {
    /// The clip, lengths in metres, its up axis decided.
    pub clip: Clip,
    /// The file's format ([`MotionFormat::DeepMimic`] for a built-in clip).
    pub format: MotionFormat,
    /// For a file: its source, format, units and up axis as decided, in words.
    pub decided: Option<String>,
}

/// Loads a clip: a built-in name ([`BUILTIN_CLIP_NAMES`]) or a skeleton motion file (BVH,
/// ASF/AMC, DeepMimic; its format from its content and extension, its units and up axis from
/// `options` or decided).
///
/// Errors: [`Error::UnknownName`] for a name that is neither built in nor a file (with the
/// built-in names), [`Error::InvalidSetting`] for a file of marker trajectories (the
/// joint-angle imitation needs a skeleton), and whatever reading the file gives.
pub fn load_clip(spec: &str, options: &MotionOptions) -> Result<LoadedClip> {
    if BUILTIN_CLIP_NAMES.contains(&spec) {
        return Ok(LoadedClip {
            clip: builtin_clip(spec)?,
            format: MotionFormat::DeepMimic,
            decided: None,
        });
    }
    let path = Path::new(spec);
    if !path.is_file() {
        return Err(Error::UnknownName {
            kind: "motion (a built-in clip or a file)",
            name: spec.to_string(),
            valid: BUILTIN_CLIP_NAMES.iter().map(|s| s.to_string()).collect(),
        });
    }
    let motion = load_motion(path, options)?;
    let decided = format!(
        "motion {} ({}): units {}; up {}",
        motion.source,
        motion.format.name(),
        motion.units,
        motion.up
    );
    let clip = motion.clip().ok_or_else(|| Error::InvalidSetting {
        name: "motion".into(),
        value: spec.to_string(),
        expected: format!(
            "a skeleton motion; this file holds marker trajectories ({}), and the joint-angle imitation needs a skeleton",
            motion.format.name()
        ),
    })??;
    Ok(LoadedClip {
        clip,
        format: motion.format,
        decided: Some(decided),
    })
}

/// Loads a retargeting map: a built-in name ([`BUILTIN_MAP_NAMES`]) or a TOML file; checked
/// against `robot` ([`crate::profile::check_map_joints`]).
///
/// Errors: [`Error::Parse`] for a file that cannot be read or parsed (naming the built-in
/// maps when it cannot be read), [`Error::InvalidSetting`] for a joint the robot lacks.
pub fn load_map(spec: &str, robot: &Robot) -> Result<RetargetMap> {
    let map = if BUILTIN_MAP_NAMES.contains(&spec) {
        builtin_map(spec)?
    } else {
        let text = std::fs::read_to_string(spec).map_err(|e| Error::Parse {
            source_name: spec.to_string(),
            line: 0,
            message: format!(
                "neither a built-in map ({}) nor a readable TOML file: {e}",
                BUILTIN_MAP_NAMES.join(", ")
            ),
        })?;
        RetargetMap::from_toml_str(&text, spec)?
    };
    crate::profile::check_map_joints(robot, &map)?;
    Ok(map)
}

impl Experiment {
    /// The default experiment: JVRC-1, the clip [`DEFAULT_CLIP`], the built-in map
    /// `deepmimic_jvrc1`, with [`ImitateConfig::jvrc1`].
    pub fn jvrc1() -> Result<(Self, ImitateConfig)> {
        let robot = crate::model::jvrc1(&crate::model::ModelOptions::default())?;
        Ok((
            Self {
                robot,
                clip: builtin_clip(DEFAULT_CLIP)?,
                map: builtin_map("deepmimic_jvrc1")?,
            },
            ImitateConfig::jvrc1(),
        ))
    }

    /// The references of a run, the same for imitating and walking:
    /// [`imitation_references`] (retarget, clamp each joint's samples into its range narrowed
    /// by `cfg.narrow` and shrunk by `cfg.reference_margin`, resample at `cfg.dt`).
    pub fn references(&self, cfg: &ImitateConfig) -> Result<RobotReferences> {
        imitation_references(&self.robot, &self.clip, &self.map, cfg)
    }

    /// Imitates the clip standing ([`run_imitate`]).
    pub fn imitate(&self, cfg: &ImitateConfig) -> Result<ImitateRun> {
        run_imitate(&self.robot, &self.references(cfg)?, cfg)
    }

    /// Walks while imitating the clip ([`run_walk_imitate`]), the references from
    /// [`Experiment::references`] with `cfg.imitate`.
    pub fn walk(&self, cfg: &WalkImitateConfig) -> Result<WalkRun> {
        run_walk_imitate(&self.robot, &self.references(&cfg.imitate)?, cfg)
    }

    /// The walk of `cfg` with and without the damping controller (whatever `cfg.damping`
    /// says), on the same references: `(with, without)`.
    pub fn walk_with_and_without_damping(
        &self,
        cfg: &WalkImitateConfig,
    ) -> Result<(WalkRun, WalkRun)> {
        let refs = self.references(&cfg.imitate)?;
        let run = |damping| {
            run_walk_imitate(
                &self.robot,
                &refs,
                &WalkImitateConfig {
                    damping,
                    ..cfg.clone()
                },
            )
        };
        Ok((run(true)?, run(false)?))
    }
}
