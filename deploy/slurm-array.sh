#!/bin/bash
# gibench reproduce all over a Slurm array: each task runs its shard (from SLURM_ARRAY_TASK_ID
# and SLURM_ARRAY_TASK_COUNT), then the last step merges them (docs/fleet.md).
#   sbatch --array=0-3 deploy/slurm-array.sh            # 4 shards, paper sizes
#   sbatch --dependency=afterok:JOBID --wrap 'bash deploy/slurm-array.sh merge'
#SBATCH --job-name=gibench
#SBATCH --gres=gpu:1
#SBATCH --time=02:00:00
set -euo pipefail
cd "${SLURM_SUBMIT_DIR:-.}"
OUT=${GIBENCH_FLEET_OUT:-results/fleet}
if [ "${1:-}" = merge ]; then
    exec cargo run --release -- merge "$OUT"/shard-* --out "$OUT/merged"
fi
exec cargo run --release -- reproduce all ${GIBENCH_QUICK:+--quick} --quiet \
    --out "$OUT/shard-${SLURM_ARRAY_TASK_ID}"
