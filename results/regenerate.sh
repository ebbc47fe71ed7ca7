#!/usr/bin/env bash
# Regenerates every committed result under results/ from the current commit, one command per
# result (each results folder's README.md lists the same commands beside its results). Run from
# the repository root on a clean checkout so that every results file records a clean git commit:
#
#   bash results/regenerate.sh            # everything (the targets' times in results/reproduce-all.json, then some minutes more)
#   bash results/regenerate.sh laine      # only the targets whose output is under results/laine
#   bash results/regenerate.sh baseline   # only CI's baseline (instruction counts, timing)
#   bash results/regenerate.sh barczak-scenes  # only barczak on Sibenik, Sponza, Maze and the conference room
#   bash results/regenerate.sh roofline        # only the stage-efficiency runs (docs/roofline.md)
#   bash results/regenerate.sh lean            # only the lean stages' before/after (results/lean)
#   bash results/regenerate.sh lean/rejected   # only the changes measured and not taken (results/lean/rejected)
#   bash results/regenerate.sh fuzz            # only the fuzz campaign (results/fuzz)
#
# Paper-size runs (`gibench reproduce all` without --quick) are for a GPU and are not part of
# this script.
set -euo pipefail
cd "$(dirname "$0")/.."
only="${1:-}"
if [ -n "$(git status --porcelain --untracked-files=no -- . ':(exclude)results')" ]; then
  echo "regenerate.sh: the checkout has uncommitted changes outside results/; results would record a -dirty commit" >&2
  exit 1
fi
# The rejected lean changes (below) are patches to this commit: each must apply, checked before
# any step runs rather than after an hour of them.
if [ -z "$only" ] || case "results/lean/rejected/" in "results/$only"*) true ;; *) false ;; esac; then
  for patch in results/lean/rejected/*.patch; do
    git apply --check "$patch" ||
      { echo "regenerate.sh: $patch does not apply to this commit: make it again on it, or drop it" >&2; exit 1; }
  done
fi
cargo build --release --quiet
# The commit every step measures, resolved once (a commit made while this runs changes nothing).
head=$(git rev-parse HEAD)
g="${CARGO_TARGET_DIR:-target}/release/gibench"
run() { # run OUTPUT_DIR command... (OUTPUT_DIR is emptied first: no stale files)
  local out="$1"; shift
  case "$out" in "results/$only"*) ;; *) [ -z "$only" ] || return 0 ;; esac
  echo "== gibench $*"
  rm -rf "${out:?}"
  "$g" "$@"
}

# Every paper table, figure and sweep: the targets of `gibench reproduce all` (listed, with their
# commands, by `gibench reproduce all --quick --list`; docs/reproducing.md). `bash
# results/regenerate.sh laine` runs only the targets whose folder is under results/laine (and
# `results/keller`, `results/clamp`, `results/reference` likewise).
# The equal-time target runs on its own with LP_NUM_THREADS=0: on lavapipe's default threads a
# shared 2-core machine moves a run's frame time by tens of percent from run to run, which no
# equal-time search can aim within (docs/running.md, --equal-time); its results record the
# setting (device.driver_env) and count as another device's.
reproduce() { # reproduce TARGET,TARGET,... (equal-time, where listed, in a process of its own)
  # equal-time first: the manifest (results/reproduce-all.*) then names the other targets' run
  # as the last one, with equal-time's entry carried over.
  local rest
  [ -n "$1" ] || { echo "regenerate.sh: no targets to reproduce" >&2; exit 1; }
  if echo "$1" | tr , '\n' | grep -qx equal-time; then
    echo "== LP_NUM_THREADS=0 gibench reproduce all --quick --html --only equal-time"
    LP_NUM_THREADS=0 "$g" reproduce all --quick --html --only equal-time --out results
  fi
  rest=$(echo "$1" | tr , '\n' | grep -vx equal-time | paste -sd, - || true)
  if [ -n "$rest" ]; then
    echo "== gibench reproduce all --quick --html --only $rest"
    "$g" reproduce all --quick --html --only "$rest" --out results
  fi
}
if [ -z "$only" ]; then
  all=$("$g" reproduce all --quick --list 2>&1 | awk '/^  [a-z]/ && NF >= 3 { print $1 }' | paste -sd, -)
  reproduce "$all"
elif [ "$only" != baseline ]; then
  targets=$("$g" reproduce all --quick --list 2>&1 | awk -v d="$only" '/^  [a-z]/ && ($3 == d || index($3, d "/") == 1) { print $1 }' | paste -sd, -)
  case "results/gaitatzes/transfer" in "results/$only"*) transfer_only=1 ;; *) transfer_only=0 ;; esac
  case "results/barczak-scenes/" in "results/$only"*) scenes_only=1 ;; *) scenes_only=0 ;; esac
  case "results/roofline/" in "results/$only"*) scenes_only=1 ;; esac
  case "results/ism/vpl-counts" in "results/$only"*) scenes_only=1 ;; esac
  case "results/lean/" in "results/$only"*) scenes_only=1 ;; esac
  case "results/lean/rejected/" in "results/$only"*) scenes_only=1 ;; esac
  case "results/fuzz/" in "results/$only"*) scenes_only=1 ;; esac
  if [ -n "$targets" ]; then
    reproduce "$targets"
  elif [ "$transfer_only" = 0 ] && [ "$scenes_only" = 0 ]; then
    echo "regenerate.sh: no target writes under results/$only" >&2; exit 1
  fi
fi

# Gaitatzes' two-wall transfer sweep (model and GPU): an example of its crate, not a gibench
# command (results/gaitatzes/README.md).
case "results/gaitatzes/transfer" in "results/$only"*) run_transfer=1 ;; *) [ -n "$only" ] && run_transfer=0 || run_transfer=1 ;; esac
if [ "$run_transfer" = 1 ] && [ "$only" != baseline ]; then
  echo "== cargo run --release -p gibench-gaitatzes --example transfer -- results/gaitatzes/transfer"
  rm -rf results/gaitatzes/transfer
  cargo run --release --quiet -p gibench-gaitatzes --example transfer -- results/gaitatzes/transfer
fi

# Instruction counts of the CPU kernels under callgrind: the baseline CI's gate fails against.
run results/baseline/instructions.json instructions --write --baseline results/baseline/instructions.json

# The timing baseline CI's regression report compares against: five repeats of every
# technique at a small size (gibench compare needs at least five a side).
for i in 1 2 3 4 5; do
  run results/baseline/r$i run --frames 20 --warmup 3 --timing stages --resolution 128x96 --no-images --quiet --out results/baseline/r$i
done
# Barczak on the papers' large scenes and the conference room (charts as patches): preparation time, peak memory and
# error against the reference, one process per scene so that the peak is barczak's own
# (results/barczak-scenes/README.md).
for s in sibenik sponza maze conference; do
  run results/barczak-scenes/$s run --scene $s --technique barczak --frames 3 --warmup 0 --timing stages --resolution 128x96 --quality --quiet --out results/barczak-scenes/$s
done
# ism's error against the VPL count in finer steps than the ism-vpls target, with either warp
# (results/ism/README.md: why one count's figure carries its point set's luck).
run results/ism/vpl-counts sweep --technique ism --sweep vpls=128,192,256,320,384,448,512,576,640,768,1024 --quality --frames 8 --warmup 3 --timing stages --no-images --quiet --out results/ism/vpl-counts
run results/ism/vpl-counts-flat sweep --technique ism --sweep vpls=128,192,256,320,384,448,512,576,640,768,1024 --param vpl-warp=flat --quality --frames 8 --warmup 3 --timing stages --no-images --quiet --out results/ism/vpl-counts-flat
# Stage efficiency against the device's bounds (docs/roofline.md): every technique on the
# Cornell box at the default size, and gaitatzes on Sibenik; `gibench report DIR --detailed`
# prints their roofline tables.
run results/roofline/cornell run --frames 20 --warmup 3 --timing stages --no-images --quiet --out results/roofline/cornell
run results/roofline/sibenik run --scene sibenik --technique gaitatzes --frames 5 --warmup 1 --timing stages --no-images --quiet --out results/roofline/sibenik
# The lean stages (docs/roofline.md): the commit before that work (264d5f0) against this one,
# five alternating repeats of the VPL techniques at 256x192 and 512x384, each commit built in a
# worktree of its own (scripts/ab.sh). `submission` is barczak's parameter that work added.
if [ -z "$only" ] || case "results/lean/" in "results/$only"*) true ;; *) false ;; esac; then
  for res in 256x192 512x384; do
    echo "== bash scripts/ab.sh 264d5f0 ${head:0:12} results/lean/$res"
    rm -rf "results/lean/$res"
    bash scripts/ab.sh 264d5f0 "$head" "results/lean/$res" --ignore-param submission -- \
      --technique keller-full,keller-incremental,laine,ism,ism-classic,barczak --backend vulkan \
      --resolution "$res" --frames 10 --warmup 3 --no-images
  done
fi
# Changes measured and not taken (docs/roofline.md): each patch in results/lean/rejected is
# applied to this commit and committed in a worktree of its own, then timed against this commit
# by scripts/ab.sh (`ism`, five alternating repeats at 256x192 and 512x384).
if [ -z "$only" ] || case "results/lean/rejected/" in "results/$only"*) true ;; *) false ;; esac; then
  for patch in results/lean/rejected/*.patch; do
    name=$(basename "$patch" .patch)
    tree="${CARGO_TARGET_DIR:-target}/ab/rejected-$name"
    git worktree remove --force "$tree" 2>/dev/null || rm -rf "$tree"
    git worktree add --quiet --detach "$tree" "$head"
    git -C "$tree" apply "$PWD/$patch" ||
      { echo "regenerate.sh: $patch does not apply to ${head:0:12}" >&2; exit 1; }
    git -C "$tree" add -A
    git -C "$tree" -c user.name=regenerate.sh -c user.email=regenerate.sh@localhost \
      commit --quiet -m "rejected: $name (results/lean/rejected/$name.patch on ${head:0:12})"
    commit=$(git -C "$tree" rev-parse HEAD)
    git worktree remove --force "$tree"
    for res in 256x192 512x384; do
      echo "== bash scripts/ab.sh ${head:0:12} ${commit:0:12} results/lean/rejected/$name/$res"
      rm -rf "results/lean/rejected/$name/$res"
      bash scripts/ab.sh "$head" "$commit" "results/lean/rejected/$name/$res" -- \
        --technique ism --backend vulkan --resolution "$res" --frames 10 --warmup 3 --no-images
    done
  done
fi
# The fuzz campaign (docs/output.md, "Fuzzing"): 200,000 inputs a target, 40,000 for the
# manifests (each pooled by a merge that writes files), about 15 minutes on 2 cores.
if [ -z "$only" ] || case "results/fuzz/" in "results/$only"*) true ;; *) false ;; esac; then
  echo "== GIBENCH_FUZZ_CASES=200000 cargo test --release --test fuzz"
  mkdir -p results/fuzz
  {
    echo "# fuzz campaign: gibench $(git rev-parse --short "$head"), $(date -u +%Y-%m-%d), $(nproc) cores, 2 test threads"
    echo "# GIBENCH_FUZZ_CASES=200000 cargo test --release --test fuzz -- --nocapture --test-threads 2 --skip manifest"
    GIBENCH_FUZZ_CASES=200000 cargo test --release --quiet --test fuzz -- --nocapture --test-threads 2 --skip manifest | grep '^fuzz '
    echo "# GIBENCH_FUZZ_CASES=40000 cargo test --release --test fuzz -- --nocapture manifest"
    GIBENCH_FUZZ_CASES=40000 cargo test --release --quiet --test fuzz -- --nocapture manifest | grep '^fuzz '
  } > results/fuzz/campaign.txt.new
  mv results/fuzz/campaign.txt.new results/fuzz/campaign.txt
fi
echo "regenerate.sh: done"
