#!/usr/bin/env bash
# The latency/area/Fmax table of docs/TIMING.md: every module placed and routed on the
# LFE5U-85F (speed 6) at each clock target, one JSON per target in target/fxrt-timing/.
# Takes hours on a 2-core machine (the intersection pipeline and the whole core about a
# quarter of an hour each per target); a bench, not a test.
#   scripts/bench-timing.sh [TARGETS] [MODULES] [extra fxrt synth options...]
#   scripts/bench-timing.sh "100 150 200 250" divider,intersect,closest,traverse,core --builtin cornell
set -euo pipefail
cd "$(dirname "$0")/.."
targets="${1:-100 150 200 250}"
modules="${2:-divider,intersect,closest,traverse,core}"
shift $(( $# > 2 ? 2 : $# ))
cargo build --release --quiet
out=target/fxrt-timing
mkdir -p "$out"
for t in $targets; do
    ./target/release/fxrt synth --family ecp5 --target-mhz "$t" --modules "$modules" \
        --build "$out/build-$t" "$@" > "$out/ecp5-$t.json"
    echo "target $t MHz: $out/ecp5-$t.json" >&2
done
