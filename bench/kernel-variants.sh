#!/usr/bin/env bash
# Specialised against generic kernels, and work-group shapes, on the Cornell box with 1, 2 and all
# material kinds; alternating runs so that drift on a shared machine hits both sides.
# Usage: bench/kernel-variants.sh [SIZE] [SPP] > results.jsonl
set -euo pipefail
cd "$(dirname "$0")/.."
size="${1:-256}"
spp="${2:-8}"
cargo build --release --locked -p rt-cli >&2
cli=target/release/rt-cli
for rep in 1 2; do
    for flags in "" "--generic"; do
        "$cli" bench --only cornell --size "$size" --spp "$spp" $flags | grep '^{'
    done
done
for rep in 1 2; do
    for wg in 8x8 16x4 4x16 16x16 32x1 8x4; do
        "$cli" bench --only cornell+all --size "$size" --spp "$spp" --workgroup "$wg" | grep '^{'
    done
done
