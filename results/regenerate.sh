#!/usr/bin/env bash
# Regenerates every committed result under results/ from the current commit, one command per
# result (the README lists the same commands beside each result). Run from the repository root
# on a clean checkout so that every results file records a clean git commit:
#
#   bash results/regenerate.sh            # everything (about 25 minutes on a 2-core CPU)
#   bash results/regenerate.sh laine      # only the commands whose output is under results/laine
#
# Paper-size runs (`gibench reproduce laine-tables` without --quick) are for a GPU and are not
# part of this script.
set -euo pipefail
cd "$(dirname "$0")/.."
only="${1:-}"
if [ -n "$(git status --porcelain --untracked-files=no -- . ':(exclude)results')" ]; then
  echo "regenerate.sh: the checkout has uncommitted changes outside results/; results would record a -dirty commit" >&2
  exit 1
fi
cargo build --release --quiet
g="${CARGO_TARGET_DIR:-target}/release/gibench"
run() { # run OUTPUT_DIR command... (a dedicated OUTPUT_DIR is emptied first: no stale files)
  local out="$1"; shift
  case "$out" in "results/$only"*) ;; *) [ -z "$only" ] || return 0 ;; esac
  echo "== gibench $*"
  case "$out" in results/laine|results/reference) ;; *) rm -rf "${out:?}" ;; esac
  "$g" "$@"
}

# Reference (Cornell, frame 0) and its two-seed error estimate.
run results/reference reference --scene cornell --frame 0 --error-estimate --no-cache --out results/reference

# Keller: tile and VPL sweeps, lag of the incremental variant.
run results/keller/tiles sweep --technique keller-full --sweep tiles=1x1,2x2,4x4,8x8 --param vpls=256 --frames 20 --warmup 3 --quiet --out results/keller/tiles
run results/keller/vpls sweep --technique keller-full --sweep vpls=64,128,256,512,1024 --frames 20 --warmup 3 --quiet --out results/keller/vpls
run results/keller/lag run --technique keller-full,keller-incremental --quality --quality-all --frames 60 --warmup 0 --timing stages --spp 64 --quiet --out results/keller/lag

# The VPL irradiance clamp: energy removed and error per scene (laine, the paper whose clamp it
# is, on Cornell, Maze and Sibenik; keller-full on Cornell).
for scene in cornell maze sibenik; do
  run results/clamp/$scene-laine sweep --scene $scene --technique laine --sweep clamp=0,1,3,10,30,100 --quality --frames 8 --warmup 3 --timing stages --quiet --out results/clamp/$scene-laine
done
run results/clamp/cornell-keller-full sweep --scene cornell --technique keller-full --sweep clamp=0,1,3,10,30,100 --quality --frames 8 --warmup 3 --timing stages --quiet --out results/clamp/cornell-keller-full

# Laine et al. 2007.
[ -n "$only" ] && [ "$only" != laine ] || rm -rf results/laine/runs
run results/laine reproduce laine-tables --quick --quiet --out results/laine
run results/laine reproduce laine-management --out results/laine
run results/laine reproduce laine-dispersion --out results/laine
run results/laine/tiles sweep --technique laine --sweep tiles=1x1,2x2,4x4,8x8 --param vpls=256 --frames 20 --warmup 3 --quiet --out results/laine/tiles
run results/laine/vpls sweep --technique laine --sweep vpls=64,128,256,512,1024 --frames 20 --warmup 3 --quiet --out results/laine/vpls
run results/laine/budget sweep --technique laine --sweep recalc-max=4,8,16,32 --param vpls=256 --frames 20 --warmup 3 --quiet --out results/laine/budget
run results/laine/quality run --technique laine,keller-full --param vpls=256 --quality --quality-all --frames 60 --warmup 0 --timing stages --spp 64 --quiet --out results/laine/quality
run results/laine/sibenik-vpls sweep --scene sibenik --technique laine --sweep vpls=64,128,256,512 --param vpl-map-size=64 --quality --quality-pairs 4 --frames 12 --warmup 3 --timing stages --quiet --out results/laine/sibenik-vpls
run results/laine/sibenik-1024 run --scene sibenik --technique laine,keller-full --param vpls=1024 --param vpl-map-size=64 --frames 3 --warmup 3 --no-images --quiet --out results/laine/sibenik-1024
# Instruction counts of the CPU kernels under callgrind: the baseline CI's gate fails against.
run results/baseline/instructions.json instructions --write --baseline results/baseline/instructions.json

# The timing baseline CI's regression report compares against: three repeats of every
# technique at a small size (gibench compare needs at least three a side).
for i in 1 2 3; do
  run results/baseline/r$i run --frames 20 --warmup 3 --timing stages --resolution 128x96 --no-images --quiet --out results/baseline/r$i
done
echo "regenerate.sh: done"
