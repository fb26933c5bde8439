//! One clip of a batch, end to end in memory: read the motion file, retarget it onto the
//! robot, run the imitation, resample it for training and measure its quality
//! ([`BatchRetarget::retarget`]); and the fingerprint of the settings a re-run compares
//! ([`BatchRetarget::settings_hash`]).

use std::path::Path;

use super::quality::{run_penetration, ClipQuality};
use super::training::TrainingTrajectory;
use crate::error::{Error, Result};
use crate::model::Robot;
use crate::motion::{MotionFormat, MotionOptions, RetargetMap};
use crate::profile::RobotProfile;
use crate::sim::{load_clip, Experiment, ImitateConfig, ImitateRun};

/// How a clip becomes robot references.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RetargetMethod {
    /// Joint angles through a [`RetargetMap`] ([`Experiment::references`]), as `iktc imitate`.
    Joints,
}

/// The method a batch uses unless told otherwise: the one place to switch the default.
pub const DEFAULT_RETARGET_METHOD: RetargetMethod = RetargetMethod::Joints;

/// The fewest frames a clip needs: resampling it at the control period interpolates between
/// samples, so one frame (no interval) is too short.
pub const MIN_CLIP_FRAMES: usize = 2;

/// Everything a batch shares across its clips.
#[derive(Debug, Clone)]
pub struct BatchRetarget {
    /// The robot.
    pub robot: Robot,
    /// Its profile (feet, pelvis, body frames, maps per motion format).
    pub profile: RobotProfile,
    /// A map for every clip; `None`: the profile's map for each clip's format.
    pub map: Option<RetargetMap>,
    /// The imitation settings (from the profile, with the command's options).
    pub config: ImitateConfig,
    /// How motion files are read.
    pub motion_options: MotionOptions,
    /// Output rate \[Hz\]; `None`: the control rate `1 / config.dt`.
    pub rate: Option<f64>,
    /// How clips are retargeted.
    pub method: RetargetMethod,
}

/// One retargeted clip.
#[derive(Debug, Clone)]
pub struct ClipOutcome {
    /// The robot, clip and map of the run.
    pub experiment: Experiment,
    /// The recorded run.
    pub run: ImitateRun,
    /// The training trajectory at the output rate.
    pub trajectory: TrainingTrajectory,
    /// Its quality figures.
    pub quality: ClipQuality,
}

impl BatchRetarget {
    /// A batch of `profile`'s robot ([`RobotProfile::robot`]) with the imitation settings
    /// [`RobotProfile::imitate_config`] makes of `base`, the profile's map for each clip's
    /// format, default motion options and the control rate as output rate.
    ///
    /// Errors: those of building the robot and the settings.
    pub fn from_profile(profile: RobotProfile, base: ImitateConfig) -> Result<Self> {
        Ok(Self {
            robot: profile.robot()?,
            config: profile.imitate_config(base)?,
            profile,
            map: None,
            motion_options: MotionOptions::default(),
            rate: None,
            method: DEFAULT_RETARGET_METHOD,
        })
    }

    /// The output rate \[Hz\].
    pub fn output_rate(&self) -> f64 {
        self.rate.unwrap_or(1.0 / self.config.dt)
    }

    /// The body frames whose world positions are written: the profile's named frames (pelvis,
    /// torso, head, hands) that are set, then the feet of the imitation.
    pub fn body_frames(&self) -> Vec<String> {
        let f = &self.profile.frames;
        let mut v: Vec<String> = [&f.pelvis, &f.torso, &f.head, &f.left_hand, &f.right_hand]
            .into_iter()
            .flatten()
            .cloned()
            .collect();
        for foot in &self.config.feet {
            if !v.contains(foot) {
                v.push(foot.clone());
            }
        }
        v
    }

    /// A text that changes whenever an output could: the crate version, the method, the
    /// profile, the map, the imitation settings, the motion options and the output rate.
    pub fn settings_text(&self) -> String {
        format!(
            "iktc {}\nmethod {:?}\nprofile {:?}\nmap {:?}\nconfig {:?}\nmotion {:?}\nrate {}\nbodies {:?}\n",
            env!("CARGO_PKG_VERSION"),
            self.method,
            self.profile,
            self.map,
            self.config,
            self.motion_options,
            self.output_rate(),
            self.body_frames()
        )
    }

    /// FNV-1a (64 bit) of [`Self::settings_text`], as 16 hex digits.
    pub fn settings_hash(&self) -> String {
        let h = self
            .settings_text()
            .bytes()
            .fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
                (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
            });
        format!("{h:016x}")
    }

    /// Retargets the motion file `path`: [`load_clip`], the map ([`Self::map`] or the
    /// profile's for the file's format), [`Experiment::imitate`] with [`Self::config`],
    /// [`TrainingTrajectory::from_run`] at [`Self::output_rate`] and [`ClipQuality`].
    ///
    /// Errors: [`Error::InsufficientData`] for a clip of fewer than [`MIN_CLIP_FRAMES`]
    /// frames; whatever reading, mapping, the run or the resampling give.
    pub fn retarget(&self, path: &Path) -> Result<ClipOutcome> {
        let spec = path.to_string_lossy();
        let loaded = load_clip(&spec, &self.motion_options)?;
        let frames = loaded.clip.frame_count();
        if frames < MIN_CLIP_FRAMES {
            return Err(Error::InsufficientData {
                what: format!("resampling clip `{spec}`"),
                message: format!(
                    "it has {frames} frame(s); at least {MIN_CLIP_FRAMES} are needed (an interval to interpolate over)"
                ),
            });
        }
        let map = match &self.map {
            Some(m) => m.clone(),
            None => {
                let format = if loaded.format == MotionFormat::DeepMimic {
                    "deepmimic"
                } else {
                    "bvh"
                };
                self.profile.retarget_map(format, &self.robot)?
            }
        };
        let experiment = Experiment {
            robot: self.robot.clone(),
            clip: loaded.clip,
            map,
        };
        let run = match self.method {
            RetargetMethod::Joints => experiment.imitate(&self.config)?,
        };
        let trajectory = TrainingTrajectory::from_run(
            &self.robot,
            &run,
            &self.body_frames(),
            self.output_rate(),
        )?;
        let mut quality = ClipQuality::from_summary(&run.summary);
        if let Some(feet) = &self.profile.feet {
            let p = run_penetration(&self.robot, &run, &[&feet.left, &feet.right])?;
            quality = quality.with_penetration(p);
        }
        Ok(ClipOutcome {
            experiment,
            run,
            trajectory,
            quality,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::batch::TrainingTrajectory;

    fn batch() -> BatchRetarget {
        let profile = RobotProfile::builtin("jvrc1").unwrap();
        BatchRetarget::from_profile(profile, ImitateConfig::default()).unwrap()
    }

    #[test]
    fn settings_hash_follows_every_setting() {
        let b = batch();
        let h = b.settings_hash();
        assert_eq!(h.len(), 16);
        assert_eq!(h, batch().settings_hash());
        let mut r = batch();
        r.rate = Some(50.0);
        assert_ne!(r.settings_hash(), h);
        let mut c = batch();
        c.config.dt = 0.01;
        assert_ne!(c.settings_hash(), h);
    }

    #[test]
    fn bad_rates_and_unknown_bodies_are_errors() {
        let b = batch();
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("data/motions/deepmimic/humanoid3d_walk.txt");
        let o = b.retarget(&path).unwrap();
        let bodies = b.body_frames();
        assert_eq!(o.trajectory.len(), o.run.steps.len());
        for rate in [0.0, -5.0, f64::NAN, f64::INFINITY] {
            let e = TrainingTrajectory::from_run(&b.robot, &o.run, &bodies, rate).unwrap_err();
            assert!(e.to_string().contains("output rate"), "{rate}: {e}");
        }
        let e = TrainingTrajectory::from_run(&b.robot, &o.run, &["no_such_frame".into()], 100.0)
            .unwrap_err();
        assert!(e.to_string().contains("no_such_frame"), "{e}");
        let mut empty = o.run.clone();
        empty.steps.clear();
        let e = TrainingTrajectory::from_run(&b.robot, &empty, &bodies, 100.0).unwrap_err();
        assert!(matches!(e, Error::InsufficientData { .. }), "{e}");
    }
}
