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
"$bin" gen --scene "$out/scene" --out "$out/hdl" --ise >/dev/null
