//! The 3D viewer of `iktc imitate`, `iktc retarget` and `iktc walk` (Fig. 21): one self-contained HTML file
//! (inline script, plain 2D canvas, no network, no library) showing the captured skeleton and the
//! robot side by side. Drag to orbit, wheel to zoom, "follow" keeps a travelling clip in the
//! centre; `viewer.html#t=1.5` opens paused at 1.5 s.
//!
//! A robot with meshes (the built-in G1, or a URDF whose STL meshes are on disk) is drawn with
//! them: every link's mesh placed by the link's pose of the frame, its triangles sorted far to
//! near and filled in that order (painter's algorithm), each shaded by a directional light from
//! the viewer's side, `shade = 0.3 + 0.7·|n·l|` with `n` the triangle's unit normal and `l` the
//! unit light direction. A robot without meshes is drawn as a stick figure.

use std::path::Path;

use anyhow::{Context, Result};
use iktc::mesh::builtin::builtin_meshes;
use iktc::mesh::urdf::meshes_from_urdf;
use iktc::mesh::{MeshSet, VIEWER_CELL};
use iktc::model::Robot;
use iktc::profile::{ProfileOrigin, RobotProfile};
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
<option selected>1</option><option>2</option></select></label>
<label title="keep the robot and the skeleton in the centre of the view"><input id="follow" type="checkbox" checked> follow</label></div>
<canvas id="c"></canvas>
<script id="data" type="application/json">__DATA__</script>
<script>
"use strict";
const D = JSON.parse(document.getElementById("data").textContent);
const cv = document.getElementById("c"), ctx = cv.getContext("2d");
const slider = document.getElementById("slider"), timeLabel = document.getElementById("time");
const playBtn = document.getElementById("play"), speedSel = document.getElementById("speed");
const n = D.robot.frames.length;
// Meshes (when the robot has them): packed link meshes and per-frame link orientations.
let M = null;
function b64(s) {
  const bin = atob(s), u = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) u[i] = bin.charCodeAt(i);
  return u;
}
if (D.meshes) {
  const u = b64(D.meshes.packed), dv = new DataView(u.buffer);
  const linkIndex = new Map(D.meshes.links.map((nm, i) => [nm, i]));
  const parts = [];
  let o = 8, NV = 0, NT = 0;
  const count = dv.getUint32(o, true); o += 4;
  for (let m = 0; m < count; m++) {
    const len = dv.getUint16(o, true); o += 2;
    const name = new TextDecoder().decode(u.subarray(o, o + len)); o += len;
    const color = [u[o], u[o + 1], u[o + 2]]; o += 3;
    const lo = [], hi = [];
    for (let k = 0; k < 6; k++) { (k < 3 ? lo : hi).push(dv.getFloat32(o, true)); o += 4; }
    const nv = dv.getUint32(o, true), nt = dv.getUint32(o + 4, true); o += 8;
    const v = new Float32Array(nv * 3);
    for (let i = 0; i < nv * 3; i++) { const k = i % 3; v[i] = lo[k] + dv.getUint16(o, true) * (hi[k] - lo[k]) / 65535; o += 2; }
    // Indices: LEB128 varints against the high-water mark hw (0: the next new vertex).
    const bytes = dv.getUint32(o, true); o += 4;
    const t = new Uint32Array(nt * 3), end = o + bytes;
    let hw = 0;
    for (let i = 0; i < nt * 3; i++) {
      let d = 0, shift = 0, byte;
      do { byte = u[o++]; d |= (byte & 127) << shift; shift += 7; } while (byte & 128);
      t[i] = NV + (d === 0 ? hw++ : hw - d);
    }
    o = end;
    const li = linkIndex.get(name);
    if (li !== undefined) parts.push({ link: li, color, v, t, v0: NV, t0: NT });
    NV += nv; NT += nt;
  }
  const r = b64(D.meshes.rotations);
  M = {
    parts, nl: D.meshes.links.length, rot: new Int16Array(r.buffer, 0, r.length >> 1),
    sx: new Float32Array(NV), sy: new Float32Array(NV), sd: new Float32Array(NV),
    wx: new Float32Array(NV), wy: new Float32Array(NV), wz: new Float32Array(NV),
    td: new Float32Array(NT), order: new Uint32Array(NT), shade: new Uint8Array(NT), part: new Uint16Array(NT),
    tris: new Uint32Array(NT * 3), nt: 0, styles: new Map()
  };
}
slider.max = String(Math.max(0, n - 1));
let frame = 0, playing = true, last = null, az = -1.25, el = 0.25, dist = 7.0, acc = 0;
let drag = null;
// Centre of the scene: between the robot and the skeleton (at frame 0, or at every frame
// with "follow" checked, so a clip that travels stays in view).
// Distance: the scene's size at frame 0 fills about two thirds of the canvas.
const followBox = document.getElementById("follow");
let cx = 0, cy = 0, cz = 0.7;
function sceneCentre(f) {
  const ks = Math.min(f, D.skeleton.frames.length - 1);
  const pts = D.robot.frames[f].concat(ks >= 0 ? D.skeleton.frames[ks] : []);
  let x = 0, y = 0;
  for (const p of pts) { x += p[0]; y += p[1]; }
  return [x / Math.max(1, pts.length), y / Math.max(1, pts.length)];
}
{
  const pts = D.robot.frames[0].concat(D.skeleton.frames.length ? D.skeleton.frames[0] : []);
  const lo = [Infinity, Infinity, 0], hi = [-Infinity, -Infinity, 0];
  for (const p of pts) { for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], p[k]); hi[k] = Math.max(hi[k], p[k]); } }
  [cx, cy] = sceneCentre(0);
  const size = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  if (size > 0 && isFinite(size)) { dist = Math.max(2, Math.min(20, 2.3 * size)); cz = hi[2] / 2; }
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
let shown = -1;
function draw() {
  shown = frame;
  const w = cv.clientWidth, h = cv.clientHeight;
  if (cv.width !== w || cv.height !== h) { cv.width = w; cv.height = h; }
  if (followBox.checked) [cx, cy] = sceneCentre(frame);
  ctx.fillStyle = "#fbfbfb"; ctx.fillRect(0, 0, cv.width, cv.height);
  // Ground grid, fixed in the world (0.25 m cells around the centre): it shows the travel.
  const gx = Math.round(cx / 0.25) * 0.25, gy = Math.round(cy / 0.25) * 0.25;
  for (let i = -10; i <= 10; i++) {
    const g = i * 0.25;
    line([gx + g, gy - 2.5, 0], [gx + g, gy + 2.5, 0], "#e2e2e2", 1);
    line([gx - 2.5, gy + g, 0], [gx + 2.5, gy + g, 0], "#e2e2e2", 1);
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
  if (M) drawMeshes(R, hot);
  else D.robot.segments.forEach((s, i) => line(R[s[0]], R[s[1]], hot.has(i) ? "#d62728" : "#1f5fbf", hot.has(i) ? 5 : 3));
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
  ctx.fillText((M ? "grey: robot (" + D.meshes.triangles + " triangles), red: link whose joint is on a limit"
    : "blue: robot, red: joint on a limit") + ", green: captured skeleton, orange: COM and its projection, green area: support polygon", 10, 40);
  const names = D.on_limit_names[frame] || [];
  ctx.fillText("on a limit: " + (names.length ? names.join(", ") : "none"), 10, 60);
  if (D.phases && D.phases.length) ctx.fillText("support: " + D.phases[Math.min(frame, D.phases.length - 1)] + " (grey: footsteps)", 10, 80);
  timeLabel.textContent = (frame * D.dt).toFixed(2) + " s";
  slider.value = String(frame);
}
// The robot's meshes at this frame: vertices to world (link pose) and screen, triangles sorted
// far to near, filled with a directional light's shade; links whose joint is on a limit in red.
function drawMeshes(R, hot) {
  const hotLinks = new Set();
  for (const i of hot) { const s = D.robot.segments[i]; if (s) hotLinks.add(s[1]); }
  const ca = Math.cos(az), sa = Math.sin(az), ce = Math.cos(el), se = Math.sin(el);
  const s0 = Math.min(cv.width, cv.height) * 1.5;
  // Light: from the viewer, raised and to the left (world axes, unit length).
  let lx = -ce * sa + 0.6 * se * sa - 0.3 * ca, ly = -ce * ca + 0.6 * se * ca + 0.3 * sa, lz = se + 0.6 * ce;
  const ln = Math.hypot(lx, ly, lz); lx /= ln; ly /= ln; lz /= ln;
  let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity, nt = 0;
  M.parts.forEach((P, pi) => {
    const p = R[P.link];
    if (!p) return;
    const b = (frame * M.nl + P.link) * 4;
    let qx = M.rot[b] / 32767, qy = M.rot[b + 1] / 32767, qz = M.rot[b + 2] / 32767, qw = M.rot[b + 3] / 32767;
    const qn = Math.hypot(qx, qy, qz, qw) || 1; qx /= qn; qy /= qn; qz /= qn; qw /= qn;
    const r00 = 1 - 2 * (qy * qy + qz * qz), r01 = 2 * (qx * qy - qz * qw), r02 = 2 * (qx * qz + qy * qw);
    const r10 = 2 * (qx * qy + qz * qw), r11 = 1 - 2 * (qx * qx + qz * qz), r12 = 2 * (qy * qz - qx * qw);
    const r20 = 2 * (qx * qz - qy * qw), r21 = 2 * (qy * qz + qx * qw), r22 = 1 - 2 * (qx * qx + qy * qy);
    const v = P.v, nv = v.length / 3;
    for (let i = 0; i < nv; i++) {
      const a = v[3 * i], c = v[3 * i + 1], d = v[3 * i + 2], j = P.v0 + i;
      const wx = p[0] + r00 * a + r01 * c + r02 * d, wy = p[1] + r10 * a + r11 * c + r12 * d, wz = p[2] + r20 * a + r21 * c + r22 * d;
      M.wx[j] = wx; M.wy[j] = wy; M.wz[j] = wz;
      const x = wx - cx, y = wy - cy, z = wz - cz;
      const xr = ca * x - sa * y, yr = sa * x + ca * y;
      const depth = ce * yr - se * z, up = se * yr + ce * z, s = s0 / (dist + depth);
      const X = cv.width / 2 + xr * s, Y = cv.height / 2 - up * s;
      M.sx[j] = X; M.sy[j] = Y; M.sd[j] = depth;
      if (X < x0) x0 = X; if (X > x1) x1 = X; if (Y < y0) y0 = Y; if (Y > y1) y1 = Y;
    }
    const hotPart = hotLinks.has(P.link);
    for (let i = 0; i < P.t.length; i += 3) {
      const a = P.t[i], c = P.t[i + 1], d = P.t[i + 2];
      // Back faces (clockwise seen from the viewer: positive area with the screen's y down)
      // are hidden by the front of a closed mesh.
      if ((M.sx[c] - M.sx[a]) * (M.sy[d] - M.sy[a]) - (M.sy[c] - M.sy[a]) * (M.sx[d] - M.sx[a]) >= 0) continue;
      const ux = M.wx[c] - M.wx[a], uy = M.wy[c] - M.wy[a], uz = M.wz[c] - M.wz[a];
      const vx = M.wx[d] - M.wx[a], vy = M.wy[d] - M.wy[a], vz = M.wz[d] - M.wz[a];
      const nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
      const nn = Math.hypot(nx, ny, nz);
      const shade = nn > 0 ? 0.3 + 0.7 * Math.abs(nx * lx + ny * ly + nz * lz) / nn : 0.3;
      M.tris[3 * nt] = a; M.tris[3 * nt + 1] = c; M.tris[3 * nt + 2] = d;
      M.td[nt] = M.sd[a] + M.sd[c] + M.sd[d];
      M.shade[nt] = Math.round(shade * 31);
      M.part[nt] = hotPart ? 65535 : pi;
      M.order[nt] = nt;
      nt++;
    }
  });
  const order = M.order.subarray(0, nt);
  order.sort((i, j) => M.td[j] - M.td[i]);
  // Far to near; consecutive triangles of one colour filled as one path, and outlined in it
  // (half a pixel each side) so that no background shows between neighbours.
  let cur = null;
  ctx.lineWidth = 1; ctx.lineJoin = "round";
  ctx.beginPath();
  for (const k of order) {
    const pi = M.part[k], level = M.shade[k], key = pi * 32 + level;
    let st = M.styles.get(key);
    if (!st) {
      const c = pi === 65535 ? [214, 39, 40] : M.parts[pi].color, f = level / 31;
      st = "rgb(" + Math.round(c[0] * f) + "," + Math.round(c[1] * f) + "," + Math.round(c[2] * f) + ")";
      M.styles.set(key, st);
    }
    if (st !== cur) {
      if (cur !== null) { ctx.fillStyle = cur; ctx.strokeStyle = cur; ctx.fill(); ctx.stroke(); ctx.beginPath(); }
      cur = st;
    }
    const a = M.tris[3 * k], b = M.tris[3 * k + 1], c = M.tris[3 * k + 2];
    ctx.moveTo(M.sx[a], M.sy[a]); ctx.lineTo(M.sx[b], M.sy[b]); ctx.lineTo(M.sx[c], M.sy[c]); ctx.closePath();
  }
  if (cur !== null) { ctx.fillStyle = cur; ctx.strokeStyle = cur; ctx.fill(); ctx.stroke(); }
  // The robot's box on the page (CSS pixels), for tests and tools.
  const off = cv.getBoundingClientRect();
  document.body.dataset.robotBox = [x0 + off.left, y0 + off.top, x1 + off.left, y1 + off.top].map(Math.round).join(",");
}
function step(ts) {
  if (last === null) last = ts;
  const dtw = (ts - last) / 1000; last = ts;
  if (playing && n > 1) {
    acc += dtw * parseFloat(speedSel.value);
    while (acc >= D.dt) { acc -= D.dt; frame = (frame + 1) % n; }
  }
  // Redrawn when the frame or the canvas size changed (events redraw by themselves).
  if (frame !== shown || cv.width !== cv.clientWidth || cv.height !== cv.clientHeight) draw();
  requestAnimationFrame(step);
}
playBtn.onclick = () => { playing = !playing; playBtn.textContent = playing ? "pause" : "play"; };
slider.oninput = () => { frame = parseInt(slider.value, 10) || 0; draw(); };
followBox.onchange = () => draw();
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

/// The meshes of the robot `profile` names, for its viewer: the built-in G1's embedded ones,
/// or the STL meshes a URDF on disk references. `None` (the page draws a stick figure) for a
/// robot without meshes; every mesh left out is a warning on stderr, never an error.
pub fn robot_meshes(profile: &RobotProfile) -> Option<MeshSet> {
    let set = match &profile.origin {
        ProfileOrigin::Builtin => match builtin_meshes(&profile.urdf) {
            Ok(s) => s,
            Err(e) => {
                eprintln!(
                    "warning: the built-in meshes of {}: {e}; the viewer draws a stick figure",
                    profile.name
                );
                None
            }
        },
        ProfileOrigin::Directory(dir) => {
            let path = dir.join(&profile.urdf);
            let text = match std::fs::read_to_string(&path) {
                Ok(t) => t,
                Err(e) => {
                    eprintln!(
                        "warning: reading {} for its meshes: {e}; the viewer draws a stick figure",
                        path.display()
                    );
                    return None;
                }
            };
            let folder = path.parent().unwrap_or(Path::new("."));
            match meshes_from_urdf(&text, folder, VIEWER_CELL) {
                Ok(m) => {
                    for line in warning_lines(&m.warnings, m.set.meshes.is_empty()) {
                        eprintln!("{line}");
                    }
                    Some(m.set)
                }
                Err(e) => {
                    eprintln!(
                        "warning: the meshes of {}: {e}; the viewer draws a stick figure",
                        path.display()
                    );
                    None
                }
            }
        }
    };
    set.filter(|s| !s.meshes.is_empty())
}

/// Meshes left out that are named one by one; the others are counted.
const LISTED_MESH_WARNINGS: usize = 3;

/// The stderr lines for the meshes of a URDF left out (`warnings`, one per mesh): the first
/// [`LISTED_MESH_WARNINGS`] as they are, then how many more, and what the viewer draws
/// (`none_read`: no mesh could be read, so a stick figure).
fn warning_lines(warnings: &[String], none_read: bool) -> Vec<String> {
    let mut out: Vec<String> = warnings
        .iter()
        .take(LISTED_MESH_WARNINGS)
        .map(|w| format!("warning: viewer: {w}"))
        .collect();
    let more = warnings.len().saturating_sub(LISTED_MESH_WARNINGS);
    if more > 0 {
        out.push(format!(
            "warning: viewer: {more} more meshes left out ({} in all){}",
            warnings.len(),
            if none_read {
                "; no mesh could be read, the viewer draws a stick figure"
            } else {
                "; the viewer draws the links whose meshes were read"
            }
        ));
    }
    out
}

/// Puts `meshes` (of `robot`'s links) in `data` when there are any; warnings on stderr.
pub fn attach(data: &mut ViewerData, robot: &Robot, meshes: Option<&MeshSet>) -> Result<()> {
    if let Some(m) = meshes {
        for w in data.attach_meshes(robot, m)? {
            eprintln!("warning: viewer: {w}");
        }
    }
    Ok(())
}

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn many_mesh_warnings_are_summarised() {
        let ws: Vec<String> = (0..7).map(|i| format!("mesh {i} missing")).collect();
        let lines = warning_lines(&ws, true);
        assert_eq!(lines.len(), LISTED_MESH_WARNINGS + 1);
        assert_eq!(lines[0], "warning: viewer: mesh 0 missing");
        assert!(
            lines[3].contains("4 more meshes left out (7 in all)"),
            "{}",
            lines[3]
        );
        assert!(lines[3].contains("stick figure"));
        let few = warning_lines(&ws[..2], false);
        assert_eq!(
            few,
            vec![
                "warning: viewer: mesh 0 missing",
                "warning: viewer: mesh 1 missing"
            ]
        );
        assert!(warning_lines(&[], true).is_empty());
        assert!(warning_lines(&ws, false)[3].contains("links whose meshes were read"));
    }
}
