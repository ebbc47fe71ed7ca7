#!/bin/bash
# The one command for a GPU machine with a short slot (docs/fleet.md): builds, then runs
# `gibench reproduce all` at paper sizes with --budget set to what is left of the slot (15
# minutes in all by default, start-up and build included, less a margin for publishing), into
# results/gpu-<device>/. The manifest there records the device, what completed and what the
# budget left out, and why.
#   bash scripts/gpu-run.sh                 # a 15-minute slot
#   GIBENCH_SLOT=9m bash scripts/gpu-run.sh # another slot (seconds or Nm)
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
slot=${GIBENCH_SLOT:-15m}
case $slot in
    *m) slot_s=$(( ${slot%m} * 60 )) ;;
    *s) slot_s=${slot%s} ;;
    *) slot_s=$slot ;;
esac
# Time the machine spent before this script (its start-up), if the caller knows it.
slot_s=$(( slot_s - ${GIBENCH_SLOT_USED:-0} ))
cargo build --release
device=$(nvidia-smi --query-gpu=name --format=csv,noheader 2>/dev/null | head -1 || true)
device=${device:-$(hostname)}   # the manifest records the adapter itself
slug=$(printf '%s' "${device:-unknown}" | tr 'A-Z' 'a-z' | tr -cs 'a-z0-9' '-' | sed 's/^-//;s/-$//')
left=$(( slot_s - ($(date +%s) - start) - 60 ))   # 60 s for publishing and the copy-out
if [ "$left" -lt 30 ]; then
    echo "gpu-run.sh: only ${left}s of the slot left after the build; nothing run" >&2
    exit 1
fi
echo "gpu-run.sh: device '${device:-unknown}', budget ${left}s, into results/gpu-$slug" >&2
exec target/release/gibench reproduce all --budget "${left}s" --quiet --out "results/gpu-$slug"
