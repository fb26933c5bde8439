//! Throughput of dataset retargeting, end to end: read each shared clip (the four DeepMimic
//! clips and the two CMU BVH files), retarget it onto G1 and onto JVRC-1 at the 200 Hz control
//! rate by the default route, keypoints ([`BatchRetarget::retarget`]), and write its CSV, NPZ
//! and quality JSON (the viewer page, which the command line adds, is not included). Criterion
//! reports the time of the whole batch with 1 and 2 worker threads; the throughput element is
//! one 200 Hz frame. Clips are taken longest first ([`longest_first`], by file size), as the
//! command line does. Then, in the same process, the 1 → 2 job scaling: five alternating
//! timings of each, the ratio of their medians printed as `scaling`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use iktc::batch::{longest_first, run_parallel_in, BatchRetarget};
use iktc::profile::RobotProfile;
use iktc::sim::ImitateConfig;

fn clips() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut v = Vec::new();
    for (dir, ext) in [
        ("data/motions/deepmimic", "txt"),
        ("tests/data/motions/cmu", "bvh"),
    ] {
        v.extend(
            std::fs::read_dir(root.join(dir))
                .expect("clip folder")
                .map(|e| e.expect("entry").path())
                .filter(|p| p.extension().is_some_and(|e| e == ext)),
        );
    }
    v.sort();
    v
}

/// Retargets every clip on `jobs` threads and writes its files under `out`; returns the
/// frames written.
fn batch(b: &BatchRetarget, clips: &[PathBuf], jobs: usize, out: &Path) -> usize {
    let mut frames = 0;
    let order = longest_first(clips, |p| {
        std::fs::metadata(p).map(|m| m.len()).unwrap_or(0)
    });
    run_parallel_in(
        clips,
        &order,
        jobs,
        |i, path| {
            let o = b.retarget(path).expect("retarget");
            let dir = out.join(i.to_string());
            std::fs::create_dir_all(&dir).expect("dir");
            std::fs::write(dir.join("motion.csv"), o.trajectory.csv()).expect("csv");
            std::fs::write(dir.join("motion.npz"), o.trajectory.npz().expect("npz")).expect("npz");
            let q =
                serde_json::to_string(&(&o.quality, o.summary().expect("summary"))).expect("json");
            std::fs::write(dir.join("quality.json"), q).expect("json");
            o.trajectory.len()
        },
        |_, r| frames += r.expect("no panic"),
    );
    frames
}

fn bench(c: &mut Criterion) {
    for robot in ["g1", "jvrc1"] {
        bench_robot(c, robot);
    }
}

fn bench_robot(c: &mut Criterion, robot: &str) {
    let profile = RobotProfile::builtin(robot).expect("profile");
    let b = BatchRetarget::from_profile(profile, ImitateConfig::default()).expect("batch");
    let clips = clips();
    let out = std::env::temp_dir().join(format!("iktc-bench-batch-{}", std::process::id()));
    let frames = batch(&b, &clips, 1, &out);
    let seconds = frames as f64 * b.control_period();
    let mut g = c.benchmark_group(format!("batch_retarget_shared_clips_{robot}"));
    g.sample_size(10);
    g.throughput(Throughput::Elements(frames as u64));
    for jobs in [1, 2] {
        g.bench_function(format!("jobs_{jobs}"), |bn| {
            bn.iter(|| batch(&b, &clips, jobs, &out))
        });
    }
    g.finish();
    // 1 → 2 jobs in one run: alternate, take medians.
    let mut t = [Vec::new(), Vec::new()];
    for _ in 0..5 {
        for (i, jobs) in [1, 2].into_iter().enumerate() {
            let s = Instant::now();
            batch(&b, &clips, jobs, &out);
            t[i].push(s.elapsed().as_secs_f64());
        }
    }
    for v in &mut t {
        v.sort_by(f64::total_cmp);
    }
    let (one, two) = (t[0][2], t[1][2]);
    println!(
        "batch {robot}: {} clips, {frames} frames ({seconds:.2} s of motion at 200 Hz); 1 job {one:.3} s = {:.0} frames/s = {:.0}x real time per core; 2 jobs {two:.3} s; scaling 1 -> 2 jobs {:.2}x",
        clips.len(),
        frames as f64 / one,
        seconds / one,
        one / two
    );
    let _ = std::fs::remove_dir_all(&out);
}

criterion_group!(benches, bench);
criterion_main!(benches);
