"""An HTML replay of a MuJoCo run next to iktc's plan: stick figures of the body tree, side
and front views, a slider (no dependency)."""
from __future__ import annotations

import json
import os
from typing import Sequence, Union

import mujoco  # type: ignore[import-untyped]

import iktc

from .plant import CONTROL_PERIOD, FloatArray, Plant, to_mujoco_qpos

_REPLAY_HTML = """<!doctype html>
<html><head><meta charset="utf-8"><title>%(title)s</title>
<style>body{font:14px sans-serif;margin:1em}svg{border:1px solid #ccc;background:#fafafa}</style>
</head><body>
<h3>%(title)s</h3>
<p><span style="color:#1f77b4">&#9632;</span> MuJoCo (physics) &nbsp;
<span style="color:#999">&#9632;</span> iktc's plan (kinematic) &nbsp; side view (x, z) and front
view (y, z), metres; ground at z = 0.</p>
<svg id="side" width="420" height="420" viewBox="-0.7 -1.4 1.4 1.4"></svg>
<svg id="front" width="420" height="420" viewBox="-0.7 -1.4 1.4 1.4"></svg><br>
<input id="k" type="range" min="0" max="%(last)d" value="0" style="width:840px">
<button id="play">play</button> <span id="t"></span>
<script>
const D = %(data)s;
const svgs = {side: document.getElementById('side'), front: document.getElementById('front')};
function draw(k) {
  for (const [name, svg] of Object.entries(svgs)) {
    const a = name === 'side' ? 0 : 1;
    let s = '<line x1="-0.7" y1="0" x2="0.7" y2="0" stroke="#333" stroke-width="0.004"/>';
    for (const [key, colour] of [['plan', '#999'], ['physics', '#1f77b4']]) {
      const p = D[key][k];
      for (const [c, q] of D.edges) {
        s += `<line x1="${p[q][a]}" y1="${-p[q][2]}" x2="${p[c][a]}" y2="${-p[c][2]}" ` +
             `stroke="${colour}" stroke-width="0.012" stroke-linecap="round"/>`;
      }
    }
    svg.innerHTML = s;
  }
  document.getElementById('t').textContent = `t = ${(k * D.dt).toFixed(3)} s`;
}
const slider = document.getElementById('k');
slider.oninput = () => draw(+slider.value);
let timer = null;
document.getElementById('play').onclick = () => {
  if (timer) { clearInterval(timer); timer = null; return; }
  timer = setInterval(() => {
    slider.value = (+slider.value + 1) %% (D.physics.length);
    draw(+slider.value);
  }, D.dt * 1000);
};
draw(0);
</script></body></html>
"""


def write_replay(path: Union[str, "os.PathLike[str]"], plant: Plant,
                 qpos_physics: Sequence[FloatArray], q_plan: Sequence[FloatArray],
                 title: str) -> None:
    """An HTML replay (no dependency, stick figures of the body tree) of the physics run next to
    iktc's plan: `qpos_physics` MuJoCo's qpos per tick, `q_plan` iktc's q per tick."""
    if len(qpos_physics) != len(q_plan) or not len(q_plan):
        raise iktc.IktcError(f"qpos_physics, q_plan: expected the same number (>= 1) of ticks, "
                             f"got {len(qpos_physics)} and {len(q_plan)}")
    m = plant.model
    d = mujoco.MjData(m)
    bodies = list(range(1, m.nbody))
    edges = [[b - 1, int(m.body_parentid[b]) - 1] for b in bodies if m.body_parentid[b] > 0]

    def frames(rows: Sequence[FloatArray], from_plan: bool) -> list:
        out = []
        for r in rows:
            d.qpos[:] = to_mujoco_qpos(plant, r) if from_plan else r
            mujoco.mj_kinematics(m, d)
            out.append([[round(float(v), 4) for v in d.xpos[b]] for b in bodies])
        return out

    data = {"dt": CONTROL_PERIOD, "edges": edges, "physics": frames(qpos_physics, False),
            "plan": frames(q_plan, True)}
    with open(path, "w") as f:
        f.write(_REPLAY_HTML % {"title": title, "last": len(qpos_physics) - 1,
                                "data": json.dumps(data, separators=(",", ":"))})
