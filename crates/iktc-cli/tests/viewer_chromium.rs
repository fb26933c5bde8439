//! The viewer written by `iktc imitate` loads in headless Chromium without a script error and
//! draws a non-blank picture; the G1 viewer of `iktc retarget` draws the robot's meshes (its
//! screen box is mostly filled); a clip that travels 2 m stays in view at its end ("follow"),
//! and leaves the centre without it. Needs Debian's `chromium` on PATH: the test fails (it does not
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

/// Loads `page` in headless Chromium: the script finishes, logs no error, and draws a picture
/// with the robot's stick figure in blue.
fn check_viewer(browser: &Path, dir: &Path, page: &Path) {
    check_viewer_with(browser, dir, page, true)
}

/// [`check_viewer`], the blue stick figure checked when `stick` is set.
fn check_viewer_with(browser: &Path, dir: &Path, page: &Path, stick: bool) {
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
    assert!(!stick || blue > 200, "no robot drawn ({blue} blue pixels)");
    assert!(green > 200, "no skeleton drawn ({green} green pixels)");
}

/// A pixel this close to the page's background (#fbfbfb) or ground grid (#e2e2e2) in every
/// channel counts as blank \[8-bit levels\] (anti-aliasing blends a few levels).
const BLANK_LEVELS: i32 = 12;

/// Share of the robot's screen box that the G1 meshes cover at least (a stick figure of
/// 3-pixel lines covers about a tenth of it; the G1's shaded body, standing, about half).
const MIN_MESH_COVER: f64 = 0.25;

#[test]
fn g1_mesh_viewer_draws_the_robot() {
    let browser = chromium();
    let dir = std::env::temp_dir().join(format!("iktc_mesh_viewer_test_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("run");
    let clip = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../iktc/data/motions/deepmimic/humanoid3d_walk.txt");
    retarget_g1(&clip, &out);
    let page = out.join("humanoid3d_walk").join("viewer.html");
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(
        html.contains("\"meshes\""),
        "no meshes in the G1 viewer data"
    );
    // Loads, draws, no script error (the shared checks, skeleton present).
    check_viewer_with(&browser, &dir, &page, false);

    // Paused at the first frame; the page writes the robot's screen box.
    let url = format!("file://{}#t=0", page.display());
    let bx = robot_box(&browser, &dir, &url, "mesh");
    let (x0, y0, x1, y1) = (bx[0], bx[1], bx[2], bx[3]);
    assert!(
        x1 - x0 > 30 && y1 - y0 > 80,
        "the robot's box is too small: {bx:?}"
    );

    let cover = box_cover(&browser, &dir, &url, &bx, "mesh");
    // The control: the same page without its meshes draws the stick figure, which fills far
    // less of the same box.
    let stick_page = dir.join("stick.html");
    std::fs::write(&stick_page, without_meshes(&html)).unwrap();
    let stick_url = format!("file://{}#t=0", stick_page.display());
    let stick = box_cover(&browser, &dir, &stick_url, &bx, "stick");
    eprintln!(
        "G1 viewer: box {bx:?}, drawn share {cover:.2} with meshes, {stick:.2} as a stick figure"
    );
    assert!(
        cover >= MIN_MESH_COVER,
        "the meshes cover {cover:.2} of the robot's box {bx:?}, expected ≥ {MIN_MESH_COVER}"
    );
    assert!(
        stick < MIN_MESH_COVER && cover > 2.0 * stick,
        "the stick figure covers {stick:.2} of the box, the meshes {cover:.2}: no difference"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `iktc retarget CLIP --robot g1 --jobs 1 --out OUT`, which must succeed.
fn retarget_g1(clip: &Path, out: &Path) {
    let run = Command::new(env!("CARGO_BIN_EXE_iktc"))
        .arg("retarget")
        .arg(clip)
        .args(["--robot", "g1", "--jobs", "1", "--out"])
        .arg(out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "iktc retarget failed: {}",
        String::from_utf8_lossy(&run.stderr)
    );
}

/// The robot's screen box (x0, y0, x1, y1, page pixels) the page at `url` reports.
fn robot_box(browser: &Path, dir: &Path, url: &str, tag: &str) -> Vec<i64> {
    let dom = Command::new(browser)
        .args(chromium_args(&dir.join(format!("profile_{tag}_dom"))))
        .arg("--dump-dom")
        .arg(url)
        .output()
        .unwrap();
    let dom = String::from_utf8_lossy(&dom.stdout);
    let at = dom
        .find("data-robot-box=\"")
        .unwrap_or_else(|| panic!("no robot box in the page: {}", &dom[..dom.len().min(300)]));
    let rest = &dom[at + "data-robot-box=\"".len()..];
    let bx: Vec<i64> = rest[..rest.find('"').unwrap()]
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(bx.len(), 4, "the robot box is x0,y0,x1,y1");
    bx
}

/// The window of [`chromium_args`] [CSS px].
const WINDOW: (i64, i64) = (800, 600);

#[test]
fn a_travelling_clip_stays_in_view() {
    let browser = chromium();
    let dir = std::env::temp_dir().join(format!("iktc_follow_test_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("run");
    // CMU 131_01: the subject walks about 2 m.
    let clip =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../iktc/tests/data/motions/cmu/131_01.bvh");
    retarget_g1(&clip, &out);
    let page = out.join("131_01").join("viewer.html");
    let html = std::fs::read_to_string(&page).unwrap();
    // The last second of the clip (8.3 s).
    let end = "#t=8";
    let centre = |bx: &[i64]| ((bx[0] + bx[2]) / 2, (bx[1] + bx[3]) / 2);
    let start = robot_box(
        &browser,
        &dir,
        &format!("file://{}#t=0", page.display()),
        "s",
    );
    let followed = robot_box(
        &browser,
        &dir,
        &format!("file://{}{end}", page.display()),
        "f",
    );
    let fixed_page = dir.join("fixed.html");
    let unchecked = html.replace(
        "id=\"follow\" type=\"checkbox\" checked",
        "id=\"follow\" type=\"checkbox\"",
    );
    assert_ne!(unchecked, html, "the follow box is in the page");
    std::fs::write(&fixed_page, unchecked).unwrap();
    let fixed = robot_box(
        &browser,
        &dir,
        &format!("file://{}{end}", fixed_page.display()),
        "x",
    );
    let (cs, cf, cx) = (centre(&start), centre(&followed), centre(&fixed));
    eprintln!("robot box centre: start {cs:?}, end followed {cf:?}, end fixed {cx:?}");
    // Followed: the robot's centre stays within the middle half of the window's width and
    // inside its height.
    assert!(
        (WINDOW.0 / 4..3 * WINDOW.0 / 4).contains(&cf.0) && (0..WINDOW.1).contains(&cf.1),
        "followed robot at {cf:?} in a {WINDOW:?} window"
    );
    // The control: with the camera left where frame 0 put it, the robot has moved far from
    // where it started on the screen (more than a quarter of the width).
    let moved = ((cx.0 - cs.0).pow(2) + (cx.1 - cs.1).pow(2)) as f64;
    assert!(
        moved.sqrt() > WINDOW.0 as f64 / 4.0,
        "without follow the robot moved {:.0} px only",
        moved.sqrt()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The page `html` with the meshes taken out of its data (the stick figure).
fn without_meshes(html: &str) -> String {
    let open = "<script id=\"data\" type=\"application/json\">";
    let a = html.find(open).unwrap() + open.len();
    let b = a + html[a..].find("</script>").unwrap();
    let mut data: serde_json::Value = serde_json::from_str(&html[a..b]).unwrap();
    assert!(data.as_object_mut().unwrap().remove("meshes").is_some());
    let json = serde_json::to_string(&data).unwrap().replace("</", "<\\/");
    format!("{}{}{}", &html[..a], json, &html[b..])
}

/// The share of the box `bx` (x0, y0, x1, y1, page pixels) not blank in a screenshot of `url`.
fn box_cover(browser: &Path, dir: &Path, url: &str, bx: &[i64], tag: &str) -> f64 {
    let shot = dir.join(format!("{tag}_shot.png"));
    let run = Command::new(browser)
        .args(chromium_args(&dir.join(format!("profile_{tag}_shot"))))
        .arg(format!("--screenshot={}", shot.display()))
        .arg(url)
        .output()
        .unwrap();
    assert!(run.status.success(), "chromium failed");
    let (w, h, channels, bytes) = decode_png(&shot);
    let (x0, y0, x1, y1) = (bx[0], bx[1], bx[2], bx[3]);
    assert!(
        x0 >= 0 && y0 >= 0 && x1 < w as i64 && y1 < h as i64,
        "the robot's box {bx:?} is not inside the {w}×{h} screenshot"
    );
    let blank = |px: &[u8]| {
        [251, 226].iter().any(|&c| {
            px[..3]
                .iter()
                .all(|&v| (i32::from(v) - c).abs() <= BLANK_LEVELS)
        })
    };
    let (mut filled, mut total) = (0usize, 0usize);
    for y in y0..=y1 {
        for x in x0..=x1 {
            let i = (y as usize * w + x as usize) * channels;
            total += 1;
            if !blank(&bytes[i..i + channels]) {
                filled += 1;
            }
        }
    }
    filled as f64 / total as f64
}

/// Width, height, channels and pixels of a PNG file.
fn decode_png(path: &Path) -> (usize, usize, usize, Vec<u8>) {
    let file = std::fs::File::open(path).expect("no screenshot written");
    let decoder = png::Decoder::new(std::io::BufReader::new(file));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    assert!(
        channels >= 3 && info.bit_depth == png::BitDepth::Eight,
        "unexpected PNG format {:?} {:?}",
        info.color_type,
        info.bit_depth
    );
    buf.truncate(info.buffer_size());
    (info.width as usize, info.height as usize, channels, buf)
}
