#!/usr/bin/env bash
# Packs what a bare GPU slot needs beside the checkout: the slot has no Rust toolchain, no
# network, no ../shared and perhaps no Vulkan or EGL loader (docs/fleet.md, "On a GPU machine
# with a short slot"). Run here, where cargo, the scenes and apt are:
#
#   bash scripts/gpu-bundle.sh
#
# It writes .gpu-bundle/ (ignored by git), which the slot's copy of the tree must carry:
#   gibench.tar.xz   bin/gibench: the `dist` profile (the release build without debug
#                    information, stripped);
#                    scenes/: every glTF file the built-in scene descriptors name (scenes/*.json),
#                    from the asset search path, and the scenes' credits (README.md);
#                    loaders/: the Vulkan, EGL and GL loader packages (amd64 .debs:
#                    libvulkan1 libegl1 libglvnd0 libgles2 libgl1 libglx0 libopengl0), which
#                    scripts/gpu-run.sh unpacks beside itself on a machine that has none;
#   BUNDLE.txt       the commit, the binary's and the bundle's sizes, the packages' versions.
# It fails when the bundle and the tracked tree together pass 60 MiB (a slot copies 64 MiB).
set -euo pipefail
cd "$(dirname "$0")/.."
limit=$((60 << 20))
out=.gpu-bundle
loaders=(libvulkan1 libegl1 libglvnd0 libgles2 libgl1 libglx0 libopengl0)

echo "gpu-bundle.sh: cargo build --profile dist --bin gibench" >&2
cargo build --profile dist --bin gibench --quiet
bin="${CARGO_TARGET_DIR:-target}/dist/gibench"

stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/bin" "$stage/scenes" "$stage/loaders" "$out"
cp "$bin" "$stage/bin/gibench"

# The scenes: each file a built-in descriptor names, found on the asset search path as gibench
# finds it ($GIBENCH_ASSETS, scenes/assets/, ../shared/scenes/).
IFS=: read -r -a search <<< "${GIBENCH_ASSETS:-}"
search+=(scenes/assets ../shared/scenes)
files=$(grep -ho '"[^"/]*\.\(glb\|gltf\)"' scenes/*.json | tr -d '"' | sort -u)
for f in $files; do
    found=
    for d in "${search[@]}"; do
        if [ -n "$d" ] && [ -f "$d/$f" ]; then found="$d/$f"; break; fi
    done
    if [ -z "$found" ]; then
        echo "gpu-bundle.sh: scene file '$f' (named in scenes/*.json) is on no asset search path (\$GIBENCH_ASSETS, scenes/assets, ../shared/scenes)" >&2
        exit 1
    fi
    cp "$found" "$stage/scenes/"
    credits="$(dirname "$found")/README.md"
done
[ -f "${credits:-}" ] && cp "$credits" "$stage/scenes/README.md"

# The loaders, amd64 whatever this machine is (the slot is x86-64), from Debian's archive as
# apt here knows it; kept under target/ so that a second bundle needs no network.
debs="${CARGO_TARGET_DIR:-target}/gpu-bundle-debs"
mkdir -p "$debs"
missing=()
for p in "${loaders[@]}"; do
    compgen -G "$debs/${p}_*_amd64.deb" >/dev/null || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    lists=$(mktemp -d)
    mkdir -p "$lists/partial"
    o=(-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 "-oDir::State::Lists=$lists")
    apt-get "${o[@]}" update -qq
    (cd "$debs" && apt-get "${o[@]}" download "${missing[@]}" -qq)
    rm -rf "$lists"
fi
cp "$debs"/*.deb "$stage/loaders/"

echo "gpu-bundle.sh: packing (xz)" >&2
tar -C "$stage" -cf - bin scenes loaders | xz -T0 -6 > "$out/gibench.tar.xz.tmp"
mv "$out/gibench.tar.xz.tmp" "$out/gibench.tar.xz"

bundle=$(stat -c %s "$out/gibench.tar.xz")
tree=$(git ls-files -z | xargs -0 stat -c %s 2>/dev/null | awk '{s += $1} END {print s + 0}')
{
    echo "commit: $(git rev-parse --short HEAD)$([ -z "$(git status --porcelain --untracked-files=no)" ] || echo -dirty)"
    echo "binary: bin/gibench, $(stat -c %s "$bin") bytes (dist profile: no debug information, stripped)"
    echo "scenes: $(cd "$stage/scenes" && ls | paste -sd' ' -)"
    echo "loaders: $(cd "$stage/loaders" && ls | paste -sd' ' -)"
    echo "bundle: gibench.tar.xz, $bundle bytes"
    echo "tracked tree: $tree bytes; bundle and tree: $((bundle + tree)) bytes of at most $limit"
} > "$out/BUNDLE.txt"
cat "$out/BUNDLE.txt" >&2
if [ $((bundle + tree)) -ge "$limit" ]; then
    echo "gpu-bundle.sh: the bundle and the tracked tree are $((bundle + tree)) bytes, over 60 MiB: a slot copies at most 64 MiB" >&2
    exit 1
fi
