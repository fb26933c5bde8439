//! One entry point for every motion source: [`load_motion`] detects the format, reads the file,
//! finds the body points (or takes a map), decides units and up axis, and gives keypoints (and,
//! for skeletons, a clip in metres).
//!
//! Format detection: by content first — BVH starts with `HIERARCHY`; ASF has `:version`,
//! `:units`, `:root` or `:bonedata` keywords; AMC has `:FULLY-SPECIFIED`, `:DEGREES` or
//! `:RADIANS` before its first frame; DeepMimic is JSON with `"Frames"`; C3D has `0x50` as its
//! second byte; a points CSV has a header whose columns end in `_x`, `_y`, `_z`; an AMASS
//! archive is a zip (`PK\x03\x04`) whose directory names `poses.npy` and `trans.npy` — then by
//! the extension (`.bvh`, `.asf`, `.amc`, `.txt`/`.json`, `.c3d`, `.csv`, `.npz`). A file read
//! by its extension alone that fails says so and lists the signatures its content did not
//! match.
//!
//! AMASS archives are read with the user's body model file ([`MotionOptions::body_model`];
//! see [`amass`](super::amass)); their units and up axis are the format's, metres and Z up
//! ([`MotionFormat::fixed_frame`]), unless given.

use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Vector3};

use super::amc::AMC_DEFAULT_RATE;
use super::body_map::{BodyMap, PointSource};
use super::keypoints::{clip_keypoints, marker_keypoints, Keypoints};
use super::markers::{MarkerSet, DEFAULT_MAX_GAP};
use super::plausible;
use super::recognise::{recognise_markers, recognise_skeleton};
use super::units::{
    decide_units, decide_up, extent_along, stands, Measured, Units, UnitsDecision, UpChoice,
    UpDecision,
};
use super::{BodyPoint, BvhReadOptions, Clip, LengthUnit, Pose, Skeleton, SkeletonJoint, UpAxis};
use crate::error::{Error, Result};

/// The formats [`load_motion`] reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotionFormat {
    /// Biovision hierarchy.
    Bvh,
    /// Acclaim skeleton alone (its rest pose, one frame).
    Asf,
    /// Acclaim motion, with its ASF skeleton.
    Amc,
    /// DeepMimic motion (JSON) on the DeepMimic character.
    DeepMimic,
    /// C3D marker trajectories.
    C3d,
    /// A CSV of named 3D points.
    PointsCsv,
    /// An AMASS motion archive (`.npz`, SMPL-H or SMPL-X poses), read with a body model file.
    Amass,
}

impl MotionFormat {
    /// A short name.
    pub fn name(self) -> &'static str {
        match self {
            MotionFormat::Bvh => "BVH",
            MotionFormat::Asf => "ASF",
            MotionFormat::Amc => "AMC",
            MotionFormat::DeepMimic => "DeepMimic JSON",
            MotionFormat::C3d => "C3D",
            MotionFormat::PointsCsv => "points CSV",
            MotionFormat::Amass => "AMASS (SMPL-H/SMPL-X)",
        }
    }

    /// The length unit and up axis the format itself states, if it does: AMASS's are metres
    /// and Z up (its rest pose stands Y up in the body model's frame, so measuring it would
    /// mislead). `None`: the format leaves them to the file, decided when not given.
    pub fn fixed_frame(self) -> Option<(LengthUnit, UpAxis)> {
        match self {
            MotionFormat::Amass => Some((LengthUnit::Metres, UpAxis::Z)),
            _ => None,
        }
    }
}

/// Options of [`load_motion`].
#[derive(Debug, Clone, PartialEq)]
pub struct MotionOptions {
    /// Length unit (default `Auto`).
    pub units: Units,
    /// Up axis (default `Auto`).
    pub up: UpChoice,
    /// The ASF skeleton of an AMC file (default: found beside it).
    pub skeleton: Option<PathBuf>,
    /// Force a format instead of detecting it.
    pub format: Option<MotionFormat>,
    /// Use this body map instead of recognising the body points.
    pub body_map: Option<BodyMap>,
    /// Longest marker gap filled \[s\] (default [`DEFAULT_MAX_GAP`]).
    pub max_gap: f64,
    /// Frame rate of AMC files, which do not carry one \[Hz\] (default [`AMC_DEFAULT_RATE`]).
    pub amc_frame_rate: f64,
    /// Most frames and longest duration accepted from a BVH, DeepMimic or AMASS file.
    pub limits: crate::resources::ReadLimits,
    /// The body model file (`.npz`, SMPL-H or SMPL-X, of the subject's gender) an AMASS
    /// archive is read with (default: none, and an AMASS archive is an error saying which
    /// model it needs).
    pub body_model: Option<PathBuf>,
}

impl Default for MotionOptions {
    fn default() -> Self {
        Self {
            units: Units::Auto,
            up: UpChoice::Auto,
            skeleton: None,
            format: None,
            body_map: None,
            max_gap: DEFAULT_MAX_GAP,
            amc_frame_rate: AMC_DEFAULT_RATE,
            limits: crate::resources::ReadLimits::default(),
            body_model: None,
        }
    }
}

/// What a file holds, in its own units and axes.
#[derive(Debug, Clone, PartialEq)]
pub enum MotionContent {
    /// A skeleton and its poses.
    Skeleton(Clip),
    /// Marker or point trajectories.
    Markers(MarkerSet),
}

/// A loaded motion: what the file holds, its body map, and the units and up axis used.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// The file.
    pub source: String,
    /// Its format.
    pub format: MotionFormat,
    /// Its content in file units and axes.
    pub content: MotionContent,
    /// The body map given or recognised; the recognition error if neither.
    pub body_map: Result<BodyMap>,
    /// The unit.
    pub units: UnitsDecision,
    /// The up axis.
    pub up: UpDecision,
}

impl Motion {
    /// The body keypoints (errors if no body map could be found).
    pub fn keypoints(&self, max_gap: f64) -> Result<Keypoints> {
        let map = self.body_map.as_ref().map_err(Clone::clone)?;
        match &self.content {
            MotionContent::Skeleton(clip) => clip_keypoints(clip, map, self.units, self.up),
            MotionContent::Markers(m) => marker_keypoints(m, map, self.units, self.up, max_gap),
        }
    }

    /// The skeleton clip in metres with its decided up axis (`None` for marker data).
    pub fn clip(&self) -> Option<Result<Clip>> {
        match &self.content {
            MotionContent::Skeleton(clip) => Some(scale_clip(
                clip,
                self.units.unit.metres_per_unit(),
                self.up.up,
            )),
            MotionContent::Markers(_) => None,
        }
    }

    /// A few lines: source, format, units, up, body map status.
    pub fn summary(&self) -> String {
        let map = match &self.body_map {
            Ok(m) => format!("{} body points mapped", m.points.len()),
            Err(e) => format!("body points not recognised: {e}"),
        };
        format!(
            "{} ({}): units {}; up {}; {map}",
            self.source,
            self.format.name(),
            self.units,
            self.up
        )
    }
}

/// A clip with every length scaled by `s` \[m/unit\] and the given up axis.
pub fn scale_clip(clip: &Clip, s: f64, up: UpAxis) -> Result<Clip> {
    let joints: Vec<SkeletonJoint> = clip
        .skeleton()
        .joints()
        .iter()
        .map(|j| SkeletonJoint {
            offset: j.offset * s,
            ..j.clone()
        })
        .collect();
    let frames: Vec<Pose> = clip
        .frames()
        .iter()
        .map(|p| Pose {
            root_position: p.root_position * s,
            root_orientation: p.root_orientation,
            rotations: p.rotations.clone(),
            translations: p.translations.iter().map(|t| t * s).collect(),
        })
        .collect();
    Clip::new(
        clip.name(),
        Skeleton::new(joints)?,
        clip.times().to_vec(),
        frames,
        up,
    )
}

fn io_error(path: &Path, e: std::io::Error) -> Error {
    Error::Parse {
        source_name: path.display().to_string(),
        line: 0,
        message: format!("cannot read the file: {e}"),
    }
}

/// The UTF-8 byte-order mark some editors write at the start of a text file.
const BOM: &str = "\u{feff}";

/// `text` without a leading UTF-8 byte-order mark.
pub fn strip_bom(text: &str) -> &str {
    text.strip_prefix(BOM).unwrap_or(text)
}

/// How many bytes at the end of a file [`is_amass_archive`] searches: a zip's directory of a
/// few members and its end record, whose comment may take up to 65 535 bytes.
const ZIP_TAIL: usize = 70_000;

/// How many bytes at the start of a file [`is_amass_archive`] searches (the first members'
/// local headers, when the directory at the end is missing).
const ZIP_HEAD: usize = 4_096;

/// Whether a file whose first bytes are `head` and last bytes `tail` looks like an AMASS
/// archive: a zip (`PK\x03\x04`) naming the members `poses.npy` and `trans.npy` (searched
/// in the first [`ZIP_HEAD`] and last [`ZIP_TAIL`] bytes).
fn amass_signature(head: &[u8], tail: &[u8]) -> bool {
    let names = |b: &[u8]| {
        let has = |n: &[u8]| b.windows(n.len()).any(|w| w == n);
        has(b"poses.npy") && has(b"trans.npy")
    };
    head.starts_with(b"PK\x03\x04")
        && (names(&tail[tail.len().saturating_sub(ZIP_TAIL)..])
            || names(&head[..head.len().min(ZIP_HEAD)]))
}

/// Whether `bytes` look like an AMASS archive (see the module documentation).
pub fn is_amass_archive(bytes: &[u8]) -> bool {
    amass_signature(bytes, bytes)
}

/// Whether the file at `path` looks like an AMASS archive, reading only its first and last
/// bytes (see the module documentation); `false` when it cannot be read.
pub fn is_amass_file(path: &Path) -> bool {
    use std::io::{Read, Seek, SeekFrom};
    let read = || -> std::io::Result<bool> {
        let mut f = std::fs::File::open(path)?;
        let len = f.metadata()?.len();
        let mut head = Vec::new();
        (&mut f).take(ZIP_HEAD as u64).read_to_end(&mut head)?;
        f.seek(SeekFrom::Start(len.saturating_sub(ZIP_TAIL as u64)))?;
        let mut tail = Vec::new();
        f.take(ZIP_TAIL as u64).read_to_end(&mut tail)?;
        Ok(amass_signature(&head, &tail))
    };
    read().unwrap_or(false)
}

/// The format a file's content shows, if any (a leading UTF-8 byte-order mark is skipped).
pub fn detect_format(bytes: &[u8]) -> Option<MotionFormat> {
    if is_amass_archive(bytes) {
        return Some(MotionFormat::Amass);
    }
    if bytes.len() >= 512 && bytes.get(1) == Some(&0x50) && bytes[0] < 0x20 {
        return Some(MotionFormat::C3d);
    }
    let bytes = bytes.strip_prefix(BOM.as_bytes()).unwrap_or(bytes);
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(4096)]);
    let mut lines = head
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'));
    let first = lines.next()?;
    if first.starts_with("HIERARCHY") {
        return Some(MotionFormat::Bvh);
    }
    let keyword = |l: &str, k: &[&str]| k.iter().any(|k| l.to_ascii_lowercase().starts_with(k));
    if keyword(
        first,
        &[
            ":version",
            ":name",
            ":units",
            ":root",
            ":bonedata",
            ":documentation",
        ],
    ) {
        return Some(MotionFormat::Asf);
    }
    if keyword(first, &[":fully-specified", ":degrees", ":radians"]) {
        return Some(MotionFormat::Amc);
    }
    if first.starts_with('{') && head.contains("\"Frames\"") {
        return Some(MotionFormat::DeepMimic);
    }
    let cols: Vec<&str> = first.split(',').map(str::trim).collect();
    if cols.len() >= 3
        && cols
            .iter()
            .any(|c| c.ends_with("_x") || c.ends_with("_X") || c.ends_with(".x"))
    {
        return Some(MotionFormat::PointsCsv);
    }
    None
}

fn format_from_extension(path: &Path) -> Option<MotionFormat> {
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    Some(match ext.as_str() {
        "bvh" => MotionFormat::Bvh,
        "asf" => MotionFormat::Asf,
        "amc" => MotionFormat::Amc,
        "txt" | "json" => MotionFormat::DeepMimic,
        "c3d" => MotionFormat::C3d,
        "csv" => MotionFormat::PointsCsv,
        "npz" => MotionFormat::Amass,
        _ => return None,
    })
}

const SIGNATURES: &str = "BVH `HIERARCHY`, ASF `:version`/`:units`/`:root`/`:bonedata`, AMC \
    `:FULLY-SPECIFIED`/`:DEGREES`, DeepMimic JSON with \"Frames\", C3D (second byte 0x50), CSV \
    header with `_x/_y/_z` columns, AMASS zip with `poses.npy` and `trans.npy`";

/// The ASF beside an AMC file: same stem, else the only `.asf` in its folder.
pub fn find_asf(amc: &Path) -> Result<PathBuf> {
    let dir = amc
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let is_asf = |p: &Path| {
        p.extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("asf"))
    };
    let entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| io_error(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| is_asf(p))
        .collect();
    let stem = amc.file_stem();
    if let Some(p) = entries.iter().find(|p| p.file_stem() == stem) {
        return Ok(p.clone());
    }
    match entries.as_slice() {
        [only] => Ok(only.clone()),
        _ => Err(Error::InsufficientData {
            what: format!("skeleton of `{}`", amc.display()),
            message: format!(
                "no `{}.asf` beside it and {} other .asf files in `{}`; give the skeleton (--skeleton FILE.asf)",
                stem.map(|s| s.to_string_lossy()).unwrap_or_default(),
                entries.len(),
                dir.display()
            ),
        }),
    }
}

/// Reads a motion file of any supported format (see the module documentation).
pub fn load_motion(path: &Path, options: &MotionOptions) -> Result<Motion> {
    let bytes = std::fs::read(path).map_err(|e| io_error(path, e))?;
    let source = path.display().to_string();
    let by_content = detect_format(&bytes);
    let by_extension = format_from_extension(path);
    let format = options
        .format
        .or(by_content)
        .or(by_extension)
        .ok_or_else(|| Error::Parse {
            source_name: source.clone(),
            line: 0,
            message: format!(
                "unknown motion format: the extension is not one of .bvh .asf .amc .txt .json \
                 .c3d .csv .npz and the content matched none of: {SIGNATURES}"
            ),
        })?;
    let content = read_content(path, &bytes, format, options).map_err(|e| {
        if options.format.is_none() && by_content.is_none() {
            Error::Parse {
                source_name: source.clone(),
                line: 0,
                message: format!(
                    "read as {} because of the extension (its content matched none of: \
                     {SIGNATURES}): {e}",
                    format.name()
                ),
            }
        } else {
            e
        }
    })?;
    motion_from_content(source, format, content, options)
}

fn read_content(
    path: &Path,
    bytes: &[u8],
    format: MotionFormat,
    options: &MotionOptions,
) -> Result<MotionContent> {
    let source = path.display().to_string();
    let text = || {
        std::str::from_utf8(bytes)
            .map(strip_bom)
            .map_err(|e| Error::Parse {
                source_name: source.clone(),
                line: 1 + bytes
                    .get(..e.valid_up_to())
                    .map_or(0, |b| b.iter().filter(|c| **c == b'\n').count()),
                message: format!("{} files are text; this one is not UTF-8", format.name()),
            })
    };
    Ok(match format {
        MotionFormat::Bvh => MotionContent::Skeleton(
            super::read_bvh(
                text()?,
                &source,
                &BvhReadOptions {
                    length_unit: LengthUnit::Metres,
                    up_axis: UpAxis::Y,
                    limits: options.limits,
                },
            )?
            .to_clip()?,
        ),
        MotionFormat::DeepMimic => MotionContent::Skeleton(super::read_deepmimic_with(
            text()?,
            &source,
            &super::DeepMimicSettings {
                limits: options.limits,
                ..Default::default()
            },
        )?),
        MotionFormat::Asf => {
            let asf = super::asf::read_asf(text()?, &source)?;
            MotionContent::Skeleton(asf.rest_clip()?)
        }
        MotionFormat::Amc => {
            let asf_path = match &options.skeleton {
                Some(p) => p.clone(),
                None => find_asf(path)?,
            };
            let asf_text =
                std::fs::read_to_string(&asf_path).map_err(|e| io_error(&asf_path, e))?;
            let asf = super::asf::read_asf(strip_bom(&asf_text), &asf_path.display().to_string())?;
            MotionContent::Skeleton(super::amc::read_amc(
                text()?,
                &source,
                &asf,
                options.amc_frame_rate,
            )?)
        }
        MotionFormat::C3d => MotionContent::Markers(super::c3d::read_c3d(bytes, &source)?),
        MotionFormat::PointsCsv => {
            MotionContent::Markers(super::points_csv::read_points_csv(text()?, &source)?)
        }
        #[cfg(feature = "amass")]
        MotionFormat::Amass => MotionContent::Skeleton(super::amass::read_amass(
            bytes,
            &source,
            options.body_model.as_deref(),
            &options.limits,
        )?),
        #[cfg(not(feature = "amass"))]
        MotionFormat::Amass => {
            return Err(Error::Parse {
                source_name: source,
                line: 0,
                message: "AMASS archives need iktc built with its `amass` feature".to_string(),
            })
        }
    })
}

/// `head − (left ankle + right ankle)/2` from a point lookup, if all three are found.
fn ankles_to_head(at: impl Fn(BodyPoint) -> Option<Vector3<f64>>) -> Option<Vector3<f64>> {
    Some(at(BodyPoint::Head)? - (at(BodyPoint::LeftAnkle)? + at(BodyPoint::RightAnkle)?) / 2.0)
}

/// The ankles-to-head vector (if the body map gives them) and all points \[file units\].
type Points = (Option<Vector3<f64>>, Vec<Vector3<f64>>);

/// [`Points`] and the posture they were measured on.
type RestMeasure = (Option<Vector3<f64>>, Vec<Vector3<f64>>, Measured);

/// Measurements for the automatic decisions: the ankles-to-head vector and all points
/// \[file units\] of a skeleton's rest pose, or of its first frame when the rest pose does not
/// stand along +Y or +Z and the first frame does (some rigs lie along +X at rest and are
/// rotated upright in every frame: Bandai Namco's motion dataset); of a marker file's most
/// complete frame.
fn rest_measure(content: &MotionContent, map: Option<&BodyMap>) -> Result<RestMeasure> {
    match content {
        MotionContent::Skeleton(clip) => {
            let skeleton = clip.skeleton();
            let measure = |pose: &Pose| -> Result<Points> {
                let mut world = vec![Isometry3::identity(); skeleton.len()];
                skeleton.world_transforms(pose, &mut world)?;
                let all: Vec<Vector3<f64>> = world.iter().map(|t| t.translation.vector).collect();
                let at = |p: BodyPoint| match map.and_then(|m| m.get(p)) {
                    Some(PointSource::Joint(name)) => skeleton.index_of(name).ok().map(|j| all[j]),
                    _ => None,
                };
                Ok((ankles_to_head(at), all))
            };
            let (v, all) = measure(&skeleton.rest_pose())?;
            if v.as_ref().is_some_and(|v| !stands(v)) {
                if let Some(first) = clip.frame(0) {
                    let (f, all_f) = measure(first)?;
                    if f.as_ref().is_some_and(stands) {
                        return Ok((f, all_f, Measured::FirstFrame));
                    }
                }
            }
            Ok((v, all, Measured::RestPose))
        }
        MotionContent::Markers(m) => {
            let f = m.most_complete_frame();
            let n = m.names.len();
            let frame: Vec<Option<Vector3<f64>>> = (0..n)
                .map(|k| m.positions.get(f * n + k).copied().flatten())
                .collect();
            let all: Vec<Vector3<f64>> = frame.iter().flatten().copied().collect();
            let at = |p: BodyPoint| -> Option<Vector3<f64>> {
                let names: Vec<&String> = match map?.get(p)? {
                    PointSource::Markers(g) => g.iter().collect(),
                    PointSource::Joint(j) => vec![j],
                };
                let pts: Vec<Vector3<f64>> = names
                    .iter()
                    .filter_map(|name| m.names.iter().position(|x| x == *name))
                    .filter_map(|k| frame.get(k).copied().flatten())
                    .collect();
                (!pts.is_empty()).then(|| pts.iter().sum::<Vector3<f64>>() / pts.len() as f64)
            };
            Ok((ankles_to_head(at), all, Measured::MostCompleteFrame))
        }
    }
}

/// Finds the body map and decides units and up axis for content already read, and checks
/// that the content is a plausible human capture ([`plausible`](super::plausible)): frame
/// times, standing height in the decided unit, and (with a body map) the body points'
/// distances and speeds.
pub fn motion_from_content(
    source: String,
    format: MotionFormat,
    content: MotionContent,
    options: &MotionOptions,
) -> Result<Motion> {
    let body_map = match &options.body_map {
        Some(m) => Ok(m.clone()),
        None => match &content {
            MotionContent::Skeleton(clip) => recognise_skeleton(clip.skeleton(), &source),
            MotionContent::Markers(m) => recognise_markers(&m.names, &source),
        },
    };
    let (ankles_to_head, rest, measured_on) = rest_measure(&content, body_map.as_ref().ok())?;
    if options.up == UpChoice::Auto && format.fixed_frame().is_none() && ankles_to_head.is_none() {
        // The recognition error says what is missing and how to write a map.
        body_map.clone()?;
    }
    let up = match (format.fixed_frame(), options.up) {
        (Some((_, up)), UpChoice::Auto) => UpDecision {
            up,
            automatic: true,
            measured_on: Measured::Format,
        },
        _ => decide_up(options.up, ankles_to_head, measured_on, &source)?,
    };
    let units = match (format.fixed_frame(), options.units) {
        (Some((unit, _)), Units::Auto) => UnitsDecision {
            unit,
            automatic: true,
            standing_height: None,
        },
        _ => decide_units(options.units, extent_along(&rest, up.up), &source)?,
    };
    let times = match &content {
        MotionContent::Skeleton(clip) => clip.times(),
        MotionContent::Markers(m) => &m.times,
    };
    plausible::check_frame_times(&source, times)?;
    if let Some(v) = ankles_to_head {
        let metres = v * units.unit.metres_per_unit();
        plausible::check_standing_height(&source, &metres, &units.to_string())?;
    }
    let motion = Motion {
        source,
        format,
        content,
        body_map,
        units,
        up,
    };
    // Keypoints that cannot be formed (no body map, a marker gap too long) give their own
    // error where they are asked for.
    if let Ok(kp) = motion.keypoints(options.max_gap) {
        plausible::check_keypoints(&kp)?;
    }
    Ok(motion)
}
