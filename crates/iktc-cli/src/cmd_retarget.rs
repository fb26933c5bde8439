//! `iktc retarget`: retarget whole datasets. Inputs are files, folders (searched recursively
//! for motion files) or glob patterns; every clip runs on a pool of threads
//! ([`iktc::batch::run_parallel`]) through [`BatchRetarget::retarget`] (keypoint retargeting
//! by default, `--retarget joints` for the joint-angle route) and gets its own folder
//! `OUT/<clip>/` with `motion.csv`, `motion.npz`, `quality.json` and `viewer.html`; a clip that
//! fails is listed with its error and the batch goes on. Every file is written to a temporary
//! name and renamed, and `.settings` (the settings hash) is written last: a clip is skipped on a
//! re-run when its `.settings` holds the same hash and is newer than its input (`--force` redoes
//! it). `OUT/index.html` is the dataset report, `OUT/batch.json` the list of clips and errors.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime};

use anyhow::{Context, Result};
use iktc::batch::{
    longest_first, run_parallel_in, BatchRetarget, ClipOutcome, ClipRun, RetargetMethod,
};
use iktc::mesh::MeshSet;
use iktc::profile::glob_match;
use iktc::sim::viewer::imitation_viewer;
use serde::Serialize;

use crate::scenario::{prepare_config, ScenarioArgs};

/// Arguments of `iktc retarget`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Motion files, folders (searched recursively for .bvh, .amc, .c3d, .txt and .json files) or
    /// glob patterns (`*` and `?`, quoted so the shell leaves them; `*` also crosses folders).
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
    /// Worker threads (default: every core).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Output rate of motion.csv and motion.npz, 1 to 100 000 Hz [Hz] (default: the control
    /// rate, 1/--dt).
    #[arg(long)]
    pub rate: Option<f64>,
    /// Redo clips whose outputs are up to date.
    #[arg(long)]
    pub force: bool,
    /// Write no viewer.html per clip.
    #[arg(long)]
    pub no_viewer: bool,
}

/// Motion file extensions taken from folders.
/// (CSV files of named points are read when named, not taken from folders, where CSV files of
/// other kinds are common.)
pub const MOTION_EXTENSIONS: [&str; 5] = ["bvh", "amc", "c3d", "txt", "json"];

/// Files of one clip, in the order they are written (`.settings` last).
const OUTPUTS: [&str; 3] = ["motion.csv", "motion.npz", "quality.json"];
const SETTINGS_FILE: &str = ".settings";

/// One input clip: its file and its output name (a relative path without extension).
#[derive(Debug, Clone)]
pub struct ClipInput {
    /// The motion file.
    pub path: PathBuf,
    /// Output folder name under `--out`.
    pub name: String,
}

/// What became of a clip.
#[derive(Debug, Clone, Serialize)]
pub struct ClipStatus {
    /// Output name.
    pub name: String,
    /// Input file.
    pub input: String,
    /// `retargeted`, `skipped` (up to date) or `failed`.
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
}

/// `batch.json`.
#[derive(Debug, Serialize)]
struct BatchFile<'a> {
    settings_hash: &'a str,
    robot: &'a str,
    clips: &'a [ClipStatus],
}

/// Runs `iktc retarget`.
pub fn run(a: &Args) -> Result<()> {
    if a.scenario.motion != iktc::sim::experiment::DEFAULT_CLIP {
        anyhow::bail!("`iktc retarget` takes its motions as INPUT arguments, not --motion");
    }
    let jobs = match a.jobs {
        Some(0) => anyhow::bail!("--jobs 0: expected at least 1 worker thread"),
        Some(n) => n,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    if let Some(r) = a.rate {
        iktc::resources::check_output_rate("--rate", r)?;
    }
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
    let (clips, mut statuses, outputs) = discover(&a.inputs, Some(&a.out));
    if !outputs.is_empty() {
        let names: Vec<String> = outputs.iter().map(|p| p.display().to_string()).collect();
        eprintln!(
            "not searched: {} folder(s) of iktc output ({})",
            outputs.len(),
            names.join(", ")
        );
    }
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    remove_temporaries(&a.out)?;
    let hash = batch.settings_hash();
    let (todo, skipped): (Vec<ClipInput>, Vec<ClipInput>) = clips
        .into_iter()
        .partition(|c| a.force || !up_to_date(&a.out.join(&c.name), &c.path, &hash));
    for c in &skipped {
        statuses.push(ClipStatus {
            name: c.name.clone(),
            input: c.path.display().to_string(),
            status: "skipped",
            error: None,
            seconds: 0.0,
            frames: 0,
            figures: read_figures(&a.out.join(&c.name)),
        });
    }
    // The robot's meshes, read once for every clip's viewer.
    let meshes = if a.no_viewer || todo.is_empty() {
        None
    } else {
        crate::viewer::robot_meshes(&batch.profile)
    };
    let viewer = (!a.no_viewer).then_some(meshes.as_ref());
    let mut progress = Progress::new(&todo, skipped.len());
    // The longest clips first (by file size), so that a long clip does not run alone at the end.
    let order = longest_first(&todo, |c| {
        std::fs::metadata(&c.path).map(|m| m.len()).unwrap_or(0)
    });
    run_parallel_in(
        &todo,
        &order,
        jobs,
        |_, c| {
            let start = Instant::now();
            let r = retarget_one(&batch, c, &a.out.join(&c.name), &hash, viewer);
            (r, start.elapsed().as_secs_f64())
        },
        |i, r| {
            let c = &todo[i];
            let (status, seconds) = match r {
                Ok((Ok((frames, figures)), s)) => (
                    ClipStatus {
                        name: c.name.clone(),
                        input: c.path.display().to_string(),
                        status: "retargeted",
                        error: None,
                        seconds: s,
                        frames,
                        figures: Some(figures),
                    },
                    s,
                ),
                Ok((Err(e), s)) => (failed(c, format!("{e:#}"), s), s),
                Err(panic) => (failed(c, format!("internal error: {panic}"), 0.0), 0.0),
            };
            progress.done(i, &status, seconds);
            statuses.push(status);
        },
    );
    progress.finish();
    statuses.sort_by(|x, y| x.name.cmp(&y.name));
    write_atomic(
        &a.out.join("batch.json"),
        crate::finite::to_json(
            "batch.json",
            &BatchFile {
                settings_hash: &hash,
                robot: &resolved.source,
                clips: &statuses,
            },
        )?
        .as_bytes(),
    )?;
    let html = crate::retarget_report::render(&statuses, &resolved.source, !a.no_viewer);
    write_atomic(&a.out.join("index.html"), html.as_bytes())?;
    let count = |s: &str| statuses.iter().filter(|c| c.status == s).count();
    let failed_count = count("failed");
    crate::outln!(
        "{} clips: {} retargeted, {} skipped (up to date), {} failed; report {}",
        statuses.len(),
        count("retargeted"),
        count("skipped"),
        failed_count,
        a.out.join("index.html").display()
    )?;
    if failed_count > 0 {
        anyhow::bail!(
            "{failed_count} of {} clips failed (listed in {})",
            statuses.len(),
            a.out.join("index.html").display()
        );
    }
    Ok(())
}

fn failed(c: &ClipInput, error: String, seconds: f64) -> ClipStatus {
    ClipStatus {
        name: c.name.clone(),
        input: c.path.display().to_string(),
        status: "failed",
        error: Some(error),
        seconds,
        frames: 0,
        figures: None,
    }
}

/// Retargets one clip and writes its files; returns its frame count and quality figures.
fn retarget_one(
    batch: &BatchRetarget,
    c: &ClipInput,
    dir: &Path,
    hash: &str,
    viewer: Option<Option<&MeshSet>>,
) -> Result<(usize, serde_json::Value)> {
    // A stale marker must not vouch for files being replaced, nor for a clip that now fails.
    let marker = dir.join(SETTINGS_FILE);
    if marker.exists() {
        std::fs::remove_file(&marker).with_context(|| format!("removing {}", marker.display()))?;
    }
    let outcome = batch.retarget(&c.path)?;
    let ClipOutcome {
        run,
        trajectory,
        quality,
    } = &outcome;
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    remove_temporaries(dir)?;
    write_atomic(&dir.join(OUTPUTS[0]), trajectory.csv().as_bytes())?;
    write_atomic(&dir.join(OUTPUTS[1]), &trajectory.npz()?)?;
    let figures = serde_json::to_value(quality)?;
    let doc = serde_json::json!({
        "clip": c.name,
        "input": c.path.display().to_string(),
        "settings_hash": hash,
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
    write_atomic(
        &dir.join(OUTPUTS[2]),
        crate::finite::to_json("quality.json", &doc)?.as_bytes(),
    )?;
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
        let html = crate::viewer::render_viewer(&data)?;
        write_atomic(&dir.join("viewer.html"), html.as_bytes())?;
    }
    write_atomic(&marker, format!("{hash}\n").as_bytes())?;
    Ok((trajectory.len(), figures))
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

/// Removes the temporary files an interrupted batch left in `dir` (`.NAME.PID.tmp`).
fn remove_temporaries(dir: &Path) -> Result<()> {
    for e in std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))? {
        let p = e?.path();
        let name = p.file_name().map(|n| n.to_string_lossy().into_owned());
        if name.is_some_and(|n| n.starts_with('.') && n.ends_with(".tmp")) && p.is_file() {
            std::fs::remove_file(&p).with_context(|| format!("removing {}", p.display()))?;
        }
    }
    Ok(())
}

fn modified(p: &Path) -> Option<SystemTime> {
    std::fs::metadata(p).and_then(|m| m.modified()).ok()
}

/// Whether the clip's outputs in `dir` were made from `input` with the settings `hash` and
/// after the input last changed.
fn up_to_date(dir: &Path, input: &Path, hash: &str) -> bool {
    let marker = dir.join(SETTINGS_FILE);
    let same = std::fs::read_to_string(&marker).is_ok_and(|s| s.trim() == hash);
    let newer = matches!((modified(&marker), modified(input)), (Some(m), Some(i)) if m >= i);
    same && newer && OUTPUTS.iter().all(|o| dir.join(o).is_file())
}

fn read_figures(dir: &Path) -> Option<serde_json::Value> {
    let text = std::fs::read_to_string(dir.join(OUTPUTS[2])).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    v.get("figures").cloned()
}

fn is_motion_file(p: &Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| MOTION_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}

/// Whether `dir` holds what iktc writes: the batch's `--out` folder (`out`), a folder of an
/// earlier batch (its `batch.json`) or of one of its clips (its settings marker), or the
/// output of `iktc imitate` (its `keypoints_summary.json`). Their files (`quality.json`,
/// summaries, trajectories) are not motion to retarget, wherever the output went, so a batch
/// whose `--out` lies inside its input folder can run again.
fn is_output_folder(dir: &Path, out: Option<&Path>) -> bool {
    let same = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    };
    out.is_some_and(|o| same(dir, o))
        || dir.join("batch.json").is_file()
        || dir.join(SETTINGS_FILE).is_file()
        || dir.join("keypoints_summary.json").is_file()
}

/// Every file under `dir`, sorted, recursively, leaving out the folders of iktc's output
/// ([`is_output_folder`]), which are counted in `skipped`.
fn walk(
    dir: &Path,
    out_dir: Option<&Path>,
    out: &mut Vec<PathBuf>,
    skipped: &mut Vec<PathBuf>,
) -> std::io::Result<()> {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)?
        .map(|e| e.map(|e| e.path()))
        .collect::<std::io::Result<_>>()?;
    entries.sort();
    for p in entries {
        if p.is_dir() {
            if is_output_folder(&p, out_dir) {
                skipped.push(p);
            } else {
                walk(&p, out_dir, out, skipped)?;
            }
        } else {
            out.push(p);
        }
    }
    Ok(())
}

/// `path` relative to `base`, without its extension, with `/` separators.
fn clip_name(path: &Path, base: &Path) -> String {
    let rel = path.strip_prefix(base).unwrap_or(path).with_extension("");
    rel.components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/")
}

/// The clips the inputs name, and an error entry for every input that names none (or a clip
/// whose output name another input already took). Folders and globs are searched without the
/// folders of iktc's output (`out`, the batch's `--out`, and those of earlier batches), which
/// are listed in the third value.
pub fn discover(
    inputs: &[String],
    out: Option<&Path>,
) -> (Vec<ClipInput>, Vec<ClipStatus>, Vec<PathBuf>) {
    let mut outputs = Vec::new();
    let mut clips: Vec<ClipInput> = Vec::new();
    let mut errors = Vec::new();
    let mut bad = |input: &str, error: String| {
        errors.push(ClipStatus {
            name: input.to_string(),
            input: input.to_string(),
            status: "failed",
            error: Some(error),
            seconds: 0.0,
            frames: 0,
            figures: None,
        })
    };
    for input in inputs {
        let p = Path::new(input);
        let found: Vec<ClipInput> = if p.is_file() {
            vec![ClipInput {
                path: p.to_path_buf(),
                name: clip_name(p, p.parent().unwrap_or(Path::new(""))),
            }]
        } else if p.is_dir() {
            let mut files = Vec::new();
            if let Err(e) = walk(p, out, &mut files, &mut outputs) {
                bad(input, format!("reading folder: {e}"));
                continue;
            }
            files
                .into_iter()
                .filter(|f| is_motion_file(f))
                .map(|f| ClipInput {
                    name: clip_name(&f, p),
                    path: f,
                })
                .collect()
        } else if input.contains(['*', '?']) {
            // The folder before the first wildcard, searched recursively.
            let base: PathBuf = p
                .components()
                .take_while(|c| !c.as_os_str().to_string_lossy().contains(['*', '?']))
                .collect();
            let root = if base.as_os_str().is_empty() {
                PathBuf::from(".")
            } else {
                base.clone()
            };
            let mut files = Vec::new();
            if let Err(e) = walk(&root, out, &mut files, &mut outputs) {
                bad(input, format!("reading folder {}: {e}", root.display()));
                continue;
            }
            files
                .into_iter()
                .filter(|f| {
                    let s = if base.as_os_str().is_empty() {
                        f.strip_prefix(".").unwrap_or(f)
                    } else {
                        f
                    };
                    glob_match(input, &s.to_string_lossy())
                })
                .map(|f| ClipInput {
                    name: clip_name(&f, &root),
                    path: f,
                })
                .collect()
        } else {
            bad(input, "no such file or folder".into());
            continue;
        };
        if found.is_empty() {
            bad(
                input,
                format!("no motion file (.{}) found", MOTION_EXTENSIONS.join(", .")),
            );
        }
        for c in found {
            if let Some(other) = clips.iter().find(|o| o.name == c.name) {
                if other.path != c.path {
                    bad(
                        &c.path.display().to_string(),
                        format!(
                            "its output name `{}` is taken by {}",
                            c.name,
                            other.path.display()
                        ),
                    );
                }
                continue;
            }
            clips.push(c);
        }
    }
    (clips, errors, outputs)
}

/// Progress on standard error: a bar redrawn in place with the ETA on a terminal, a log line
/// per clip otherwise. The ETA scales the elapsed time by the input bytes left over those done.
struct Progress {
    start: Instant,
    bytes: Vec<u64>,
    total: usize,
    done: usize,
    failed: usize,
    done_bytes: u64,
    left_bytes: u64,
    frames: usize,
    tty: bool,
}

impl Progress {
    fn new(todo: &[ClipInput], skipped: usize) -> Self {
        let bytes: Vec<u64> = todo
            .iter()
            .map(|c| std::fs::metadata(&c.path).map_or(1, |m| m.len().max(1)))
            .collect();
        let tty = std::io::stderr().is_terminal();
        if skipped > 0 {
            eprintln!("{skipped} clips up to date (skipped; --force redoes them)");
        }
        Self {
            start: Instant::now(),
            left_bytes: bytes.iter().sum(),
            bytes,
            total: todo.len(),
            done: 0,
            failed: 0,
            done_bytes: 0,
            frames: 0,
            tty,
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
        if self.tty {
            let width = 30;
            let filled = width * self.done / self.total.max(1);
            if let Some(e) = &c.error {
                eprintln!("\r\x1b[2K{}: FAILED: {e}", c.name);
            }
            eprint!(
                "\r\x1b[2K[{}{}] {}/{} clips, {} failed, {:.0} frames/s, ETA {}",
                "#".repeat(filled),
                ".".repeat(width - filled),
                self.done,
                self.total,
                self.failed,
                self.frames as f64 / self.start.elapsed().as_secs_f64().max(1e-9),
                self.eta()
            );
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

    fn finish(&self) {
        if self.tty && self.total > 0 {
            eprintln!();
        }
    }
}
