#!/usr/bin/env bash
# Reproduces the sweeps behind docs/SWEEPS.md and copies its figures into docs/sweeps/.
# Usage: scripts/sweep-figures.sh [WORK_DIR]   (a few minutes on 2 cores; needs a release build)
set -euo pipefail
cd "$(dirname "$0")/.."
work="${1:-target/sweep-figures}"
fxrt=target/release/fxrt
[ -x "$fxrt" ] || cargo build --release
# Seed 001 figures 2.7-2.9 and the edge shift, one parameter at a time around the defaults.
"$fxrt" sweep --builtin teapot,cornell --size 256x256 --n 16,20,24,29 --m 8..16:2,20,24,32 \
    --t 0..24:4 --c 0..16:2 --edge-shift auto,6,8,10,12,14 --one-at-a-time --out "$work/figures"
# C on axis-aligned faces: the Cornell box seen obliquely.
"$fxrt" sweep --builtin cornell --eye=-300,650,-700 --at 278,273,280 --size 256x256 --c 0..8:2,12,16 \
    --out "$work/oblique"
# The cheapest parameters with the defaults' image: a cross product.
"$fxrt" sweep --builtin teapot,cornell --size 256x256 --n 20,22,24,26,29 --m 16..32:2 --c 6,8,12,16 \
    --t 0,8,16 --out "$work/cross"
# Seed 003: E = 10 against the adaptive E, every built-in and shared scene, n from 12 to 29.
shared=()
[ -d ../shared/scenes ] && shared=(../shared/scenes/*.obj)
"$fxrt" sweep "${shared[@]}" --builtin teapot,cornell,jackstraws,thin,random --size 128x128 \
    --n 12,16,20,24,29 --edge-shift auto,6,8,10,12 --out "$work/edge"
# The same at n = 16, where E = 10 clamps most edges, for the plot.
"$fxrt" sweep "${shared[@]}" --builtin teapot,cornell,jackstraws,thin,random --size 128x128 \
    --n 16 --edge-shift auto,6,8,10,12 --out "$work/edge16"
# The scene in external memory: rays per clock and bytes per ray against the memory's latency
# and the node cache's size (the teapot in 8 x 8 tiles).
"$fxrt" sweep --builtin teapot --size 64x64 --memory external --mem-latency 1,40,100,200 \
    --node-cache-kb 4,8,32 --ray-order tiles --core-sim --out "$work/memory"
mkdir -p docs/sweeps
cp "$work/figures/grids/teapot_m.png" "$work/figures/grids/teapot_t.png" "$work/figures/grids/teapot_c.png" docs/sweeps/
cp "$work/oblique/grids/cornell_c.png" docs/sweeps/cornell_oblique_c.png
cp "$work/edge16/plots/error_edge-shift.png" docs/sweeps/error_edge-shift_n16.png
cp "$work/cross/plots/pareto_dsp48e.png" docs/sweeps/pareto_dsp48e.png
for what in rays_per_clock bytes_per_ray; do
    for axis in mem-latency node-cache-kb; do
        cp "$work/memory/plots/memory_${what}_${axis}.png" "docs/sweeps/teapot64_tiles_${what}_${axis}.png"
    done
done
echo "figures in docs/sweeps; reports in $work/*/report.md"
