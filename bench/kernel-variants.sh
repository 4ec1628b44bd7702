#!/usr/bin/env bash
# Specialised against generic kernels, and work-group shapes, of the megakernel (the wavefront
# kernels' shape is fixed at 64x1) on the Cornell box with 1, 2 and all material kinds; alternating
# runs so that drift on a shared machine hits both sides. (16x16 is gone: the traversal stacks in
# work-group memory allow at most 64 invocations.)
# Usage: bench/kernel-variants.sh [SIZE] [SPP] > results.jsonl
set -euo pipefail
cd "$(dirname "$0")/.."
size="${1:-256}"
spp="${2:-8}"
cargo build --release --locked -p rt-cli >&2
cli=target/release/rt-cli
for rep in 1 2; do
    for flags in "" "--generic"; do
        "$cli" bench --kernel megakernel --only cornell --size "$size" --spp "$spp" $flags | grep '^{'
    done
done
for rep in 1 2; do
    for wg in 8x8 16x4 4x16 32x1 8x4; do
        "$cli" bench --kernel megakernel --only cornell+all --size "$size" --spp "$spp" --workgroup "$wg" | grep '^{'
    done
done
