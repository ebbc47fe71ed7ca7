#!/bin/bash
# gibench reproduce all over a Slurm array: each task runs its shard (from SLURM_ARRAY_TASK_ID
# and SLURM_ARRAY_TASK_COUNT), then the last step merges them (docs/fleet.md).
#   sbatch --array=0-3 deploy/slurm-array.sh            # 4 shards, paper sizes
#   sbatch --dependency=afterok:JOBID --wrap 'bash deploy/slurm-array.sh merge'
#SBATCH --job-name=gibench
#SBATCH --gres=gpu:1
#SBATCH --time=02:00:00
# Preempted, the task is requeued; SIGTERM (preemption, or 2 minutes before the time limit)
# stops gibench politely with status 75, and the task requeues itself: the next start on the
# same --out resumes from the targets complete (docs/fleet.md, "Preemption and resume").
#SBATCH --requeue
#SBATCH --signal=B:TERM@120
set -euo pipefail
cd "${SLURM_SUBMIT_DIR:-.}"
OUT=${GIBENCH_FLEET_OUT:-results/fleet}
if [ "${1:-}" = merge ]; then
    exec cargo run --release -- merge "$OUT"/shard-* --out "$OUT/merged"
fi
cargo build --release --quiet
target/release/gibench reproduce all ${GIBENCH_QUICK:+--quick} --quiet \
    --out "$OUT/shard-${SLURM_ARRAY_TASK_ID}" &
pid=$!
# --signal=B: signals this shell only: pass SIGTERM on to gibench and wait for its status.
stopping=
trap 'stopping=1; kill -TERM "$pid" 2>/dev/null || true' TERM INT
rc=0
wait "$pid" || rc=$?
# A trapped signal ends a wait early: wait again, until one ends with gibench's own status
# (127: it was already collected).
while [ -n "$stopping" ]; do
    stopping=
    wait "$pid" && rc=0 || { r=$?; [ "$r" = 127 ] || rc=$r; }
done
if [ "$rc" = 75 ]; then
    scontrol requeue "$SLURM_JOB_ID"
fi
exit "$rc"
