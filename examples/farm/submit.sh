#!/usr/bin/env bash
# Renders SCENE on a Slurm cluster as TILES array tasks, then merges them.
#   examples/farm/submit.sh SCENE TILES OUT.exr [PBRS FLAGS...]
# PBRS (default: pbrs on PATH) and PARTS (default: OUT's directory/parts-OUT)
# must be on storage every node sees. Prints the two job ids (array, merge).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
scene=$(realpath "$1"); tiles=$2; out=$(realpath -m "$3"); shift 3
export PBRS=${PBRS:-$(command -v pbrs)} SCENE=$scene TILES=$tiles OUT=$out
export PARTS=${PARTS:-$(dirname "$out")/parts-$(basename "$out" .exr)}
export PBRS_ARGS="$*"
mkdir -p "$PARTS"
array=$(sbatch --parsable --export=ALL --array="0-$((tiles - 1))" \
    --output="$PARTS/task-%a.log" "$here/render-tile.sbatch")
array=${array%%;*}
merge=$(sbatch --parsable --export=ALL --dependency="afterok:$array" \
    --kill-on-invalid-dep=yes --output="$PARTS/merge.log" "$here/merge.sbatch")
echo "$array ${merge%%;*}"
