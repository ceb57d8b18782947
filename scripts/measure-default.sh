#!/usr/bin/env bash
# Places and routes the default core (built-in teapot, default parameters, 150 MHz target,
# seed 1) on the LFE5U-85F and keeps the report generated/ cites: its clock and resources go
# into generated/hdl's core manifest (scripts/generate.sh). A bench, not a test: about half an
# hour on a 2-core machine. Run it whenever the core's netlist changes, then scripts/generate.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
mkdir -p generated/measured target/measure-default
./target/release/fxrt synth --family ecp5 --builtin teapot --target-mhz 150 --seed 1 --modules core \
    --build target/measure-default > generated/measured/ecp5-core.json
echo "generated/measured/ecp5-core.json written; now run scripts/generate.sh" >&2
