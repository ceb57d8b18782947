#!/usr/bin/env bash
# The whole test suite: installs what it needs, runs every test, and checks that generated/
# is what the current code generates. This is the command README.md and CI use.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cargo build --release --all-targets
cargo test --release
# generated/ must be reproducible, byte for byte.
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
scripts/generate.sh "$tmp"
if ! diff -r -q generated/scene "$tmp/scene" || ! diff -r -q generated/hdl "$tmp/hdl"; then
    echo "generated/ is stale: run scripts/generate.sh and commit the result" >&2
    exit 1
fi
echo "generated/: up to date"
