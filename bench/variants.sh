#!/usr/bin/env bash
# The kernel and BVH variants against the default on the Cornell box scenes, alternating rounds so
# that drift on a shared machine hits every variant alike; one JSON record per scene and variant
# (a "variant" field is added). Used for the Mesa 25.0 re-measurement in docs/performance-log.md.
# Usage: bench/variants.sh [SIZE] [SPP] > results.jsonl
set -euo pipefail
cd "$(dirname "$0")/.."
size="${1:-256}"
spp="${2:-16}"
cargo build --release --locked -p rt-cli >&2
cli=target/release/rt-cli
for rep in 1 2; do
    for v in "" "--bvh bvh2" "--generic" "--kernel megakernel" "--kernel megakernel --workgroup 16x4" \
        "--kernel megakernel --workgroup 32x1" "--trace hw"; do
        # shellcheck disable=SC2086 # $v is a list of flags
        "$cli" bench --only cornell --size "$size" --spp "$spp" $v | grep '^{' |
            sed "s/^{/{\"variant\":\"${v:-default}\",/"
    done
done
