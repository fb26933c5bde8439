//! One clip of a batch, end to end in memory: read the motion file, retarget it onto the
//! robot, resample the run for training and measure its quality
//! ([`BatchRetarget::retarget`]); and the fingerprint of the settings a re-run compares
//! ([`BatchRetarget::settings_hash`]).
//!
//! Two routes ([`RetargetMethod`]): keypoint retargeting (the default, as `iktc imitate`),
//! where the clip's body points are scaled to the robot and tracked
//! ([`retarget_keypoints`](crate::retarget::retarget_keypoints)) with the joint route's angles, where the profile has a map for
//! the clip's format, as the posture level's references; and the paper's joint-angle route
//! ([`Experiment::imitate`]).

use std::path::Path;

use super::quality::{
    run_penetration, trajectory_penetration, ClipQuality, JointFigures, KeypointFigures,
    Penetration,
};
use super::training::TrainingTrajectory;
use crate::error::{Error, Result};
use crate::model::Robot;
use crate::motion::{
    load_motion, Clip, Keypoints, MotionFormat, MotionOptions, RetargetMap, RobotReferences,
    DEFAULT_MAX_GAP,
};
use crate::profile::RobotProfile;
use crate::retarget::{retarget_keypoints_on, KeypointRun, KeypointSettings};
use crate::sim::{imitation_references, load_clip, Experiment, ImitateConfig, ImitateRun};

/// How a clip becomes robot references.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RetargetMethod {
    /// Body keypoints scaled to the robot and tracked by the keypoint stack
    /// ([`retarget_keypoints`](crate::retarget::retarget_keypoints)), as `iktc imitate` does by default.
    Keypoints,
    /// Joint angles through a [`RetargetMap`] ([`Experiment::references`]), as
    /// `iktc imitate --retarget joints`.
    Joints,
}

/// The method a batch uses unless told otherwise: the one place to switch the default.
pub const DEFAULT_RETARGET_METHOD: RetargetMethod = RetargetMethod::Keypoints;

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
    /// The imitation settings (from the profile, with the command's options); the joint
    /// route runs them, and the keypoint route takes its period from them.
    pub config: ImitateConfig,
    /// The keypoint route's settings.
    pub keypoints: KeypointSettings,
    /// How motion files are read.
    pub motion_options: MotionOptions,
    /// Output rate \[Hz\]; `None`: the control rate `1 / config.dt`.
    pub rate: Option<f64>,
    /// How clips are retargeted.
    pub method: RetargetMethod,
}

/// The run of one clip, by route.
#[derive(Debug, Clone)]
pub enum ClipRun {
    /// A keypoint retargeting: the clip's body points and the run.
    Keypoints {
        /// The clip's body points (metres, Z up; boxed, as the run).
        keypoints: Box<Keypoints>,
        /// The recorded run (boxed: the variants stay of similar size).
        run: Box<KeypointRun>,
        /// Where the posture level's references came from ([`Posture::describe`]).
        posture: String,
    },
    /// A joint-route imitation.
    Joints {
        /// The robot, clip and map of the run (boxed: the variants stay of similar size).
        experiment: Box<Experiment>,
        /// The recorded run (boxed, as above).
        run: Box<ImitateRun>,
    },
}

/// One retargeted clip.
#[derive(Debug, Clone)]
pub struct ClipOutcome {
    /// The run.
    pub run: ClipRun,
    /// The training trajectory at the output rate.
    pub trajectory: TrainingTrajectory,
    /// Its quality figures.
    pub quality: ClipQuality,
}

impl ClipOutcome {
    /// The run's own summary as JSON (the `summary` of `quality.json`): the keypoint route's
    /// [`crate::retarget::RetargetQuality`] with its scaling, GF ticks and the levels IKTC
    /// sacrificed ([`crate::retarget::Sacrifices`]), or the imitation's
    /// [`crate::sim::ImitateSummary`].
    ///
    /// Errors: [`Error::InvalidSetting`] if a figure cannot be written as JSON.
    pub fn summary(&self) -> Result<serde_json::Value> {
        let v = match &self.run {
            ClipRun::Keypoints {
                keypoints,
                run,
                posture,
            } => serde_json::json!({
                "source": keypoints.source,
                "posture": posture,
                "leg_ratio": run.scaling.leg,
                "gf_ticks": run.fallback_ticks,
                "stance_gf_ticks": run.stance_gf_ticks,
                "sacrificed": run.sacrificed,
                "settle_sacrificed": run.settle_sacrificed,
                "keypoints": run.quality,
            }),
            ClipRun::Joints { run, .. } => {
                serde_json::to_value(&run.summary).map_err(|e| Error::InvalidSetting {
                    name: "summary".into(),
                    value: e.to_string(),
                    expected: "figures that JSON can hold".into(),
                })?
            }
        };
        Ok(v)
    }
}

/// The posture level's references of a keypoint run.
#[derive(Debug, Clone)]
pub enum Posture {
    /// The joint route's references of the clip (its angles decomposed through a map; boxed:
    /// the variants stay of similar size).
    JointRoute(Box<RobotReferences>),
    /// None: the posture level holds the start posture, for the reason given.
    Start(String),
}

impl Posture {
    /// The references to pass to [`crate::retarget::retarget_keypoints`].
    pub fn references(&self) -> Option<&RobotReferences> {
        match self {
            Self::JointRoute(r) => Some(r),
            Self::Start(_) => None,
        }
    }

    /// One line saying where the posture references came from.
    pub fn describe(&self) -> String {
        match self {
            Self::JointRoute(_) => "the joint route's angles".into(),
            Self::Start(why) => format!("the start posture ({why})"),
        }
    }
}

/// The keypoint route's posture references for a skeleton `clip` in `format` on `profile`'s
/// robot `robot`: the joint route's references ([`imitation_references`] with `cfg`, the
/// narrowed ranges left out, low-passed at the keypoint route's `smoothing` \[Hz\] instead of
/// `cfg`'s) through `map`, else the profile's map for the format. The posture
/// is a regulariser below every keypoint task, so a profile map that does not fit the clip
/// (a built-in BVH map naming joints another rig lacks) leaves the start posture, with the
/// reason; a `map` the caller gave that does not fit is an error.
///
/// Errors: those of `map` (given) on the robot or the clip.
pub fn posture_references(
    robot: &Robot,
    profile: &RobotProfile,
    clip: &Clip,
    format: MotionFormat,
    map: Option<&RetargetMap>,
    cfg: &ImitateConfig,
    smoothing: Option<f64>,
) -> Result<Posture> {
    let cfg = ImitateConfig {
        narrow: Vec::new(),
        smoothing,
        ..cfg.clone()
    };
    let map = match map {
        Some(m) => {
            return imitation_references(robot, clip, m, &cfg)
                .map(|r| Posture::JointRoute(r.into()))
        }
        None => {
            let key = if format == MotionFormat::DeepMimic {
                "deepmimic"
            } else {
                "bvh"
            };
            match profile.retarget_map(key, robot) {
                Ok(m) => m,
                Err(e) => return Ok(Posture::Start(format!("no joint route: {e}"))),
            }
        }
    };
    Ok(match imitation_references(robot, clip, &map, &cfg) {
        Ok(r) => Posture::JointRoute(r.into()),
        Err(e) => Posture::Start(format!("the profile's map does not fit the clip: {e}")),
    })
}

/// The body frames whose world positions a retargeted clip's outputs carry: `profile`'s named
/// frames (pelvis, torso, head, hands) that are set, then the feet of the imitation `config`
/// (from [`RobotProfile::imitate_config`]) not already listed.
pub fn body_frames(profile: &RobotProfile, config: &ImitateConfig) -> Vec<String> {
    let f = &profile.frames;
    let mut v: Vec<String> = [&f.pelvis, &f.torso, &f.head, &f.left_hand, &f.right_hand]
        .into_iter()
        .flatten()
        .cloned()
        .collect();
    for foot in &config.feet {
        if !v.contains(foot) {
            v.push(foot.clone());
        }
    }
    v
}

impl BatchRetarget {
    /// A batch of `profile`'s robot ([`RobotProfile::robot`]) with the imitation settings
    /// [`RobotProfile::imitate_config`] makes of `base`, the keypoint settings' defaults with
    /// `base`'s solver, period and tick limit, the profile's map for each clip's format,
    /// default motion options, the control rate as output rate and the default method.
    ///
    /// Errors: those of building the robot and the settings.
    pub fn from_profile(profile: RobotProfile, base: ImitateConfig) -> Result<Self> {
        let config = profile.imitate_config(base)?;
        Ok(Self {
            robot: profile.robot()?,
            keypoints: KeypointSettings {
                method: config.method,
                dt: config.dt,
                run_limits: config.run_limits,
                ..KeypointSettings::default()
            },
            config,
            profile,
            map: None,
            motion_options: MotionOptions::default(),
            rate: None,
            method: DEFAULT_RETARGET_METHOD,
        })
    }

    /// The output rate \[Hz\].
    pub fn output_rate(&self) -> f64 {
        self.rate.unwrap_or(1.0 / self.control_period())
    }

    /// The control period of the method's run \[s\].
    pub fn control_period(&self) -> f64 {
        match self.method {
            RetargetMethod::Keypoints => self.keypoints.dt,
            RetargetMethod::Joints => self.config.dt,
        }
    }

    /// The body frames whose world positions are written ([`body_frames`] of the batch's
    /// profile and imitation settings).
    pub fn body_frames(&self) -> Vec<String> {
        body_frames(&self.profile, &self.config)
    }

    /// A text that changes whenever an output could: the crate version, the method, the
    /// profile, the map, the imitation and keypoint settings, the motion options and the
    /// output rate.
    pub fn settings_text(&self) -> String {
        format!(
            "iktc {}\nmethod {:?}\nprofile {:?}\nmap {:?}\nconfig {:?}\nkeypoints {:?}\nmotion {:?}\nrate {}\nbodies {:?}\n",
            env!("CARGO_PKG_VERSION"),
            self.method,
            self.profile,
            self.map,
            self.config,
            self.keypoints,
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

    /// The retargeting map of a clip in `format`: [`Self::map`] or the profile's.
    fn map_for(&self, format: MotionFormat) -> Result<RetargetMap> {
        match &self.map {
            Some(m) => Ok(m.clone()),
            None => {
                let key = if format == MotionFormat::DeepMimic {
                    "deepmimic"
                } else {
                    "bvh"
                };
                self.profile.retarget_map(key, &self.robot)
            }
        }
    }

    /// Retargets the motion file `path` by [`Self::method`], resamples the run at
    /// [`Self::output_rate`] ([`TrainingTrajectory`]) and measures its [`ClipQuality`].
    ///
    /// Keypoint route: [`load_motion`], the clip's body points, the joint route's references
    /// as posture (when the profile, or [`Self::map`], maps the clip; a profile without a map
    /// for the format leaves the posture at the start pose, a given map that fails is an
    /// error), [`retarget_keypoints`](crate::retarget::retarget_keypoints). Joint route: [`load_clip`], the map,
    /// [`Experiment::imitate`] with [`Self::config`].
    ///
    /// Errors: [`Error::InsufficientData`] for a clip of fewer than [`MIN_CLIP_FRAMES`]
    /// frames; whatever reading, mapping, the run or the resampling give.
    pub fn retarget(&self, path: &Path) -> Result<ClipOutcome> {
        match self.method {
            RetargetMethod::Keypoints => self.retarget_keypoints(path),
            RetargetMethod::Joints => self.retarget_joints(path),
        }
    }

    fn check_frames(spec: &str, frames: usize) -> Result<()> {
        if frames < MIN_CLIP_FRAMES {
            return Err(Error::InsufficientData {
                what: format!("resampling clip `{spec}`"),
                message: format!(
                    "it has {frames} frame(s); at least {MIN_CLIP_FRAMES} are needed (an interval to interpolate over)"
                ),
            });
        }
        Ok(())
    }

    fn feet_penetration(&self, qs: &[Vec<f64>]) -> Result<Penetration> {
        match &self.profile.feet {
            Some(feet) => trajectory_penetration(&self.robot, qs, &[&feet.left, &feet.right]),
            None => Ok(Penetration {
                depth: 0.0,
                share: 0.0,
            }),
        }
    }

    fn retarget_keypoints(&self, path: &Path) -> Result<ClipOutcome> {
        let spec = path.to_string_lossy();
        let motion = load_motion(path, &self.motion_options)?;
        let keypoints = motion.keypoints(DEFAULT_MAX_GAP)?;
        Self::check_frames(&spec, keypoints.times.len())?;
        let s = &self.keypoints;
        let posture = match motion.clip().transpose()? {
            Some(clip) => self.posture(&clip, motion.format)?,
            None => Posture::Start("the motion has no skeleton".into()),
        };
        let robot = std::sync::Arc::new(self.robot.clone());
        let run = retarget_keypoints_on(robot, &self.profile, &keypoints, posture.references(), s)?;
        let trajectory = TrainingTrajectory::from_keypoint_run(
            &self.robot,
            &run,
            s.dt,
            &self.body_frames(),
            self.output_rate(),
        )?;
        let p = self.feet_penetration(&run.trajectory)?;
        let quality = ClipQuality::Keypoints(KeypointFigures::from_run(&run, s.dt, p));
        Ok(ClipOutcome {
            run: ClipRun::Keypoints {
                keypoints: Box::new(keypoints),
                run: Box::new(run),
                posture: posture.describe(),
            },
            trajectory,
            quality,
        })
    }

    /// The joint route's references of `clip` at the keypoint period, the posture level's
    /// references ([`posture_references`] with [`Self::map`]).
    fn posture(&self, clip: &Clip, format: MotionFormat) -> Result<Posture> {
        let cfg = ImitateConfig {
            dt: self.keypoints.dt,
            ..self.config.clone()
        };
        posture_references(
            &self.robot,
            &self.profile,
            clip,
            format,
            self.map.as_ref(),
            &cfg,
            self.keypoints.smoothing,
        )
    }

    fn retarget_joints(&self, path: &Path) -> Result<ClipOutcome> {
        let spec = path.to_string_lossy();
        let loaded = load_clip(&spec, &self.motion_options)?;
        Self::check_frames(&spec, loaded.clip.frame_count())?;
        let map = self.map_for(loaded.format)?;
        let experiment = Experiment {
            robot: self.robot.clone(),
            clip: loaded.clip,
            map,
        };
        let run = experiment.imitate(&self.config)?;
        let trajectory = TrainingTrajectory::from_run(
            &self.robot,
            &run,
            &self.body_frames(),
            self.output_rate(),
        )?;
        let mut figures = JointFigures::from_summary(&run.summary);
        if let Some(feet) = &self.profile.feet {
            let p = run_penetration(&self.robot, &run, &[&feet.left, &feet.right])?;
            figures = figures.with_penetration(p);
        }
        Ok(ClipOutcome {
            run: ClipRun::Joints {
                experiment: Box::new(experiment),
                run: Box::new(run),
            },
            trajectory,
            quality: ClipQuality::Joints(figures),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::batch::TrainingTrajectory;
    use crate::retarget::KEYPOINT_LEVELS;

    fn batch() -> BatchRetarget {
        let profile = RobotProfile::builtin("jvrc1").unwrap();
        BatchRetarget::from_profile(profile, ImitateConfig::default()).unwrap()
    }

    fn walk() -> std::path::PathBuf {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("data/motions/deepmimic/humanoid3d_walk.txt")
    }

    /// The share of the ticks that sacrifice the feet's, COM's or pelvis and torso's level
    /// flags the clip the robot cannot take: JVRC-1 on `humanoid3d_dance_a`, whose first frame
    /// is out of its reach (a body level sacrificed on 0.43 of its ticks), more than a quarter
    /// of its ticks, against `humanoid3d_walk` (0.08: the torso's twist at times faster than
    /// the waist's bounds allow).
    #[test]
    fn the_body_sacrificed_share_flags_the_clip_the_robot_cannot_take() {
        let b = batch();
        let share = |clip: &str| {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join(format!("data/motions/deepmimic/{clip}.txt"));
            let o = b.retarget(&path).unwrap();
            let ClipQuality::Keypoints(f) = &o.quality else {
                panic!("{clip}: not the keypoint route");
            };
            (f.body_sacrificed_share, f.most_sacrificed.clone())
        };
        let (bad, bad_level) = share("humanoid3d_dance_a");
        let (walk, _) = share("humanoid3d_walk");
        assert!(bad > 0.25, "dance_a: {bad}");
        assert!(KEYPOINT_LEVELS.contains(&bad_level.as_str()), "{bad_level}");
        assert!(walk < 0.25 * bad, "walk {walk} against dance_a {bad}");
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
        let mut m = batch();
        m.method = RetargetMethod::Joints;
        assert_ne!(m.settings_hash(), h);
        let mut k = batch();
        k.keypoints.land_height = 0.03;
        assert_ne!(k.settings_hash(), h);
    }

    #[test]
    fn the_default_route_is_keypoints_at_the_imitation_period() {
        let b = batch();
        assert_eq!(b.method, RetargetMethod::Keypoints);
        assert_eq!(b.keypoints.dt, b.config.dt);
        assert_eq!(b.keypoints.method, b.config.method);
        assert_eq!(b.output_rate(), 1.0 / b.keypoints.dt);
    }

    #[test]
    fn bad_rates_and_unknown_bodies_are_errors() {
        let mut b = batch();
        b.method = RetargetMethod::Joints;
        let o = b.retarget(&walk()).unwrap();
        let ClipRun::Joints { run, .. } = &o.run else {
            panic!("the joint route gives a joint run")
        };
        assert!(matches!(o.quality, ClipQuality::Joints(_)));
        let bodies = b.body_frames();
        assert_eq!(o.trajectory.len(), run.steps.len());
        for rate in [0.0, -5.0, f64::NAN, f64::INFINITY] {
            let e = TrainingTrajectory::from_run(&b.robot, run, &bodies, rate).unwrap_err();
            assert!(e.to_string().contains("output rate"), "{rate}: {e}");
        }
        let e = TrainingTrajectory::from_run(&b.robot, run, &["no_such_frame".into()], 100.0)
            .unwrap_err();
        assert!(e.to_string().contains("no_such_frame"), "{e}");
        let mut empty = run.clone();
        empty.steps.clear();
        let e = TrainingTrajectory::from_run(&b.robot, &empty, &bodies, 100.0).unwrap_err();
        assert!(matches!(e, Error::InsufficientData { .. }), "{e}");
    }

    /// At the control rate the keypoint route's training trajectory is the recorded run itself:
    /// every configuration and velocity copied, in the robot's order; its figures are the run's.
    #[test]
    fn keypoint_route_writes_the_run_at_the_control_rate() {
        let b = batch();
        let o = b.retarget(&walk()).unwrap();
        let ClipRun::Keypoints {
            run,
            keypoints,
            posture,
        } = &o.run
        else {
            panic!("the default route gives a keypoint run")
        };
        let ClipQuality::Keypoints(f) = &o.quality else {
            panic!("keypoint figures")
        };
        let t = &o.trajectory;
        let (nqb, nb) = (b.robot.base_nq(), b.robot.base_nv());
        assert_eq!(nqb, 7);
        assert_eq!(t.len(), run.trajectory.len());
        assert_eq!(t.joint_names, b.robot.dof_names()[nb..].to_vec());
        // Frame times j / rate against ticks t0 + k Δt: equal to rounding [s].
        const TIME_ROUNDING: f64 = 1e-12;
        for k in 0..t.len() {
            let (q, qd) = (&run.trajectory[k], &run.velocities[k]);
            assert!((t.time[k] - run.times[k]).abs() < TIME_ROUNDING, "{k}");
            assert_eq!(t.base_pos[k][..], q[..3]);
            assert_eq!(t.base_quat_xyzw[k][..], q[3..7]);
            assert_eq!(t.joint_pos[k][..], q[nqb..]);
            assert_eq!(t.base_lin_vel[k][..], qd[..3]);
            assert_eq!(t.base_ang_vel[k][..], qd[3..6]);
            assert_eq!(t.joint_vel[k][..], qd[nb..]);
        }
        assert_eq!(f.ticks, run.quality.ticks);
        assert_eq!(f.mean_keypoint_error, run.quality.mean_cm / 100.0);
        assert_eq!(f.foot_slip, run.quality.slip_mm / 1000.0);
        assert_eq!(f.foot_float, run.quality.float_mm / 1000.0);
        assert_eq!(f.foot_float_share, run.quality.float_share);
        assert_eq!(f.leg_ratio, run.scaling.leg);
        assert_eq!(f.healthy, f.failures.is_empty(), "{f:?}");
        assert!(!f.failures.iter().any(|m| m.contains("limit")), "{f:?}");
        let feet = b.profile.feet.as_ref().unwrap();
        let p =
            trajectory_penetration(&b.robot, &run.trajectory, &[&feet.left, &feet.right]).unwrap();
        assert_eq!(o.quality.penetration(), p);
        let summary = o.summary().unwrap();
        assert_eq!(summary["source"], keypoints.source.as_str());
        assert_eq!(summary["posture"], posture.as_str());
        assert_eq!(posture, "the joint route's angles");
        assert_eq!(
            summary["keypoints"]["ticks"].as_u64(),
            Some(run.quality.ticks as u64)
        );
        assert_eq!(
            summary["sacrificed"]["ticks"].as_u64(),
            Some(run.quality.ticks as u64)
        );
        let body: usize = KEYPOINT_LEVELS[..5]
            .iter()
            .map(|l| run.sacrificed.of(l))
            .sum();
        assert_eq!(
            f.body_sacrificed_share,
            body as f64 / run.quality.ticks as f64
        );
        assert!(
            f.most_sacrificed.is_empty() || KEYPOINT_LEVELS.contains(&f.most_sacrificed.as_str())
        );
        for (level, n) in &run.sacrificed.levels {
            assert_eq!(
                summary["sacrificed"]["levels"][level].as_u64(),
                Some(*n as u64)
            );
        }
    }

    /// The posture level's references: the profile's map for the clip's format, none where
    /// the profile has no map for it (JVRC-1 maps DeepMimic and BVH, G1 DeepMimic only).
    #[test]
    fn posture_references_come_from_the_profiles_map_for_the_format() {
        let clip = crate::motion::builtin_clip("humanoid3d_walk").unwrap();
        let g1 = RobotProfile::builtin("g1").unwrap();
        let b = BatchRetarget::from_profile(g1, ImitateConfig::default()).unwrap();
        let refs = b.posture(&clip, MotionFormat::DeepMimic).unwrap();
        let refs = refs.references().unwrap();
        let dt = b.keypoints.dt;
        assert!(refs.len() > 1);
        assert!(((refs.len() - 1) as f64 * dt - clip.duration()).abs() <= dt);
        assert!(!refs.joint_names.is_empty());
        for n in &refs.joint_names {
            assert!(b.robot.joints().iter().any(|j| &j.name == n), "{n}");
        }
        let none = b.posture(&clip, MotionFormat::Bvh).unwrap();
        assert!(none.references().is_none());
        assert!(
            none.describe().contains("no joint route"),
            "{}",
            none.describe()
        );
    }

    /// At another output rate every frame is the linear interpolation of the two recorded
    /// ticks around its time (slerp for the base orientation), recomputed here from the run,
    /// and the frame count covers the run.
    #[test]
    fn other_output_rates_interpolate_the_recorded_ticks() {
        let b = batch();
        let o = b.retarget(&walk()).unwrap();
        let ClipRun::Keypoints { run, .. } = &o.run else {
            panic!("keypoint run")
        };
        let dt = b.keypoints.dt;
        let (nqb, nb) = (b.robot.base_nq(), b.robot.base_nv());
        let bodies = b.body_frames();
        // Interpolation against recomputation: rounding of a few operations [rad, m].
        const SAME: f64 = 1e-12;
        for rate in [50.0, 37.5, 130.0] {
            let t =
                TrainingTrajectory::from_keypoint_run(&b.robot, run, dt, &bodies, rate).unwrap();
            let span = run.times[run.times.len() - 1] - run.times[0];
            assert_eq!(t.len(), (span * rate + 1e-9).floor() as usize + 1, "{rate}");
            for (j, tj) in t.time.iter().enumerate() {
                assert!((tj - (run.times[0] + j as f64 / rate)).abs() < SAME);
                let x = (tj - run.times[0]) / dt;
                let k = (x.floor() as usize).min(run.trajectory.len() - 1);
                let k1 = (k + 1).min(run.trajectory.len() - 1);
                let s = if k1 > k { x - k as f64 } else { 0.0 };
                let (a, c) = (&run.trajectory[k], &run.trajectory[k1]);
                for (d, q) in t.joint_pos[j].iter().enumerate() {
                    let want = a[nqb + d] * (1.0 - s) + c[nqb + d] * s;
                    assert!((q - want).abs() < SAME, "{rate} Hz frame {j} joint {d}");
                }
                let (va, vc) = (&run.velocities[k], &run.velocities[k1]);
                for (d, v) in t.joint_vel[j].iter().enumerate() {
                    let want = va[nb + d] * (1.0 - s) + vc[nb + d] * s;
                    assert!((v - want).abs() < SAME, "{rate} Hz frame {j} rate {d}");
                }
                for i in 0..3 {
                    let want = a[i] * (1.0 - s) + c[i] * s;
                    assert!((t.base_pos[j][i] - want).abs() < SAME);
                }
                let quat = |q: &[f64]| {
                    nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
                        q[6], q[3], q[4], q[5],
                    ))
                };
                let want = quat(a).slerp(&quat(c), s);
                let got = quat(&[
                    0.0,
                    0.0,
                    0.0,
                    t.base_quat_xyzw[j][0],
                    t.base_quat_xyzw[j][1],
                    t.base_quat_xyzw[j][2],
                    t.base_quat_xyzw[j][3],
                ]);
                assert!(want.angle_to(&got) < 1e-9, "{rate} Hz frame {j}");
            }
        }
    }

    #[test]
    fn a_keypoint_run_of_the_wrong_shape_is_an_error() {
        let b = batch();
        let o = b.retarget(&walk()).unwrap();
        let ClipRun::Keypoints { run, .. } = o.run else {
            panic!("keypoint run")
        };
        let bodies = b.body_frames();
        let dt = b.keypoints.dt;
        let mut short = run.clone();
        short.velocities.pop();
        let e = TrainingTrajectory::from_keypoint_run(&b.robot, &short, dt, &bodies, 100.0)
            .unwrap_err();
        assert!(matches!(e, Error::DimensionMismatch { .. }), "{e}");
        let mut narrow = run.clone();
        narrow.trajectory[3].pop();
        let e = TrainingTrajectory::from_keypoint_run(&b.robot, &narrow, dt, &bodies, 100.0)
            .unwrap_err();
        assert!(e.to_string().contains("configuration"), "{e}");
        for bad in [0.0, f64::NAN] {
            let e = TrainingTrajectory::from_keypoint_run(&b.robot, &run, bad, &bodies, 100.0)
                .unwrap_err();
            assert!(e.to_string().contains("control period"), "{bad}: {e}");
        }
        let mut empty = run;
        empty.trajectory.clear();
        empty.velocities.clear();
        empty.times.clear();
        let e = TrainingTrajectory::from_keypoint_run(&b.robot, &empty, dt, &bodies, 100.0)
            .unwrap_err();
        assert!(matches!(e, Error::InsufficientData { .. }), "{e}");
    }
}
