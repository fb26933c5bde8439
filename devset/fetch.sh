#!/usr/bin/env bash
# Usage: devset/fetch.sh — copies the development set's clips into devset/motions/ from the
# public repositories they come from (cloned once into $CACHE, default ~/.cache/iktc-devset).
# Nothing here runs at build or test time.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
cache=${CACHE:-$HOME/.cache/iktc-devset}
mkdir -p "$cache" "$here/motions"
clone() { [ -d "$cache/$2" ] || git clone --depth 1 "https://github.com/$1.git" "$cache/$2"; }
clone BandaiNamcoResearchInc/Bandai-Namco-Research-Motiondataset bandai
clone 20tab/bvh-python bvh-python
clone omimo/PyMO pymo
bn=$cache/bandai/dataset
for f in 1/data/dataset-1_bow_normal_001 1/data/dataset-1_dance-short_normal_001 \
         1/data/dataset-1_walk_normal_001 2/data/dataset-2_run_active_005 \
         2/data/dataset-2_walk-turn-left_normal_001; do
  cp "$bn/Bandai-Namco-Research-Motiondataset-$f.bvh" "$here/motions/bn_$(basename "$f").bvh"
done
cp "$cache/bvh-python/tests/test_freebvh.bvh" "$here/motions/mixamo_freebvh.bvh"
cp "$cache/bvh-python/tests/test_mocapbank.bvh" "$here/motions/mocapbank.bvh"
cp "$cache/pymo/demos/data/AV_8Walk_Meredith_HVHA_Rep1.bvh" "$here/motions/pymo_av8walk.bvh"
ls "$here/motions"
