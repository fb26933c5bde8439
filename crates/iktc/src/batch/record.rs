//! The record of a finished clip, and writing a clip's folder whole.
//!
//! A clip's outputs depend on its input file, the robot (its URDF, the mesh files the URDF
//! names, the profile and the maps it names), the settings and the program's version. The
//! record is the SHA-256 digest of all of them ([`BatchRetarget::dependency_digest`] for what
//! the clips share, [`clip_record`] with the input's bytes); a clip is done when its folder's
//! [`RECORD_FILE`] holds that digest and every output is there ([`is_done`]); a batch run
//! again skips it ([`clip_state`]). File times play no part: a changed file changes the digest whatever its time, and a touched one does not.
//!
//! A clip's folder is written as a temporary folder beside it and renamed into place whole
//! ([`write_clip_folder`]), the record written last: a clip that fails, or a batch that is
//! killed, leaves no folder that reads as finished.

use std::fmt::Write as _;
use std::io;
use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

pub use super::discover::RECORD_FILE;
use super::retarget::BatchRetarget;
use crate::error::{Error, Result};
use crate::profile::ProfileOrigin;

/// Version of the record's layout: changing what is digested changes it.
const RECORD_LAYOUT: &str = "iktc clip record 1";

fn hex(bytes: &[u8]) -> String {
    bytes.iter().fold(String::with_capacity(64), |mut s, b| {
        let _ = write!(s, "{b:02x}");
        s
    })
}

/// Feeds one named part to the digest: its name, its length in bytes and its bytes, so that
/// no two different lists of parts feed the same bytes.
fn part(h: &mut Sha256, name: &str, bytes: &[u8]) {
    h.update((name.len() as u64).to_le_bytes());
    h.update(name.as_bytes());
    h.update((bytes.len() as u64).to_le_bytes());
    h.update(bytes);
}

impl BatchRetarget {
    /// The SHA-256 digest (64 hex digits) of what every clip's outputs depend on besides its
    /// input: the program's version and [`Self::settings_text`] (method, profile, map,
    /// settings, rate), the maps the profile names (read now), the URDF's text, the bytes
    /// of every mesh file it names and those of the body model AMASS archives are read with
    /// (a file that cannot be read enters as its error).
    ///
    /// Errors: those of reading the URDF ([`crate::profile::RobotProfile::urdf_text`]).
    pub fn dependency_digest(&self) -> Result<String> {
        let mut h = Sha256::new();
        part(&mut h, "layout", RECORD_LAYOUT.as_bytes());
        part(&mut h, "version", env!("CARGO_PKG_VERSION").as_bytes());
        part(&mut h, "settings", self.settings_text().as_bytes());
        for key in self.profile.imitate.maps.keys() {
            let map = match self.profile.retarget_map(key, &self.robot) {
                Ok(m) => format!("{m:?}"),
                Err(e) => format!("error: {e}"),
            };
            part(&mut h, &format!("map {key}"), map.as_bytes());
        }
        if let Some(model) = &self.motion_options.body_model {
            let bytes = std::fs::read(model).unwrap_or_else(|e| format!("{e}").into_bytes());
            part(&mut h, &format!("body model {}", model.display()), &bytes);
        }
        let urdf = self.profile.urdf_text()?;
        part(&mut h, "urdf", urdf.as_bytes());
        if let ProfileOrigin::Directory(dir) = &self.profile.origin {
            let path = dir.join(&self.profile.urdf);
            let folder = path.parent().unwrap_or(Path::new("."));
            for mesh in mesh_files(&urdf, folder) {
                let bytes = std::fs::read(&mesh).unwrap_or_else(|e| format!("{e}").into_bytes());
                part(&mut h, &format!("mesh {}", mesh.display()), &bytes);
            }
        }
        Ok(hex(&h.finalize()))
    }
}

/// The files of the `<mesh filename>`s of the URDF `text` whose folder is `dir`, as the
/// viewer finds them ([`crate::mesh::urdf::resolve`]); none if the URDF cannot be read.
fn mesh_files(text: &str, dir: &Path) -> Vec<PathBuf> {
    let Ok(u) =
        crate::model::read_description(text, Some(dir), &crate::resources::ReadLimits::default())
    else {
        return Vec::new();
    };
    u.links
        .iter()
        .flat_map(|l| &l.visual)
        .filter_map(|v| match &v.geometry {
            urdf_rs::Geometry::Mesh { filename, .. } => {
                Some(crate::mesh::urdf::resolve(filename, dir))
            }
            _ => None,
        })
        .collect()
}

/// The record of the clip read from `input` under a batch whose
/// [`BatchRetarget::dependency_digest`] is `dependencies`: the SHA-256 digest (64 hex digits)
/// of both and of the input file's bytes.
///
/// Errors: [`Error::Parse`] naming the input if it cannot be read.
pub fn clip_record(dependencies: &str, input: &Path) -> Result<String> {
    let bytes = std::fs::read(input).map_err(|e| Error::Parse {
        source_name: input.display().to_string(),
        line: 0,
        message: format!("cannot read the motion file: {e}"),
    })?;
    let mut h = Sha256::new();
    part(&mut h, "layout", RECORD_LAYOUT.as_bytes());
    part(&mut h, "dependencies", dependencies.as_bytes());
    part(&mut h, "input", &bytes);
    Ok(hex(&h.finalize()))
}

/// Whether the clip folder `dir` is finished for `record`: its [`RECORD_FILE`] holds `record`
/// and every file of `outputs` (names in `dir`) is there.
pub fn is_done(dir: &Path, record: &str, outputs: &[&str]) -> bool {
    std::fs::read_to_string(dir.join(RECORD_FILE)).is_ok_and(|s| s.trim() == record)
        && outputs.iter().all(|o| dir.join(o).is_file())
}

/// What a batch does with a clip found again: skip it or run it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ClipState {
    /// Its folder is finished for its current record ([`is_done`]): skipped.
    Done,
    /// To run (never run, its input or the batch's dependencies changed since, its folder
    /// incomplete, or forced); the record to write when its folder is whole.
    ToRun(String),
}

/// Whether the clip read from `input`, whose folder is `dir`, is [`ClipState::Done`] under a
/// batch whose [`BatchRetarget::dependency_digest`] is `dependencies` and which writes the
/// files `outputs` (names in `dir`), or still to run. `force` runs every clip.
///
/// Errors: those of [`clip_record`] (the input cannot be read).
pub fn clip_state(
    dependencies: &str,
    input: &Path,
    dir: &Path,
    outputs: &[&str],
    force: bool,
) -> Result<ClipState> {
    let record = clip_record(dependencies, input)?;
    Ok(if !force && is_done(dir, &record, outputs) {
        ClipState::Done
    } else {
        ClipState::ToRun(record)
    })
}

/// The name of a temporary sibling of `dir` (`.NAME.PID.KIND`).
fn sibling(dir: &Path, kind: &str) -> PathBuf {
    let name = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    dir.with_file_name(format!(".{name}.{}.{kind}", std::process::id()))
}

fn with_path(e: io::Error, what: &str, p: &Path) -> io::Error {
    io::Error::new(e.kind(), format!("{what} {}: {e}", p.display()))
}

/// Writes the clip folder `dir` whole: `write` fills a fresh temporary folder beside `dir`
/// (`.NAME.PID.tmp`), `record` is written into it last ([`RECORD_FILE`]), then it replaces
/// `dir` (any earlier `dir` is renamed aside and removed). If `write` or any step fails, the
/// temporary folder is removed and the error returned; `dir` is then left as it was, or
/// missing if the failure came between the two renames — never holding part of this clip.
pub fn write_clip_folder<T, E: From<io::Error>>(
    dir: &Path,
    record: &str,
    write: impl FnOnce(&Path) -> std::result::Result<T, E>,
) -> std::result::Result<T, E> {
    let tmp = sibling(dir, "tmp");
    if let Some(parent) = dir.parent() {
        std::fs::create_dir_all(parent).map_err(|e| with_path(e, "creating", parent))?;
    }
    remove_any(&tmp).map_err(|e| with_path(e, "removing", &tmp))?;
    std::fs::create_dir(&tmp).map_err(|e| with_path(e, "creating", &tmp))?;
    let result = write(&tmp).and_then(|v| {
        let marker = tmp.join(RECORD_FILE);
        std::fs::write(&marker, format!("{record}\n"))
            .map_err(|e| with_path(e, "writing", &marker))?;
        replace(&tmp, dir)?;
        Ok(v)
    });
    if result.is_err() {
        let _ = remove_any(&tmp);
    }
    result
}

/// Renames the folder `from` to `to`, an earlier `to` renamed aside first and then removed.
fn replace(from: &Path, to: &Path) -> io::Result<()> {
    let old = sibling(to, "old");
    let had = std::fs::symlink_metadata(to).is_ok();
    if had {
        remove_any(&old).map_err(|e| with_path(e, "removing", &old))?;
        std::fs::rename(to, &old).map_err(|e| with_path(e, "renaming aside", to))?;
    }
    std::fs::rename(from, to).map_err(|e| with_path(e, "renaming into place", from))?;
    if had {
        remove_any(&old).map_err(|e| with_path(e, "removing", &old))?;
    }
    Ok(())
}

/// Removes the file, link or folder `p` if there is one.
fn remove_any(p: &Path) -> io::Result<()> {
    match std::fs::symlink_metadata(p) {
        Ok(m) if m.is_dir() => std::fs::remove_dir_all(p),
        Ok(_) => std::fs::remove_file(p),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
    }
}

/// Removes what an interrupted batch left under `dir`: the temporary files and folders of
/// [`write_clip_folder`] and of single-file writes (`.NAME.PID.tmp`, `.NAME.PID.old`), in
/// `dir` and in its subfolders that are not clip folders (links are not followed).
///
/// Errors: the first entry that cannot be listed or removed, named.
pub fn remove_leftovers(dir: &Path) -> io::Result<()> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(with_path(e, "reading", dir)),
    };
    for e in entries {
        let p = e.map_err(|e| with_path(e, "reading", dir))?.path();
        let name = p.file_name().map(|n| n.to_string_lossy().into_owned());
        if name.is_some_and(|n| n.starts_with('.') && (n.ends_with(".tmp") || n.ends_with(".old")))
        {
            remove_any(&p).map_err(|e| with_path(e, "removing", &p))?;
        } else if std::fs::symlink_metadata(&p).is_ok_and(|m| m.is_dir())
            && !p.join(RECORD_FILE).exists()
        {
            remove_leftovers(&p)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("iktc-record-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// A clip is done only when its folder holds its current record and every output; a
    /// changed input, other dependencies, a missing output or `force` make it run again,
    /// with the record of what it now depends on.
    #[test]
    fn a_clip_is_skipped_only_when_its_folder_is_whole_and_current() {
        let d = tmp("state");
        let (input, dir) = (d.join("clip.bvh"), d.join("out/clip"));
        std::fs::write(&input, "first").unwrap();
        let outputs = ["motion.csv", "quality.json"];
        let state = |deps: &str, outputs: &[&str], force: bool| {
            clip_state(deps, &input, &dir, outputs, force).unwrap()
        };
        let r1 = clip_record("deps", &input).unwrap();
        assert_eq!(state("deps", &outputs, false), ClipState::ToRun(r1.clone()));
        write_clip_folder(&dir, &r1, |tmp| {
            outputs
                .iter()
                .try_for_each(|o| std::fs::write(tmp.join(o), "x"))
        })
        .unwrap();
        assert_eq!(state("deps", &outputs, false), ClipState::Done);
        assert_eq!(state("deps", &outputs, true), ClipState::ToRun(r1.clone()));
        let more = ["motion.csv", "quality.json", "viewer.html"];
        assert_eq!(state("deps", &more, false), ClipState::ToRun(r1.clone()));
        let r2 = clip_record("other", &input).unwrap();
        assert_ne!(r2, r1);
        assert_eq!(state("other", &outputs, false), ClipState::ToRun(r2));
        std::fs::write(&input, "second").unwrap();
        let r3 = clip_record("deps", &input).unwrap();
        assert_ne!(r3, r1);
        assert_eq!(state("deps", &outputs, false), ClipState::ToRun(r3));
        std::fs::remove_file(&input).unwrap();
        let e = clip_state("deps", &input, &dir, &outputs, false).unwrap_err();
        assert!(e.to_string().contains("clip.bvh"), "{e}");
    }

    /// The record is the SHA-256 digest of three named parts, each fed as its name's length
    /// (8 bytes, little-endian), the name, its bytes' length and the bytes, in lower-case hex;
    /// here spelled out byte by byte.
    #[test]
    fn the_record_is_the_digest_of_its_named_parts() {
        let d = tmp("digest");
        let input = d.join("clip.bvh");
        std::fs::write(&input, "bytes").unwrap();
        let mut fed: Vec<u8> = Vec::new();
        for (name, bytes) in [
            ("layout", "iktc clip record 1"),
            ("dependencies", "deps"),
            ("input", "bytes"),
        ] {
            fed.extend((name.len() as u64).to_le_bytes());
            fed.extend(name.bytes());
            fed.extend((bytes.len() as u64).to_le_bytes());
            fed.extend(bytes.bytes());
        }
        let expected: String = Sha256::digest(&fed)
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        assert_eq!(clip_record("deps", &input).unwrap(), expected);
    }

    /// A path that cannot be examined (here: below a file) is an error, not taken for one
    /// that is not there; a missing one is removed already.
    #[test]
    fn an_entry_that_cannot_be_examined_is_not_taken_as_absent() {
        let d = tmp("examine");
        std::fs::write(d.join("file"), "x").unwrap();
        assert!(remove_any(&d.join("missing")).is_ok());
        let e = remove_any(&d.join("file/below")).unwrap_err();
        assert_ne!(e.kind(), io::ErrorKind::NotFound);
        assert!(d.join("file").is_file());
    }
}
