//! A folder tree built from fuzz bytes in a fresh temporary folder, for the discovery target:
//! folders, files, symbolic links (to folders above them, to themselves, dangling) and
//! folders whose permissions refuse listing (which only bites without root's rights).
//!
//! The bytes are read as steps of three: what to make, where (an index into the folders made
//! so far), and which name or link target (an index into [`NAMES`] or the entries made so
//! far). Links only point inside the tree, so a walk of it never leaves it.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Most steps read from the bytes \[steps\]: enough for a few levels of folders, links and
/// files, few enough to keep one run well under a millisecond's worth of system calls.
pub const MAX_STEPS: usize = 64;

/// The names entries get: motion files in several cases, other files, hidden names, names
/// that are glob wildcards or Unicode, and the marker files of iktc's output folders.
pub const NAMES: [&str; 20] = [
    "a",
    "b.bvh",
    "C.BVH",
    "clip.txt",
    "x.json",
    "m.amc",
    "c.c3d",
    "p.csv",
    ".hidden.bvh",
    "é ü.bvh",
    "sp ace.Txt",
    ".record",
    "batch.json",
    "keypoints_summary.json",
    ".settings",
    "d",
    "dir.bvh",
    "*.bvh",
    "?.amc",
    "..bvh",
];

/// A tree in its temporary folder, removed when dropped.
pub struct Tree {
    /// The tree's top folder.
    pub root: PathBuf,
    /// Every folder made (the root first).
    pub dirs: Vec<PathBuf>,
    /// Folders whose permissions were taken away (given back before removal).
    locked: Vec<PathBuf>,
}

impl Tree {
    /// The tree `data` describes (see the module documentation), or `None` if no temporary
    /// folder can be made.
    pub fn build(data: &[u8]) -> Option<Tree> {
        static COUNT: AtomicUsize = AtomicUsize::new(0);
        let root = std::env::temp_dir().join(format!(
            "iktc-fuzz-tree-{}-{}",
            std::process::id(),
            COUNT.fetch_add(1, Ordering::Relaxed)
        ));
        let _ = std::fs::remove_dir_all(&root);
        std::fs::create_dir_all(&root).ok()?;
        let mut tree = Tree {
            root: root.clone(),
            dirs: vec![root],
            locked: Vec::new(),
        };
        let mut entries: Vec<PathBuf> = Vec::new();
        for step in data.chunks_exact(3).take(MAX_STEPS) {
            let parent = tree.dirs[step[1] as usize % tree.dirs.len()].clone();
            let name = NAMES[step[2] as usize % NAMES.len()];
            let path = parent.join(name);
            match step[0] % 5 {
                0 => {
                    if std::fs::create_dir(&path).is_ok() {
                        tree.dirs.push(path.clone());
                        entries.push(path);
                    }
                }
                1 => {
                    if std::fs::write(&path, name).is_ok() {
                        entries.push(path);
                    }
                }
                2 => {
                    // A link to an entry made earlier (a folder above it makes a cycle), to
                    // the root, or to itself.
                    let target = match entries.get(step[2] as usize % (entries.len() + 2)) {
                        Some(e) => e.clone(),
                        None if step[2] % 2 == 0 => tree.root.clone(),
                        None => path.clone(),
                    };
                    if link(&target, &path) {
                        entries.push(path);
                    }
                }
                3 => {
                    // A relative link: `.` (its own folder), `..` below the root, or dangling.
                    let target = match step[2] % 3 {
                        0 => ".",
                        1 if parent != tree.root => "..",
                        _ => "missing.bvh",
                    };
                    if link(Path::new(target), &path) {
                        entries.push(path);
                    }
                }
                _ => {
                    if parent != tree.root && set_listable(&parent, false) {
                        tree.locked.push(parent);
                    }
                }
            }
        }
        Some(tree)
    }
}

impl Drop for Tree {
    fn drop(&mut self) {
        // Folders above first: a folder inside a locked one cannot be reached.
        self.locked.sort_by_key(|d| d.components().count());
        for d in &self.locked {
            set_listable(d, true);
        }
        let _ = std::fs::remove_dir_all(&self.root);
    }
}

#[cfg(unix)]
fn link(target: &Path, path: &Path) -> bool {
    std::os::unix::fs::symlink(target, path).is_ok()
}

#[cfg(not(unix))]
fn link(_: &Path, _: &Path) -> bool {
    false
}

/// Gives a folder its owner's rights back (`rwx`), or takes them all away.
#[cfg(unix)]
fn set_listable(dir: &Path, listable: bool) -> bool {
    use std::os::unix::fs::PermissionsExt;
    let mode = if listable { 0o700 } else { 0o000 };
    std::fs::set_permissions(dir, std::fs::Permissions::from_mode(mode)).is_ok()
}

#[cfg(not(unix))]
fn set_listable(_: &Path, _: bool) -> bool {
    false
}
