#!/bin/bash
# Submit the conversion array and the merge that runs after it; prints both job ids.
#
#   examples/cluster/slurm/submit.sh ROOT OUT TASKS [more `interact3d batch` options]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
ROOT=${1:?usage: submit.sh ROOT OUT TASKS [options]}
OUT=${2:?usage: submit.sh ROOT OUT TASKS [options]}
TASKS=${3:?usage: submit.sh ROOT OUT TASKS [options]}
shift 3
array=$(sbatch --parsable --array="0-$((TASKS - 1))" "$here/convert.sbatch" "$ROOT" "$OUT" "$@")
merge=$(sbatch --parsable --dependency="afterany:${array%%;*}" "$here/merge.sbatch" "$OUT")
echo "array ${array%%;*} merge ${merge%%;*}"
