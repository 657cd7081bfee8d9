#!/usr/bin/env bash
# The paper's experiment on a Slurm cluster: a job array runs one shard per task, then a
# dependent job merges the shards (docs/experiment.md).
#   scripts/slurm-experiment.sh OUT_DIR [SHARDS] [extra fvp experiment options...]
# e.g. scripts/slurm-experiment.sh /scratch/fvp-exp 8 --trials 35 --first-seed 1
# Each shard writes OUT_DIR/shard-<i>/; the merge writes OUT_DIR/merged/ (trials.jsonl,
# summary.json, table1.md, sizes.png). Re-submitting resumes unfinished shards.
set -euo pipefail
if [ $# -lt 1 ]; then
  echo "usage: $0 OUT_DIR [SHARDS] [fvp experiment options...]" >&2
  exit 2
fi
out=$(realpath -m "$1")
shards=${2:-8}
shift $(( $# >= 2 ? 2 : 1 ))
fvp=${FVP:-$(realpath "$(dirname "$0")/../build/apps/fvp")}
[ -x "$fvp" ] || { echo "$0: $fvp is not built (cmake --build build)" >&2; exit 2; }
mkdir -p "$out/logs"

array_job=$(sbatch --parsable --job-name=fvp-exp --array=0-$((shards - 1)) \
  --cpus-per-task="${FVP_CPUS:-2}" --output="$out/logs/shard-%a.log" \
  --wrap="'$fvp' experiment --resume --shard \${SLURM_ARRAY_TASK_ID}/$shards --out '$out/shard-'\${SLURM_ARRAY_TASK_ID} $*")
dirs=""
for ((i = 0; i < shards; i++)); do dirs="$dirs '$out/shard-$i'"; done
merge_job=$(sbatch --parsable --job-name=fvp-merge --dependency=afterok:"$array_job" \
  --output="$out/logs/merge.log" --wrap="'$fvp' merge --out '$out/merged' $dirs")
echo "submitted shards as job $array_job, merge as job $merge_job; results in $out/merged"
