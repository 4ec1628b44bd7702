#!/usr/bin/env bash
# Renders one frame on a Slurm cluster: an array of SHARDS render tasks and a merge job that runs
# when all of them succeeded. Prints the two job ids.
#
#   RT_SPP=4096 RT_PARTS=/shared/frame1 RT_OUTPUT=/shared/frame1.exr RT_SCENE=/shared/scene.glb \
#   RT_ARGS="--width 3840 --height 2160" deploy/slurm/submit.sh 100 [extra sbatch flags...]
set -euo pipefail
shards=${1:?usage: submit.sh SHARDS [sbatch flags...]}
shift
here=$(cd "$(dirname "$0")" && pwd)
: "${RT_PARTS:?set RT_PARTS}" "${RT_OUTPUT:?set RT_OUTPUT}" "${RT_SPP:?set RT_SPP}"
mkdir -p "$RT_PARTS"
export RT_PARTS RT_OUTPUT RT_SPP
logs=${RT_LOGS:-$RT_PARTS}
render=$(sbatch --parsable --array="0-$((shards - 1))" --output="$logs/render-%a.log" "$@" \
    "$here/render.sbatch")
render=${render%%;*}
merge=$(sbatch --parsable --dependency="afterok:$render" --kill-on-invalid-dep=yes \
    --output="$logs/merge.log" "$@" "$here/merge.sbatch")
echo "render array $render, merge $merge"
