//! `iktc retarget`: retarget whole datasets. Inputs are files, folders (searched recursively
//! for motion files) or glob patterns; every clip runs on a pool of threads
//! ([`iktc::batch::run_parallel`]) through [`BatchRetarget::retarget`] (keypoint retargeting
//! by default, `--retarget joints` for the joint-angle route) and gets its own folder
//! `OUT/<clip>/` with `motion.csv`, `motion.npz` (the motion files are chosen with `--format`:
//! also `motion_gmr.pkl`, `motion_lafan.csv`, `motion_mjlab.npz`, see
//! [`iktc::batch::formats`]), `quality.json` and `viewer.html`; a clip that
//! fails is listed with its error (its earlier folder removed) and the batch goes on. Clips are
//! found by [`iktc::batch::discover`]. A clip's folder is written beside its place and renamed
//! into it whole, its `.record` last ([`iktc::batch::write_clip_folder`]): a clip is skipped
//! on a re-run when its `.record` holds the digest of its input's bytes, the robot's files,
//! the settings and the version ([`iktc::batch::clip_record`]) and its files are all there
//! (`--force` redoes it). SIGINT or SIGTERM stops the batch taking clips: the clips in hand
//! finish, and the report lists the clips not run (a second signal ends the process at once).
//! `OUT/index.html` is the dataset report, `OUT/batch.json` the list of clips and errors.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result};
use iktc::batch::{
    clip_state, discover_motions, longest_first, remove_leftovers, run_parallel_until,
    write_clip_folder, BatchRetarget, ClipInput, ClipOutcome, ClipRun, ClipState, MotionFormat,
    RetargetMethod,
};
use iktc::mesh::MeshSet;
use iktc::sim::viewer::imitation_viewer;
use serde::Serialize;

use crate::scenario::{prepare_config, ScenarioArgs};

/// Arguments of `iktc retarget`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Motion files, folders (searched recursively for .bvh, .amc, .c3d, .txt and .json files,
    /// and AMASS .npz archives with --body-model) or glob patterns (`*` and `?`, quoted so the
    /// shell leaves them; `*` also crosses folders).
    #[arg(required = true, value_name = "INPUT")]
    pub inputs: Vec<String>,
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// Retargeting: body keypoints tracked by a task stack, or the paper's joint-angle route
    /// (captured rotations decomposed onto the robot's joints through a map).
    #[arg(long, value_enum, default_value = "keypoints")]
    pub retarget: crate::cmd_keypoints::RetargetArg,
    #[command(flatten)]
    pub keypoints: crate::cmd_keypoints::KeypointArgs,
    /// Output directory: one folder per clip, index.html and batch.json.
    #[arg(long, default_value = "out/retarget")]
    pub out: PathBuf,
    /// Worker threads, 1 to 1024 (default: every core, at most 1024).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Output rate of the motion files, 1 to 100 000 Hz [Hz] (default: the control rate,
    /// 1/--dt).
    #[arg(long)]
    pub rate: Option<f64>,
    /// Motion files to write per clip (repeatable or a comma list): `csv` (motion.csv), `npz`
    /// (motion.npz), `gmr` (GMR's pickle, motion_gmr.pkl), `lafan-csv` (the LAFAN1
    /// retargeting dataset's CSV, motion_lafan.csv), `mjlab` (mjlab / BeyondMimic's motion
    /// NPZ, motion_mjlab.npz). Default: csv,npz.
    #[arg(long = "format", value_name = "FMT", value_delimiter = ',', value_parser = parse_format)]
    pub formats: Vec<MotionFormat>,
    /// Redo clips whose outputs are up to date.
    #[arg(long)]
    pub force: bool,
    /// Write no viewer.html per clip.
    #[arg(long)]
    pub no_viewer: bool,
}

/// The quality file of a clip.
const QUALITY: &str = "quality.json";
const VIEWER: &str = "viewer.html";

/// A `--format` name, with the library's error (listing the valid names).
fn parse_format(s: &str) -> std::result::Result<MotionFormat, String> {
    MotionFormat::parse(s).map_err(|e| e.to_string())
}

impl Args {
    /// The motion formats chosen (`--format`, or csv and npz).
    fn motion_formats(&self) -> Vec<MotionFormat> {
        let mut out: Vec<MotionFormat> = Vec::new();
        for f in &self.formats {
            if !out.contains(f) {
                out.push(*f);
            }
        }
        if out.is_empty() {
            out = MotionFormat::DEFAULT.to_vec();
        }
        out
    }

    /// The files a finished clip's folder holds: the motion files, quality.json and, unless
    /// --no-viewer, viewer.html.
    fn outputs(&self) -> Vec<&'static str> {
        let mut outputs: Vec<&str> = self
            .motion_formats()
            .into_iter()
            .map(MotionFormat::file_name)
            .collect();
        outputs.push(QUALITY);
        if !self.no_viewer {
            outputs.push(VIEWER);
        }
        outputs
    }
}

/// What became of a clip.
#[derive(Debug, Clone, Serialize)]
pub struct ClipStatus {
    /// Output name.
    pub name: String,
    /// Input file.
    pub input: String,
    /// `retargeted`, `skipped` (up to date), `failed` or `interrupted` (not run: the batch
    /// was stopped by a signal).
    pub status: &'static str,
    /// The error of a failed clip.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// Wall-clock time of the clip [s] (0 when skipped).
    pub seconds: f64,
    /// Frames written.
    pub frames: usize,
    /// Quality figures (from quality.json for a skipped clip).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub figures: Option<serde_json::Value>,
    /// The files of the clip's folder (names), for the report's links.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub files: Vec<String>,
}

/// `batch.json`.
#[derive(Debug, Serialize)]
struct BatchFile<'a> {
    settings_hash: &'a str,
    /// [`BatchRetarget::dependency_digest`].
    dependencies: &'a str,
    /// Whether a signal stopped the batch.
    interrupted: bool,
    robot: &'a str,
    clips: &'a [ClipStatus],
}

/// Runs `iktc retarget`.
pub fn run(a: &Args) -> Result<()> {
    if a.scenario.motion != iktc::sim::experiment::DEFAULT_CLIP {
        anyhow::bail!("`iktc retarget` takes its motions as INPUT arguments, not --motion");
    }
    let jobs = match a.jobs {
        Some(n) => iktc::resources::check_jobs("--jobs", n)?,
        None => std::thread::available_parallelism()
            .map_or(1, |n| n.get())
            .min(iktc::resources::MAX_JOBS),
    };
    if let Some(r) = a.rate {
        iktc::resources::check_output_rate("--rate", r)?;
    }
    let (batch, robot) = batch_of(a)?;
    let archives = a.scenario.motion_options.body_model.is_some();
    let found = discover_motions(&a.inputs, Some(&a.out), archives);
    if !found.output_folders.is_empty() {
        let names: Vec<String> = found
            .output_folders
            .iter()
            .map(|p| p.display().to_string())
            .collect();
        eprintln!(
            "not searched: {} folder(s) of iktc output ({})",
            names.len(),
            names.join(", ")
        );
    }
    let mut statuses: Vec<ClipStatus> = found
        .problems
        .iter()
        .map(|p| status(&p.path, &p.path, "failed", Some(p.message.clone())))
        .collect();
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    remove_leftovers(&a.out)?;
    let hash = batch.settings_hash();
    let dependencies = batch.dependency_digest()?;
    let outputs = a.outputs();
    let mut todo: Vec<(ClipInput, String)> = Vec::new();
    for c in found.clips {
        let dir = a.out.join(&c.name);
        let mut s = status(&c.name, &c.path.display().to_string(), "skipped", None);
        match clip_state(&dependencies, &c.path, &dir, &outputs, a.force) {
            Err(e) => {
                s.status = "failed";
                s.error = Some(e.to_string());
                statuses.push(s);
            }
            Ok(ClipState::Done) => {
                s.figures = read_figures(&dir);
                s.files = files_of(&dir);
                statuses.push(s);
            }
            Ok(ClipState::ToRun(r)) => todo.push((c, r)),
        }
    }
    let skipped = statuses.iter().filter(|s| s.status == "skipped").count();
    let stop = stop_on_signal()?;
    let done = run_clips(a, &batch, &todo, skipped, jobs, &stop, &hash);
    let interrupted = done.len() < todo.len();
    for (i, (c, _)) in todo.iter().enumerate() {
        if !done.iter().any(|s| s.0 == i) {
            let input = c.path.display().to_string();
            statuses.push(status(&c.name, &input, "interrupted", None));
        }
    }
    statuses.extend(done.into_iter().map(|(_, s)| s));
    statuses.sort_by(|x, y| x.name.cmp(&y.name));
    let summary = BatchFile {
        settings_hash: &hash,
        dependencies: &dependencies,
        interrupted,
        robot: &robot,
        clips: &statuses,
    };
    write_summary(&a.out, &summary)
}

/// The batch of the command's robot, profile and settings, and the robot's name as given.
fn batch_of(a: &Args) -> Result<(BatchRetarget, String)> {
    let (resolved, mut config) = prepare_config(&a.scenario)?;
    a.keypoints.apply(a.retarget, &mut config)?;
    let profile = resolved
        .profile
        .clone()
        .context("`planar3r` has no profile and cannot imitate a motion")?;
    let map = match &a.scenario.map {
        Some(spec) => Some(
            iktc::sim::load_map(spec, &resolved.robot)
                .with_context(|| format!("--map `{spec}`"))?,
        ),
        None => None,
    };
    let batch = BatchRetarget {
        robot: resolved.robot.clone(),
        profile,
        map,
        keypoints: crate::cmd_keypoints::keypoint_settings(
            &config,
            crate::scenario::keypoint_bounds(&a.scenario)?,
            &a.keypoints,
        ),
        config,
        motion_options: a.scenario.motion_options.options()?,
        rate: a.rate,
        method: match a.retarget {
            crate::cmd_keypoints::RetargetArg::Keypoints => RetargetMethod::Keypoints,
            crate::cmd_keypoints::RetargetArg::Joints => RetargetMethod::Joints,
        },
    };
    // Settings are checked once, before any clip (the keypoint route's --dt bound).
    if batch.method == RetargetMethod::Keypoints {
        batch.keypoints.validate()?;
    }
    Ok((batch, resolved.source))
}

/// A flag set by the first SIGINT or SIGTERM (the batch then takes no more clips); a second
/// one ends the process at once (the clips in hand leave only temporary folders, removed by
/// the next run).
fn stop_on_signal() -> Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) {
            eprintln!("\nstopped at once; the clips in hand are left out");
            std::process::exit(130);
        }
        eprintln!(
            "\ninterrupted: finishing the clips in hand, taking no more (a second signal stops at once)"
        );
    })
    .context("installing the SIGINT/SIGTERM handler")?;
    Ok(stop)
}

/// Runs the clips of `todo` (each with its record) until done or `stop`; returns the status of
/// every clip that ran, with its index in `todo`.
fn run_clips(
    a: &Args,
    batch: &BatchRetarget,
    todo: &[(ClipInput, String)],
    skipped: usize,
    jobs: usize,
    stop: &AtomicBool,
    hash: &str,
) -> Vec<(usize, ClipStatus)> {
    // The robot's meshes, read once for every clip's viewer.
    let meshes = if a.no_viewer || todo.is_empty() {
        None
    } else {
        crate::viewer::robot_meshes(&batch.profile)
    };
    let viewer = (!a.no_viewer).then_some(meshes.as_ref());
    let clips: Vec<&ClipInput> = todo.iter().map(|(c, _)| c).collect();
    let mut progress = Progress::new(&clips, skipped);
    // The longest clips first (by file size), so that a long clip does not run alone at the end.
    let order = longest_first(todo, |(c, _)| {
        std::fs::metadata(&c.path).map(|m| m.len()).unwrap_or(0)
    });
    let mut done = Vec::new();
    run_parallel_until(
        todo,
        &order,
        jobs,
        stop,
        |_, (c, record)| {
            let start = Instant::now();
            let dir = a.out.join(&c.name);
            let r = retarget_one(batch, c, &dir, hash, record, viewer, &a.motion_formats());
            if r.is_err() {
                // An earlier folder of a clip that now fails no longer describes its input.
                let _ = std::fs::remove_dir_all(&dir);
            }
            (r, start.elapsed().as_secs_f64())
        },
        |i, r| {
            let c = &todo[i].0;
            let input = c.path.display().to_string();
            let (s, seconds) = match r {
                Ok((Ok((frames, figures, files)), s)) => {
                    let mut st = status(&c.name, &input, "retargeted", None);
                    (st.seconds, st.frames) = (s, frames);
                    (st.figures, st.files) = (Some(figures), files);
                    (st, s)
                }
                Ok((Err(e), s)) => {
                    let mut st = status(&c.name, &input, "failed", Some(format!("{e:#}")));
                    st.seconds = s;
                    (st, s)
                }
                Err(panic) => {
                    let e = format!("internal error: {panic}");
                    (status(&c.name, &input, "failed", Some(e)), 0.0)
                }
            };
            progress.done(i, &s, seconds);
            done.push((i, s));
        },
    );
    progress.finish();
    done
}

/// Writes `batch.json` and `index.html` and prints the counts; an error if a clip failed or
/// the batch was interrupted.
fn write_summary(out: &Path, summary: &BatchFile<'_>) -> Result<()> {
    let statuses = summary.clips;
    write_atomic(
        &out.join("batch.json"),
        crate::finite::to_json("batch.json", summary)?.as_bytes(),
    )?;
    let html = crate::retarget_report::render(statuses, summary.robot);
    write_atomic(&out.join("index.html"), html.as_bytes())?;
    let count = |s: &str| statuses.iter().filter(|c| c.status == s).count();
    let (failed, not_run) = (count("failed"), count("interrupted"));
    crate::outln!(
        "{} clips: {} retargeted, {} skipped (up to date), {} failed, {} not run; report {}",
        statuses.len(),
        count("retargeted"),
        count("skipped"),
        failed,
        not_run,
        out.join("index.html").display()
    )?;
    if not_run > 0 {
        anyhow::bail!(
            "interrupted: {not_run} of {} clips not run, {failed} failed (listed in {})",
            statuses.len(),
            out.join("batch.json").display()
        );
    }
    if failed > 0 {
        anyhow::bail!(
            "{failed} of {} clips failed (listed in {})",
            statuses.len(),
            out.join("index.html").display()
        );
    }
    Ok(())
}

fn status(name: &str, input: &str, status: &'static str, error: Option<String>) -> ClipStatus {
    ClipStatus {
        name: name.to_string(),
        input: input.to_string(),
        status,
        error,
        seconds: 0.0,
        frames: 0,
        figures: None,
        files: Vec::new(),
    }
}

/// Retargets one clip and writes its folder whole ([`write_clip_folder`], `record` last);
/// returns its frame count, quality figures and the names of the files written.
fn retarget_one(
    batch: &BatchRetarget,
    c: &ClipInput,
    dir: &Path,
    hash: &str,
    record: &str,
    viewer: Option<Option<&MeshSet>>,
    formats: &[MotionFormat],
) -> Result<(usize, serde_json::Value, Vec<String>)> {
    let outcome = batch.retarget(&c.path)?;
    let ClipOutcome {
        run,
        trajectory,
        quality,
    } = &outcome;
    let figures = serde_json::to_value(quality)?;
    let doc = serde_json::json!({
        "clip": c.name,
        "input": c.path.display().to_string(),
        "settings_hash": hash,
        "record": record,
        "output_rate_hz": trajectory.fps,
        "frames": trajectory.len(),
        "quaternion_order": "x, y, z, w",
        "route": match run {
            ClipRun::Keypoints { .. } => "keypoints",
            ClipRun::Joints { .. } => "joints",
        },
        "figures": figures,
        "summary": outcome.summary()?,
    });
    let mut files: Vec<(&str, Vec<u8>)> = Vec::new();
    for f in formats {
        let bytes = f
            .encode(&batch.robot, trajectory)
            .with_context(|| format!("writing {}", f.file_name()))?;
        files.push((f.file_name(), bytes));
    }
    files.push((
        QUALITY,
        crate::finite::to_json("quality.json", &doc)?.into_bytes(),
    ));
    if let Some(meshes) = viewer {
        let mut data = match run {
            ClipRun::Keypoints { keypoints, run, .. } => iktc::retarget::keypoint_viewer(
                &batch.robot,
                keypoints,
                run,
                batch.control_period(),
            )?,
            ClipRun::Joints { experiment, run } => imitation_viewer(run, experiment)?,
        };
        crate::viewer::attach(&mut data, &batch.robot, meshes)?;
        files.push((VIEWER, crate::viewer::render_viewer(&data)?.into_bytes()));
    }
    write_clip_folder(dir, record, |tmp| -> Result<()> {
        for (name, bytes) in &files {
            let p = tmp.join(name);
            std::fs::write(&p, bytes).with_context(|| format!("writing {}", p.display()))?;
        }
        Ok(())
    })
    .with_context(|| format!("writing the folder {}", dir.display()))?;
    let names = files.iter().map(|(n, _)| n.to_string()).collect();
    Ok((trajectory.len(), figures, names))
}

/// Writes `bytes` to a temporary file beside `path`, then renames it over `path`: a reader
/// (or an interrupted batch) sees the old file or the new one, never half of one.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.{}.tmp", std::process::id()));
    std::fs::write(&tmp, bytes).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, path)
        .with_context(|| format!("renaming {} to {}", tmp.display(), path.display()))
}

fn read_figures(dir: &Path) -> Option<serde_json::Value> {
    let text = std::fs::read_to_string(dir.join(QUALITY)).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    v.get("figures").cloned()
}

/// The output files (viewer, motion files of every format, quality) that `dir` holds.
fn files_of(dir: &Path) -> Vec<String> {
    std::iter::once(VIEWER)
        .chain(MotionFormat::ALL.map(MotionFormat::file_name))
        .chain([QUALITY])
        .filter(|f| dir.join(f).is_file())
        .map(str::to_string)
        .collect()
}

/// Progress on standard error: an [`indicatif`] bar redrawn in place with the ETA on a
/// terminal (failed clips printed above it), a log line per clip otherwise. The ETA scales the
/// elapsed time by the input bytes left over those done.
struct Progress {
    start: Instant,
    bytes: Vec<u64>,
    total: usize,
    done: usize,
    failed: usize,
    done_bytes: u64,
    left_bytes: u64,
    frames: usize,
    /// The bar, on a terminal only.
    bar: Option<indicatif::ProgressBar>,
}

impl Progress {
    fn new(todo: &[&ClipInput], skipped: usize) -> Self {
        let bytes: Vec<u64> = todo
            .iter()
            .map(|c| std::fs::metadata(&c.path).map_or(1, |m| m.len().max(1)))
            .collect();
        if skipped > 0 {
            eprintln!("{skipped} clips up to date (skipped; --force redoes them)");
        }
        let bar = (std::io::stderr().is_terminal() && !todo.is_empty()).then(|| {
            let bar = indicatif::ProgressBar::with_draw_target(
                Some(todo.len() as u64),
                indicatif::ProgressDrawTarget::stderr(),
            );
            // The template is a constant: a mistake in it shows as the default style.
            if let Ok(style) =
                indicatif::ProgressStyle::with_template("[{bar:30}] {pos}/{len} clips, {msg}")
            {
                bar.set_style(style.progress_chars("#>."));
            }
            bar.set_message("0 failed, ETA ?");
            bar
        });
        Self {
            start: Instant::now(),
            left_bytes: bytes.iter().sum(),
            bytes,
            total: todo.len(),
            done: 0,
            failed: 0,
            done_bytes: 0,
            frames: 0,
            bar,
        }
    }

    fn eta(&self) -> String {
        if self.done_bytes == 0 {
            return "?".into();
        }
        let s =
            self.start.elapsed().as_secs_f64() * self.left_bytes as f64 / self.done_bytes as f64;
        format!("{}m{:02}s", (s / 60.0) as u64, (s % 60.0) as u64)
    }

    fn done(&mut self, i: usize, c: &ClipStatus, seconds: f64) {
        let b = self.bytes.get(i).copied().unwrap_or(1);
        self.done += 1;
        self.done_bytes += b;
        self.left_bytes = self.left_bytes.saturating_sub(b);
        self.frames += c.frames;
        if c.status == "failed" {
            self.failed += 1;
        }
        if let Some(bar) = &self.bar {
            if let Some(e) = &c.error {
                bar.println(format!("{}: FAILED: {e}", c.name));
            }
            bar.set_message(format!(
                "{} failed, {:.0} frames/s, ETA {}",
                self.failed,
                self.frames as f64 / self.start.elapsed().as_secs_f64().max(1e-9),
                self.eta()
            ));
            bar.set_position(self.done as u64);
        } else {
            match &c.error {
                Some(e) => eprintln!("[{}/{}] {}: FAILED: {e}", self.done, self.total, c.name),
                None => eprintln!(
                    "[{}/{}] {}: {} frames in {seconds:.2} s, ETA {}",
                    self.done,
                    self.total,
                    c.name,
                    c.frames,
                    self.eta()
                ),
            }
        }
    }

    /// Leaves the bar's last state on screen, the output that follows on its own line.
    fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish();
        }
    }
}
