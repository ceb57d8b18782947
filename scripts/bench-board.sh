#!/usr/bin/env bash
# The ULX3S board top placed, routed and packed for each scene given (default: the built-in
# Cornell box and teapot, default parameters, a 256 × 256 frame from inside the box, the
# 80 MHz board clock, placement seed 1): the bitstreams and nextpnr's timing reports go to
# target/bench-board/<scene>/, and a line per scene says whether the clock was met. A bench,
# not a test: 15 to 50 minutes per scene on a 2-core machine. Extra arguments after `--` go
# to every `fxrt gen` (e.g. -- --board-mhz 90 --pnr-seed 3).
set -euo pipefail
cd "$(dirname "$0")/.."
scenes=()
extra=()
seen_dashes=0
for a in "$@"; do
    if [ "$a" = "--" ]; then seen_dashes=1; continue; fi
    if [ "$seen_dashes" = 1 ]; then extra+=("$a"); else scenes+=("$a"); fi
done
[ ${#scenes[@]} -eq 0 ] && scenes=(cornell teapot)
cargo build --release --quiet
status=0
for s in "${scenes[@]}"; do
    out="target/bench-board/$s"
    rm -rf "$out"
    start=$(date +%s)
    if ./target/release/fxrt gen --board ulx3s --builtin "$s" --out "$out" "${extra[@]}"; then
        verdict="met"
    else
        verdict="NOT met (or failed)"
        status=1
    fi
    echo "$s: $verdict in $(( $(date +%s) - start )) s; report: $(ls "$out"/*_timing.json 2>/dev/null || echo none)"
done
exit $status
