"""The README's Python examples run as written: every ```python block, in a scratch folder
that holds a `mocap/` folder of two BVH clips (the shared CMU test clips)."""
import contextlib
import io
import os
import re
import shutil
import tempfile

from test_controller import REPO

CLIPS = REPO / "crates" / "iktc" / "tests" / "data" / "motions" / "cmu"


def python_blocks():
    text = (REPO / "README.md").read_text(encoding="utf-8")
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def test_the_readme_has_python_examples():
    assert len(python_blocks()) >= 2


def test_every_python_example_of_the_readme_runs():
    work = tempfile.mkdtemp()
    shutil.copytree(CLIPS, os.path.join(work, "mocap"))
    here = os.getcwd()
    os.chdir(work)
    out = io.StringIO()
    try:
        for i, block in enumerate(python_blocks()):
            with contextlib.redirect_stdout(out):
                exec(compile(block, f"README python block {i}", "exec"), {"__name__": f"readme_{i}"})
    finally:
        os.chdir(here)
    # The folder example wrote one NPZ per clip and printed each clip's error.
    written = sorted(f for f in os.listdir(os.path.join(work, "mocap")) if f.endswith(".g1.npz"))
    assert written == ["131_01.g1.npz", "scaled_131_02.g1.npz"]
    lines = [line for line in out.getvalue().splitlines() if line.endswith(" cm")]
    assert [line.split()[0] for line in lines] == ["131_01.bvh", "scaled_131_02.bvh"]
