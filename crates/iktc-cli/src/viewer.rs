//! The 3D viewer of `iktc imitate` and `iktc walk` (Fig. 21): one self-contained HTML file (inline script, plain
//! 2D canvas, no network, no library) showing the captured skeleton and the robot side by side.
//! Drag to orbit, wheel to zoom; `viewer.html#t=1.5` opens paused at 1.5 s.

use std::path::Path;

use anyhow::{Context, Result};
use iktc::sim::viewer::ViewerData;

/// The page; `__DATA__` is replaced by the JSON of [`ViewerData`].
const TEMPLATE: &str = r##"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>iktc viewer (loading)</title>
<style>
body{margin:0;font:13px sans-serif;background:#f4f4f4;color:#222}
#bar{display:flex;gap:8px;align-items:center;padding:6px 8px;background:#fff;border-bottom:1px solid #ccc}
#bar input[type=range]{flex:1}
canvas{display:block;width:100%;height:calc(100vh - 40px);cursor:grab}
</style></head><body>
<div id="bar"><button id="play">pause</button><input id="slider" type="range" min="0" value="0" step="1">
<span id="time">0.00 s</span><label>speed <select id="speed"><option>0.25</option><option>0.5</option>
<option selected>1</option><option>2</option></select></label></div>
<canvas id="c"></canvas>
<script id="data" type="application/json">__DATA__</script>
<script>
"use strict";
const D = JSON.parse(document.getElementById("data").textContent);
const cv = document.getElementById("c"), ctx = cv.getContext("2d");
const slider = document.getElementById("slider"), timeLabel = document.getElementById("time");
const playBtn = document.getElementById("play"), speedSel = document.getElementById("speed");
const n = D.robot.frames.length;
slider.max = String(Math.max(0, n - 1));
let frame = 0, playing = true, last = null, az = -1.25, el = 0.25, dist = 7.0, acc = 0;
let drag = null;
// Centre of the scene: between the robot and the skeleton at frame 0.
let cx = 0, cy = 0, cz = 0.7;
{
  const pts = D.robot.frames[0].concat(D.skeleton.frames.length ? D.skeleton.frames[0] : []);
  for (const p of pts) { cx += p[0]; cy += p[1]; }
  cx /= Math.max(1, pts.length); cy /= Math.max(1, pts.length);
}
function project(p) {
  const x = p[0] - cx, y = p[1] - cy, z = p[2] - cz;
  const ca = Math.cos(az), sa = Math.sin(az), ce = Math.cos(el), se = Math.sin(el);
  const xr = ca * x - sa * y, yr = sa * x + ca * y;
  const depth = ce * yr - se * z, up = se * yr + ce * z;
  const s = Math.min(cv.width, cv.height) * 1.5 / (dist + depth);
  return [cv.width / 2 + xr * s, cv.height / 2 - up * s];
}
function line(a, b, color, w) {
  const p = project(a), q = project(b);
  ctx.strokeStyle = color; ctx.lineWidth = w;
  ctx.beginPath(); ctx.moveTo(p[0], p[1]); ctx.lineTo(q[0], q[1]); ctx.stroke();
}
function draw() {
  const w = cv.clientWidth, h = cv.clientHeight;
  if (cv.width !== w || cv.height !== h) { cv.width = w; cv.height = h; }
  ctx.fillStyle = "#fbfbfb"; ctx.fillRect(0, 0, cv.width, cv.height);
  // Ground grid.
  for (let i = -10; i <= 10; i++) {
    const g = i * 0.25;
    line([cx + g, cy - 2.5, 0], [cx + g, cy + 2.5, 0], "#e2e2e2", 1);
    line([cx - 2.5, cy + g, 0], [cx + 2.5, cy + g, 0], "#e2e2e2", 1);
  }
  // Footsteps (walking).
  for (const f of (D.footsteps || [])) {
    ctx.strokeStyle = "#888"; ctx.lineWidth = 1; ctx.beginPath();
    f.forEach((p, i) => { const q = project(p); if (i) ctx.lineTo(q[0], q[1]); else ctx.moveTo(q[0], q[1]); });
    ctx.closePath(); ctx.stroke();
  }
  // Support polygon (per frame when walking).
  const SP = (D.support_frames && D.support_frames.length) ? D.support_frames[Math.min(frame, D.support_frames.length - 1)] : D.support;
  if (SP.length > 2) {
    ctx.fillStyle = "rgba(60,160,90,0.25)"; ctx.strokeStyle = "#3a9a5a"; ctx.lineWidth = 1.5;
    ctx.beginPath();
    SP.forEach((p, i) => { const q = project(p); if (i) ctx.lineTo(q[0], q[1]); else ctx.moveTo(q[0], q[1]); });
    ctx.closePath(); ctx.fill(); ctx.stroke();
  }
  // Skeleton.
  if (D.skeleton.frames.length) {
    const ks = Math.min(frame, D.skeleton.frames.length - 1);
    const P = D.skeleton.frames[ks];
    for (const s of D.skeleton.segments) line(P[s[0]], P[s[1]], "#2f8f3f", 3);
  }
  // Robot, joints on a limit in red.
  const R = D.robot.frames[frame];
  const hot = new Set(D.on_limit[frame] || []);
  D.robot.segments.forEach((s, i) => line(R[s[0]], R[s[1]], hot.has(i) ? "#d62728" : "#1f5fbf", hot.has(i) ? 5 : 3));
  for (const i of hot) {
    const s = D.robot.segments[i];
    if (!s) continue;
    const q = project(R[s[1]]);
    ctx.fillStyle = "#d62728"; ctx.beginPath(); ctx.arc(q[0], q[1], 6, 0, 2 * Math.PI); ctx.fill();
  }
  // COM and its ground projection.
  const c = D.com[frame];
  if (c) {
    line(c, [c[0], c[1], 0], "#aa7700", 1);
    for (const [p, r, col] of [[c, 6, "#ff9900"], [[c[0], c[1], 0], 4, "#aa7700"]]) {
      const q = project(p); ctx.fillStyle = col; ctx.beginPath(); ctx.arc(q[0], q[1], r, 0, 2 * Math.PI); ctx.fill();
    }
  }
  ctx.fillStyle = "#222"; ctx.font = "14px sans-serif";
  ctx.fillText(D.title, 10, 20);
  ctx.fillText("blue: robot, red: joint on a limit, green: captured skeleton, orange: COM and its projection, green area: support polygon", 10, 40);
  const names = D.on_limit_names[frame] || [];
  ctx.fillText("on a limit: " + (names.length ? names.join(", ") : "none"), 10, 60);
  if (D.phases && D.phases.length) ctx.fillText("support: " + D.phases[Math.min(frame, D.phases.length - 1)] + " (grey: footsteps)", 10, 80);
  timeLabel.textContent = (frame * D.dt).toFixed(2) + " s";
  slider.value = String(frame);
}
function step(ts) {
  if (last === null) last = ts;
  const dtw = (ts - last) / 1000; last = ts;
  if (playing && n > 1) {
    acc += dtw * parseFloat(speedSel.value);
    while (acc >= D.dt) { acc -= D.dt; frame = (frame + 1) % n; }
  }
  draw();
  requestAnimationFrame(step);
}
playBtn.onclick = () => { playing = !playing; playBtn.textContent = playing ? "pause" : "play"; };
slider.oninput = () => { frame = parseInt(slider.value, 10) || 0; draw(); };
cv.onmousedown = e => { drag = [e.clientX, e.clientY]; };
window.onmouseup = () => { drag = null; };
window.onmousemove = e => {
  if (!drag) return;
  az -= (e.clientX - drag[0]) * 0.01; el = Math.max(-1.4, Math.min(1.4, el + (e.clientY - drag[1]) * 0.01));
  drag = [e.clientX, e.clientY]; draw();
};
cv.onwheel = e => { e.preventDefault(); dist = Math.max(1, Math.min(20, dist * (e.deltaY > 0 ? 1.1 : 0.9))); draw(); };
// viewer.html#t=1.5 opens paused at 1.5 s.
{
  const m = /t=([0-9.]+)/.exec(location.hash);
  if (m) { frame = Math.max(0, Math.min(n - 1, Math.round(parseFloat(m[1]) / D.dt))); playing = false; playBtn.textContent = "play"; }
}
draw();
document.title = "iktc viewer ready";
requestAnimationFrame(step);
</script></body></html>
"##;

/// Renders the page.
pub fn render_viewer(data: &ViewerData) -> Result<String> {
    // `</` inside the JSON would end the script element early.
    crate::finite::check("viewer data", data)?;
    let json = serde_json::to_string(data)?.replace("</", "<\\/");
    Ok(TEMPLATE.replace("__DATA__", &json))
}

/// Writes the page to `path`.
pub fn write_viewer(path: &Path, data: &ViewerData) -> Result<()> {
    let html = render_viewer(data)?;
    std::fs::write(path, html).with_context(|| format!("writing {}", path.display()))
}
