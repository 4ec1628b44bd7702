#!/usr/bin/env bash
# The light tree against power sampling: relMSE against time on the many-lights room (1,024 small
# emitters, bench/many-lights.py), each sampler's series in one CSV, on the backend --device names
# (cpu by default: the native backend; gpu: lavapipe where there is no GPU). With --punctual, the
# same room lit by 256 point and spot lights (room-punctual.gltf, bench/many-lights.py --punctual
# --lights 256), which power sampling sums at every vertex and the tree samples one at a time.
# The reference (target/many-lights[-punctual]-reference-1024spp.exr, or $REF) is rendered first
# if missing (light tree, 1024 spp: about 6 min, or 3 min for the punctual room, on 2 cores).
# Usage: bench/many-lights.sh [OUT_DIR] [--device cpu|gpu] [--punctual]
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-docs/data}"
[ $# -gt 0 ] && shift
device=cpu
punctual=""
while [ $# -gt 0 ]; do
  case "$1" in
    --device) device="$2"; shift 2 ;;
    --punctual) punctual="-punctual"; shift ;;
    *) echo "usage: bench/many-lights.sh [OUT_DIR] [--device cpu|gpu] [--punctual]" >&2; exit 2 ;;
  esac
done
mkdir -p "$out"
cargo build --release --locked -p rt-cli
cli=target/release/rt-cli
dir=bench/scenes/many-lights
if [ -n "$punctual" ]; then
  scene="$dir/room-punctual.gltf"
  power_spp=8
  title="Many-lights room 320x240 (256 point and spot lights): error against time ($device)"
else
  scene="$dir/room.obj"
  power_spp=64
  title="Many-lights room 320x240 (1,024 emitters): error against time ($device)"
fi
ref="${REF:-target/many-lights$punctual-reference-1024spp.exr}"
if [ ! -f "$ref" ]; then
  "$cli" render "$scene" --camera "$dir/camera.json" --device cpu --spp 1024 \
    --light-sampler tree -o "$ref"
fi
csv="$out/many-lights$punctual-converge-$device.csv"
rm -f "$csv"
common=("$scene" --camera "$dir/camera.json" --reference "$ref" --device "$device" --csv "$csv")
# Power sampling sums the 256 punctual lights at each vertex: 8 of its samples take longer than
# the tree's 64.
"$cli" converge "${common[@]}" --max-spp "$power_spp" --light-sampler power \
  --label "power (alias table${punctual:+; points and spots summed})"
"$cli" converge "${common[@]}" --max-spp 64 --light-sampler tree --label "light tree"
"$cli" plot "$csv" -o "$out/many-lights$punctual-converge-$device.svg" --title "$title"
