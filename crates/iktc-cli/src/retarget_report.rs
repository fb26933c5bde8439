//! The dataset report of `iktc retarget`, `OUT/index.html`: one offline page (inline CSS,
//! script and SVG) with every clip's quality figures in a table sortable by any column (click a
//! header), the worst first (failed run checks, then the largest upper-body RMS error), a
//! histogram of each figure across the dataset, the failures with their errors, and a link to
//! each clip's viewer and files.

use iktc_report::escape_html;

use crate::cmd_retarget::ClipStatus;

/// The figures shown: key in `quality.json`'s `figures`, column label with its unit. A column
/// appears when some clip has its figure (the keypoint and joint routes measure different
/// things).
const COLUMNS: [(&str, &str); 40] = [
    ("duration", "duration [s]"),
    (
        "neutral_keypoint_error",
        "mean keypoint error against the person (joint centres, leg scale) [m]",
    ),
    ("contact_slip", "foot slip over the person's contacts [m]"),
    (
        "contact_height",
        "highest sole over the person's contacts [m]",
    ),
    ("lowest_sole", "lowest sole [m]"),
    ("skate_share", "share of foot-ticks skating [–]"),
    (
        "knee_flexion_gap",
        "median knee flexion, robot − person [rad]",
    ),
    (
        "elbow_flexion_gap",
        "median elbow flexion, robot − person [rad]",
    ),
    ("trunk_lean_gap", "median trunk lean, robot − person [rad]"),
    (
        "hip_height_gap",
        "median hip height, robot − scaled person [m]",
    ),
    (
        "reversal_share",
        "share of ticks where q̈'s change reverses [–]",
    ),
    ("flip_max", "largest tick-to-tick sign flip of q̈ [rad/s²]"),
    (
        "mean_keypoint_error",
        "the tool's own tracking error against its targets [m]",
    ),
    (
        "reach_keypoint_error",
        "static reach: least mean keypoint error of a posture within the joint ranges [m]",
    ),
    (
        "balanced_reach_keypoint_error",
        "balanced reach: the same, keeping the clip's feet and the COM over them [m]",
    ),
    ("max_keypoint_error", "max keypoint error [m]"),
    (
        "max_orientation_error",
        "max pelvis/torso orientation error [rad]",
    ),
    ("rms_error_upper_body", "upper-body RMS error [rad]"),
    ("max_error_upper_body", "upper-body max error [rad]"),
    (
        "rms_error_pelvis_attitude",
        "pelvis attitude RMS error [rad]",
    ),
    ("rms_error_pelvis_height", "pelvis height RMS error [m]"),
    ("rms_error_com", "COM RMS error [m]"),
    ("foot_slip", "foot slip [m]"),
    (
        "foot_float",
        "highest a foot floats while the clip has it on the ground [m]",
    ),
    (
        "foot_float_share",
        "share of the clip's foot-contact ticks with the foot more than 1 cm up [–]",
    ),
    ("penetration", "sole penetration [m]"),
    (
        "penetration_share",
        "share of ticks with a sole below the ground [–]",
    ),
    ("worst_position_margin", "worst position margin [rad]"),
    ("worst_velocity_margin", "worst velocity margin [rad/s]"),
    (
        "worst_acceleration_margin",
        "worst acceleration margin [rad/s²]",
    ),
    ("rms_jerk", "RMS jerk [rad/s³]"),
    ("max_jerk", "max jerk [rad/s³]"),
    ("max_rms_jerk", "max RMS jerk [rad/s³]"),
    (
        "jerk_limit_share",
        "share of the squared jerk on the ticks corrected into the joint limits' box [–]",
    ),
    ("com_min_margin", "COM min margin [m]"),
    ("fallback_share", "fallback share [–]"),
    (
        "stance_gf_share",
        "share of ticks solved by GF for the feet [–]",
    ),
    ("leg_ratio", "leg ratio robot/person [–]"),
    (
        "body_sacrificed_share",
        "share of ticks sacrificing the feet, COM or pelvis [–]",
    ),
    (
        "most_on_limit_share",
        "largest share of ticks a joint spends on a position limit [–]",
    ),
];

/// The figure rows are sorted by, worst first: the first of these a clip has.
const SORT_KEYS: [&str; 2] = ["mean_keypoint_error", "rms_error_upper_body"];

fn sort_key(c: &ClipStatus) -> f64 {
    SORT_KEYS
        .iter()
        .find_map(|k| figure(c, k))
        .unwrap_or(f64::INFINITY)
}

/// Bins of each histogram.
const BINS: usize = 12;

fn figure(c: &ClipStatus, key: &str) -> Option<f64> {
    c.figures.as_ref()?.get(key)?.as_f64()
}

fn healthy(c: &ClipStatus) -> bool {
    c.figures
        .as_ref()
        .and_then(|f| f.get("healthy"))
        .and_then(|h| h.as_bool())
        .unwrap_or(true)
}

/// What made a clip unhealthy, in words (its figures' `failures`).
fn failures(c: &ClipStatus) -> Vec<String> {
    c.figures
        .as_ref()
        .and_then(|f| f.get("failures"))
        .and_then(|f| f.as_array())
        .map(|a| {
            a.iter()
                .filter_map(|m| m.as_str().map(str::to_string))
                .collect()
        })
        .unwrap_or_default()
}

/// A figure as a table cell: four decimals for magnitudes in [0.01, 10⁴), scientific otherwise.
fn cell(v: f64) -> String {
    if v == 0.0 || (0.01..1e4).contains(&v.abs()) {
        format!("{v:.4}")
    } else {
        format!("{v:.3e}")
    }
}

/// An inline SVG histogram of `values`.
fn histogram(label: &str, values: &[f64]) -> String {
    let (w, h) = (220.0, 90.0);
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mut counts = [0usize; BINS];
    let span = hi - lo;
    for v in values {
        let b = if span > 0.0 {
            (((v - lo) / span) * BINS as f64) as usize
        } else {
            0
        };
        counts[b.min(BINS - 1)] += 1;
    }
    let top = counts.iter().copied().max().unwrap_or(1).max(1) as f64;
    let bw = w / BINS as f64;
    let bars: String = counts
        .iter()
        .enumerate()
        .map(|(i, n)| {
            let bh = (h - 20.0) * *n as f64 / top;
            format!(
                "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{bh:.1}\" fill=\"#4a78c2\"><title>{n}</title></rect>",
                i as f64 * bw + 1.0,
                h - 14.0 - bh,
                bw - 2.0
            )
        })
        .collect();
    format!(
        "<figure><svg width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">{bars}\
         <text x=\"0\" y=\"{h}\" font-size=\"10\">{lo:.3e}</text>\
         <text x=\"{w}\" y=\"{h}\" font-size=\"10\" text-anchor=\"end\">{hi:.3e}</text></svg>\
         <figcaption>{} ({} clips)</figcaption></figure>",
        escape_html(label),
        values.len()
    )
}

/// The page's head: its title and style sheet, up to the body's start.
const HEAD: &str = "<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>iktc retarget: dataset report</title><style>\
         body{font:13px sans-serif;margin:16px;color:#222}table{border-collapse:collapse}\
         td,th{border:1px solid #ccc;padding:3px 6px;text-align:right}td:first-child,th:first-child{text-align:left}\
         th{cursor:pointer;background:#f0f0f0}tr.bad td{background:#fde8e8}\
         figure{display:inline-block;margin:6px}figcaption{font-size:11px}pre{white-space:pre-wrap}\
         </style></head><body>";

/// The script that sorts the clips table by the column clicked, and the page's end.
const SORT_SCRIPT: &str = "<script>\"use strict\";\
         const t=document.getElementById('clips');let dir={};\
         t.querySelectorAll('th').forEach((th,i)=>th.onclick=()=>{\
         const rows=[...t.tBodies[0].rows];dir[i]=-(dir[i]||1);\
         const key=r=>{const c=r.cells[i];const v=c.dataset.v;return v===undefined?c.textContent:(v===''?NaN:parseFloat(v));};\
         rows.sort((a,b)=>{const x=key(a),y=key(b);\
         if(typeof x==='string')return dir[i]*x.localeCompare(y);\
         if(isNaN(x))return 1;if(isNaN(y))return -1;return dir[i]*(x-y);});\
         rows.forEach(r=>t.tBodies[0].appendChild(r));});\
         </script></body></html>";

/// The page.
pub fn render(clips: &[ClipStatus], robot: &str) -> String {
    let mut ok: Vec<&ClipStatus> = clips
        .iter()
        .filter(|c| matches!(c.status, "retargeted" | "skipped"))
        .collect();
    let failed: Vec<&ClipStatus> = clips.iter().filter(|c| c.status == "failed").collect();
    // Worst first: failed checks, then the largest keypoint (or upper-body) error.
    ok.sort_by(|a, b| {
        healthy(a)
            .cmp(&healthy(b))
            .then(sort_key(b).total_cmp(&sort_key(a)))
    });
    let columns: Vec<(&str, &str)> = COLUMNS
        .into_iter()
        .filter(|(key, _)| ok.iter().any(|c| figure(c, key).is_some()))
        .collect();
    let mut s = String::from(HEAD);
    s.push_str(&intro(clips, robot, failed.len()));
    s.push_str(&clips_table(&ok, &columns));
    s.push_str("<h2>Distributions across the dataset</h2>");
    for (key, label) in &columns {
        let v: Vec<f64> = ok.iter().filter_map(|c| figure(c, key)).collect();
        if !v.is_empty() {
            s.push_str(&histogram(label, &v));
        }
    }
    s.push_str(&failures_table(&failed));
    s.push_str(SORT_SCRIPT);
    s
}

/// The title and the paragraph counting the clips by status (`failed` of them failed).
fn intro(clips: &[ClipStatus], robot: &str, failed: usize) -> String {
    format!(
        "<h1>Dataset report</h1><p>Robot: {}. {} clips: {} retargeted, {} up to date (skipped), {} failed, {} not run (batch interrupted). \
         Rows are sorted worst first (checks failed, then the largest mean keypoint error, or upper-body RMS error on the joint route); click a header to sort by it. \
         Checks: on the keypoint route every joint limit kept, on the joint route the run checks (feet held, finite state, COM over the support). \
         Margins are signed: positive means a limit was exceeded.</p>",
        escape_html(robot),
        clips.len(),
        clips.iter().filter(|c| c.status == "retargeted").count(),
        clips.iter().filter(|c| c.status == "skipped").count(),
        failed,
        clips.iter().filter(|c| c.status == "interrupted").count()
    )
}

/// The table of the clips `ok` with the figures of `columns` (key, label), one row per clip.
fn clips_table(ok: &[&ClipStatus], columns: &[(&str, &str)]) -> String {
    let mut s =
        String::from("<h2>Clips</h2><table id=\"clips\"><thead><tr><th>clip</th><th>checks</th>");
    for (_, label) in columns {
        s.push_str(&format!("<th>{}</th>", escape_html(label)));
    }
    s.push_str("<th>files</th></tr></thead><tbody>");
    for c in ok {
        s.push_str(&clip_row(c, columns));
    }
    s.push_str("</tbody></table>");
    s
}

/// One clip's row: its name, checks, figures and links to its files.
fn clip_row(c: &ClipStatus, columns: &[(&str, &str)]) -> String {
    let h = healthy(c);
    let why = failures(c).join("; ");
    let mut s = format!(
        "<tr{}><td>{}</td><td data-v=\"{}\" title=\"{}\">{}</td>",
        if h { "" } else { " class=\"bad\"" },
        escape_html(&c.name),
        u8::from(h),
        escape_html(&why),
        if h {
            "passed".to_string()
        } else if why.is_empty() {
            "FAILED".to_string()
        } else {
            format!("FAILED: {}", escape_html(&why))
        }
    );
    for (key, _) in columns {
        match figure(c, key) {
            Some(v) => s.push_str(&format!("<td data-v=\"{v:e}\">{}</td>", cell(v))),
            None => s.push_str("<td data-v=\"\">–</td>"),
        }
    }
    // Links to the files the clip's folder holds, the viewer first.
    let dir = escape_html(&c.name);
    let links: Vec<String> = [
        ("viewer.html", "viewer"),
        ("motion.csv", "csv"),
        ("motion.npz", "npz"),
        ("quality.json", "quality"),
    ]
    .iter()
    .filter(|(f, _)| c.files.iter().any(|x| x == f))
    .map(|(f, label)| format!("<a href=\"{dir}/{f}\">{label}</a>"))
    .collect();
    let links = links.join(" ");
    s.push_str(&format!("<td>{links}</td></tr>"));
    s
}

/// The failed clips with their input and error, or "None.".
fn failures_table(failed: &[&ClipStatus]) -> String {
    let mut s = format!("<h2>Failures ({})</h2>", failed.len());
    if failed.is_empty() {
        s.push_str("<p>None.</p>");
    } else {
        s.push_str("<table id=\"failures\"><thead><tr><th>clip</th><th>input</th><th>error</th></tr></thead><tbody>");
        for c in failed {
            s.push_str(&format!(
                "<tr><td>{}</td><td>{}</td><td><pre>{}</pre></td></tr>",
                escape_html(&c.name),
                escape_html(&c.input),
                escape_html(c.error.as_deref().unwrap_or(""))
            ));
        }
        s.push_str("</tbody></table>");
    }
    s
}
