#!/usr/bin/env bash
# Builds the browser viewer into web/dist: the wasm32 build of zoo-web, wasm-bindgen's
# JavaScript glue (the CLI at the version of the crate, installed when missing) and the page.
# `bash web/build.sh --release` for a smaller, faster build (slower to compile).
# Open it with: python3 -m http.server --bind 127.0.0.1 -d web/dist 8000, then
# http://localhost:8000
set -euo pipefail
cd "$(dirname "$0")/.."

profile=dev
folder=debug
if [ "${1:-}" = "--release" ]; then
    profile=release
    folder=release
fi

if ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
    rustup target add wasm32-unknown-unknown
fi
# The CLI must match the wasm-bindgen crate the build links exactly.
version=$(grep -A1 '^name = "wasm-bindgen"$' Cargo.lock | sed -n 's/^version = "\(.*\)"$/\1/p')
if [ -z "$version" ]; then
    echo "Cargo.lock names no wasm-bindgen version" >&2
    exit 1
fi
if [ "$(wasm-bindgen --version 2>/dev/null)" != "wasm-bindgen $version" ]; then
    echo "installing wasm-bindgen-cli $version"
    cargo install wasm-bindgen-cli --version "$version"
fi

cargo build --locked --target wasm32-unknown-unknown -p zoo-web --profile "$profile"
rm -rf web/dist
wasm-bindgen --target web --no-typescript --out-dir web/dist \
    "target/wasm32-unknown-unknown/$folder/zoo_web.wasm"
cp web/index.html web/dist/
echo "built web/dist ($(du -h web/dist/zoo_web_bg.wasm | cut -f1) of wasm)"
