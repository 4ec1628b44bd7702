#!/usr/bin/env bash
# How a frame's cost splits across shards on this machine (docs/distributed.md): renders SCENE at
# SIZE and SPP as 1, 2 and 4 shards one after another (as 1, 2 or 4 machines would, each paying its
# own start-up), times each shard and the merge, and prints one line per run. Start-up (process,
# adapter, scene load, BVH build, pipeline compile) is the time of a 1-sample shard.
#
#   bench/shards.sh [SCENE] [WIDTHxHEIGHT] [SPP]      (defaults: the Cornell box, 512x512, 256)
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/env.sh
scene=${1:-}
size=${2:-512x512}
spp=${3:-256}
width=${size%x*}
height=${size#*x}
cli=target/release/rt-cli
[ -x "$cli" ] || cargo build --release -p rt-cli
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
args=(--width "$width" --height "$height")
if [ -n "$scene" ]; then args=("$scene" "${args[@]}"); fi
now() { date +%s.%N; }
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
echo "adapter: $("$cli" render --width 8 --height 8 --spp 1 -o "$dir/probe.png" 2>&1 | grep -m1 "^adapter" | cut -d: -f2- | xargs)"
t0=$(now)
"$cli" render "${args[@]}" --spp "$spp" --sample-range 0..1 -o "$dir/startup.exr" 2>/dev/null
startup=$(echo "$(now) - $t0" | bc)
echo "start-up (a 1-sample shard): ${startup}s"
for n in 1 2 4; do
    total=0
    longest=0
    for ((i = 0; i < n; i++)); do
        t0=$(now)
        "$cli" render "${args[@]}" --spp "$spp" --shard "$i/$n" -o "$dir/part-$n-$i.exr" 2>/dev/null
        t=$(echo "$(now) - $t0" | bc)
        total=$(echo "$total + $t" | bc)
        longest=$(echo "if ($t > $longest) $t else $longest" | bc)
    done
    t0=$(now)
    "$cli" merge "$dir"/part-$n-*.exr -o "$dir/frame-$n.exr" 2>/dev/null
    merge=$(echo "$(now) - $t0" | bc)
    printf 'shards %d: sum of shard times %.2fs, longest shard %.2fs, merge %.2fs, part %s\n' \
        "$n" "$total" "$longest" "$merge" "$(du -h "$dir/part-$n-0.exr" | cut -f1)"
done
