# shellcheck shell=bash
# Sourced by tests/run.sh and tests/web.sh: on Linux without a Vulkan driver, installs Mesa's
# lavapipe software driver when run as root, and otherwise stops with the command to run; then
# points wgpu at it.
if [ "$(uname -s)" = Linux ]; then
    have_driver() {
        local icds
        shopt -s nullglob
        icds=(/usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json /usr/local/share/vulkan/icd.d/*.json)
        shopt -u nullglob
        # (No `grep -q` on a pipe: with pipefail, ldconfig's SIGPIPE would fail the check.)
        [ "${#icds[@]}" -gt 0 ] && [[ "$(ldconfig -p 2>/dev/null)" == *libvulkan.so.1* ]]
    }
    if ! have_driver; then
        install="apt-get update && apt-get install -y mesa-vulkan-drivers libvulkan1"
        if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
            echo "No Vulkan driver found: installing lavapipe ($install)"
            apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq mesa-vulkan-drivers libvulkan1
        else
            echo "No Vulkan driver found. Install Mesa's software driver (lavapipe) first:" >&2
            echo "    sudo $install" >&2
            exit 1
        fi
    fi
    # One software adapter only (lavapipe), not a second GL one.
    export WGPU_BACKEND="${WGPU_BACKEND:-vulkan}"
    export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
fi
