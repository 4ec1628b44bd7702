#!/usr/bin/env bash
# Convergence curves of the Cornell box against Mitsuba 3's 8192-spp reference, one series per
# knob, for docs/quality.md. Usage: bench/converge-cornell.sh [REFERENCE.exr] [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
ref="${1:-../shared/scenes/cornell/reference_mitsuba_8192spp.exr}"
out="${2:-docs/data}"
[ -f "$ref" ] || { echo "no reference at $ref (pass its path)" >&2; exit 1; }
mkdir -p "$out"
csv="$out/cornell-converge.csv"
rm -f "$csv"
cargo build --release --locked -p rt-cli
cli=target/release/rt-cli
common=(--reference "$ref" --width 128 --height 128 --max-spp 256 --csv "$csv")
"$cli" converge "${common[@]}" --label "NEE+MIS, Sobol, depth 8 (default)"
"$cli" converge "${common[@]}" --sampler independent --label "NEE+MIS, independent sampler"
"$cli" converge "${common[@]}" --denoise --label "NEE+MIS, denoised"
"$cli" converge "${common[@]}" --no-nee --label "BSDF sampling only"
"$cli" converge "${common[@]}" --nee-only --label "NEE only (no MIS)"
"$cli" converge "${common[@]}" --no-roulette --label "no Russian roulette"
"$cli" converge "${common[@]}" --max-depth 3 --label "max depth 3"
"$cli" converge "${common[@]}" --max-depth 16 --label "max depth 16"
"$cli" converge "${common[@]}" --clamp 1 --label "firefly clamp 1 (biased)"
"$cli" converge "${common[@]}" --bvh-quality fastest --label "fastest BVH build"
"$cli" plot "$csv" -o "$out/cornell-converge-time.svg" --title "Cornell box 128x128: error against time (lavapipe)"
"$cli" plot "$csv" -o "$out/cornell-converge-spp.svg" --x spp --title "Cornell box 128x128: error against samples"
