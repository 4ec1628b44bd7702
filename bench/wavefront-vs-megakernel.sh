#!/usr/bin/env bash
# The wavefront kernels against the megakernel on the whole bench suite, and optionally against an
# older rt-cli binary (e.g. the first version, d599ca9, whose bench has neither --kernel nor
# --only), in alternating rounds so that drift on a shared machine hits every side. Each JSON
# record gets a "bin" field: old, wavefront or megakernel. Medians: see docs/performance-log.md.
# Usage: bench/wavefront-vs-megakernel.sh [ROUNDS] [SIZE] [SPP] [OLD_RT_CLI] > results.jsonl
set -euo pipefail
cd "$(dirname "$0")/.."
rounds="${1:-5}"
size="${2:-256}"
spp="${3:-8}"
old="${4:-}"
cargo build --release --locked -p rt-cli >&2
cli=target/release/rt-cli
tag() { sed "s/^{/{\"bin\":\"$1\",/"; }
for _ in $(seq "$rounds"); do
    if [ -n "$old" ]; then
        "$old" bench --size "$size" --spp "$spp" | grep '^{' | tag old
    fi
    for kernel in wavefront megakernel; do
        "$cli" bench --size "$size" --spp "$spp" --kernel "$kernel" | grep '^{' | tag "$kernel"
    done
done
