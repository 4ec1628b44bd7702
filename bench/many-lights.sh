#!/usr/bin/env bash
# The light tree against power sampling: relMSE against time on the many-lights room (1,024 small
# emitters, bench/many-lights.py) and the Cornell box, each sampler's series in one CSV, on the
# backend --device names (cpu by default: the native backend; gpu: lavapipe where there is no
# GPU). The reference (target/many-lights-reference-1024spp.exr, or $REF) is rendered first if
# missing (light tree, 1024 spp, about 6 min on 2 cores).
# Usage: bench/many-lights.sh [OUT_DIR] [--device cpu|gpu]
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-docs/data}"
device="${3:-cpu}"
[ "${2:-}" = "--device" ] || device=cpu
mkdir -p "$out"
cargo build --release --locked -p rt-cli
cli=target/release/rt-cli
scene=bench/scenes/many-lights
ref="${REF:-target/many-lights-reference-1024spp.exr}"
if [ ! -f "$ref" ]; then
  "$cli" render "$scene/room.obj" --camera "$scene/camera.json" --device cpu --spp 1024 \
    --light-sampler tree -o "$ref"
fi
csv="$out/many-lights-converge-$device.csv"
rm -f "$csv"
common=("$scene/room.obj" --camera "$scene/camera.json" --reference "$ref" --max-spp 64
        --device "$device" --csv "$csv")
"$cli" converge "${common[@]}" --light-sampler power --label "power (alias table)"
"$cli" converge "${common[@]}" --light-sampler tree --label "light tree"
"$cli" plot "$csv" -o "$out/many-lights-converge-$device.svg" \
  --title "Many-lights room 320x240 (1,024 emitters): error against time ($device)"
