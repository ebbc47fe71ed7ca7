#!/usr/bin/env bash
# Before/after timings of two commits, measured in one alternating run (docs/comparing.md):
#
#   bash scripts/ab.sh BEFORE AFTER OUT [COMPARE-OPTION...] -- RUN-ARGUMENT...
#
# builds the gibench binary of each commit (a git worktree and a target directory of each under
# target/ab/, kept for the next comparison: a first build of a commit is a cold one, minutes;
# one target directory for both would let cargo take one commit's crates for the other's, as
# their sources' times can say they are fresh), then runs `gibench run RUN-ARGUMENT...`
# five times with each binary, BEFORE and AFTER alternating (REPEATS=N for another count), into
# OUT/before/rI and OUT/after/rI, and compares them with `gibench compare --statistic median`
# (and COMPARE-OPTIONs, e.g. --ignore-param NAME) into OUT/compare.{md,csv,tex,json}. Each run
# records the commit its binary was built from; of each repeat only its results files are kept.
# OUT must not exist (nothing is overwritten); OUT/command.txt holds the command line.
set -euo pipefail

usage() {
  echo "usage: bash scripts/ab.sh BEFORE AFTER OUT [COMPARE-OPTION...] -- RUN-ARGUMENT..." >&2
  echo "error: $1" >&2
  exit 2
}

[ $# -ge 4 ] || usage "expected two commits, an output folder and run arguments after --"
before=$1 after=$2 out=$3
shift 3
compare_options=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
  compare_options+=("$1")
  shift
done
[ $# -gt 0 ] || usage "no -- before the run arguments"
shift
[ $# -gt 0 ] || usage "no run arguments after --"
repeats=${REPEATS:-5}
[[ $repeats =~ ^[0-9]+$ ]] && [ "$repeats" -ge 5 ] ||
  usage "REPEATS=$repeats: expected a whole number of at least 5 (gibench compare needs five repeats a side)"
[ ! -e "$out" ] || usage "OUT $out exists: name a new folder (nothing is overwritten)"
for arg in "$@"; do
  case $arg in
    --out | --out=*) usage "the run arguments name --out; scripts/ab.sh chooses each run's folder" ;;
    --quiet) usage "the run arguments name --quiet; scripts/ab.sh passes it to every run" ;;
  esac
done

root=$(git rev-parse --show-toplevel)
declare -A commit
for side in before after; do
  rev=${!side}
  commit[$side]=$(git -C "$root" rev-parse --verify --quiet "$rev^{commit}") ||
    usage "$side: '$rev' is not a commit of this repository"
done

# Both binaries first: a build failing after half the runs would leave half a measurement.
ab="$root/target/ab"
mkdir -p "$ab"
# Forget worktrees whose folders are gone (`cargo clean` removes target/ab).
git -C "$root" worktree prune
declare -A bin
for side in before after; do
  c=${commit[$side]}
  tree="$ab/tree-${c:0:12}"
  # A kept tree is used only while it is still that commit, unchanged; else made again.
  if [ -d "$tree" ] && { [ "$(git -C "$tree" rev-parse HEAD 2>/dev/null)" != "$c" ] ||
    [ -n "$(git -C "$tree" status --porcelain --untracked-files=no 2>/dev/null)" ]; }; then
    git -C "$root" worktree remove --force "$tree" 2>/dev/null || rm -rf "$tree"
    git -C "$root" worktree prune
  fi
  if [ ! -d "$tree" ]; then
    git -C "$root" worktree add --detach --quiet "$tree" "$c"
  fi
  echo "== building $side (${c:0:12})" >&2
  (cd "$tree" && CARGO_TARGET_DIR="$ab/target-${c:0:12}" cargo build --release --quiet --bin gibench)
  bin[$side]="$ab/target-${c:0:12}/release/gibench"
done

mkdir -p "$out"
printf 'bash scripts/ab.sh %s %s %s' "$before" "$after" "$out" >"$out/command.txt"
printf ' %q' ${compare_options[@]+"${compare_options[@]}"} -- "$@" >>"$out/command.txt"
printf '\n# before = %s, after = %s, %s repeats\n' "${commit[before]}" "${commit[after]}" "$repeats" >>"$out/command.txt"
for i in $(seq 1 "$repeats"); do
  for side in before after; do
    echo "== repeat $i of $repeats: $side" >&2
    "${bin[$side]}" run "$@" --out "$out/$side/r$i" --quiet >/dev/null
    # The results files are what the comparison reads; each repeat's own tables and figures
    # would only make the folder large.
    find "$out/$side/r$i" -maxdepth 1 -type f ! -name '*.json' -delete
  done
done
"${bin[after]}" compare "$out/before" "$out/after" --statistic median \
  ${compare_options[@]+"${compare_options[@]}"} --out "$out"
