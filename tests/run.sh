#!/usr/bin/env bash
# Runs the test suite headless (README's test command; .ci/run calls it too). With `--long`
# first, runs the long checks instead (the tests marked `#[ignore = "long check: ..."]`: limits,
# scales and walks of many frames), which .ci/run runs after the suite.
# On Linux without a Vulkan driver it installs Mesa's lavapipe software driver when run as
# root, and otherwise stops with the command to run.
set -euo pipefail
cd "$(dirname "$0")/.."

# shellcheck source=tests/lavapipe.sh
source tests/lavapipe.sh
export RUST_LOG="${RUST_LOG:-warn}"
# A fresh build without incremental caches: the test build of a new clone is 17 % faster (77 s
# against 93 s for the workspace's own crates on two cores). Its artifacts have their own
# hashes, so a developer's incremental builds are kept beside them, not replaced.
export CARGO_INCREMENTAL="${CARGO_INCREMENTAL:-0}"

# Without the viewer's window (the `window` feature): the tests drive the viewer headless, and
# the windowing stack is about 80 s of a fresh build. CI's clippy still checks the window code.
if [ "${1:-}" = --long ]; then
    shift
    # `--tests`: the long checks are tests (the doc examples all run in the suite).
    exec cargo test --workspace --locked --no-default-features --tests "$@" -- --ignored
fi
test=(cargo test --workspace --locked --no-default-features)
if [ "$#" -gt 0 ]; then
    exec "${test[@]}" "$@"
fi
# The suite: built once, then `tests/zoo` and the doc tests beside every other test binary
# (cargo runs test binaries one after another, and a binary whose last test runs alone leaves a
# core idle; two streams keep both busy: about a fifth off the suite's running time on two
# cores; the doc tests go with the shorter one). `[!z]*` names every integration test but `zoo`
# (no other test target's name starts with z).
"${test[@]}" --no-run
zoo_log="$(mktemp)"
# One folder of traced references for the run's test binaries, each its own process: a view
# that several judge is traced once (half the suite's tracing; `judging::shared_references`).
# Fresh for this run and removed with it, so only the code that traced a reference reuses it.
shared_references="$(mktemp -d)"
export ZOO_SHARED_REFERENCES="$shared_references"
echo "tests/zoo and the doc tests run beside the other tests; their output follows theirs"
echo "(live in $zoo_log)"
(
    zoo_status=0
    "${test[@]}" --test zoo || zoo_status=$?
    "${test[@]}" --doc || zoo_status=$?
    exit "$zoo_status"
) >"$zoo_log" 2>&1 &
zoo=$!
# A process and its descendants, the children first.
stop_tree() {
    local child
    if command -v pgrep >/dev/null; then
        for child in $(pgrep -P "$1"); do stop_tree "$child"; done
    fi
    kill "$1" 2>/dev/null || true
}
# On any exit (an interrupt too), the zoo stream stops with the script: its test binaries,
# cargo, its shell.
stop_zoo() {
    stop_tree "$zoo"
    rm -f "$zoo_log"
    rm -rf "$shared_references"
}
trap stop_zoo EXIT
trap 'exit 130' INT TERM
status=0
"${test[@]}" --lib --bins --test '[!z]*' || status=$?
wait "$zoo" || status=$?
echo "--- tests/zoo and the doc tests ---"
cat "$zoo_log"
exit "$status"
