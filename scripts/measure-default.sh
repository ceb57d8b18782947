#!/usr/bin/env bash
# Places and routes the default core (built-in teapot, default parameters, 150 MHz target,
# placement seeds 1, 2 and 3, two at a time) on the LFE5U-85F and keeps the report generated/
# cites: the median seed's clock and resources, with every seed's and the spread, go into
# generated/hdl's core manifest (scripts/generate.sh). A bench, not a test: about 50 minutes on
# a 2-core machine. Run it whenever the core's netlist changes, then scripts/generate.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
mkdir -p generated/measured target/measure-default
./target/release/fxrt synth --family ecp5 --builtin teapot --target-mhz 150 --seeds 1,2,3 --modules core \
    --build target/measure-default > generated/measured/ecp5-core.json
echo "generated/measured/ecp5-core.json written; now run scripts/generate.sh" >&2
