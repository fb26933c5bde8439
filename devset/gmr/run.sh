#!/usr/bin/env bash
# Usage: devset/gmr/run.sh OUT
#   GMR_SRC: GMR's source tree (https://github.com/YanjieZe/GMR), default /tmp/gmr.
#   PYTHON: a Python with GMR's dependencies (mujoco, mink, numpy, scipy, qpsolvers[proxqp],
#           rich, tqdm, natsort, loop_rate_limiters, imageio), default python3.
#   IKTC: the iktc binary (default target/release/iktc).
#   GMR_HEIGHT: a fixed stature [m] (GMR's BVH loader uses 1.75); unset: estimated per clip.
# Runs GMR through gmr_adapter.py on every development-set clip onto Unitree G1 (GMR's own
# model and IK configuration), then scores its trajectories with `iktc evaluate` at 200 Hz
# (OUT/<clip>.json) and prints the table (../table.py reads the same figures).
set -u
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$(dirname "$here")")
OUT=$1
IKTC=${IKTC:-$root/target/release/iktc}
mkdir -p "$OUT"
for c in "$here"/../motions/*.bvh "$root"/crates/iktc/tests/data/motions/cmu/131_01.bvh \
         "$root"/crates/iktc/tests/data/motions/cmu/scaled_131_02.bvh; do
  n=$(basename "$c" .bvh)
  ${PYTHON:-python3} "$here/gmr_adapter.py" "$c" "$OUT/gmr" || { echo "GMR failed on $n"; continue; }
  mkdir -p "$OUT/g1/$n"
  "$IKTC" evaluate "$c" --robot g1 --trajectory "$OUT/gmr/$n.csv" --rate 200 \
    --out "$OUT/g1/$n/evaluate.json" > "$OUT/g1/$n.txt" 2>&1 || echo "evaluate failed on $n"
  # table.py reads quality.json's summary.keypoints.fidelity
  python3 -c "import json,sys; f=json.load(open(sys.argv[1]))['fidelity']; json.dump({'summary':{'keypoints':{'fidelity':f}}}, open(sys.argv[2],'w'))" \
    "$OUT/g1/$n/evaluate.json" "$OUT/g1/$n/quality.json"
done
python3 "$here/../table.py" "$OUT/g1"
