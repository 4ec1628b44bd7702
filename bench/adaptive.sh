#!/usr/bin/env bash
# Adaptive sampling against uniform sampling at equal time: the Cornell box (against the Mitsuba
# reference) and the low-resolution bunny (against rt's own 2048-spp render with the independent
# sampler, made first), 256x256, time limits 1-8 s, thresholds 0.05, 0.02, 0.01. Prints CSV:
# scene,variant,limit_s,render_s,mean_spp,rel_mse (docs/quality.md, "Adaptive sampling").
# Usage: bench/adaptive.sh CORNELL_REFERENCE.exr > adaptive.csv
set -euo pipefail
cd "$(dirname "$0")/.."
cornell_ref="${1:?usage: bench/adaptive.sh CORNELL_REFERENCE.exr}"
cargo build --release --locked -p rt-cli >&2
cli=target/release/rt-cli
bunny=assets/bunny/bunny-lowres-npm.obj
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
"$cli" render "$bunny" --width 256 --height 256 --spp 2048 --sampler independent -o "$tmp/bunny.exr" >&2
echo "scene,variant,limit_s,render_s,mean_spp,rel_mse"
for t in 1 2 4 8; do
    for a in "" "--adaptive 0.05" "--adaptive 0.02" "--adaptive 0.01"; do
        for scene in cornell bunny; do
            if [ "$scene" = cornell ]; then args=(); ref="$cornell_ref"; else args=("$bunny"); ref="$tmp/bunny.exr"; fi
            # shellcheck disable=SC2086 # $a is a list of flags
            log=$("$cli" render "${args[@]}" --width 256 --height 256 --time-limit "$t" $a -o "$tmp/a.exr" 2>&1)
            spp=$(grep -oP "mean \K[\d.]+" <<<"$log" || grep -oP "^image: +\d+x\d+, \K\d+" <<<"$log")
            secs=$(grep -oP "render time: +\K[\d.]+m?s" <<<"$log")
            err=$("$cli" compare "$tmp/a.exr" "$ref" | grep -oP "relMSE: +\K\S+")
            echo "$scene,${a:-none},$t,$secs,$spp,$err"
        done
    done
done
