#!/usr/bin/env bash
# Before/after timings of `fourfold render`: two binaries run interleaved (so the machine's
# noise falls on both alike) on the same scenes, printing per run the process's wall time
# and the pipeline, frame and GPU-pass stages it reports, and whether the two pictures are
# identical.  Usage: tools/compare-render.sh OLD_BINARY NEW_BINARY [RUNS]
set -euo pipefail
old=$1 new=$2 runs=${3:-3}
cd "$(dirname "$0")/.."
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
scenes=(
  "examples/scenes/glome.toml --slice 0.3"
  "examples/scenes/fig-3-9-left.toml --slice 0.5"
  "examples/scenes/spheritorus.toml --slice 0.2"
  "examples/scenes/glome.toml --slab 0.2,0.3"
  "examples/scenes/glome.toml"
)
# The GPU's frames: a small slice is drawn on the CPU unless asked (binaries since
# render's --gpu).
declare -A gpu_flag
for which in old new; do
  gpu_flag[$which]=""
  if [[ $("${!which}" render --help) == *--gpu* ]]; then gpu_flag[$which]=--gpu; fi
done
echo "scene|binary|wall ms|pipeline ms|frame ms|GPU pass ms"
for scene in "${scenes[@]}"; do
  for _ in $(seq "$runs"); do
    for which in old new; do
      binary=${!which}
      gpu=${gpu_flag[$which]}
      start=$(date +%s%N)
      # shellcheck disable=SC2086
      line=$(XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp} "$binary" render $scene $gpu --size 512x512 -o "$out/$which.png" | grep '^times')
      end=$(date +%s%N)
      stages=$(echo "$line" | sed -E 's/.*pipeline ([0-9.]+)[^,]*, frame ([0-9.]+)( \(of which the GPU.s pass ([0-9.]+)\))?.*/\1|\2|\4/')
      echo "$scene|$which|$(( (end - start) / 1000000 ))|$stages"
    done
  done
  if cmp -s "$out/old.png" "$out/new.png"; then echo "$scene|the same picture"; else echo "$scene|the pictures differ"; fi
done
