#!/usr/bin/env bash
# Renders the chapter's figures in examples/images/ from the scenes in examples/scenes/.
# Usage: examples/render-figures.sh   (from the repository root; uses the GPU, lavapipe here)
set -euo pipefail
cargo build --release --quiet
ff=target/release/fourfold
out=examples/images
$ff render examples/scenes/fig-3-9-left.toml  --size 512x512 -o $out/fig-3-9-left.png
$ff render examples/scenes/fig-3-9-right.toml --size 512x512 -o $out/fig-3-9-right.png
$ff render examples/scenes/fig-3-11.toml      --size 512x512 -o $out/fig-3-11.png
# 100 rays per pixel. (fourfold warns if a driver cut pixels short: then add --cpu, the CPU
# reference renderer of the same method.)
s=examples/scenes/fig-3-12.toml
cpu=""
$ff render $s --size 256x256 --no-silhouette --no-border $cpu -o $out/fig-3-12-light.png
$ff render $s --size 256x256 --no-lighting --no-border $cpu -o $out/fig-3-12-silhouette.png
$ff render $s --size 256x256 --no-lighting --no-silhouette $cpu -o $out/fig-3-12-border.png
$ff render $s --size 256x256 $cpu -o $out/fig-3-12-all.png
