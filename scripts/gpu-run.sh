#!/usr/bin/env bash
# The one command for a GPU machine with a short slot (docs/fleet.md): runs `gibench reproduce
# all` at paper sizes with --budget set to what is left of the slot (15 minutes in all by
# default, less a margin for packing), into results/gpu-<device>/, whose manifest records the
# device, what completed and what the budget left out, and why. Then packs that folder into
# results/gpu-<device>.tar.xz (split into 15 MiB parts when larger), which comes back as one file.
#
#   bash scripts/gpu-bundle.sh              # here, once: the bundle the slot carries (.gpu-bundle/)
#   bash scripts/gpu-run.sh                 # there: a 15-minute slot
#   GIBENCH_SLOT=9m GIBENCH_PACK_TO=$OUT bash scripts/gpu-run.sh   # another slot; copy the pack out
#
# With .gpu-bundle/ it needs no toolchain, network or ../shared: it unpacks the bundle's binary
# and scenes into a temporary folder, and the bundle's Vulkan/EGL loaders too when the machine
# has no libvulkan.so.1 (ldconfig), pointing the loaders at NVIDIA's ICD and EGL vendor files
# when the standard folders have none. Without a bundle it builds (`cargo build --release`).
# It refuses to spend the slot on a CPU rasteriser (llvmpipe, lavapipe, SwiftShader), naming it,
# unless GIBENCH_ALLOW_CPU=1 (the dry run, scripts/gpu-dry-run.sh).
#
# Environment: GIBENCH_SLOT (seconds, `Ns` or `Nm`; default 15m), GIBENCH_SLOT_USED (seconds the
# machine spent before this script), GIBENCH_ALLOW_CPU=1, GIBENCH_PACK_TO=DIR (copy the pack and
# the log there), GIBENCH_FORCE_LOADERS=1 (use the bundle's loaders even where the machine has
# its own: how the dry run tries them).
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
slot=${GIBENCH_SLOT:-15m}
case $slot in
    *m) slot_s=$(( ${slot%m} * 60 )) ;;
    *s) slot_s=${slot%s} ;;
    *) slot_s=$slot ;;
esac
if ! [[ "$slot_s" =~ ^[0-9]+$ ]]; then
    echo "gpu-run.sh: GIBENCH_SLOT='$slot': expected seconds, Ns or Nm (e.g. 15m)" >&2
    exit 2
fi
slot_s=$(( slot_s - ${GIBENCH_SLOT_USED:-0} ))
say() { echo "gpu-run.sh: $*" >&2; }

if [ -f .gpu-bundle/gibench.tar.xz ]; then
    unpacked=$(mktemp -d "${TMPDIR:-/tmp}/gibench-slot.XXXXXX")
    trap 'rm -rf "$unpacked"' EXIT
    xz -dc .gpu-bundle/gibench.tar.xz | tar -C "$unpacked" -xf -
    g="$unpacked/bin/gibench"
    export GIBENCH_ASSETS="$unpacked/scenes${GIBENCH_ASSETS:+:$GIBENCH_ASSETS}"
    say "bundle: $(head -1 .gpu-bundle/BUNDLE.txt 2>/dev/null || echo '(no BUNDLE.txt)')"
    if [ "${GIBENCH_FORCE_LOADERS:-0}" = 1 ] || ! ldconfig -p 2>/dev/null | grep -q 'libvulkan\.so\.1'; then
        # The loaders go beside the binary, not into /: nothing of the machine's is replaced.
        for deb in "$unpacked"/loaders/*.deb; do
            if command -v dpkg-deb >/dev/null; then
                dpkg-deb -x "$deb" "$unpacked/root"
            else
                (mkdir -p "$unpacked/ar" && cd "$unpacked/ar" && ar x "$deb" && mkdir -p ../root &&
                    tar -C ../root -xf data.tar.* && rm -f ./*)
            fi
        done
        libs="$unpacked/root/usr/lib/x86_64-linux-gnu"
        export LD_LIBRARY_PATH="$libs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
        say "the bundle's Vulkan/EGL loaders: $libs"
    fi
elif command -v cargo >/dev/null; then
    cargo build --release
    g="${CARGO_TARGET_DIR:-target}/release/gibench"
else
    say "no bundle (.gpu-bundle/gibench.tar.xz: run 'bash scripts/gpu-bundle.sh' where cargo is, and carry .gpu-bundle) and no cargo to build with"
    exit 2
fi

# NVIDIA's driver may install its ICD and EGL vendor files outside the standard folders.
nv_icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -z "${VK_DRIVER_FILES:-}${VK_ICD_FILENAMES:-}" ] && [ -f "$nv_icd" ] &&
    ! compgen -G "/usr/share/vulkan/icd.d/nvidia*.json" >/dev/null &&
    ! compgen -G "/etc/vulkan/icd.d/nvidia*.json" >/dev/null; then
    export VK_DRIVER_FILES=$nv_icd VK_ICD_FILENAMES=$nv_icd
    say "Vulkan ICD: $nv_icd"
fi
nv_egl=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
if [ -z "${__EGL_VENDOR_LIBRARY_FILENAMES:-}" ] && [ -f "$nv_egl" ] &&
    ! compgen -G "/usr/share/glvnd/egl_vendor.d/*nvidia*.json" >/dev/null; then
    export __EGL_VENDOR_LIBRARY_FILENAMES=$nv_egl
fi

# The device: a GPU, or the slot is not spent.
if [ "${GIBENCH_ALLOW_CPU:-0}" = 1 ]; then
    device=$("$g" adapter) || exit 1
    say "adapter: $device (GIBENCH_ALLOW_CPU=1: a CPU rasteriser is accepted)"
else
    device=$("$g" adapter --require-gpu) || {
        say "not spending the slot on this adapter (GIBENCH_ALLOW_CPU=1 to run anyway)"
        exit 3
    }
    say "adapter: $device"
fi
slug=$("$g" adapter --slug)
folder="results/gpu-$slug"

left=$(( slot_s - ($(date +%s) - start) - 60 ))   # 60 s for packing and the copy-out
if [ "$left" -lt 30 ]; then
    say "only ${left}s of the slot left after the start; nothing run"
    exit 1
fi
say "budget ${left}s, into $folder"
log="results/gpu-$slug.log"
set +e
"$g" reproduce all --budget "${left}s" --quiet --out "$folder" 2>&1 | tee "$log"
status=${PIPESTATUS[0]}
set -e

# One file (or parts of 15 MiB) to bring back.
pack="results/gpu-$slug.tar.xz"
rm -f "$pack" "$pack".part-*
tar -C results -cf - "gpu-$slug" "gpu-$slug.log" | xz -T0 -6 > "$pack"
if [ "$(stat -c %s "$pack")" -gt $((15 << 20)) ]; then
    split -b 15M -d "$pack" "$pack.part-"
    rm "$pack"
    say "packed into $(ls "$pack".part-* | wc -l) parts: cat $pack.part-* > $pack"
fi
if [ -n "${GIBENCH_PACK_TO:-}" ]; then
    mkdir -p "$GIBENCH_PACK_TO"
    cp "$pack"* "$GIBENCH_PACK_TO"/
fi
say "$(ls "$pack"*) ($(( $(date +%s) - start ))s of the slot)"
exit "$status"
