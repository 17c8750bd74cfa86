#!/usr/bin/env bash
# The browser build in a real browser (.ci/run runs it after README's test command). As root,
# installs what is missing: Mesa's lavapipe (for the native frames), Debian's Chromium, and the
# npm driver playwright-core (web/test). Builds the web viewer (web/build.sh) and the native
# command, then web/test/browser-test.mjs serves web/dist on loopback, opens the viewer in
# headless Chromium on SwiftShader's WebGPU for every technique that runs there, and checks
# each third frame against the native lavapipe render of the same scene, view and size.
# `bash tests/web.sh --only sm-pcf,planar` runs some techniques only. Results and frames go to
# target/web-test/.
set -euo pipefail
cd "$(dirname "$0")/.."

# shellcheck source=tests/lavapipe.sh
source tests/lavapipe.sh
export RUST_LOG="${RUST_LOG:-warn}"
export CARGO_INCREMENTAL="${CARGO_INCREMENTAL:-0}"

install_packages() {
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
        echo "installing $*"
        apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$@"
    else
        echo "missing: $*. Install them first: sudo apt-get install -y $*" >&2
        exit 1
    fi
}
command -v chromium >/dev/null || install_packages chromium
command -v npm >/dev/null || install_packages nodejs npm
# playwright-core 1.64 (and node:zlib's crc32) need Node.js 20 or later.
node_major=$(node --version | sed 's/^v\([0-9]*\).*/\1/')
if [ "$node_major" -lt 20 ]; then
    echo "tests/web.sh needs Node.js 20 or later (found $(node --version))" >&2
    exit 1
fi
if [ ! -d web/test/node_modules/playwright-core ]; then
    (cd web/test && npm ci --no-audit --no-fund --loglevel=error)
fi

bash web/build.sh
cargo build --locked --no-default-features --bin shadow-zoo
out=target/web-test
rm -rf "$out"
mkdir -p "$out"
node web/test/browser-test.mjs --dist web/dist --native-bin target/debug/shadow-zoo \
    --chromium "$(command -v chromium)" --out "$out" "$@"
