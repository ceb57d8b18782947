#!/usr/bin/env bash
# Rebuilds generated/ (the committed default build: built-in teapot, default parameters).
# Usage: scripts/generate.sh [OUT_DIR]   (default: generated)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-generated}"
cargo build --release --quiet
bin="${CARGO_TARGET_DIR:-target}/release/fxrt"
rm -rf "$out/scene" "$out/hdl"
"$bin" scene --builtin teapot --out "$out/scene" >/dev/null
# The core's measured clock and resources (docs/TIMING.md): a `fxrt synth --family ecp5` report
# of exactly this netlist; `fxrt gen` refuses it once the netlist changed (place and route
# again: scripts/measure-default.sh).
measured=()
if [ -f generated/measured/ecp5-core.json ]; then
    measured=(--measured generated/measured/ecp5-core.json)
fi
"$bin" gen --scene "$out/scene" --out "$out/hdl" --ise "${measured[@]}" >/dev/null
