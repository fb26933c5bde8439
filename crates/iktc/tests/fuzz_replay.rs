//! Replays every checked-in fuzz corpus file and crash reproducer through the fuzz targets'
//! own entry points (`fuzz/src/lib.rs`, included here), so that a fixed crash stays fixed
//! without nightly or cargo-fuzz. Ok and Err are both fine; a panic fails the test.
//!
//! Files: `fuzz/corpus/<target>/*`, `fuzz/artifacts/<target>/*` and
//! `crates/iktc/tests/fuzz_regressions/<target>/*`.

#[allow(dead_code)]
#[path = "../../../fuzz/src/lib.rs"]
mod entries;

use std::path::{Path, PathBuf};

fn files(dir: &Path) -> Vec<PathBuf> {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut v: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file())
        .collect();
    v.sort();
    v
}

#[test]
fn every_corpus_and_crash_file_replays_without_panic() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let fuzz = root.join("../../fuzz");
    let mut total = 0;
    for (name, entry) in entries::TARGETS {
        let mut n = 0;
        for dir in [
            fuzz.join("corpus").join(name),
            fuzz.join("artifacts").join(name),
            root.join("tests/fuzz_regressions").join(name),
        ] {
            for f in files(&dir) {
                let data = std::fs::read(&f).unwrap();
                let r = std::panic::catch_unwind(|| entry(&data));
                assert!(r.is_ok(), "{name}: {} panics", f.display());
                n += 1;
            }
        }
        // Every target has a seed corpus.
        assert!(n > 0, "no corpus for fuzz target {name}");
        total += n;
    }
    assert!(total >= entries::TARGETS.len());
}
