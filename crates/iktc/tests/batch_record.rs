//! The batch's clip discovery (link cycles, files under two names, dangling links) and the
//! record of a finished clip (what changes it and what does not; a folder written whole).

use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime};

use iktc::batch::{
    clip_record, discover, is_done, remove_leftovers, write_clip_folder, BatchRetarget, RECORD_FILE,
};
use iktc::profile::RobotProfile;
use iktc::sim::ImitateConfig;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("iktc-batch-record-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("data")
}

/// G1's profile and URDF copied to `dir` (`profiles/g1.toml`, `robots/g1/…urdf`), with one mesh
/// file the URDF names.
fn g1_copy(dir: &Path) -> PathBuf {
    let robots = dir.join("robots/g1");
    std::fs::create_dir_all(robots.join("meshes")).unwrap();
    std::fs::create_dir_all(dir.join("profiles")).unwrap();
    std::fs::copy(
        data().join("robots/g1/g1_29dof_rev_1_0.urdf"),
        robots.join("g1_29dof_rev_1_0.urdf"),
    )
    .unwrap();
    std::fs::write(robots.join("meshes/left_hip_pitch_link.STL"), b"mesh one").unwrap();
    let profile = dir.join("profiles/g1.toml");
    std::fs::copy(data().join("profiles/g1.toml"), &profile).unwrap();
    profile
}

fn digest(profile: &Path) -> String {
    let p = RobotProfile::load(profile).unwrap();
    BatchRetarget::from_profile(p, ImitateConfig::default())
        .unwrap()
        .dependency_digest()
        .unwrap()
}

fn is_hex_digest(s: &str) -> bool {
    s.len() == 64 && s.bytes().all(|b| b.is_ascii_hexdigit())
}

#[test]
fn the_dependency_digest_follows_the_urdf_its_meshes_and_the_profile() {
    let dir = tmp("deps");
    let profile = g1_copy(&dir);
    let base = digest(&profile);
    assert!(is_hex_digest(&base), "{base}");
    assert_eq!(
        digest(&profile),
        base,
        "the same files give the same digest"
    );

    // A tighter hip range in the URDF.
    let urdf = dir.join("robots/g1/g1_29dof_rev_1_0.urdf");
    let text = std::fs::read_to_string(&urdf).unwrap();
    let limit = r#"<limit lower="-2.5307" upper="2.8798" effort="88" velocity="32"/>"#;
    assert!(text.contains(limit));
    std::fs::write(
        &urdf,
        text.replacen(
            limit,
            r#"<limit lower="-1" upper="1" effort="88" velocity="32"/>"#,
            1,
        ),
    )
    .unwrap();
    let tighter = digest(&profile);
    assert_ne!(tighter, base);
    std::fs::write(&urdf, &text).unwrap();
    assert_eq!(
        digest(&profile),
        base,
        "the URDF restored gives the digest back"
    );

    // A mesh file the URDF names, changed.
    std::fs::write(
        dir.join("robots/g1/meshes/left_hip_pitch_link.STL"),
        b"mesh two",
    )
    .unwrap();
    assert_ne!(digest(&profile), base);
    std::fs::write(
        dir.join("robots/g1/meshes/left_hip_pitch_link.STL"),
        b"mesh one",
    )
    .unwrap();

    // A profile value.
    let ptext = std::fs::read_to_string(&profile).unwrap();
    std::fs::write(
        &profile,
        ptext.replace("ankle_height = 0.035", "ankle_height = 0.036"),
    )
    .unwrap();
    assert_ne!(digest(&profile), base);
    std::fs::write(&profile, &ptext).unwrap();
    assert_eq!(digest(&profile), base);
}

#[test]
fn the_clip_record_follows_the_input_bytes_not_its_time() {
    let dir = tmp("clip");
    let input = dir.join("clip.bvh");
    std::fs::write(&input, "first clip").unwrap();
    let deps = "a".repeat(64);
    let r = clip_record(&deps, &input).unwrap();
    assert!(is_hex_digest(&r), "{r}");
    // Touched: a time far in the past or the future leaves the record.
    for t in [
        SystemTime::UNIX_EPOCH + Duration::from_secs(1),
        SystemTime::now() + Duration::from_secs(3600),
    ] {
        std::fs::File::options()
            .append(true)
            .open(&input)
            .unwrap()
            .set_modified(t)
            .unwrap();
        assert_eq!(clip_record(&deps, &input).unwrap(), r);
    }
    // Other bytes, an older time: another record.
    std::fs::write(&input, "other clip").unwrap();
    std::fs::File::options()
        .append(true)
        .open(&input)
        .unwrap()
        .set_modified(SystemTime::UNIX_EPOCH + Duration::from_secs(1))
        .unwrap();
    assert_ne!(clip_record(&deps, &input).unwrap(), r);
    // Other dependencies: another record.
    std::fs::write(&input, "first clip").unwrap();
    assert_eq!(clip_record(&deps, &input).unwrap(), r);
    assert_ne!(clip_record(&"b".repeat(64), &input).unwrap(), r);
    // A missing input is an error naming it.
    let e = clip_record(&deps, &dir.join("gone.bvh"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("gone.bvh"), "{e}");
}

#[test]
fn a_folder_written_whole_is_done_and_a_failed_one_leaves_nothing() {
    let dir = tmp("folder");
    let clip = dir.join("sub/clip");
    let outputs = ["a.csv", "b.json"];
    let r = "1".repeat(64);
    write_clip_folder(&clip, &r, |tmp| {
        for o in outputs {
            std::fs::write(tmp.join(o), o)?;
        }
        Ok::<_, std::io::Error>(())
    })
    .unwrap();
    assert!(is_done(&clip, &r, &outputs));
    assert!(!is_done(&clip, &"2".repeat(64), &outputs), "another record");
    assert!(
        !is_done(&clip, &r, &["a.csv", "b.json", "viewer.html"]),
        "a file missing"
    );
    assert_eq!(
        std::fs::read_to_string(clip.join(RECORD_FILE))
            .unwrap()
            .trim(),
        r
    );

    // A write that fails after its first file: the earlier folder is kept as it was, and
    // nothing of the failed write is left beside it.
    let e = write_clip_folder(&clip, &"3".repeat(64), |tmp| {
        std::fs::write(tmp.join("a.csv"), "new")?;
        Err::<(), _>(std::io::Error::other("failed late"))
    })
    .unwrap_err();
    assert!(e.to_string().contains("failed late"));
    assert_eq!(
        std::fs::read_to_string(clip.join("a.csv")).unwrap(),
        "a.csv"
    );
    assert!(is_done(&clip, &r, &outputs));
    let names: Vec<String> = std::fs::read_dir(dir.join("sub"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["clip"]);

    // A failed first write leaves no folder at all.
    let fresh = dir.join("fresh");
    let _ = write_clip_folder(&fresh, &r, |tmp| {
        std::fs::write(tmp.join("a.csv"), "x")?;
        Err::<(), _>(std::io::Error::other("no"))
    });
    assert!(!fresh.exists());
    let names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["sub"]);

    // A second write replaces the folder whole: a file of the first that the second does
    // not write is gone.
    let r2 = "4".repeat(64);
    write_clip_folder(&clip, &r2, |tmp| {
        std::fs::write(tmp.join("a.csv"), "second")
    })
    .unwrap();
    assert!(is_done(&clip, &r2, &["a.csv"]));
    assert!(!clip.join("b.json").exists());
}

#[test]
fn leftovers_of_an_interrupted_batch_are_removed_and_clips_kept() {
    let dir = tmp("leftovers");
    std::fs::create_dir_all(dir.join("sub/.clip.99.tmp")).unwrap();
    std::fs::write(dir.join("sub/.clip.99.tmp/motion.csv"), "half").unwrap();
    std::fs::create_dir_all(dir.join(".other.99.old")).unwrap();
    std::fs::write(dir.join(".batch.json.99.tmp"), "half").unwrap();
    std::fs::create_dir_all(dir.join("sub/clip")).unwrap();
    std::fs::write(dir.join("sub/clip").join(RECORD_FILE), "r").unwrap();
    std::fs::write(dir.join("sub/clip/motion.csv"), "whole").unwrap();
    // A user's files are kept: a name that ends in `.tmp` without the leading dot, a hidden
    // file with another ending.
    std::fs::write(dir.join("notes.tmp"), "mine").unwrap();
    std::fs::write(dir.join(".hidden"), "mine").unwrap();
    remove_leftovers(&dir).unwrap();
    assert!(dir.join("notes.tmp").is_file() && dir.join(".hidden").is_file());
    // A missing folder has nothing left over; a file is not a folder to clean.
    assert!(remove_leftovers(&dir.join("missing")).is_ok());
    assert!(remove_leftovers(&dir.join("notes.tmp")).is_err());
    assert!(!dir.join("sub/.clip.99.tmp").exists());
    assert!(!dir.join(".other.99.old").exists());
    assert!(!dir.join(".batch.json.99.tmp").exists());
    assert_eq!(
        std::fs::read_to_string(dir.join("sub/clip/motion.csv")).unwrap(),
        "whole"
    );
}

/// A folder holding a link to itself, a link to its parent and a second name for a file:
/// the walk ends, and each real file gives one clip, under its first name in sorted order.
#[cfg(unix)]
#[test]
fn link_cycles_end_and_each_real_file_is_one_clip() {
    use std::os::unix::fs::symlink;
    let dir = tmp("cycles");
    let input = dir.join("in");
    std::fs::create_dir_all(input.join("sub")).unwrap();
    std::fs::write(input.join("b_clip.bvh"), "x").unwrap();
    std::fs::write(input.join("sub/c_clip.bvh"), "y").unwrap();
    symlink(&input, input.join("sub/up")).unwrap();
    symlink(".", input.join("self")).unwrap();
    symlink("b_clip.bvh", input.join("a_alias.bvh")).unwrap();
    let found = discover(&[input.display().to_string()], None);
    let names: Vec<&str> = found.clips.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["a_alias", "sub/c_clip"]);
    assert!(found.problems.is_empty(), "{:?}", found.problems);
    // The same file named again by a second input is not a second clip.
    let twice = discover(
        &[
            input.display().to_string(),
            input.join("sub/c_clip.bvh").display().to_string(),
        ],
        None,
    );
    assert_eq!(twice.clips.len(), 2);
    assert!(twice.problems.is_empty(), "{:?}", twice.problems);
}

/// A dangling link is named with its error; the folder's other clips are kept.
#[cfg(unix)]
#[test]
fn a_dangling_link_is_named_and_the_other_clips_kept() {
    let dir = tmp("dangling");
    std::fs::write(dir.join("clip.bvh"), "x").unwrap();
    std::os::unix::fs::symlink(dir.join("nowhere.bvh"), dir.join("gone.bvh")).unwrap();
    let found = discover(&[dir.display().to_string()], None);
    let names: Vec<&str> = found.clips.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["clip"]);
    assert_eq!(found.problems.len(), 1, "{:?}", found.problems);
    assert_eq!(
        found.problems[0].path,
        dir.join("gone.bvh").display().to_string()
    );
    assert!(found.problems[0].message.contains("cannot read"));
}

/// A clip folder of an earlier batch inside the input folder is not searched.
#[test]
fn output_folders_are_not_searched() {
    let dir = tmp("outputs");
    std::fs::create_dir_all(dir.join("done")).unwrap();
    std::fs::write(dir.join("done").join(RECORD_FILE), "r").unwrap();
    std::fs::write(dir.join("done/quality.json"), "{}").unwrap();
    std::fs::write(dir.join("clip.json"), "{}").unwrap();
    let found = discover(&[dir.display().to_string()], None);
    let names: Vec<&str> = found.clips.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["clip"]);
    assert_eq!(found.output_folders, [dir.join("done")]);
}
