#!/usr/bin/env bash
# Usage: devset/run.sh OUT ROBOT [iktc retarget flags...]
#   ROBOT: a built-in robot (g1, jvrc1) or a profile (.iktc.toml) or robot file.
#   IKTC: the binary (default target/release/iktc).
# Retargets every clip of devset/motions plus the two CMU clips under the crate's test data
# onto ROBOT and prints the neutral fidelity figures per clip and their means (table.py).
set -u
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
OUT=$1; R=$2; shift 2
IKTC=${IKTC:-$root/target/release/iktc}
name=$(basename "$R" .iktc.toml)
clips=("$here"/motions/*.bvh "$root"/crates/iktc/tests/data/motions/cmu/131_01.bvh \
       "$root"/crates/iktc/tests/data/motions/cmu/scaled_131_02.bvh)
mkdir -p "$OUT/$name"
"$IKTC" retarget "${clips[@]}" --robot "$R" "$@" --no-viewer --force --out "$OUT/$name" \
  > "$OUT/$name.log" 2>&1 || echo "$name: iktc exited with $? (see $OUT/$name.log)"
python3 "$here/table.py" "$OUT/$name"
