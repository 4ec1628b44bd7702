#!/usr/bin/env bash
# Raw, À-Trous and Open Image Denoise against high-spp references at 1 to 64 spp, on the Cornell
# box and the materials scene (tests/data/mitsuba-pbr: rough metals, plastic, glass, an
# environment), for docs/quality.md; then OIDN's time at 512² and 1280x720. The references are rt
# renders with another seed (2048 spp), so only the denoisers' error is measured, not a renderer
# difference. Usage: bench/denoise.sh [OUT_DIR]  (needs scripts/ensure-oidn for the OIDN rows)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-docs/data}"
mkdir -p "$out"
cargo build --release --locked -p rt-cli
cli=target/release/rt-cli
refs="${TMPDIR:-/tmp}/rt-denoise-refs"
mkdir -p "$refs"
pbr=tests/data/mitsuba-pbr
materials=("$pbr/scene.obj" --environment "$pbr/env.exr" --camera-from 0,1.6,5.2 --camera-to 0,0.55,0
    --vfov 32 --width 256 --height 192 --max-depth 8)
cornell=(--width 256 --height 256)
csv="$out/denoise-$(date +%F).csv"
rm -f "$csv"
for name in cornell materials; do
    if [ "$name" = cornell ]; then args=("${cornell[@]}"); else args=("${materials[@]}"); fi
    ref="$refs/$name-2048.exr"
    [ -f "$ref" ] || "$cli" render "${args[@]}" --seed 1234 --spp 2048 -o "$ref"
    "$cli" converge "${args[@]}" --reference "$ref" --max-spp 64 --csv "$csv" --label "$name raw"
    for d in atrous oidn; do
        "$cli" converge "${args[@]}" --reference "$ref" --max-spp 64 --csv "$csv" \
            --denoise="$d" --label "$name $d"
    done
done
echo "wrote $csv"
for size in "512 512" "1280 720"; do
    set -- $size
    "$cli" render --width "$1" --height "$2" --spp 1 --denoise=oidn -o "${TMPDIR:-/tmp}/rt-oidn-$1.png" 2>&1 |
        grep '^denoised:'
done
