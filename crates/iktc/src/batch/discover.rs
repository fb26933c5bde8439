//! Finding the clips of a batch: motion files named directly, folders searched recursively,
//! and glob patterns ([`discover`]).
//!
//! A folder walk follows symbolic links but enters each real folder once (by its canonical
//! path), so a link cycle ends; a real file reached under several names is taken once, under
//! the first name in sorted order. An entry that cannot be read (a folder whose listing
//! fails, a dangling link) is reported by name in [`Discovery::problems`] and the walk goes
//! on with the others. Folders of iktc's own output ([`is_output_folder`]) are not searched.
//!
//! AMASS archives (`.npz`) are taken from folders only when asked ([`discover_motions`], the
//! CLI's `--body-model`), and only those whose zip directory names `poses.npy` and
//! `trans.npy` ([`is_amass_file`](crate::motion::is_amass_file)): the NPZ files iktc writes,
//! body model files and other arrays beside the clips are left out, as they are from the
//! matches of a glob pattern.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use crate::profile::glob_match;

/// Motion file extensions taken from folders (lower case; matched without regard to case).
/// CSV files of named points are read when named, not taken from folders, where CSV files of
/// other kinds are common.
pub const MOTION_EXTENSIONS: [&str; 5] = ["bvh", "amc", "c3d", "txt", "json"];

/// The file that marks a finished clip's folder ([`super::record`]).
pub const RECORD_FILE: &str = ".record";

/// The marker file of clip folders written by earlier versions of iktc.
const LEGACY_MARKER: &str = ".settings";

/// One input clip: its file and its output name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ClipInput {
    /// The motion file, as found (a link is not resolved).
    pub path: PathBuf,
    /// Output name: the path relative to the folder searched (or the file name of a file
    /// given directly), without extension, `/` between folders.
    pub name: String,
}

/// An input, or an entry under one, that gave no clip.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DiscoveryProblem {
    /// The input, or the entry under a folder, it concerns.
    pub path: String,
    /// What is wrong.
    pub message: String,
}

/// What [`discover`] found.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Discovery {
    /// The clips, each real file once, in the inputs' order (a folder's in sorted order).
    pub clips: Vec<ClipInput>,
    /// Every input that names no clip, every entry that could not be read, every clip whose
    /// output name another clip already took.
    pub problems: Vec<DiscoveryProblem>,
    /// Folders of iktc's output that were not searched.
    pub output_folders: Vec<PathBuf>,
}

/// The extension of the AMASS archives [`discover_motions`] takes from folders when asked.
pub const ARCHIVE_EXTENSION: &str = "npz";

/// Whether `p` has one of the [`MOTION_EXTENSIONS`].
pub fn is_motion_file(p: &Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| MOTION_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}

/// Whether `p` is an AMASS archive: the extension [`ARCHIVE_EXTENSION`] and a zip naming
/// `poses.npy` and `trans.npy` ([`is_amass_file`](crate::motion::is_amass_file)).
pub fn is_archive_file(p: &Path) -> bool {
    has_archive_extension(p) && crate::motion::is_amass_file(p)
}

fn has_archive_extension(p: &Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case(ARCHIVE_EXTENSION))
}

/// Whether `dir` holds what iktc writes: the batch's output folder `out`, a folder of an
/// earlier batch (its `batch.json`) or of one of its clips (its [`RECORD_FILE`] or the marker
/// of earlier versions), or the output of `iktc imitate` (its `keypoints_summary.json`).
pub fn is_output_folder(dir: &Path, out: Option<&Path>) -> bool {
    let same = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    };
    out.is_some_and(|o| same(dir, o))
        || [
            "batch.json",
            RECORD_FILE,
            LEGACY_MARKER,
            "keypoints_summary.json",
        ]
        .iter()
        .any(|f| dir.join(f).is_file())
}

/// `path` relative to `base`, without its extension, with `/` separators.
pub fn clip_name(path: &Path, base: &Path) -> String {
    let rel = path.strip_prefix(base).unwrap_or(path).with_extension("");
    rel.components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/")
}

/// Lists a folder's entries (paths), as [`std::fs::read_dir`]; a test can put another in.
type ReadDir<'a> = &'a dyn Fn(&Path) -> std::io::Result<Vec<std::io::Result<PathBuf>>>;

fn read_dir(dir: &Path) -> std::io::Result<Vec<std::io::Result<PathBuf>>> {
    Ok(std::fs::read_dir(dir)?
        .map(|e| e.map(|e| e.path()))
        .collect())
}

/// One folder walk's state: the real folders entered, and what was found.
struct Walk<'a> {
    out: Option<&'a Path>,
    read: ReadDir<'a>,
    entered: HashSet<PathBuf>,
    files: Vec<PathBuf>,
    problems: Vec<DiscoveryProblem>,
    output_folders: Vec<PathBuf>,
}

impl Walk<'_> {
    fn problem(&mut self, p: &Path, message: String) {
        self.problems.push(DiscoveryProblem {
            path: p.display().to_string(),
            message,
        });
    }

    /// Every file under `dir`, sorted, recursively; each real folder entered once.
    fn folder(&mut self, dir: &Path) {
        let real = match dir.canonicalize() {
            Ok(r) => r,
            Err(e) => return self.problem(dir, format!("cannot read the folder: {e}")),
        };
        if !self.entered.insert(real) {
            return;
        }
        let entries = match (self.read)(dir) {
            Ok(e) => e,
            Err(e) => return self.problem(dir, format!("cannot read the folder: {e}")),
        };
        let mut paths = Vec::with_capacity(entries.len());
        for e in entries {
            match e {
                Ok(p) => paths.push(p),
                Err(e) => self.problem(dir, format!("cannot read an entry of the folder: {e}")),
            }
        }
        paths.sort();
        for p in paths {
            match std::fs::metadata(&p) {
                Ok(m) if m.is_dir() => {
                    if is_output_folder(&p, self.out) {
                        self.output_folders.push(p);
                    } else {
                        self.folder(&p);
                    }
                }
                Ok(_) => self.files.push(p),
                Err(e) => self.problem(&p, format!("cannot read the entry: {e}")),
            }
        }
    }
}

/// The clips the `inputs` name: files, folders (searched recursively for
/// [`MOTION_EXTENSIONS`]) and glob patterns (`*` and `?`, `*` crossing folders, searched from
/// the folder before the first wildcard). Folders of iktc's output ([`is_output_folder`],
/// `out` the batch's own) are not searched. Each real file gives one clip, under the first
/// name it is found by; a second file whose output name is taken is a problem, as is every
/// input that names no clip and every entry that cannot be read.
pub fn discover(inputs: &[String], out: Option<&Path>) -> Discovery {
    discover_with(inputs, out, false, &read_dir)
}

/// [`discover`], and with `archives` also the AMASS archives found in folders and patterns
/// ([`is_archive_file`]; read with a body model).
pub fn discover_motions(inputs: &[String], out: Option<&Path>, archives: bool) -> Discovery {
    discover_with(inputs, out, archives, &read_dir)
}

fn discover_with(
    inputs: &[String],
    out: Option<&Path>,
    archives: bool,
    read: ReadDir<'_>,
) -> Discovery {
    let mut found = Discovery::default();
    let mut seen: HashSet<PathBuf> = HashSet::new();
    for input in inputs {
        let mut walk = Walk {
            out,
            read,
            entered: HashSet::new(),
            files: Vec::new(),
            problems: Vec::new(),
            output_folders: Vec::new(),
        };
        let clips = input_clips(input, &mut walk, archives);
        let named_none = clips.is_empty();
        found.problems.append(&mut walk.problems);
        found.output_folders.append(&mut walk.output_folders);
        if named_none && !found.problems.iter().any(|p| p.path == *input) {
            let archive = if archives {
                format!(", AMASS .{ARCHIVE_EXTENSION}")
            } else {
                String::new()
            };
            found.problems.push(DiscoveryProblem {
                path: input.clone(),
                message: format!(
                    "no motion file (.{}{archive}) found",
                    MOTION_EXTENSIONS.join(", .")
                ),
            });
        }
        for c in clips {
            add_clip(&mut found, &mut seen, c);
        }
    }
    found
}

/// Adds `c` unless its real file was taken; a name taken by another file is a problem.
fn add_clip(found: &mut Discovery, seen: &mut HashSet<PathBuf>, c: ClipInput) {
    let real = c.path.canonicalize().unwrap_or_else(|_| c.path.clone());
    if !seen.insert(real) {
        return;
    }
    if let Some(other) = found.clips.iter().find(|o| o.name == c.name) {
        found.problems.push(DiscoveryProblem {
            path: c.path.display().to_string(),
            message: format!(
                "its output name `{}` is taken by {}",
                c.name,
                other.path.display()
            ),
        });
        return;
    }
    found.clips.push(c);
}

/// The clips of one input, its unreadable entries left in `walk.problems`.
fn input_clips(input: &str, walk: &mut Walk<'_>, archives: bool) -> Vec<ClipInput> {
    let p = Path::new(input);
    let taken = |f: &Path| is_motion_file(f) || (archives && is_archive_file(f));
    if p.is_file() {
        return vec![ClipInput {
            path: p.to_path_buf(),
            name: clip_name(p, p.parent().unwrap_or(Path::new(""))),
        }];
    }
    if p.is_dir() {
        walk.folder(p);
        return std::mem::take(&mut walk.files)
            .into_iter()
            .filter(|f| taken(f))
            .map(|f| ClipInput {
                name: clip_name(&f, p),
                path: f,
            })
            .collect();
    }
    if !input.contains(['*', '?']) {
        walk.problem(p, "no such file or folder".into());
        return Vec::new();
    }
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
    walk.folder(&root);
    std::mem::take(&mut walk.files)
        .into_iter()
        .filter(|f| {
            // A pattern's `.npz` matches that are no AMASS archive (body models, iktc's
            // own arrays) are left out.
            if has_archive_extension(f) && !is_archive_file(f) {
                return false;
            }
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
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("iktc-discover-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// A folder whose listing fails (injected: the tests run with every permission) is named
    /// with its error, and the clips of the other folders are still found.
    #[test]
    fn an_unreadable_folder_is_named_and_the_others_kept() {
        let d = tmp("unreadable");
        for sub in ["a", "b", "c"] {
            std::fs::create_dir_all(d.join(sub)).unwrap();
            std::fs::write(d.join(sub).join("clip.bvh"), "x").unwrap();
        }
        let refuse = |p: &Path| {
            if p.ends_with("b") {
                Err(std::io::Error::new(
                    std::io::ErrorKind::PermissionDenied,
                    "injected refusal",
                ))
            } else {
                read_dir(p)
            }
        };
        let found = discover_with(&[d.display().to_string()], None, false, &refuse);
        let names: Vec<&str> = found.clips.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["a/clip", "c/clip"]);
        assert_eq!(found.problems.len(), 1, "{:?}", found.problems);
        assert_eq!(found.problems[0].path, d.join("b").display().to_string());
        assert!(found.problems[0].message.contains("injected refusal"));
    }

    /// Motion files by extension, in any case; a folder's other files are not clips.
    #[test]
    fn only_motion_files_are_taken_from_folders() {
        for yes in ["a.bvh", "A.BVH", "x.Txt", "d/x.json", "m.amc", "c.C3d"] {
            assert!(is_motion_file(Path::new(yes)), "{yes}");
        }
        for no in ["p.csv", "bvh", "x.bvh.bak", ".bvh", "x.", "x.npz"] {
            assert!(!is_motion_file(Path::new(no)), "{no}");
        }
        let d = tmp("kinds");
        for f in ["clip.bvh", "notes.csv", "README", "motion.npz"] {
            std::fs::write(d.join(f), "x").unwrap();
        }
        let found = discover(&[d.display().to_string()], None);
        let names: Vec<&str> = found.clips.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["clip"]);
        assert!(found.problems.is_empty(), "{:?}", found.problems);
    }

    /// AMASS archives are taken from folders when asked, and only they among `.npz` files:
    /// not a body model, not iktc's own arrays (in a clip folder of an earlier batch, or
    /// beside the clips).
    #[test]
    fn amass_archives_are_taken_when_asked_and_other_npz_files_never() {
        use super::super::npz::{npz_bytes, NpyArray};
        let d = tmp("amass");
        let array = |name: &str| NpyArray::f64(name, vec![1, 3], vec![0.0; 3]);
        let archive = npz_bytes(&[array("trans"), array("poses")]).unwrap();
        let other = npz_bytes(&[array("v_template"), array("J_regressor")]).unwrap();
        std::fs::create_dir_all(d.join("old")).unwrap();
        std::fs::write(d.join("old").join(RECORD_FILE), "x").unwrap();
        std::fs::write(d.join("old").join("motion.npz"), &archive).unwrap();
        std::fs::write(d.join("walk.npz"), &archive).unwrap();
        std::fs::write(d.join("SMPLX_NEUTRAL.npz"), &other).unwrap();
        std::fs::write(d.join("motion.npz"), &other).unwrap();
        std::fs::write(d.join("clip.bvh"), "x").unwrap();
        let names = |found: &Discovery| -> Vec<String> {
            found.clips.iter().map(|c| c.name.clone()).collect()
        };
        let inputs = [d.display().to_string()];
        assert_eq!(names(&discover(&inputs, None)), ["clip"]);
        let found = discover_motions(&inputs, None, true);
        assert_eq!(names(&found), ["clip", "walk"]);
        assert_eq!(found.output_folders, [d.join("old")]);
        let pattern = [format!("{}/*.npz", d.display())];
        assert_eq!(names(&discover_motions(&pattern, None, true)), ["walk"]);
        assert!(is_archive_file(&d.join("walk.npz")));
        assert!(!is_archive_file(&d.join("SMPLX_NEUTRAL.npz")));
    }

    /// The batch's own output folder inside an input folder is not searched, even before it
    /// holds any marker; its sibling folders are.
    #[test]
    fn the_batchs_own_output_folder_is_not_searched() {
        let d = tmp("own-out");
        for sub in ["out", "sub"] {
            std::fs::create_dir_all(d.join(sub)).unwrap();
            std::fs::write(d.join(sub).join("clip.bvh"), "x").unwrap();
        }
        let out = d.join("out");
        assert!(is_output_folder(&out, Some(&out)));
        assert!(!is_output_folder(&d.join("sub"), Some(&out)));
        assert!(!is_output_folder(&out, Some(&d.join("missing"))));
        let found = discover(&[d.display().to_string()], Some(&out));
        let names: Vec<&str> = found.clips.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["sub/clip"]);
        assert_eq!(found.output_folders, [out]);
    }

    /// An input that names no clip gives one problem naming it: a missing path its error, a
    /// folder without motion files that none was found; each problem is the input's own.
    #[test]
    fn each_input_that_names_no_clip_is_one_problem() {
        let d = tmp("none");
        std::fs::write(d.join("notes.csv"), "x").unwrap();
        let missing = d.join("missing.bvh").display().to_string();
        let empty = d.display().to_string();
        let found = discover(&[missing.clone(), empty.clone()], None);
        assert!(found.clips.is_empty());
        let problems: Vec<(&str, &str)> = found
            .problems
            .iter()
            .map(|p| (p.path.as_str(), p.message.as_str()))
            .collect();
        assert_eq!(
            problems,
            [
                (missing.as_str(), "no such file or folder"),
                (
                    empty.as_str(),
                    "no motion file (.bvh, .amc, .c3d, .txt, .json) found"
                )
            ]
        );
    }

    /// A glob pattern is searched from the folder before its first wildcard, `*` crossing
    /// folders and `?` one character; the names are relative to that folder.
    #[test]
    fn glob_patterns_search_from_the_folder_before_the_first_wildcard() {
        let d = tmp("glob");
        for f in ["top.bvh", "a/x.bvh", "a/y.txt", "b/z.bvh", "bb/w.txt"] {
            std::fs::create_dir_all(d.join(f).parent().unwrap()).unwrap();
            std::fs::write(d.join(f), "x").unwrap();
        }
        let names = |pattern: &str| -> Vec<String> {
            let found = discover(&[format!("{}/{pattern}", d.display())], None);
            assert!(found.problems.is_empty(), "{pattern}: {:?}", found.problems);
            found.clips.into_iter().map(|c| c.name).collect()
        };
        assert_eq!(names("*.bvh"), ["a/x", "b/z", "top"]);
        assert_eq!(names("?/*.txt"), ["a/y"]);
        assert_eq!(names("b*/*"), ["b/z", "bb/w"]);
        let found = discover(&[format!("{}/*.amc", d.display())], None);
        assert!(found.clips.is_empty());
        assert_eq!(found.problems.len(), 1, "{:?}", found.problems);
        assert!(found.problems[0].message.contains("no motion file"));
    }

    /// An entry the listing cannot give (injected) is named by its folder; the rest is kept.
    #[test]
    fn an_unreadable_entry_is_named_by_its_folder() {
        let d = tmp("entry");
        std::fs::write(d.join("clip.bvh"), "x").unwrap();
        let broken = |p: &Path| {
            let mut v = read_dir(p)?;
            v.push(Err(std::io::Error::other("injected entry error")));
            Ok(v)
        };
        let found = discover_with(&[d.display().to_string()], None, false, &broken);
        assert_eq!(found.clips.len(), 1);
        assert_eq!(found.problems.len(), 1);
        assert_eq!(found.problems[0].path, d.display().to_string());
        assert!(found.problems[0].message.contains("injected entry error"));
    }
}
