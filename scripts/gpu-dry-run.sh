#!/usr/bin/env bash
# The GPU slot's path, tried here so that it cannot rot before a GPU comes (CI runs it): builds
# the bundle (scripts/gpu-bundle.sh), copies the tracked tree and .gpu-bundle/ alone into a
# temporary folder with no ../shared beside it, and there, with no cargo or rustc on PATH, runs
# scripts/gpu-run.sh as a slot would:
#   1. as it is: it must refuse the CPU adapter (llvmpipe or lavapipe here), naming it, and run
#      nothing;
#   2. with GIBENCH_ALLOW_CPU=1 GIBENCH_SLOT=${GIBENCH_SLOT:-4m} and the bundle's loaders forced:
#      it must write a complete results/gpu-<device>/ with its manifest (reproduce-all.json, in
#      which every target either completed or was left out by the budget) and the pack.
#   bash scripts/gpu-dry-run.sh
set -euo pipefail
cd "$(dirname "$0")/.."
fail() { echo "gpu-dry-run.sh: $*" >&2; exit 1; }

bash scripts/gpu-bundle.sh
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
tree="$work/checkout"
mkdir -p "$tree"
git ls-files -z | tar --null -T - -cf - | tar -C "$tree" -xf -
cp -r .gpu-bundle "$tree/"
size=$(du -sb "$tree" | cut -f1)
echo "gpu-dry-run.sh: the slot's copy is $size bytes (of at most 64 MiB)" >&2
[ "$size" -lt $((64 << 20)) ] || fail "the copy is $size bytes, over 64 MiB"
[ ! -e "$work/shared" ] || fail "$work/shared exists"

# PATH without the Rust toolchain.
path=
IFS=: read -r -a dirs <<< "$PATH"
for d in "${dirs[@]}"; do
    [ -x "$d/cargo" ] || [ -x "$d/rustc" ] || path="${path:+$path:}$d"
done
slot() { (cd "$tree" && env -u GIBENCH_ASSETS -u CARGO_TARGET_DIR PATH="$path" "$@" bash scripts/gpu-run.sh); }
(PATH="$path" command -v cargo >/dev/null) && fail "cargo is still on PATH"

echo "== without GIBENCH_ALLOW_CPU: the CPU adapter is refused by name" >&2
set +e
out=$(slot 2>&1)
status=$?
set -e
echo "$out" >&2
[ "$status" = 3 ] || fail "expected exit status 3 (refused), got $status"
echo "$out" | grep -Eqi "adapter is '[^']*(llvmpipe|lavapipe)" || fail "the refusal does not name the adapter"
! compgen -G "$tree/results/gpu-*" >/dev/null || fail "the refused run wrote results/gpu-*"

echo "== GIBENCH_ALLOW_CPU=1 GIBENCH_SLOT=${GIBENCH_SLOT:-4m}, the bundle's loaders" >&2
# A target may fail on the CPU driver at paper sizes (llvmpipe's 128 MiB storage buffers): the
# budget run leaves it out with its error, publishes the rest and exits 1. Any other status
# fails the dry run; so does a failure the manifest does not record.
set +e
slot GIBENCH_ALLOW_CPU=1 GIBENCH_SLOT="${GIBENCH_SLOT:-4m}" GIBENCH_FORCE_LOADERS=1 \
    GIBENCH_PACK_TO="$work/back"
status=$?
set -e
[ "$status" = 0 ] || [ "$status" = 1 ] || fail "gpu-run.sh exited with $status"
folder=$(compgen -G "$tree/results/gpu-*/" | head -1)
[ -n "$folder" ] || fail "no results/gpu-<device>/ folder"
manifest="$folder/reproduce-all.json"
[ -s "$manifest" ] || fail "no manifest $manifest"
python3 - "$manifest" "$folder" "$status" <<'EOF'
import json, os, sys
m = json.load(open(sys.argv[1]))
folder = sys.argv[2]
done = [t for t in m["targets"] if not t.get("left_out")]
left = [t for t in m["targets"] if t.get("left_out")]
assert done, "no target completed in the dry run"
assert m.get("budget_s"), "the manifest records no budget"
for t in done:
    missing = [f for f in t["files"] if not os.path.isfile(os.path.join(folder, f))]
    assert not missing, f"{t['name']}: files listed but not written: {missing[:5]}"
failed = [t["name"] for t in left if t["left_out"].startswith("failed: ")]
status = int(sys.argv[3])
assert (status != 0) == bool(failed), f"exit status {status} with failed targets {failed}"
if failed:
    print(f"gpu-dry-run.sh: failed on this adapter (left out, recorded): {failed}", file=sys.stderr)
print(f"gpu-dry-run.sh: {len(done)} targets completed on {m['adapter']}, "
      f"{len(left)} left out by the budget ({m['budget_s']:.0f} s)", file=sys.stderr)
EOF
ls "$work/back"/gpu-*.tar.xz* >/dev/null 2>&1 || fail "no pack copied to GIBENCH_PACK_TO"
n=$(ls "$work/back" | wc -l)
[ "$n" -le 8 ] || fail "$n files to bring back, over 8"
echo "gpu-dry-run.sh: ok ($(ls "$work/back" | paste -sd' ' -))" >&2
