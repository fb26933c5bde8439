//! Retargeting whole datasets: one clip end to end in memory ([`BatchRetarget::retarget`], by
//! keypoints or joint angles),
//! its outputs for training code ([`TrainingTrajectory`] as CSV and NPZ, written by
//! [`npz`] without a dependency, and in the files of other pipelines, [`MotionFormat`]: GMR's
//! pickle written by [`pickle`], the LAFAN1 dataset's CSV, mjlab's NPZ), its quality figures ([`ClipQuality`]), and a pool of worker
//! threads over the clips ([`run_parallel`], the longest clips first with [`longest_first`]).
//! Finding the clips of files, folders and patterns ([`discover()`]), the record of a finished
//! clip and writing its folder whole ([`record`]). Progress and the dataset report are the
//! command line's (`iktc retarget`).

pub mod discover;
pub mod formats;
pub mod npz;
pub mod pickle;
#[cfg(feature = "parallel")]
pub mod pool;
pub mod quality;
pub mod record;
pub mod retarget;
pub mod training;

pub use discover::{
    discover, discover_motions, is_archive_file, is_motion_file, is_output_folder, ClipInput,
    Discovery, DiscoveryProblem, MOTION_EXTENSIONS, RECORD_FILE,
};
pub use formats::{body_links, gmr_pickle, lafan_csv, mjlab_npz, BodyMotion, MotionFormat};
pub use npz::{npz_bytes, read_npz, zip_stored, NpyArray, NpyData, MAX_NPZ_ELEMENTS};
#[cfg(feature = "parallel")]
pub use pool::{longest_first, run_parallel, run_parallel_in, run_parallel_until};
pub use quality::{
    run_penetration, sole_penetration, trajectory_penetration, ClipQuality, JointFigures,
    KeypointFigures, Penetration,
};
pub use record::{
    clip_record, clip_state, is_done, remove_leftovers, write_clip_folder, ClipState,
};
pub use retarget::{
    body_frames, posture_references, BatchRetarget, ClipOutcome, ClipRun, Posture, RetargetMethod,
    DEFAULT_RETARGET_METHOD, MIN_CLIP_FRAMES,
};
pub use training::TrainingTrajectory;
