#!/usr/bin/env bash
# The sources' claims and the standard benchmark suites on one GPU machine, in at most eight
# minutes there: `bash tests/gpu-bench.sh [OUT]` (default target/gpu-bench) runs
# `shadow-zoo claims` and then each suite while time is left, and writes their tables under
# OUT (OUT/claims/claims.md, OUT/suites/NAME/bench.md) with an index, OUT/README.md, listing
# what ran, how long it took and what was left out for time.
# It builds the release command unless SHADOW_ZOO_BIN names one already built (a machine
# without network access to crates.io runs a binary built elsewhere).
set -euo pipefail
cd "$(dirname "$0")/.."

out=${1:-target/gpu-bench}
# Seconds for the whole script; a suite starts only with SUITE_SECONDS still left.
BUDGET_SECONDS=${BUDGET_SECONDS:-480}
SUITE_SECONDS=${SUITE_SECONDS:-45}
# The standard suites, cheapest first (on a GPU; lavapipe's order differs).
SUITES=(sm-map-size sm-triangles cube-vs-single sv-vs-sm hybrid-vs-sv ssss-vs-pcss
    lpv-cascades pssm-vista rt-vs-raster virtual-maps gi exact-methods)

bin=${SHADOW_ZOO_BIN:-}
if [ -z "$bin" ]; then
    cargo build --locked --release --no-default-features --bin shadow-zoo
    bin=target/release/shadow-zoo
fi
export RUST_LOG="${RUST_LOG:-warn}"
mkdir -p "$out/suites"
started=$SECONDS
index="$out/README.md"
claims_started=$SECONDS
if timeout "$BUDGET_SECONDS" "$bin" claims --out "$out/claims"; then
    claims="$((SECONDS - claims_started)) s ([claims.md](claims/claims.md))"
else
    claims="stopped after $((SECONDS - claims_started)) s (time or failure)"
fi
{
    echo "# GPU benchmark"
    echo
    echo "- Date: $(date -u +%Y-%m-%d)"
    grep -m1 '^- Adapter:' "$out/claims/claims.md" 2>/dev/null || true
    echo "- claims: $claims"
} > "$index"

for suite in "${SUITES[@]}"; do
    left=$((BUDGET_SECONDS - (SECONDS - started)))
    if [ "$left" -lt "$SUITE_SECONDS" ]; then
        echo "- $suite: not run ($left s left of $BUDGET_SECONDS)" >> "$index"
        continue
    fi
    suite_started=$SECONDS
    if timeout "$left" "$bin" bench --suite "$suite" --no-flicker --out "$out/suites/$suite"; then
        echo "- $suite: $((SECONDS - suite_started)) s ([bench.md](suites/$suite/bench.md))" \
            >> "$index"
    else
        echo "- $suite: stopped after $((SECONDS - suite_started)) s (time or failure)" >> "$index"
    fi
done
echo "- total: $((SECONDS - started)) s" >> "$index"
cat "$index"
