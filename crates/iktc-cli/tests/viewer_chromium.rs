//! The viewer written by `iktc imitate` loads in headless Chromium without a script error and
//! draws a non-blank picture. Needs Debian's `chromium` on PATH: the test fails (it does not
//! skip) when it is missing.

use std::path::{Path, PathBuf};
use std::process::Command;

fn chromium() -> PathBuf {
    let path = std::env::var_os("PATH").unwrap_or_default();
    for dir in std::env::split_paths(&path) {
        for name in ["chromium", "chromium-browser"] {
            let p = dir.join(name);
            if p.is_file() {
                return p;
            }
        }
    }
    panic!(
        "chromium is not on PATH: the viewer test needs a headless browser; install it with \
         `apt-get install -y chromium` (Debian) and run the test again"
    );
}

fn chromium_args(profile: &Path) -> Vec<String> {
    [
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--window-size=800,600",
        "--virtual-time-budget=2000",
    ]
    .iter()
    .map(|s| s.to_string())
    .chain([format!("--user-data-dir={}", profile.display())])
    .collect()
}

#[test]
fn viewer_loads_and_draws() {
    let browser = chromium();
    let dir = std::env::temp_dir().join(format!("iktc_viewer_test_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("run");
    let status = Command::new(env!("CARGO_BIN_EXE_iktc"))
        .args(["imitate", "--retarget", "joints", "--out"])
        .arg(&out)
        .status()
        .unwrap();
    assert!(status.success(), "iktc imitate failed");
    check_viewer(&browser, &dir, &out.join("viewer.html"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn walking_viewer_loads_and_draws() {
    let browser = chromium();
    let dir = std::env::temp_dir().join(format!("iktc_walk_viewer_test_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("run");
    let status = Command::new(env!("CARGO_BIN_EXE_iktc"))
        .args(["walk", "--out"])
        .arg(&out)
        .status()
        .unwrap();
    assert!(status.success(), "iktc walk failed");
    let page = out.join("walk_viewer.html");
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(
        html.contains("\"footsteps\"") && html.contains("\"phases\""),
        "footsteps and phases in the data"
    );
    check_viewer(&browser, &dir, &page);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Loads `page` in headless Chromium: the script finishes, logs no error, and draws a picture.
fn check_viewer(browser: &Path, dir: &Path, page: &Path) {
    let html = std::fs::read_to_string(page).unwrap();
    // Self-contained: no external script, stylesheet or image.
    for bad in [
        "src=\"http",
        "href=\"http",
        "src='http",
        "<link ",
        "import(",
    ] {
        assert!(
            !html.contains(bad),
            "the viewer references something external: {bad}"
        );
    }
    let url = format!("file://{}", page.display());

    // The page script sets the title to "iktc viewer ready" once it has drawn a frame; a JS
    // error before that leaves "iktc viewer (loading)".
    let dom = Command::new(browser)
        .args(chromium_args(&dir.join("profile_dom")))
        .arg("--dump-dom")
        .arg(&url)
        .output()
        .unwrap();
    let dom = String::from_utf8_lossy(&dom.stdout);
    assert!(
        dom.contains("<title>iktc viewer ready</title>"),
        "the viewer script did not finish: {}",
        &dom[..dom.len().min(300)]
    );

    // Console errors are logged on stderr with --enable-logging=stderr.
    let shot = dir.join("shot.png");
    let run = Command::new(browser)
        .args(chromium_args(&dir.join("profile_shot")))
        .args(["--enable-logging=stderr", "--v=0"])
        .arg(format!("--screenshot={}", shot.display()))
        .arg(&url)
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&run.stderr);
    for line in log.lines() {
        let l = line.to_ascii_lowercase();
        assert!(
            !(l.contains("console") && (l.contains("error") || l.contains("uncaught"))),
            "JavaScript error: {line}"
        );
    }
    // Decode the screenshot and check that it is not blank: many distinct colours, and the
    // robot's blue and the skeleton's green both present.
    let file = std::fs::File::open(&shot).expect("no screenshot written");
    let decoder = png::Decoder::new(std::io::BufReader::new(file));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let bytes = &buf[..info.buffer_size()];
    let channels = info.color_type.samples();
    assert!(
        channels >= 3,
        "unexpected PNG colour type {:?}",
        info.color_type
    );
    let (mut blue, mut green, mut colours) = (0usize, 0usize, std::collections::HashSet::new());
    for px in bytes.chunks(channels) {
        let (r, g, b) = (px[0] as i32, px[1] as i32, px[2] as i32);
        colours.insert((r >> 3, g >> 3, b >> 3));
        if b > 150 && r < 80 && g < 130 {
            blue += 1;
        }
        if g > 110 && r < 80 && b < 100 {
            green += 1;
        }
    }
    assert!(
        colours.len() > 20,
        "the screenshot looks blank ({} colours)",
        colours.len()
    );
    assert!(blue > 200, "no robot drawn ({blue} blue pixels)");
    assert!(green > 200, "no skeleton drawn ({green} green pixels)");
}
