#!/usr/bin/env bash
# Runs a command on a lavapipe that has ray queries (VK_KHR_ray_query, Mesa 24.1 and later),
# so that the ray-tracing library's hardware path runs on a machine without a GPU. On Debian 12,
# whose own Mesa (22.3) has none, it unpacks Mesa and libdrm from the release's backports suite
# (through the system's own Debian mirror) under target/ray-query-driver, leaving the system's
# driver as it is, and points the Vulkan loader there. For example:
#
#   bash tests/ray-query-driver.sh cargo test --no-default-features -p zoo-plugin-rt-shadows \
#       --test judge ray_queries -- --nocapture
set -euo pipefail
cd "$(dirname "$0")/.."
dir="$PWD/target/ray-query-driver"
icd="$dir/lvp_icd.json"

if [ ! -f "$icd" ]; then
    . /etc/os-release
    if [ "${ID:-}" != debian ] || ! command -v apt-get >/dev/null; then
        echo "tests/ray-query-driver.sh unpacks Debian packages; on ${PRETTY_NAME:-this system}," >&2
        echo "install Mesa 24.1 or later (lavapipe) instead and run the command directly." >&2
        exit 1
    fi
    mirror=$(apt-cache policy | awk -v suite="$VERSION_CODENAME/main" '$3 == suite { print $2; exit }')
    if [ -z "$mirror" ]; then
        echo "no Debian mirror for $VERSION_CODENAME in the apt sources (run apt-get update)" >&2
        exit 1
    fi
    mkdir -p "$dir/apt/lists/partial" "$dir/apt/cache/archives/partial" "$dir/root"
    echo "deb $mirror $VERSION_CODENAME-backports main" >"$dir/apt/sources.list"
    apt=(-o "Dir::Etc::SourceList=$dir/apt/sources.list" -o Dir::Etc::SourceParts=/dev/null
        -o "Dir::State::Lists=$dir/apt/lists" -o "Dir::Cache=$dir/apt/cache"
        -o APT::Sandbox::User=root)
    echo "Fetching lavapipe from $VERSION_CODENAME-backports into $dir"
    apt-get "${apt[@]}" update -qq
    (cd "$dir" && apt-get "${apt[@]}" download -qq mesa-vulkan-drivers libdrm2 libdrm-amdgpu1)
    for deb in "$dir"/*.deb; do
        dpkg -x "$deb" "$dir/root"
    done
    lvp=$(find "$dir/root" -name libvulkan_lvp.so | head -n 1)
    sed "s#\"library_path\": \"[^\"]*\"#\"library_path\": \"$lvp\"#" \
        "$dir/root/usr/share/vulkan/icd.d/lvp_icd.json" >"$icd"
fi
libs=$(sed -n 's#.*"library_path": "\(.*\)/libvulkan_lvp.so".*#\1#p' "$icd")

export VK_ICD_FILENAMES="$icd"
export LD_LIBRARY_PATH="$libs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export WGPU_BACKEND="${WGPU_BACKEND:-vulkan}"
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
# The ray-query tests fail rather than skip on this driver.
export ZOO_REQUIRE_RAY_QUERY=1
exec "$@"
